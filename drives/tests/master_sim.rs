//! The master against the simulated drives, over the in-process link (the same socketcan
//! code path as a real bus): full set-up, enable, >= 1000 cycles, disable; and every fault
//! injection, each ending with the drives quick-stopped or disabled and an error that names
//! the node and the cause.
//!
//! Master and drives are stepped in turn on a virtual clock (`Lockstep`): the master's
//! cycle sends its frames, the drives answer them, the clock moves on a period. No test
//! sleeps or reads the system clock, so none depends on how busy the machine is. The
//! master's cycle and its reset allocate nothing, faults included (a counting allocator,
//! armed around the master's calls only: the simulated drives allocate).

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

use drives::cia402::{Goal, State};
use drives::link::{CanLink, SocketLink};
use drives::master::{
    configure, Clock, DriveFault, FaultCause, Master, ResetRefused, SetupErrorKind, SetupOptions,
    Supervision, RESET_CYCLES,
};
use drives::sim::{Faults, Lockstep, Record, SimBus, SimNodeConfig};
use drives::wire::NodeId;
use std::time::Duration;

const PERIOD: f64 = 0.002;

/// The simulated drives on the far end of the link, on a virtual clock.
fn sim(link: SocketLink, nodes: Vec<SimNodeConfig>) -> Lockstep<SocketLink> {
    Lockstep::new(link, nodes, PERIOD)
}

/// A master and its drives, stepped a period at a time.
struct Rig {
    m: Master<SocketLink>,
    drives: Lockstep<SocketLink>,
}

impl Rig {
    /// One period: the master's cycle at the present time, the drives' answer, then the
    /// clock a period on.
    fn cycle(&mut self, targets: &[i32]) {
        let now = self.drives.now();
        test_support::arm_this_thread();
        self.m.cycle(targets, now.as_secs_f64());
        let events = test_support::disarm_this_thread();
        assert_eq!(events, 0, "heap events in the master's cycle");
        self.drives.advance_to(now);
        self.drives
            .advance_to(now + Duration::from_secs_f64(PERIOD));
    }
}

fn nodes(n: u8) -> Vec<NodeId> {
    (1..=n).map(|i| NodeId::new(i).unwrap()).collect()
}

fn sim_nodes(n: u8, faults: impl Fn(u8) -> Faults) -> Vec<SimNodeConfig> {
    lagging_nodes(n, 0.0, faults)
}

/// As [`sim_nodes`], each drive's position following its target with time constant `lag_s`.
fn lagging_nodes(n: u8, lag_s: f64, faults: impl Fn(u8) -> Faults) -> Vec<SimNodeConfig> {
    (1..=n)
        .map(|i| {
            let mut c = SimNodeConfig::new(NodeId::new(i).unwrap());
            c.initial_position = 1000 * i32::from(i);
            c.lag_s = lag_s;
            c.faults = faults(i);
            c
        })
        .collect()
}

fn options() -> SetupOptions {
    let mut o = SetupOptions::new(PERIOD);
    o.boot_timeout = Duration::from_millis(500);
    o.sdo_timeout = Duration::from_millis(100);
    o
}

const SUPERVISION: Supervision = Supervision {
    heartbeat_timeout_s: 0.35,
    feedback_timeout_cycles: 25,
};

/// Set up, enable and return a running master.
fn start(n: u8, faults: impl Fn(u8) -> Faults) -> (Rig, Vec<i32>) {
    start_nodes(n, sim_nodes(n, faults))
}

fn start_nodes(n: u8, sims: Vec<SimNodeConfig>) -> (Rig, Vec<i32>) {
    let (mut link, drive_end) = SocketLink::pair().unwrap();
    let mut drives = sim(drive_end, sims);
    let initial = configure(&mut link, &nodes(n), &options(), &mut drives, &mut |_| {})
        .expect("set-up succeeds");
    let m = Master::new(
        link,
        &nodes(n),
        &initial,
        SUPERVISION,
        drives.now().as_secs_f64(),
    );
    let mut rig = Rig {
        m: m.unwrap(),
        drives,
    };
    rig.m.set_goal(Goal::Enabled);
    for _ in 0..200 {
        rig.cycle(&initial);
        if rig.m.all_in(State::OperationEnabled) {
            break;
        }
    }
    assert!(
        rig.m.all_in(State::OperationEnabled),
        "not enabled: {:?}",
        rig.m.status()
    );
    (rig, initial)
}

