//! The whole pipeline touches neither the heap nor a new page: the streamed interpolator,
//! unit conversion and the CiA-402 master over the in-process link, against simulated
//! drives, while a planner streams segments through a 4-deep queue and an operator pauses,
//! resumes and overrides the feed through the control queue, and every period's targets go
//! into the trace's queue (`run --trace`; on the virtual clock). A counting global allocator
//! counts the allocations and frees of the loop's thread, and getrusage(RUSAGE_THREAD) its
//! minor page faults.
//!
//! * On a virtual clock (`rt_loop::clock::VirtualClock`), >= 100 000 periods, over the kernel
//!   socketpair link (the socketcan code path) and over the in-memory link of `dnurbs demo`:
//!   the loop, the drives, the planner and the operator take turns in one thread, and the
//!   drives', the planner's and the operator's turns are left out of the counts (counting
//!   paused; their page faults measured and taken off). Deterministic, and as fast as the
//!   machine computes.
//! * In the real-time thread as `dnurbs run` sets it up (memory locked where allowed, stack
//!   prefaulted, the monotonic clock, a lead before each deadline), beside a planner thread
//!   and the drives' thread: what the virtual clock cannot show, that the loop's own thread
//!   set-up, clock and sleeps allocate nothing either. A 2 s program by default;
//!   `NOALLOC_PROGRAM=paper` (`.ci/run`) runs the paper example, 125 000 periods.
//!
//! The counts are per thread, so the tests may run side by side.

mod common;

use drives::link::{CanLink, MemLink, SocketLink};
use nc_follow::{Feeder, Follower, Queues};
use nc_geom::kinematics::MachineKinematics;
use nc_plan::stream::chunks;
use rt_loop::clock::{OsClock, VirtualClock};
use rt_loop::control::{Command, Commands};
use rt_loop::interval::{Queues as IntervalQueues, Recorder};
use rt_loop::os;
use rt_loop::pipeline::{drive_loop, ApproachLimits, BusDrives, Pipeline, Progress, Stage};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

const PERIOD: f64 = 150e-6;
/// The loop wakes this early and rehearses the step before each deadline, so the warm-up
/// and the wait on the clock are inside the counted loop too.
const LEAD_NS: u64 = 20_000;
const PAPER: &str = include_str!("../../tests/data/paper-example.nc");
const SHORT: &str = include_str!("../../tests/data/two-blocks-g2.nc");
/// Counts per mm (X Y Z) and per degree (A C).
const CPU: [f64; 5] = [1e4, 1e4, 1e4, 1e3, 1e3];

/// The operator's script: (ms of running, command).
const SCRIPT: [(u64, Command); 4] = [
    (200, Command::Pause),
    (400, Command::Resume),
    (500, Command::Override(60)),
    (700, Command::Override(100)),
];

#[test]
fn the_full_pipeline_neither_allocates_nor_faults_over_100k_periods_on_a_socketpair() {
    let (link, drive_end) = SocketLink::pair().unwrap();
    prove_on_a_virtual_clock(link, drive_end);
}

#[test]
fn the_full_pipeline_neither_allocates_nor_faults_over_100k_periods_on_the_memory_link() {
    let (link, drive_end) = MemLink::pair(1024);
    prove_on_a_virtual_clock(link, drive_end);
}

#[test]
fn the_real_time_thread_neither_allocates_nor_faults_over_a_run() {
    let (link, drive_end) = MemLink::pair(1024);
    prove_in_the_real_time_thread(link, drive_end);
}

/// The program planned on the small mill at [`PERIOD`], cut for a 4-deep queue: its start
/// and its chunks.
fn planned(src: &str) -> (nc_follow::Start, std::vec::IntoIter<Box<nc_follow::Chunk>>) {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let program = nc_lang::parse(src).unwrap();
    let path = nc_geom::segment::build(&program, &kin, &bl).unwrap();
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).unwrap();
    let (start, list) = chunks(path, &profile, &cfg.hold(), 4);
    (start, list.into_iter())
}

