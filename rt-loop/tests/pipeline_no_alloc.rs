//! The whole pipeline touches neither the heap nor a new page: >= 100 000 periods of the
//! streamed interpolator, unit conversion and the CiA-402 master over the in-process link,
//! against simulated drives in another thread, while a planner thread streams segments
//! through a 4-deep queue. A counting global allocator counts allocations and frees made
//! by the loop's own thread (the planner and the drives allocate freely in theirs), and
//! getrusage(RUSAGE_THREAD) counts its minor page faults. Meanwhile an operator pauses,
//! resumes and overrides the feed through the control queue. Run once over the kernel
//! socketpair link (the socketcan code path) and once over the in-memory link of
//! `dnurbs demo`; the counts are per thread, so the two tests may run side by side.

mod common;

use drives::link::{CanLink, MemLink, SocketLink};
use nc_follow::{Follower, Queues};
use nc_geom::kinematics::MachineKinematics;
use nc_plan::stream::chunks;
use rt_loop::control::{Command, Commands};
use rt_loop::interval::{Queues as IntervalQueues, Recorder};
use rt_loop::os;
use rt_loop::pipeline::{drive_loop, ApproachLimits, Pipeline, Progress, Stage};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

const PERIOD: f64 = 150e-6;
/// The loop wakes this early and rehearses the step before each deadline, so the warm-up
/// and the wait on the clock are inside the counted loop too.
const LEAD_NS: u64 = 20_000;
const PAPER: &str = include_str!("../../tests/data/paper-example.nc");

#[test]
fn the_full_pipeline_neither_allocates_nor_faults_over_100k_periods_on_a_socketpair() {
    let (link, drive_end) = SocketLink::pair().unwrap();
    prove(link, drive_end);
}

#[test]
fn the_full_pipeline_neither_allocates_nor_faults_over_100k_periods_on_the_memory_link() {
    let (link, drive_end) = MemLink::pair(1024);
    prove(link, drive_end);
}

fn prove<L: CanLink + Send, D: CanLink + Send + 'static>(link: L, drive_end: D) {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let program = nc_lang::parse(PAPER).unwrap();
    let path = nc_geom::segment::build(&program, &kin, &bl).unwrap();
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).unwrap();
    let (start, list) = chunks(path, &profile, &cfg.hold(), 4);
    let mut source = list.into_iter();

    let (bus, sim) = common::sim_bus(link, drive_end, PERIOD, [1e4, 1e4, 1e4, 1e3, 1e3]);

    let mut queues = Queues::new();
    let (mut feeder, inlet) = queues.split(4);
    feeder.feed(&mut source.by_ref().take(4));
    let follower = Follower::new(inlet, start, kin, cfg.rotary, cfg.hold());
    let lim = ApproachLimits {
        velocity: [250.0, 250.0, 250.0, 90.0, 90.0],
        acceleration: [2500.0, 2500.0, 2500.0, 900.0, 900.0],
        jerk: [50000.0, 50000.0, 50000.0, 20000.0, 20000.0],
    };
    let mut pipeline = Pipeline::new(
        follower,
        vec![bus],
        start.joints,
        PERIOD,
        Some(lim),
        true,
        100_000,
    )
    .unwrap();
    // The operator's commands arrive through the lock-free queue during the counted loop.
    let mut commands = Commands::new();
    let (mut command_tx, command_rx) = commands.split();
    pipeline.set_commands(command_rx);
    let script = [
        (200, Command::Pause),
        (400, Command::Resume),
        (500, Command::Override(60)),
        (700, Command::Override(100)),
    ];
    let mut paused_seen = false;

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
        // The planner: stream the rest, free what comes back; the operator: the script. Its
        // clock runs while the program runs, and holds at the resume until the pause has
        // shown: on a loaded machine the drives' set-up can outlast the whole script, and
        // the pause and the resume would then land in one period, the pause never shown.
        let (mut ms, mut next) = (0, 0);
        while !finished.load(Ordering::SeqCst) {
            feeder.feed(&mut source);
            while let Some(&(_, c)) = script.get(next).filter(|s| ms >= s.0) {
                command_tx.enqueue(c).unwrap();
                next += 1;
            }
            let snap = progress.snapshot();
            paused_seen |= snap.paused;
            std::thread::sleep(Duration::from_millis(1));
            let resuming = script.get(next).is_some_and(|s| s.1 == Command::Resume);
            if snap.stage == "running" && (paused_seen || !resuming) {
                ms += 1;
            }
        }
        rt.join().unwrap()
    });
    feeder.feed(&mut std::iter::empty());
    let records = sim.finish();

    let cycles = progress.cycles.load(Ordering::SeqCst);
    assert!(
        paused_seen,
        "the pause was never seen in the published status"
    );
    assert_eq!(pipeline.stage(), Stage::Finished);
    assert_eq!(pipeline.reason(), None, "stopped early");
    assert!(cycles >= 100_000, "only {cycles} periods");
    assert_eq!(
        events, 0,
        "heap allocations or frees in the loop over {cycles} periods"
    );
    assert_eq!(
        faults, 0,
        "minor page faults in the loop over {cycles} periods"
    );
    assert_eq!(pipeline.follower.counters().hard_stops, 0);
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
    assert!(
        records.len() as u64 > 5 * 100_000,
        "{} targets",
        records.len()
    );
}