/// Cycle until `done` (at most `max` cycles), with a ramp on every axis.
fn run(
    rig: &mut Rig,
    initial: &[i32],
    max: usize,
    done: impl Fn(&Master<SocketLink>) -> bool,
) -> usize {
    let mut targets = initial.to_vec();
    for k in 0..max {
        for (t, i) in targets.iter_mut().zip(initial) {
            *t = i + 10 * k as i32;
        }
        rig.cycle(&targets);
        if done(&rig.m) {
            return k + 1;
        }
    }
    max
}

#[test]
fn set_up_enable_1000_cycles_and_disable() {
    let (mut rig, initial) = start(5, |_| Faults::default());
    // Set-up read each drive's actual position: the first targets equal it.
    assert_eq!(initial, vec![1000, 2000, 3000, 4000, 5000]);
    let cycles = run(&mut rig, &initial, 1000, |_| false);
    assert_eq!(cycles, 1000);
    assert_eq!(rig.m.fault(), None, "{:?}", rig.m.fault());
    let last_targets: Vec<i32> = rig.m.status().iter().map(|n| n.target).collect();
    rig.m.set_goal(Goal::Disabled);
    for _ in 0..50 {
        rig.cycle(&last_targets);
        if rig.m.all_in(State::SwitchOnDisabled) {
            break;
        }
    }
    assert!(
        rig.m.all_in(State::SwitchOnDisabled),
        "{:?}",
        rig.m.status()
    );
    let records = rig.drives.take_records();
    for (i, node) in (1u8..=5).enumerate() {
        let mine: Vec<&Record> = records.iter().filter(|r| r.node == node).collect();
        assert!(mine.len() >= 1000, "node {node}: {} records", mine.len());
        // Every target the drive took is one the master sent: the ramp, never a jump.
        for w in mine.windows(2) {
            let step = (w[1].target_counts - w[0].target_counts).abs();
            assert!(
                step <= 10,
                "node {node}: target jumped by {step} at sync {}",
                w[1].sync
            );
        }
        let last = mine.last().unwrap();
        assert_eq!(last.target_counts, last_targets[i]);
        assert_eq!(
            last.actual_counts, last_targets[i],
            "node {node} ends on its last target"
        );
    }
}

fn expect_fault(fault: Option<&DriveFault>, node: u8) -> DriveFault {
    let f = *fault.unwrap_or_else(|| panic!("no fault raised; expected one on node {node}"));
    assert_eq!(f.node, node, "{f}");
    assert!(f.to_string().starts_with(&format!("node {node}: ")), "{f}");
    f
}

/// After a fault the master must bring every drive to a stop: quick-stopped, disabled or
/// (the faulty one) in Fault; never Operation enabled.
fn assert_stopped(m: &Master<SocketLink>, silent: Option<u8>) {
    for n in m.status() {
        if Some(n.node.get()) == silent {
            continue; // nothing can be known of a node that no longer answers
        }
        assert!(
            matches!(
                n.state,
                Some(State::QuickStopActive | State::SwitchOnDisabled | State::Fault)
            ),
            "node {} left in {:?}",
            n.node.get(),
            n.state
        );
    }
}

fn stopped(m: &Master<SocketLink>) -> bool {
    m.fault().is_some()
        && m.status().iter().all(|n| {
            n.cycles_without_feedback > 3
                || matches!(n.state, Some(State::SwitchOnDisabled | State::Fault))
        })
}

