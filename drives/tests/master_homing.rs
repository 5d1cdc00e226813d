//! The master homes axes through CiA-402 homing mode while it runs its cycle, against the
//! simulated drives over the in-process link, stepped in lock-step on a virtual clock: each
//! method the drives offer, a switch that is never found, refusals, and the return to
//! cyclic synchronous position mode where the drive stands (no target ever jumps). The
//! master's calls allocate nothing while axes home (a counting allocator, armed around
//! them only: the simulated drives allocate).

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

use drives::cia402::{Goal, State};
use drives::link::SocketLink;
use drives::master::{
    configure, HomeRefused, HomeRequest, HomingError, HomingState, Master, SetupOptions,
    Supervision,
};
use drives::sim::{HomeHardware, Lockstep, Record, SimNodeConfig};
use drives::wire::NodeId;
use std::time::Duration;

const PERIOD: f64 = 0.002;

struct Rig {
    m: Master<SocketLink>,
    drives: Lockstep<SocketLink>,
}

impl Rig {
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

    /// Cycles, every target the drive's own position, until `done` (at most `max`).
    fn run_until(&mut self, max: usize, done: impl Fn(&Master<SocketLink>) -> bool) -> usize {
        for k in 0..max {
            let targets: Vec<i32> = self.m.status().iter().map(|n| n.target).collect();
            self.cycle(&targets);
            if done(&self.m) {
                return k + 1;
            }
        }
        max
    }
}

fn ids(n: u8) -> Vec<NodeId> {
    (1..=n).map(|i| NodeId::new(i).unwrap()).collect()
}

/// `n` drives at 5 000 counts, each with `home(node)`, set up and Operation enabled.
fn start(n: u8, home: impl Fn(u8) -> HomeHardware) -> Rig {
    let sims = (1..=n)
        .map(|i| SimNodeConfig {
            initial_position: 5_000,
            home: home(i),
            ..SimNodeConfig::new(NodeId::new(i).unwrap())
        })
        .collect();
    let (mut link, drive_end) = SocketLink::pair().unwrap();
    let mut drives = Lockstep::new(drive_end, sims, PERIOD);
    let mut o = SetupOptions::new(PERIOD);
    o.boot_timeout = Duration::from_millis(500);
    o.sdo_timeout = Duration::from_millis(100);
    let initial = configure(&mut link, &ids(n), &o, &mut drives, &mut |_| {}).unwrap();
    let sup = Supervision {
        heartbeat_timeout_s: 0.35,
        feedback_timeout_cycles: 25,
    };
    let m = Master::new(link, &ids(n), &initial, sup, drives.now().as_secs_f64()).unwrap();
    let mut rig = Rig { m, drives };
    rig.m.set_goal(Goal::Enabled);
    rig.run_until(200, |m| m.all_in(State::OperationEnabled));
    assert!(rig.m.all_in(State::OperationEnabled));
    rig
}

fn request(method: i8, offset: i32) -> HomeRequest {
    HomeRequest {
        method,
        switch_speed: 20_000,
        index_speed: 2_000,
        acceleration: 100_000,
        offset,
        timeout_cycles: 20_000,
    }
}

fn ended(m: &Master<SocketLink>, i: usize) -> bool {
    !matches!(m.homing(i), HomingState::Running)
}

/// Node `node`'s records from its SYNC `from` on (back in CSP): targets never jump by more
/// than `step` counts a period, and the first is where the drive stood.
fn no_jump(records: &[Record], node: u8, from: u64, step: i32) {
    let mine: Vec<&Record> = records
        .iter()
        .filter(|r| r.node == node && r.sync >= from)
        .collect();
    assert!(mine.len() > 3, "node {node}: {} records", mine.len());
    assert!((mine[0].target_counts - mine[0].actual_counts).abs() <= step);
    for w in mine.windows(2) {
        let d = (w[1].target_counts - w[0].target_counts).abs();
        assert!(
            d <= step,
            "node {node}: target jumped {d} at sync {}",
            w[1].sync
        );
    }
}

