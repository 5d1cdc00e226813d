//! Fault reactions of the whole pipeline, against simulated drives that fail: the run ends
//! soon after the supervision notices (not after the boot timeout), names the node, and
//! the targets the drives received never step.

mod common;

use drives::master::{FaultCause, Supervision};
use drives::sim::{Faults, SimNodeConfig};
use drives::wire::NodeId;
use rt_loop::pipeline::{ApproachLimits, Stage, StopReason};

const PERIOD: f64 = 0.002;
/// The boot timeout's worth of periods (3 s), also the bound on disabling.
const ENABLE_CYCLES: u64 = 1500;

fn rig(faults: impl Fn(u8) -> Faults, lag_s: f64) -> common::Rig {
    common::Rig {
        period: PERIOD,
        counts_per_unit: [1e4, 1e4, 1e4, 1e3, 1e3],
        sims: (1..=5)
            .map(|n| {
                let mut c = SimNodeConfig::new(NodeId::new(n).unwrap());
                c.faults = faults(n);
                c.lag_s = lag_s;
                c
            })
            .collect(),
        // The supervision of a real machine: 25 periods without feedback is a lost drive.
        sup: Supervision {
            heartbeat_timeout_s: 0.35,
            feedback_timeout_cycles: 25,
        },
        approach: Some(ApproachLimits {
            velocity: [250.0, 250.0, 250.0, 90.0, 90.0],
            acceleration: [2500.0, 2500.0, 2500.0, 900.0, 900.0],
            jerk: [50000.0, 50000.0, 50000.0, 20000.0, 20000.0],
        }),
        enable_cycles: ENABLE_CYCLES,
        max_cycles: 100_000,
        loop_period_ns: None,
        max_overruns: u64::MAX,
    }
}

/// SYNCs: enabling and the approach take under 1000 periods, the program about 10 000.
const SILENT_AT: u64 = 2000;
const FAULT_AT: u64 = 2000;

const PROGRAM: &str = include_str!("../../tests/data/paper-example.nc");

#[test]
fn a_node_that_goes_silent_ends_the_run_after_its_supervision_timeout() {
    // Node 3 (Z) stops answering while the program runs (after the approach).
    let out = common::run_pipeline(
        PROGRAM,
        rig(
            |n| Faults {
                silent_from_sync: (n == 3).then_some(SILENT_AT),
                ..Faults::default()
            },
            0.0,
        ),
    );
    assert_eq!(out.stage, Stage::Finished);
    let Some(StopReason::Fault(f)) = out.reason else {
        panic!("expected a fault, got {:?}", out.reason);
    };
    assert_eq!(f.node, 3, "{f}");
    assert!(
        matches!(
            f.cause,
            FaultCause::NoFeedback(_) | FaultCause::HeartbeatLost { .. }
        ),
        "{f}"
    );
    // Measured before the fix: the run waited the whole enable timeout for the silent node
    // to report a stopped state (SILENT_AT + 25 + 1500 periods and more).
    let last_sync = out.records.iter().map(|r| r.sync).max().unwrap_or(0);
    assert!(
        out.cycles < SILENT_AT + 25 + ENABLE_CYCLES / 3,
        "the run went on for {} periods ({} SYNCs recorded)",
        out.cycles,
        last_sync
    );
}

#[test]
fn after_a_drive_fault_no_target_moves_back() {
    // Drives 30 ms behind their targets; node 2 faults mid-program.
    let out = common::run_pipeline(
        PROGRAM,
        rig(
            |n| Faults {
                fault_at_sync: (n == 2).then_some(FAULT_AT),
                ..Faults::default()
            },
            0.03,
        ),
    );
    let Some(StopReason::Fault(f)) = out.reason else {
        panic!("expected a fault, got {:?}", out.reason);
    };
    assert_eq!(f.node, 2, "{f}");
    for node in 1u8..=5 {
        let mut mine: Vec<_> = out.records.iter().filter(|r| r.node == node).collect();
        mine.sort_by_key(|r| r.sync);
        // The largest step of the program itself, then no larger step after the fault and
        // none against the direction of motion beyond it.
        let before = mine
            .windows(2)
            .filter(|w| w[1].sync < FAULT_AT)
            .map(|w| (w[1].target_counts - w[0].target_counts).abs())
            .max()
            .unwrap_or(0);
        for w in mine.windows(2).filter(|w| w[1].sync >= FAULT_AT) {
            let step = (w[1].target_counts - w[0].target_counts).abs();
            assert!(
                step <= before,
                "node {node}: target stepped {step} counts at SYNC {} (largest program step {before})",
                w[1].sync
            );
        }
    }
}

#[test]
fn too_many_consecutive_overruns_stop_the_run_along_the_path() {
    // A 1 us loop period no cycle can meet: every period overruns. With at most 10 in a row
    // allowed, the run stops along the path and disables the drives.
    let mut r = rig(|_| Faults::default(), 0.0);
    r.loop_period_ns = Some(1_000);
    r.max_overruns = 10;
    let out = common::run_pipeline(PROGRAM, r);
    assert_eq!(out.stage, Stage::Finished);
    assert!(
        matches!(out.reason, Some(StopReason::Overruns(n)) if n == 11),
        "{:?}",
        out.reason
    );
    // Stopped along the path: no target ever steps by more than the program's own largest.
    for node in 1u8..=5 {
        let mut mine: Vec<_> = out.records.iter().filter(|r| r.node == node).collect();
        mine.sort_by_key(|r| r.sync);
        let steps: Vec<i32> = mine
            .windows(2)
            .map(|w| (w[1].target_counts - w[0].target_counts).abs())
            .collect();
        assert!(steps.iter().all(|&s| s < 10_000), "node {node}: {steps:?}");
    }
}
