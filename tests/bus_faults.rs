//! Bus faults met mid-program, each with its reaction (`drives::master::health`): a warning
//! is counted and the run goes on; error passive and a lost-arbitration storm hold the feed
//! until the operator resumes; a TX timeout and a transmit queue full three periods in a
//! row stop along the path; bus-off, a controller restart and the interface going down
//! quick-stop every drive. Each reaction is named in the report with the counts.
//!
//! On simulated time: the paper example on the demo machine's simulated drives (the stages
//! of `dnurbs run`), the faults injected into the in-memory link (`MemLink::faults`) at a
//! moment of the program, as a SocketCAN interface would deliver them. The targets are
//! checked per axis by finite differences at the period from the run's trace (every period's
//! targets as sent), up to the quick stop where there is one: from there the drives stop by
//! their own ramp and the targets are held.

mod common;

use dnurbs_tools::demo::DEMO_PROGRAM;
use dnurbs_tools::report::Report;
use drives::link::errors::*;
use drives::link::LinkFaults;
use drives::sim::Record;
use rt_loop::control::{Command, Producer, Snapshot};
use std::sync::Arc;

/// Running periods before the fault: well inside the program.
const AT: u64 = 1500;

/// What a run met: the report, the trace's targets (period by period, in drive order),
/// the drives' records, and the periods the operator saw the path paused.
struct Met {
    report: Report,
    sent: Vec<Vec<i32>>,
    records: Vec<Record>,
    paused: u64,
}

/// The paper example with `inject(k, snapshot, faults, commands)` called every period,
/// `k` the running periods so far.
fn run(
    name: &str,
    mut inject: impl FnMut(u64, &Snapshot, &LinkFaults, &mut Producer<'_, Command>),
) -> Met {
    let machine = dnurbs_tools::demo::demo_machine().expect("the demo machine");
    let file = common::temp(&format!("{name}.csv"));
    let opts = dnurbs_tools::run::RunOptions {
        trace: Some(file.clone()),
        ..common::run_options("paper-example.nc", None)
    };
    let sims = common::simulated_buses(&machine, |_| Default::default());
    let faults: Arc<LinkFaults> = sims[0].0.faults();
    let mut running = 0;
    let mut paused = 0;
    let (r, records) = dnurbs_tools::run::simulated::run_simulated(
        dnurbs_tools::feed::Input::Text(DEMO_PROGRAM.as_bytes().into()),
        &machine,
        sims,
        &opts,
        |p, tx| {
            let s = p.snapshot();
            if s.stage == "running" {
                running += 1;
            }
            if s.paused {
                paused += 1;
            }
            inject(running, &s, &faults, tx);
        },
    )
    .expect("the run starts");
    let report = r.report("paper-example.nc", &machine.name);
    let text = std::fs::read_to_string(&file).expect("the trace");
    let _ = std::fs::remove_file(&file);
    let nodes = machine.drives.len();
    let sent = text
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            f[8..8 + nodes].iter().map(|c| c.parse().unwrap()).collect()
        })
        .collect();
    Met {
        report,
        sent,
        records,
        paused,
    }
}

/// Every axis within its velocity and acceleration limits over `sent`.
fn within_limits(name: &str, sent: &[Vec<i32>]) {
    let machine = dnurbs_tools::demo::demo_machine().unwrap();
    let setup = dnurbs_tools::setup::MachineSetup::new(&machine);
    common::within_the_limits_at_the_period(name, &machine, &setup.limits, sent);
}

fn error_frame(class: u32, crtl: u8) -> (u32, [u8; 8]) {
    (CAN_ERR_FLAG | class, [0, crtl, 0, 0, 0, 0, 0, 0])
}

/// Inject the error frame once, at [`AT`].
fn once(
    class: u32,
    crtl: u8,
) -> impl FnMut(u64, &Snapshot, &LinkFaults, &mut Producer<'_, Command>) {
    let mut done = false;
    move |k, _, f, _| {
        if k == AT && !done {
            done = true;
            let (id, data) = error_frame(class, crtl);
            f.error_frame(id, data);
        }
    }
}