/// The pipeline over `bus`, its follower on `queues` (4 deep, the first chunks pushed).
fn pipeline<'q, L: CanLink>(
    bus: BusDrives<L>,
    queues: &'q mut Queues,
    start: nc_follow::Start,
    source: &mut std::vec::IntoIter<Box<nc_follow::Chunk>>,
) -> (Pipeline<'q, L>, Feeder<'q>) {
    let cfg = nc_plan::fixtures::small_mill(PERIOD).0;
    let (mut feeder, inlet) = queues.split(4);
    feeder.feed(&mut source.by_ref().take(4));
    let follower = Follower::new(
        inlet,
        start,
        MachineKinematics::Paper,
        cfg.rotary,
        cfg.hold(),
    );
    let lim = ApproachLimits {
        velocity: [250.0, 250.0, 250.0, 90.0, 90.0],
        acceleration: [2500.0, 2500.0, 2500.0, 900.0, 900.0],
        jerk: [50000.0, 50000.0, 50000.0, 20000.0, 20000.0],
    };
    let pipeline = Pipeline::new(
        follower,
        vec![bus],
        start.joints,
        PERIOD,
        Some(lim),
        true,
        100_000,
    )
    .unwrap();
    (pipeline, feeder)
}

/// The operator: sends the script's commands as the run's clock passes their times. The
/// clock runs while the program runs, and holds at the resume until the pause has shown:
/// the pause and the resume must not land in one period, the pause never shown.
struct Operator {
    ms: u64,
    next: usize,
    paused_seen: bool,
}

impl Operator {
    fn act(&mut self, progress: &Progress, tx: &mut rt_loop::control::Producer<'_, Command>) {
        while let Some(&(_, c)) = SCRIPT.get(self.next).filter(|s| self.ms >= s.0) {
            tx.enqueue(c).unwrap();
            self.next += 1;
        }
        let snap = progress.snapshot();
        self.paused_seen |= snap.paused;
        let resuming = SCRIPT
            .get(self.next)
            .is_some_and(|s| s.1 == Command::Resume);
        if snap.stage == "running" && (self.paused_seen || !resuming) {
            self.ms += 1;
        }
    }
}

/// The checks after a run of the paper's program (or of `min_cycles` periods of another).
fn check_the_run<L: CanLink>(
    pipeline: &Pipeline<'_, L>,
    cycles: u64,
    min_cycles: u64,
    events: u64,
    faults: i64,
    paper: bool,
) {
    assert_eq!(pipeline.stage(), Stage::Finished);
    assert_eq!(pipeline.reason(), None, "stopped early");
    assert!(cycles >= min_cycles, "only {cycles} periods");
    assert_eq!(
        events, 0,
        "heap allocations or frees in the loop over {cycles} periods"
    );
    assert_eq!(
        faults, 0,
        "minor page faults in the loop over {cycles} periods"
    );
    assert_eq!(pipeline.follower.counters().hard_stops, 0);
    if paper {
        // The drives end at the program's end point (cutter X Y Z = machine X Y Z here).
        let end = [-16963, 1636796, 58369];
        for (axis, node, target, actual) in pipeline.drive_positions() {
            if axis < 3 {
                assert_eq!(target, end[axis], "node {node}");
            }
            assert!(
                (target - actual).abs() <= 1,
                "node {node}: {target} vs {actual}"
            );
        }
    }
}

