//! The limits on what the drives receive (issue "Limits guaranteed": "the same check runs
//! over `dnurbs run` for a sample"). A sample of programs goes through the whole `run`
//! pipeline: planner, segment queue, real-time `Follower`, the approach move from where the
//! drives stand, count conversion and CiA-402 RPDOs on the in-memory link to simulated
//! drives, which record the target that took effect at every SYNC. Velocity and
//! acceleration of every axis are then measured on those recorded targets alone, by finite
//! differences per SYNC at the period, padded with the rest before and after.
//!
//! Targets are whole counts (1e6 per mm, 1e5 per degree here), so each is within half a
//! count of the exact setpoint: the bound checked is the limit plus what rounding can add
//! (1 count per period for velocity, 2 counts per period squared for acceleration). Jerk is
//! not checked here: the recorded stream does not say where blocks meet. The check does not
//! depend on timing: a late period delays a SYNC, it does not change the targets' sequence.

mod common;

use drives::link::MemLink;
use drives::sim::Record;
use nc::kinematics::MachineKinematics;
use nc::stream::{chunks, Follower, HoldConfig, Queues};
use rt_loop::interval::{Queues as IntervalQueues, Recorder};
use rt_loop::os;
use rt_loop::pipeline::{drive_loop, ApproachLimits, Pipeline, Progress, Stage};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

const PERIOD: f64 = 0.001;
/// Counts per mm (X Y Z) and per degree (A C).
const CPU: [f64; 5] = [1e6, 1e6, 1e6, 1e5, 1e5];
/// nc::fixtures::small_mill: velocity, acceleration (mm or degrees, s).
const LIMITS: [(f64, f64); 5] = [
    (250.0, 2500.0),
    (250.0, 2500.0),
    (250.0, 2500.0),
    (90.0, 900.0),
    (90.0, 900.0),
];

const SAMPLE: [(&str, &str); 4] = [
    (
        "butterfly",
        include_str!("../../tests/data/classics/butterfly.nc"),
    ),
    (
        "fan-5axis",
        include_str!("../../tests/data/classics/fan-5axis.nc"),
    ),
    (
        "dual-spline",
        include_str!("../../tests/data/classics/dual-spline.nc"),
    ),
    (
        "tight-curvature",
        include_str!("../../tests/data/tight-curvature.nc"),
    ),
];

/// Run one program through the pipeline; the targets each node received, by SYNC.
fn run(src: &str) -> Vec<Vec<i32>> {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc::fixtures::small_mill(PERIOD);
    let program = nc::parse::parse(src).unwrap();
    let path = nc::segment::build(&program, &kin, &bl).unwrap();
    let profile = nc::plan::plan(&path, &kin, &cfg).unwrap();
    let (start, list) = chunks(path, &profile);
    let mut source = list.into_iter();
    let (link, drive_end) = MemLink::pair(1024);
    let (bus, sim) = common::sim_bus(link, drive_end, PERIOD, CPU);
    let mut queues = Queues::new();
    let (mut feeder, inlet) = queues.split(64);
    feeder.feed(&mut source);
    let follower = Follower::new(inlet, start, kin, cfg.rotary, HoldConfig::from_plan(&cfg));
    let lim = ApproachLimits {
        velocity: LIMITS.map(|l| l.0),
        acceleration: LIMITS.map(|l| l.1),
        jerk: [50000.0, 50000.0, 50000.0, 20000.0, 20000.0],
    };
    let mut pipeline = Pipeline::new(
        follower,
        vec![bus],
        start.joints,
        PERIOD,
        Some(lim),
        true,
        1000,
    )
    .unwrap();
    let (mut iq, first) = IntervalQueues::new();
    let (full, _full_c) = iq.full.split();
    let (_free_p, free) = iq.free.split();
    let progress = Progress::default();
    let finished = AtomicBool::new(false);
    let stop = AtomicBool::new(false);
    std::thread::scope(|s| {
        let (progress, finished, stop, pl) = (&progress, &finished, &stop, &mut pipeline);
        let rt = s.spawn(move || {
            let mut rec = Recorder::new(first, full, free, 100_000_000, os::now());
            drive_loop(
                &mut rec,
                pl,
                (PERIOD * 1e9) as u64,
                50_000,
                stop,
                progress,
                200_000,
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
    let records = sim.finish();
    assert_eq!(pipeline.stage(), Stage::Finished);
    assert_eq!(pipeline.reason(), None, "stopped early");
    by_node(&records)
}

/// The targets of each node in SYNC order, one per SYNC every node saw.
fn by_node(records: &[Record]) -> Vec<Vec<i32>> {
    let mut out = vec![Vec::new(); 5];
    let mut rows: Vec<&Record> = records.iter().collect();
    rows.sort_by_key(|r| (r.sync, r.node));
    for r in rows {
        out[usize::from(r.node) - 1].push(r.target_counts);
    }
    out
}

#[test]
fn the_targets_the_drives_received_hold_every_velocity_and_acceleration_limit() {
    for (name, src) in SAMPLE {
        let targets = run(src);
        let n = targets[0].len();
        assert!(n > 1000, "{name}: only {n} SYNCs recorded");
        for (j, t) in targets.iter().enumerate() {
            assert_eq!(t.len(), n, "{name}: node {} missed SYNCs", j + 1);
            let mut q: Vec<f64> = vec![f64::from(t[0]); 2];
            q.extend(t.iter().map(|&c| f64::from(c)));
            q.extend([f64::from(t[n - 1]); 2]);
            let (vmax, amax) = LIMITS[j];
            let count = 1.0 / CPU[j];
            let mut worst = (0.0f64, 0.0f64);
            for w in q.windows(3) {
                let v = (w[2] - w[1]).abs() / CPU[j] / PERIOD;
                let a = (w[2] - 2.0 * w[1] + w[0]).abs() / CPU[j] / (PERIOD * PERIOD);
                worst = (worst.0.max(v / vmax), worst.1.max(a / amax));
                assert!(
                    v <= vmax * (1.0 + 1e-9) + count / PERIOD,
                    "{name}: axis {j} velocity {v} > {vmax}"
                );
                assert!(
                    a <= amax * (1.0 + 1e-9) + 2.0 * count / (PERIOD * PERIOD),
                    "{name}: axis {j} acceleration {a} > {amax}"
                );
            }
            eprintln!(
                "{name}: axis {j}: {n} targets, v {:.1} %, a {:.1} % of the limit",
                worst.0 * 100.0,
                worst.1 * 100.0
            );
        }
    }
}