#[test]
fn three_axes_home_by_three_methods_and_go_on_in_csp() {
    let mut rig = start(3, |_| HomeHardware::default());
    assert_eq!(rig.m.homing(0), HomingState::Idle);
    // Node 1: the switch (edge at 0, active above) from 5 000: moves negative to the edge.
    // Node 2: the switch, then the index pulse below it (-10 000). Node 3: here.
    test_support::arm_this_thread();
    rig.m.home(0, request(19, 100)).unwrap();
    rig.m.home(1, request(3, 200)).unwrap();
    rig.m.home(2, request(35, 300)).unwrap();
    assert_eq!(
        test_support::disarm_this_thread(),
        0,
        "heap events in home()"
    );
    assert_eq!(rig.m.home(0, request(19, 0)), Err(HomeRefused::Busy(1)));
    let cycles = rig.run_until(20_000, |m| (0..3).all(|i| ended(m, i)));
    assert!(cycles < 20_000);
    assert_eq!(rig.m.fault(), None, "{:?}", rig.m.fault());
    let pos = |i| match rig.m.homing(i) {
        HomingState::Attained { position } => position,
        other => panic!("axis {i}: {other:?}"),
    };
    // Stopped beyond the home point by the stop from 20 000 counts/s (2 000 counts).
    assert!((100 - 2_100..=100 - 1_900).contains(&pos(0)), "{}", pos(0));
    // At the index speed (2 000 counts/s) the stop takes 20 counts.
    assert!((200 - 30..=200 - 15).contains(&pos(1)), "{}", pos(1));
    assert_eq!(pos(2), 300);
    // Back in CSP where they stand: a ramp from there is followed.
    let from: Vec<i32> = rig.m.status().iter().map(|n| n.actual).collect();
    let resumed = rig.drives.bus().records().last().unwrap().sync;
    for k in 1..=200 {
        let t: Vec<i32> = from.iter().map(|p| p + 10 * k).collect();
        rig.cycle(&t);
    }
    assert_eq!(rig.m.fault(), None);
    // The actual the master holds is the target of two periods before (the SYNC that
    // applied it, the TPDO that reported it).
    for (n, p) in rig.m.status().iter().zip(&from) {
        assert_eq!(
            n.actual,
            p + 10 * 198,
            "node {} follows CSP targets",
            n.node
        );
    }
    let records = rig.drives.bus().records().to_vec();
    for node in 1..=3 {
        no_jump(&records, node, resumed, 10);
    }
}

#[test]
fn a_switch_never_found_fails_with_the_drives_error_and_the_axis_stays_enabled() {
    let mut rig = start(2, |node| HomeHardware {
        switch: (node == 2).then_some(0),
        index_pitch: 10_000,
        search_limit: 30_000,
        ..HomeHardware::default()
    });
    rig.m.home(0, request(19, 0)).unwrap();
    rig.run_until(20_000, |m| ended(m, 0));
    match rig.m.homing(0) {
        HomingState::Failed(HomingError::Drive(sw)) => assert_ne!(sw & (1 << 13), 0),
        other => panic!("{other:?}"),
    }
    // A homing error is no fault of the master: the axis is enabled and in CSP again.
    assert_eq!(rig.m.fault(), None);
    assert!(rig.m.all_in(State::OperationEnabled));
    rig.run_until(5, |_| false);
    let resumed = rig.drives.bus().records().last().unwrap().sync;
    let at = rig.m.status()[0].actual;
    let t = vec![at + 50, rig.m.status()[1].actual];
    for _ in 0..5 {
        rig.cycle(&t);
    }
    assert_eq!(rig.m.status()[0].actual, at + 50);
    no_jump(rig.drives.bus().records(), 1, resumed, 50);
}

#[test]
fn a_method_the_drive_does_not_offer_is_refused_with_its_object() {
    let mut rig = start(1, |_| HomeHardware::default());
    rig.m.home(0, request(1, 0)).unwrap();
    rig.run_until(100, |m| ended(m, 0));
    match rig.m.homing(0) {
        HomingState::Failed(e @ HomingError::Refused { index: 0x6098, .. }) => {
            assert!(
                e.to_string().starts_with("the drive refused 0x6098:00"),
                "{e}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(rig.m.fault(), None);
}

#[test]
fn homing_is_refused_unless_enabled_and_interrupted_by_a_disable() {
    let mut rig = start(1, |_| HomeHardware::default());
    assert_eq!(
        rig.m.home(1, request(35, 0)),
        Err(HomeRefused::NoSuchAxis(1))
    );
    rig.m.home(0, request(19, 0)).unwrap();
    rig.run_until(30, |_| false);
    assert_eq!(rig.m.homing(0), HomingState::Running);
    rig.m.set_goal(Goal::Disabled);
    rig.run_until(50, |m| ended(m, 0));
    assert_eq!(
        rig.m.homing(0),
        HomingState::Failed(HomingError::Interrupted)
    );
    rig.run_until(50, |m| m.all_in(State::SwitchOnDisabled));
    assert_eq!(
        rig.m.home(0, request(35, 0)),
        Err(HomeRefused::NotEnabled(1))
    );
}
