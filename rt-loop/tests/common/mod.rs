//! What the pipeline tests stand on: five CiA-402 drives (nodes 1..=5 for X Y Z A C),
//! simulated on the far end of a link, configured and taken over by a master.
#![allow(dead_code)]

use drives::link::{CanLink, MemLink};
use drives::master::{configure, Master, SetupOptions, Supervision};
use drives::sim::{Record, SimNodeConfig, SimThread};
use drives::wire::NodeId;
use machine::bus::Drive;
use nc_follow::{Follower, Queues};
use nc_geom::kinematics::MachineKinematics;
use nc_plan::stream::chunks;
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
/// `drive_end`; the master on `link` has configured them, with [`LENIENT`] supervision.
pub fn sim_bus<L: CanLink, D: CanLink + Send + 'static>(
    link: L,
    drive_end: D,
    period: f64,
    counts_per_unit: [f64; 5],
) -> (BusDrives<L>, SimThread) {
    let sims = (1..=5)
        .map(|n| SimNodeConfig::new(NodeId::new(n).unwrap()))
        .collect();
    sim_bus_with(link, drive_end, period, counts_per_unit, sims, LENIENT)
}

/// [`sim_bus`] with the simulated nodes (1..=5, with their faults) and supervision given.
pub fn sim_bus_with<L: CanLink, D: CanLink + Send + 'static>(
    mut link: L,
    drive_end: D,
    period: f64,
    counts_per_unit: [f64; 5],
    sims: Vec<SimNodeConfig>,
    sup: Supervision,
) -> (BusDrives<L>, SimThread) {
    let drives: Vec<Drive> = (0..5)
        .map(|axis| Drive {
            axis,
            bus: 0,
            node: axis as u8 + 1,
            counts_per_unit: counts_per_unit[axis],
            sign: 1,
            offset: 0,
        })
        .collect();
    let nodes: Vec<NodeId> = (1..=5).map(|n| NodeId::new(n).unwrap()).collect();
    // SCHED_FIFO where allowed (one below the loop's): on a loaded machine a starved drive
    // thread would miss its feedback deadline, a fault these tests did not inject.
    let sim = SimThread::start_with(drive_end, sims, period, Duration::from_micros(20), || {
        let _ = os::set_fifo(79);
    })
    .unwrap();
    let mut opts = SetupOptions::new(period);
    opts.boot_timeout = Duration::from_secs(5);
    let initial = configure(&mut link, &nodes, &opts, &mut |_| {}).unwrap();
    let master = Master::new(link, &nodes, &initial, sup, os::now() as f64 * 1e-9).unwrap();
    (BusDrives::new(master, &drives).unwrap(), sim)
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
    /// The loop's period when it is not the plan's (a period no cycle can meet), ns.
    pub loop_period_ns: Option<u64>,
    /// `[realtime] max_consecutive_overruns`.
    pub max_overruns: u64,
}

/// Plan `src` on the small mill at the rig's period and run it: planner feeding the
/// segment queue from this thread, `drive_loop` in another, to the simulated drives.
pub fn run_pipeline(src: &str, rig: Rig) -> PipelineRun {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(rig.period);
    let program = nc_lang::parse(src).unwrap();
    let path = nc_geom::segment::build(&program, &kin, &bl).unwrap();
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).unwrap();
    let (start, list) = chunks(path, &profile, &cfg.hold(), 64);
    let mut source = list.into_iter();
    let (link, drive_end) = MemLink::pair(1024);
    let (bus, sim) = sim_bus_with(
        link,
        drive_end,
        rig.period,
        rig.counts_per_unit,
        rig.sims,
        rig.sup,
    );
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
    let (full, _full_c) = iq.full.split();
    let (_free_p, free) = iq.free.split();
    let progress = Progress::default();
    let finished = AtomicBool::new(false);
    let stop = AtomicBool::new(false);
    std::thread::scope(|s| {
        let (progress, finished, stop, pl) = (&progress, &finished, &stop, &mut pipeline);
        let rt = s.spawn(move || {
            let _ = os::set_fifo(80);
            let mut rec = Recorder::new(first, full, free, 100_000_000, os::now());
            drive_loop(
                &mut rec,
                pl,
                rig.loop_period_ns.unwrap_or((rig.period * 1e9) as u64),
                if rig.loop_period_ns.is_some() {
                    0
                } else {
                    50_000
                },
                stop,
                progress,
                rig.max_cycles,
            );
            finished.store(true, Ordering::SeqCst);
        });
        while !finished.load(Ordering::SeqCst) {
            feeder.feed(&mut source);
            std::thread::sleep(Duration::from_millis(1));
        }
        rt.join().unwrap();
    });
    feeder.feed(&mut std::iter::empty());
    PipelineRun {
        stage: pipeline.stage(),
        reason: pipeline.reason(),
        records: sim.finish(),
        cycles: progress.cycles.load(Ordering::SeqCst),
    }
}
