//! What the pipeline tests stand on: five CiA-402 drives (nodes 1..=5 for X Y Z A C),
//! simulated on the far end of a link, configured and taken over by a master; and the whole
//! pipeline run on a virtual clock ([`run_pipeline`]): the loop, the planner's pushes and the
//! drives' answers take turns, a period at a time, as fast as the machine computes them.
#![allow(dead_code)]

use drives::link::{CanLink, MemLink};
use drives::master::{configure, Clock, Master, SetupOptions, Supervision, WallClock};
use drives::sim::{Lockstep, Record, SimNodeConfig, SimThread};
use drives::wire::NodeId;
use machine::bus::Drive;
use nc_follow::{Follower, Queues};
use nc_geom::kinematics::MachineKinematics;
use nc_plan::stream::chunks;
use rt_loop::clock::VirtualClock;
use rt_loop::interval::{Queues as IntervalQueues, Recorder};
use rt_loop::os;
use rt_loop::pipeline::{
    drive_loop, ApproachLimits, BusDrives, Pipeline, Progress, Stage, StopReason,
};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Lenient supervision: the tests are about function, not timing, and must hold on a
/// loaded machine.
pub const LENIENT: Supervision = Supervision {
    heartbeat_timeout_s: 30.0,
    feedback_timeout_cycles: 1_000_000,
};

/// Drives for X Y Z A C on nodes 1..=5 with these counts per mm or degree, simulated on
/// `drive_end` in a thread of their own; the master on `link` has configured them, with
/// [`LENIENT`] supervision.
pub fn sim_bus<L: CanLink, D: CanLink + Send + 'static>(
    link: L,
    drive_end: D,
    period: f64,
    counts_per_unit: [f64; 5],
) -> (BusDrives<L>, SimThread) {
    // SCHED_FIFO where allowed (one below the loop's): on a loaded machine a starved drive
    // thread would miss its feedback deadline, a fault these tests did not inject.
    let sim = SimThread::start_with(
        drive_end,
        five_drives(),
        period,
        Duration::from_micros(20),
        || {
            let _ = os::set_fifo(79);
        },
    )
    .unwrap();
    let now = |_: &WallClock| os::now() as f64 * 1e-9;
    let bus = take_over(
        link,
        &mut WallClock::default(),
        now,
        period,
        counts_per_unit,
        LENIENT,
    );
    (bus, sim)
}

/// [`sim_bus`] on a virtual clock: the drives `sims` on `drive_end`, set up by the master on
/// `link` with its waits on the drives' clock, and supervision `sup`.
pub fn lockstep_bus<L: CanLink, D: CanLink>(
    link: L,
    drive_end: D,
    period: f64,
    counts_per_unit: [f64; 5],
    sims: Vec<SimNodeConfig>,
    sup: Supervision,
) -> (BusDrives<L>, Lockstep<D>) {
    let mut sim = Lockstep::new(drive_end, sims, period);
    let now = |s: &Lockstep<D>| s.now().as_secs_f64();
    let bus = take_over(link, &mut sim, now, period, counts_per_unit, sup);
    (bus, sim)
}

/// The master on `link` sets up drives 1..=5, its waits on `clock`, and takes them over at
/// `now(clock)` s with supervision `sup`.
fn take_over<L: CanLink, C: Clock>(
    mut link: L,
    clock: &mut C,
    now: impl FnOnce(&C) -> f64,
    period: f64,
    counts_per_unit: [f64; 5],
    sup: Supervision,
) -> BusDrives<L> {
    let nodes: Vec<NodeId> = (1..=5).map(|n| NodeId::new(n).unwrap()).collect();
    let mut opts = SetupOptions::new(period);
    opts.boot_timeout = Duration::from_secs(5);
    let initial = configure(&mut link, &nodes, &opts, clock, &mut |_| {}).unwrap();
    let master = Master::new(link, &nodes, &initial, sup, now(clock)).unwrap();
    BusDrives::new(master, &axis_drives(counts_per_unit)).unwrap()
}

/// Drives for X Y Z A C on nodes 1..=5, as simulated nodes.
pub fn five_drives() -> Vec<SimNodeConfig> {
    (1..=5)
        .map(|n| SimNodeConfig::new(NodeId::new(n).unwrap()))
        .collect()
}