/// The operator resumes once the path has been paused for `after` periods.
fn resume_after(after: u64) -> impl FnMut(&Snapshot, &mut Producer<'_, Command>) {
    let mut held = 0;
    move |s, tx| {
        if s.paused {
            held += 1;
            if held == after {
                tx.enqueue(Command::Resume).expect("room for a command");
            }
        }
    }
}

fn assert_completed(m: &Met) {
    let rep = &m.report;
    assert_eq!(rep.exit_code, 0, "{}", rep.text());
    for d in &rep.drives {
        assert_eq!(Some(d.target_counts), d.program_end_counts, "{d:?}");
    }
}

#[test]
fn an_error_warning_is_counted_and_the_run_goes_on() {
    let m = run("warning", once(ERR_CRTL, CRTL_TX_WARNING));
    assert_completed(&m);
    assert_eq!(m.paused, 0);
    let bus = &m.report.buses[0];
    assert_eq!(bus.error_frames.get("error warning"), Some(&1));
    assert_eq!(bus.reactions.get("warning"), Some(&1));
    let text = m.report.text();
    assert!(
        text.contains("bus can0: error frames: 1 error warning, no frame dropped"),
        "{text}"
    );
    within_limits("warning", &m.sent);
}

#[test]
fn error_passive_holds_the_feed_until_the_operator_resumes() {
    let mut inject = once(ERR_CRTL, CRTL_RX_PASSIVE);
    let mut resume = resume_after(300);
    let m = run("passive", |k, s, f, tx| {
        inject(k, s, f, tx);
        resume(s, tx);
    });
    // Held along the path, at rest for the operator's 300 periods, then resumed to the end.
    assert!(m.paused >= 300, "paused {} periods", m.paused);
    assert_completed(&m);
    let bus = &m.report.buses[0];
    assert_eq!(bus.error_frames.get("error passive"), Some(&1));
    assert_eq!(bus.reactions.get("feed hold"), Some(&1));
    assert_eq!(
        bus.worst.as_deref(),
        Some("CAN controller error passive (feed hold)")
    );
    within_limits("passive", &m.sent);
}

#[test]
fn a_lost_arbitration_storm_holds_the_feed_and_a_few_losses_do_not() {
    // Nine periods in a row: counted, nothing else.
    let m = run("arbitration-9", |k, _, f, _| {
        if (AT..AT + 9).contains(&k) {
            let (id, data) = error_frame(ERR_LOSTARB, 0);
            f.error_frame(id, data);
        }
    });
    assert_completed(&m);
    assert_eq!(m.paused, 0);
    assert_eq!(
        m.report.buses[0].error_frames.get("lost arbitration"),
        Some(&9)
    );
    // Ten: a storm, held until the operator resumes.
    let mut resume = resume_after(100);
    let m = run("arbitration-10", |k, s, f, tx| {
        if (AT..AT + 10).contains(&k) {
            let (id, data) = error_frame(ERR_LOSTARB, 0);
            f.error_frame(id, data);
        }
        resume(s, tx);
    });
    assert!(m.paused >= 100, "paused {} periods", m.paused);
    assert_completed(&m);
    assert_eq!(m.report.buses[0].reactions.get("feed hold"), Some(&1));
    within_limits("arbitration storm", &m.sent);
}

/// Stopped along the path by the bus: exit 3, no node to blame, short of the end, every
/// target within the limits.
fn assert_stopped_along_the_path(m: &Met, why: &str) {
    let rep = &m.report;
    assert_eq!(rep.exit_code, 3, "{}", rep.text());
    assert_eq!(rep.outcome, "stopped by a fault");
    assert_eq!(rep.stop_node, None);
    let reason = rep.stop_reason.as_deref().unwrap_or_default();
    assert!(
        reason.starts_with(&format!("CAN bus: {why}"))
            && reason.ends_with("stopped along the path, drives disabled"),
        "{reason}"
    );
    assert!(
        rep.drives
            .iter()
            .any(|d| Some(d.target_counts) != d.program_end_counts),
        "stopped short of the end"
    );
    assert_eq!(m.report.buses[0].reactions.get("controlled stop"), Some(&1));
}