#[test]
fn drive_fault_stops_every_drive_and_names_the_node() {
    let (mut rig, initial) = start(5, |i| Faults {
        fault_at_sync: (i == 3).then_some(300),
        ..Faults::default()
    });
    run(&mut rig, &initial, 2000, stopped);
    let f = expect_fault(rig.m.fault(), 3);
    assert!(
        matches!(f.cause, FaultCause::Emcy(_) | FaultCause::DriveFault { .. }),
        "{f}"
    );
    assert_stopped(&rig.m, None);
    assert_eq!(rig.m.status()[2].state, Some(State::Fault));
}

#[test]
fn after_a_fault_no_target_steps_back_to_a_lagging_drive() {
    // Drives 50 ms behind a ramp of 10 counts per cycle (5000 counts/s) are 250 counts
    // behind their targets. Measured before the fix: on the fault every target stepped back
    // to the actual position: node 1 by 255 counts in one period (25x the ramp step).
    let (mut rig, initial) = start_nodes(
        3,
        lagging_nodes(3, 0.05, |i| Faults {
            fault_at_sync: (i == 2).then_some(300),
            ..Faults::default()
        }),
    );
    run(&mut rig, &initial, 2000, stopped);
    expect_fault(rig.m.fault(), 2);
    let records = rig.drives.take_records();
    for node in 1u8..=3 {
        let mine: Vec<&Record> = records.iter().filter(|r| r.node == node).collect();
        let lagging = mine
            .iter()
            .map(|r| (r.target_counts - r.actual_counts).abs())
            .max()
            .unwrap_or(0);
        assert!(
            lagging > 100,
            "node {node}: the drive lagged only {lagging}"
        );
        for w in mine.windows(2) {
            let step = w[1].target_counts - w[0].target_counts;
            assert!(
                (0..=10).contains(&step),
                "node {node}: target moved by {step} at sync {} (ramp step 10)",
                w[1].sync
            );
        }
    }
}

#[test]
fn lost_heartbeat_stops_every_drive_and_names_the_node() {
    let (mut rig, initial) = start(3, |i| Faults {
        heartbeat_stops_at: (i == 2).then_some(100),
        ..Faults::default()
    });
    run(&mut rig, &initial, 3000, stopped);
    let f = expect_fault(rig.m.fault(), 2);
    assert!(matches!(f.cause, FaultCause::HeartbeatLost { .. }), "{f}");
    assert!(f.to_string().contains("heartbeat lost"), "{f}");
    assert_stopped(&rig.m, None);
}

#[test]
fn a_node_that_goes_silent_is_a_fault_and_the_others_stop() {
    let (mut rig, initial) = start(3, |i| Faults {
        silent_from_sync: (i == 1).then_some(200),
        ..Faults::default()
    });
    run(&mut rig, &initial, 3000, stopped);
    let f = expect_fault(rig.m.fault(), 1);
    assert!(
        matches!(
            f.cause,
            FaultCause::NoFeedback(_) | FaultCause::HeartbeatLost { .. }
        ),
        "{f}"
    );
    assert_stopped(&rig.m, Some(1));
}

#[test]
fn occasional_lost_frames_are_retried_and_tolerated() {
    // Every 7th frame of node 2 is lost: SDO retries carry the set-up through and the cycle
    // holds the last feedback for a missed TPDO; no fault.
    let (mut rig, initial) = start(3, |i| Faults {
        drop_every: (i == 2).then_some(7),
        ..Faults::default()
    });
    run(&mut rig, &initial, 500, |_| false);
    assert_eq!(rig.m.fault(), None, "{:?}", rig.m.fault());
}

#[test]
fn a_node_that_never_boots_is_a_set_up_error_naming_it() {
    let (mut link, drive_end) = SocketLink::pair().unwrap();
    let mut drives = sim(
        drive_end,
        sim_nodes(4, |i| Faults {
            never_boots: i == 4,
            ..Faults::default()
        }),
    );
    let err = configure(&mut link, &nodes(4), &options(), &mut drives, &mut |_| {}).unwrap_err();
    assert_eq!(err.node, 4);
    assert!(
        matches!(err.kind, SetupErrorKind::NoBootUp { cob: 0x704, .. }),
        "{err}"
    );
    assert!(
        err.to_string()
            .starts_with("node 4: no boot-up message (0x704)"),
        "{err}"
    );
}

