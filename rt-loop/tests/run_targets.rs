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

use drives::sim::{Record, SimNodeConfig};
use drives::wire::NodeId;
use rt_loop::pipeline::{ApproachLimits, Stage};

const PERIOD: f64 = 0.001;
/// Counts per mm (X Y Z) and per degree (A C).
const CPU: [f64; 5] = [1e6, 1e6, 1e6, 1e5, 1e5];
/// nc_plan::fixtures::small_mill: velocity, acceleration (mm or degrees, s).
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
    let out = common::run_pipeline(
        src,
        common::Rig {
            period: PERIOD,
            counts_per_unit: CPU,
            sims: (1..=5)
                .map(|n| SimNodeConfig::new(NodeId::new(n).unwrap()))
                .collect(),
            sup: common::LENIENT,
            approach: Some(ApproachLimits {
                velocity: LIMITS.map(|l| l.0),
                acceleration: LIMITS.map(|l| l.1),
                jerk: [50000.0, 50000.0, 50000.0, 20000.0, 20000.0],
            }),
            enable_cycles: 1000,
            max_cycles: 200_000,
            loop_period_ns: None,
            max_overruns: u64::MAX,
        },
    );
    assert_eq!(out.stage, Stage::Finished);
    assert_eq!(out.reason, None, "stopped early");
    by_node(&out.records)
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