#[test]
fn a_tx_timeout_stops_along_the_path() {
    let m = run("tx-timeout", once(ERR_TX_TIMEOUT, 0));
    assert_stopped_along_the_path(&m, "TX timeout");
    within_limits("tx timeout", &m.sent);
}

#[test]
fn a_transmit_queue_full_three_periods_in_a_row_stops_along_the_path() {
    // Two periods: the drives miss two targets; counted, the run goes on.
    let m = run("tx-full-2", |k, _, f, _| {
        f.set_tx_full((AT..AT + 2).contains(&k))
    });
    assert_completed(&m);
    let bus = &m.report.buses[0];
    assert_eq!(bus.reactions.get("warning"), Some(&2));
    // Five drives' RPDOs and the SYNC, each period.
    assert_eq!(bus.dropped_frames, 12);
    // Three: stopped while targets still reach the drives.
    let m = run("tx-full-3", |k, _, f, _| {
        f.set_tx_full((AT..AT + 3).contains(&k))
    });
    assert_stopped_along_the_path(&m, "transmit queue full in 3 periods in a row");
    assert_eq!(m.report.buses[0].dropped_frames, 18);
    // The targets as computed hold the limits; the drives took all but the three periods'.
    within_limits("tx full", &m.sent);
    let node1 = m.records.iter().filter(|r| r.node == 1).count();
    let missed = m.sent.len() - node1;
    assert!((3..=4).contains(&missed), "{missed} periods missed");
}

/// Quick-stopped by the bus: exit 3, the bus named, every target held from the fault on,
/// the drives out of Operation enabled.
fn assert_quick_stopped(m: &Met, why: &str) {
    let rep = &m.report;
    assert_eq!(rep.exit_code, 3, "{}", rep.text());
    assert_eq!(rep.stop_node, None);
    let reason = rep.stop_reason.as_deref().unwrap_or_default();
    assert!(
        reason.starts_with(&format!("drive fault: CAN bus: {why}"))
            && reason.ends_with("drives quick-stopped and disabled"),
        "{reason}"
    );
    // Held from the fault on: the last rows equal. Up to then, within the limits.
    let last = m.sent.last().unwrap();
    let held = m.sent.iter().rev().take_while(|r| *r == last).count();
    assert!(held > 1, "targets held after the fault");
    within_limits(why, &m.sent[..m.sent.len() - held + 1]);
}

#[test]
fn bus_off_quick_stops_every_drive() {
    let m = run("bus-off", once(ERR_BUSOFF, 0));
    assert_quick_stopped(&m, "bus-off");
    assert_eq!(m.report.buses[0].reactions.get("quick stop"), Some(&1));
    assert_eq!(m.report.buses[0].error_frames.get("bus-off"), Some(&1));
    // Each drive took the quick stop and was disabled (statusword: not Operation enabled).
    for node in 1..=5u8 {
        let last = m.records.iter().rev().find(|r| r.node == node).unwrap();
        assert_ne!(
            last.statusword & 0x6F,
            0x27,
            "node {node}: {:04X}",
            last.statusword
        );
    }
}

#[test]
fn a_restarted_controller_quick_stops_every_drive() {
    let m = run("restarted", once(ERR_RESTARTED, 0));
    assert_quick_stopped(&m, "CAN controller restarted");
}

#[test]
fn the_interface_going_down_quick_stops_and_the_run_ends() {
    let m = run("down", |k, _, f, _| {
        if k == AT {
            f.set_down(true);
        }
    });
    assert_quick_stopped(&m, "CAN link: CAN interface down (ENETDOWN)");
}