#[test]
fn an_sdo_abort_is_reported_with_node_object_and_meaning() {
    // A drive that does not know 0x60C2 answers with abort 0x06020000.
    struct Intercepting {
        bus: SimBus,
        link: SocketLink,
        now: Duration,
    }
    impl Clock for Intercepting {
        fn now(&self) -> Duration {
            self.now
        }
        fn idle(&mut self) {
            let mut out = Vec::new();
            while let Ok(Some(f)) = self.link.recv() {
                // Intercept the SDO download to 0x60C2 sub 1 and abort it as unknown.
                if f.id() == 0x601 && f.data().get(1..4) == Some(&[0xC2, 0x60, 0x01][..]) {
                    out.push("581#80C2600100000206".parse().unwrap());
                    continue;
                }
                self.bus.on_frame(&f, 0.0, &mut |o| out.push(o));
            }
            self.bus.poll(0.0, &mut |o| out.push(o));
            for f in out {
                let _ = self.link.send(&f);
            }
            self.now += Duration::from_micros(100);
        }
    }
    let (mut link, drive_end) = SocketLink::pair().unwrap();
    let mut drives = Intercepting {
        bus: SimBus::new(sim_nodes(1, |_| Faults::default()), PERIOD),
        link: drive_end,
        now: Duration::ZERO,
    };
    let err = configure(&mut link, &nodes(1), &options(), &mut drives, &mut |_| {}).unwrap_err();
    assert_eq!((err.node, err.object), (1, Some((0x60C2, 1))));
    let text = err.to_string();
    assert!(
        text.starts_with("node 1, object 0x60C2:01: SDO abort 0x06020000"),
        "{text}"
    );
    assert!(text.contains("does not exist"), "{text}");
}

/// Heartbeats a node sent during the set-up, before its NMT start (pre-operational), may
/// still be queued in the socket when the master's first cycle reads it (seen in the
/// PREEMPT_RT guest: every drive quick-stopped before it was ever enabled). They are not a
/// fault while an Operational heartbeat can still come, within the heartbeat timeout; a node
/// that leaves Operational afterwards, or never reaches it within the timeout, is.
#[test]
fn a_pre_operational_heartbeat_queued_from_the_set_up_is_not_a_fault() {
    use drives::wire::heartbeat::{self, NmtState};
    let id = NodeId::new(1).unwrap();
    let beat = |node: &mut SocketLink, s: NmtState| {
        node.send_all(&[heartbeat::encode(id, s)]).unwrap();
    };
    let (link, mut node) = SocketLink::pair().unwrap();
    let mut m = Master::new(link, &[id], &[0], SUPERVISION, 0.0).unwrap();
    beat(&mut node, NmtState::PreOperational);
    assert!(m.cycle(&[0], 0.002).is_none(), "{:?}", m.fault());
    beat(&mut node, NmtState::Operational);
    assert!(m.cycle(&[0], 0.004).is_none(), "{:?}", m.fault());
    beat(&mut node, NmtState::PreOperational);
    let f = m
        .cycle(&[0], 0.006)
        .expect("leaving Operational is a fault");
    assert_eq!(
        f.cause,
        FaultCause::NotOperational(NmtState::PreOperational)
    );

    // Never Operational: a fault once the heartbeat timeout (0.35 s) has passed.
    let (link, mut node) = SocketLink::pair().unwrap();
    let mut m = Master::new(link, &[id], &[0], SUPERVISION, 0.0).unwrap();
    beat(&mut node, NmtState::PreOperational);
    assert!(m.cycle(&[0], 0.002).is_none(), "{:?}", m.fault());
    beat(&mut node, NmtState::PreOperational);
    assert!(m.cycle(&[0], 0.34).is_none(), "{:?}", m.fault());
    beat(&mut node, NmtState::PreOperational);
    let f = m
        .cycle(&[0], 0.36)
        .expect("still pre-operational after the timeout");
    assert_eq!(
        f.cause,
        FaultCause::NotOperational(NmtState::PreOperational)
    );
}