fn prove_on_a_virtual_clock<L: CanLink, D: CanLink>(link: L, drive_end: D) {
    let (start, mut source) = planned(PAPER);
    let (bus, mut sim) = common::lockstep_bus(
        link,
        drive_end,
        PERIOD,
        CPU,
        common::five_drives(),
        common::LENIENT,
    );
    let mut ring = Box::new(rt_loop::trace::TraceRing::new());
    let mut queues = Queues::new();
    let (mut pipeline, mut feeder) = pipeline(bus, &mut queues, start, &mut source);
    let mut commands = Commands::new();
    let (mut command_tx, command_rx) = commands.split();
    pipeline.set_commands(command_rx);
    // `run --trace`: every period's targets into the trace's queue, drained by the world.
    let (trace_tx, mut trace_rx) = ring.split();
    pipeline.set_trace(trace_tx).expect("five drives fit a row");
    let mut traced = 0u64;
    let mut operator = Operator {
        ms: 0,
        next: 0,
        paused_seen: false,
    };
    let (mut iq, first) = IntervalQueues::new();
    let (full, _full_c) = iq.full.split();
    let (_free_p, free) = iq.free.split();
    let progress = Progress::default();
    let stop = AtomicBool::new(false);
    let t0 = sim.now().as_nanos() as u64;
    let mut periods = 0u64;
    // What the world does between two periods is not the loop's: counting paused, its
    // page faults taken off.
    let mut world_faults = 0;
    let (events, faults) = {
        let world = |t: u64| {
            test_support::pause_this_thread();
            let f0 = os::minor_faults();
            sim.advance_to(Duration::from_nanos(t));
            feeder.feed(&mut source);
            while trace_rx.dequeue().is_some() {
                traced += 1;
            }
            // A millisecond of the operator's clock every 1 / PERIOD periods.
            periods += 1;
            if periods % 7 == 0 {
                operator.act(&progress, &mut command_tx);
            }
            world_faults += os::minor_faults() - f0;
            test_support::resume_this_thread();
        };
        let mut clock = VirtualClock::new(t0, world);
        let _ = os::lock_memory();
        os::prefault_stack(256 * 1024);
        let mut rec = Recorder::new(first, full, free, 100_000_000, t0);
        let f0 = os::minor_faults();
        test_support::arm_this_thread();
        drive_loop(
            &mut rec,
            &mut pipeline,
            &mut clock,
            (PERIOD * 1e9) as u64,
            LEAD_NS,
            &stop,
            &progress,
            2_000_000,
        );
        let e = test_support::disarm_this_thread();
        (e, os::minor_faults() - f0)
    };
    let faults = faults - world_faults;
    feeder.feed(&mut std::iter::empty());
    let cycles = progress.cycles.load(Ordering::SeqCst);
    assert!(
        operator.paused_seen,
        "the pause was never seen in the published status"
    );
    check_the_run(&pipeline, cycles, 100_000, events, faults, true);
    assert_eq!(pipeline.trace_dropped(), 0);
    assert!(
        traced + 1 >= cycles,
        "{traced} rows traced over {cycles} periods"
    );
    let records = sim.take_records();
    assert!(
        records.len() as u64 > 5 * 100_000,
        "{} targets",
        records.len()
    );
}

fn prove_in_the_real_time_thread<L: CanLink + Send, D: CanLink + Send + 'static>(
    link: L,
    drive_end: D,
) {
    let paper = std::env::var("NOALLOC_PROGRAM").is_ok_and(|p| p == "paper");
    let (start, mut source) = planned(if paper { PAPER } else { SHORT });
    let (bus, sim) = common::sim_bus(link, drive_end, PERIOD, CPU);
    let mut queues = Queues::new();
    let (mut pipeline, mut feeder) = pipeline(bus, &mut queues, start, &mut source);
    let (mut iq, first) = IntervalQueues::new();
    let (full, _full_c) = iq.full.split();
    let (_free_p, free) = iq.free.split();
    let progress = Progress::default();
    let finished = AtomicBool::new(false);
    let stop = AtomicBool::new(false);
    let (events, faults) = std::thread::scope(|s| {
        let (progress, finished, stop, pl) = (&progress, &finished, &stop, &mut pipeline);
        let rt = std::thread::Builder::new()
            .stack_size(1 << 20)
            .spawn_scoped(s, move || {
                // Locked memory if allowed (root in CI); the loop must not fault either way.
                let _ = os::lock_memory();
                os::set_timer_slack(1);
                os::prefault_stack(256 * 1024);
                let mut rec = Recorder::new(first, full, free, 100_000_000, os::now());
                os::sleep_until(os::now());
                let f0 = os::minor_faults();
                test_support::arm_this_thread();
                drive_loop(
                    &mut rec,
                    pl,
                    &mut OsClock,
                    (PERIOD * 1e9) as u64,
                    LEAD_NS,
                    stop,
                    progress,
                    2_000_000,
                );
                let e = test_support::disarm_this_thread();
                let f = os::minor_faults() - f0;
                finished.store(true, Ordering::SeqCst);
                (e, f)
            })
            .unwrap();
        // The planner: stream the rest, free what comes back.
        while !finished.load(Ordering::SeqCst) {
            feeder.feed(&mut source);
            std::thread::sleep(Duration::from_millis(1));
        }
        rt.join().unwrap()
    });
    feeder.feed(&mut std::iter::empty());
    sim.finish();
    let cycles = progress.cycles.load(Ordering::SeqCst);
    // 2 s of program at 150 us (or the paper's 18 s), with the approach and the enable and
    // disable cycles.
    let least = if paper { 100_000 } else { 10_000 };
    check_the_run(&pipeline, cycles, least, events, faults, paper);
}