/// A program run through the whole `run` pipeline on the in-memory link.
pub struct PipelineRun {
    pub stage: Stage,
    pub reason: Option<StopReason>,
    /// Every target the simulated drives took, with the SYNC it came with.
    pub records: Vec<Record>,
    /// Periods the loop ran.
    pub cycles: u64,
}

/// Everything [`run_pipeline`] needs besides the program.
pub struct Rig {
    pub period: f64,
    pub counts_per_unit: [f64; 5],
    pub sims: Vec<SimNodeConfig>,
    pub sup: Supervision,
    pub approach: Option<ApproachLimits>,
    /// Cycles to wait for the drives to enable (and to disable).
    pub enable_cycles: u64,
    /// A bound on the loop, a last resort.
    pub max_cycles: u64,
    /// The loop's period when it is not the plan's (a period no cycle can meet), ns; every
    /// read of the clock then takes 1 us of it.
    pub loop_period_ns: Option<u64>,
    /// `[realtime] max_consecutive_overruns`.
    pub max_overruns: u64,
}

fn axis_drives(counts_per_unit: [f64; 5]) -> Vec<Drive> {
    (0..5)
        .map(|axis| Drive {
            axis,
            bus: 0,
            node: axis as u8 + 1,
            counts_per_unit: counts_per_unit[axis],
            sign: 1,
            offset: 0,
            guard: machine::bus::Guard::default(),
            home: None,
        })
        .collect()
}

/// Plan `src` on the small mill at the rig's period and run it through the whole pipeline on
/// a virtual clock: set-up, then `drive_loop`, the planner feeding the segment queue and
/// the drives answering while the loop sleeps.
pub fn run_pipeline(src: &str, rig: Rig) -> PipelineRun {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(rig.period);
    let program = nc_lang::parse(src).unwrap();
    let path = nc_geom::segment::build(&program, &kin, &bl).unwrap();
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).unwrap();
    let (start, list) = chunks(path, &profile, &cfg.hold(), 64);
    let mut source = list.into_iter();
    let (link, drive_end) = MemLink::pair(1024);
    let (bus, mut sim) = lockstep_bus(
        link,
        drive_end,
        rig.period,
        rig.counts_per_unit,
        rig.sims,
        rig.sup,
    );
    let t0 = sim.now().as_nanos() as u64;
    let mut queues = Queues::new();
    let (mut feeder, inlet) = queues.split(64);
    feeder.feed(&mut source);
    let follower = Follower::new(inlet, start, kin, cfg.rotary, cfg.hold());
    let mut pipeline = Pipeline::new(
        follower,
        vec![bus],
        start.joints,
        rig.period,
        rig.approach,
        true,
        rig.enable_cycles,
    )
    .unwrap();
    pipeline.set_max_consecutive_overruns(rig.max_overruns);
    let (mut iq, first) = IntervalQueues::new();
    let (full, mut full_c) = iq.full.split();
    let (mut free_p, free) = iq.free.split();
    let progress = Progress::default();
    let stop = AtomicBool::new(false);
    {
        let world = |t: u64| {
            // What the other threads do while the loop sleeps: the drives answer the
            // period's frames, the reporter hands the intervals back, the planner pushes.
            sim.advance_to(std::time::Duration::from_nanos(t));
            while let Some(mut iv) = full_c.dequeue() {
                iv.stats.clear();
                let _ = free_p.enqueue(iv);
            }
            feeder.feed(&mut source);
        };
        let mut clock = VirtualClock::new(t0, world);
        if rig.loop_period_ns.is_some() {
            clock = clock.reads_take(1_000);
        }
        let mut rec = Recorder::new(first, full, free, 100_000_000, t0);
        drive_loop(
            &mut rec,
            &mut pipeline,
            &mut clock,
            rig.loop_period_ns.unwrap_or((rig.period * 1e9) as u64),
            0,
            &stop,
            &progress,
            rig.max_cycles,
        );
    }
    feeder.feed(&mut std::iter::empty());
    PipelineRun {
        stage: pipeline.stage(),
        reason: pipeline.reason(),
        records: sim.take_records(),
        cycles: progress.cycles.load(Ordering::SeqCst),
    }
}