/// The operator's reset (issue 55): after a drive fault and the quick stop, `reset` sends
/// the faulted drive the fault-reset edge (the simulated drive leaves Fault only on a
/// rising bit 7) and leaves every drive Switch on disabled; enabling again resumes where
/// each drive stands, with no step, and the program goes on.
#[test]
fn a_reset_clears_a_drive_fault_and_the_drives_enable_again_where_they_stand() {
    let (mut rig, initial) = start(3, |i| Faults {
        fault_at_sync: (i == 2).then_some(300),
        ..Faults::default()
    });
    // Refused while nothing is faulted.
    assert_eq!(rig.m.reset(), Err(ResetRefused::NoFault));
    let mut targets = initial.clone();
    let mut stopping_refused = false;
    for k in 0..2000 {
        for (t, i) in targets.iter_mut().zip(&initial) {
            *t = i + 10 * k;
        }
        rig.cycle(&targets);
        if rig.m.fault().is_some() && !stopping_refused {
            // The quick stop has only begun.
            assert!(matches!(rig.m.reset(), Err(ResetRefused::Stopping(_))));
            stopping_refused = true;
        }
        if rig.m.fault().is_some() && rig.m.goal() == Goal::Disabled {
            break;
        }
    }
    assert!(stopping_refused);
    test_support::arm_this_thread();
    let reset = rig.m.reset();
    assert_eq!(
        test_support::disarm_this_thread(),
        0,
        "heap events in the reset"
    );
    let f = reset.expect("reset once stopped");
    assert_eq!(f.node, 2, "{f}");
    assert!(rig.m.fault().is_none());
    // Held where they stand, the faulted drive reset: all Switch on disabled, none enabled.
    let held: Vec<i32> = rig.m.status().iter().map(|n| n.actual).collect();
    for _ in 0..(RESET_CYCLES as usize) {
        rig.cycle(&held);
        assert!(rig.m.fault().is_none(), "{:?}", rig.m.fault());
    }
    assert!(
        rig.m.all_in(State::SwitchOnDisabled),
        "{:?}",
        rig.m.status()
    );
    // On again: enabled where they stand, then a ramp from there for 500 cycles.
    rig.m.set_goal(Goal::Enabled);
    for _ in 0..200 {
        rig.cycle(&held);
        if rig.m.all_in(State::OperationEnabled) {
            break;
        }
    }
    assert!(
        rig.m.all_in(State::OperationEnabled),
        "{:?}",
        rig.m.status()
    );
    let from: Vec<i32> = rig.m.status().iter().map(|n| n.actual).collect();
    assert_eq!(from, held, "enabling moved nothing");
    for k in 0..500 {
        let t: Vec<i32> = from.iter().map(|p| p + 10 * k).collect();
        rig.cycle(&t);
        assert!(rig.m.fault().is_none(), "{:?}", rig.m.fault());
    }
    let end: Vec<i32> = rig.m.status().iter().map(|n| n.actual).collect();
    assert!(
        end.iter()
            .zip(&from)
            .all(|(e, f)| (e - f - 4990).abs() <= 20),
        "{end:?} {from:?}"
    );
}

/// A cause still there comes back with its reason: a node silent for good is raised again
/// after the reset, with no feedback from it.
#[test]
fn a_reset_with_the_cause_still_there_faults_again_naming_it() {
    let (mut rig, initial) = start(3, |i| Faults {
        silent_from_sync: (i == 3).then_some(300),
        ..Faults::default()
    });
    run(&mut rig, &initial, 3000, |m| {
        m.fault().is_some() && m.goal() == Goal::Disabled
    });
    let f = rig.m.reset().expect("reset once stopped");
    assert_eq!(f.node, 3, "{f}");
    let held: Vec<i32> = rig.m.status().iter().map(|n| n.actual).collect();
    for _ in 0..50 {
        rig.cycle(&held);
    }
    let again = expect_fault(rig.m.fault(), 3);
    assert!(
        matches!(
            again.cause,
            FaultCause::NoFeedback(_) | FaultCause::HeartbeatLost { .. }
        ),
        "{again}"
    );
}
