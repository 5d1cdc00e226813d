//! The master with a spindle drive (profile velocity) and a CiA-401 I/O module beside an axis,
//! against the simulated nodes over the in-process socket link: set-up by SDO as each kind
//! needs, the spindle ramping to its target with the target-reached bit, the module's
//! outputs echoed by its inputs, and on a fault of the axis the spindle commanded to 0 and
//! the outputs switched off. Master and nodes are stepped in turn on a virtual clock.

use drives::cia402::{Goal, State, Statusword};
use drives::link::SocketLink;
use drives::master::{
    configure_nodes, Master, NodeKind, NodeSetup, SetupOptions, Supervision, VelocitySetup,
};
use drives::sim::{Faults, Lockstep, Record, SimNodeConfig};
use drives::wire::NodeId;
use std::time::Duration;

const PERIOD: f64 = 0.002;
const AXIS: u8 = 1;
const SPINDLE: u8 = 6;
const IO: u8 = 7;

fn id(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

/// Ramp 6000 units/s: 1200 units in 0.2 s (100 periods).
const VELOCITY: VelocitySetup = VelocitySetup {
    ramp: 6000,
    quick_stop: 12_000,
    window: 10,
    window_ms: 10,
};

/// A master and its nodes, stepped a period at a time.
struct Rig {
    m: Master<SocketLink>,
    sim: Lockstep<SocketLink>,
}

impl Rig {
    /// One period: the master's cycle, the nodes' answer, the clock a period on.
    fn cycle(&mut self, targets: &[i32]) {
        let now = self.sim.now();
        self.m.cycle(targets, now.as_secs_f64());
        self.sim.advance_to(now);
        self.sim.advance_to(now + Duration::from_secs_f64(PERIOD));
    }
}

/// An axis, the spindle and the module, set up and enabled; the axis faults at `fault_at`.
fn start(fault_at: Option<u64>) -> Rig {
    let (mut link, drive_end) = SocketLink::pair().unwrap();
    let mut axis = SimNodeConfig::new(id(AXIS));
    axis.faults = Faults {
        fault_at_sync: fault_at,
        ..Faults::default()
    };
    let sims = vec![
        axis,
        SimNodeConfig::new(id(SPINDLE)),
        SimNodeConfig::io(id(IO)),
    ];
    let mut sim = Lockstep::new(drive_end, sims, PERIOD);
    let setups = [
        NodeSetup::Position(id(AXIS), drives::master::Protections::default()),
        NodeSetup::Velocity(id(SPINDLE), VELOCITY),
        NodeSetup::Io(id(IO)),
    ];
    let mut opts = SetupOptions::new(PERIOD);
    opts.boot_timeout = Duration::from_millis(500);
    let initial =
        configure_nodes(&mut link, &setups, &opts, &mut sim, &mut |_| {}).expect("set-up");
    assert_eq!(initial, [0, 0, 0], "position, velocity actual, inputs");
    let kinds: Vec<_> = setups.iter().map(|s| (s.node(), s.kind())).collect();
    assert_eq!(
        kinds.iter().map(|k| k.1).collect::<Vec<_>>(),
        [NodeKind::Position, NodeKind::Velocity, NodeKind::Io]
    );
    let sup = Supervision {
        heartbeat_timeout_s: 0.35,
        feedback_timeout_cycles: 25,
    };
    let now = sim.now().as_secs_f64();
    let m = Master::with_kinds(link, &kinds, &initial, sup, now).unwrap();
    let mut rig = Rig { m, sim };
    rig.m.set_goal(Goal::Enabled);
    for _ in 0..200 {
        rig.cycle(&[0, 0, 0]);
        if rig.m.all_in(State::OperationEnabled) {
            break;
        }
    }
    assert!(
        rig.m.all_in(State::OperationEnabled),
        "{:?}",
        rig.m.status()
    );
    rig
}

fn records_of(records: &[Record], node: u8) -> Vec<Record> {
    records.iter().filter(|r| r.node == node).copied().collect()
}

#[test]
fn the_spindle_ramps_to_speed_and_the_outputs_are_echoed() {
    let mut rig = start(None);
    let mut at_speed = None;
    for k in 0..400 {
        rig.cycle(&[0, 1200, 0x02]);
        let s = rig.m.status()[1];
        if at_speed.is_none() && Statusword(s.statusword).target_reached() && s.actual == 1200 {
            at_speed = Some(k);
        }
    }
    let io = rig.m.status()[2];
    assert_eq!(
        (io.target, io.actual),
        (0x02, 0x02),
        "outputs and the inputs echoing them"
    );
    assert_eq!(io.state, None, "an I/O module has no CiA-402 state");
    assert!(rig.m.fault().is_none(), "{:?}", rig.m.fault());
    let records = rig.sim.take_records();
    let spindle = records_of(&records, SPINDLE);
    // The drive ramps at 0x6083: 12 units per 2 ms SYNC, so 1200 takes 100 SYNCs.
    let first = spindle
        .iter()
        .position(|r| r.target_counts == 1200)
        .unwrap();
    let reached = spindle
        .iter()
        .position(|r| r.actual_counts == 1200)
        .unwrap();
    assert!(
        (99..=101).contains(&(reached - first)),
        "{}",
        reached - first
    );
    for w in spindle.windows(2) {
        assert!(
            (w[1].actual_counts - w[0].actual_counts).abs() <= 12,
            "{w:?}"
        );
    }
    assert!(at_speed.is_some(), "the master saw the speed reached");
}

#[test]
fn a_fault_stops_the_spindle_and_switches_the_outputs_off() {
    let mut rig = start(Some(150));
    for _ in 0..400 {
        rig.cycle(&[0, 1200, 0x03]);
    }
    let f = rig.m.fault().copied().expect("the axis faulted");
    assert_eq!(f.node, AXIS);
    assert_ne!(rig.m.goal(), Goal::Enabled);
    assert_eq!(rig.m.status()[1].target, 0, "spindle commanded to 0");
    assert_eq!(rig.m.status()[2].target, 0, "outputs off");
    let records = rig.sim.take_records();
    let io = records_of(&records, IO);
    assert!(
        io.iter().any(|r| r.target_counts == 0x03),
        "outputs were on"
    );
    assert_eq!(io.last().unwrap().target_counts, 0, "and are off");
    let spindle = records_of(&records, SPINDLE);
    let last = spindle.last().unwrap();
    assert_eq!(last.actual_counts, 0, "the spindle stopped: {last:?}");
}
