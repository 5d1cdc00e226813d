//! The e-stop (issue 55): the e-stop chain on an input of the bus's I/O module, and the
//! operator's command. Against the simulated nodes over the in-process socket link, stepped
//! in turn on a virtual clock: the chain opening mid-motion quick-stops and disables the
//! axis and switches the outputs off, with a fault that names the module and the input; a
//! reset is refused while the chain is open and accepted once it closes; the machine then
//! enables again where it stands. The master's calls allocate nothing (a counting
//! allocator armed around them only).

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

use drives::cia402::{Goal, State};
use drives::link::SocketLink;
use drives::master::{
    configure_nodes, DriveFault, EStop, EStopRefused, FaultCause, Master, NodeSetup, Protections,
    ResetRefused, SetupOptions, Supervision, RESET_CYCLES,
};
use drives::sim::{EStopChain, Faults, Lockstep, SimNodeConfig};
use drives::wire::NodeId;
use std::time::Duration;

const PERIOD: f64 = 0.002;
const AXIS: u8 = 1;
const IO: u8 = 7;
/// Module input 4 (bit 3).
const INPUT: u8 = 4;
const BIT: u8 = INPUT - 1;

fn id(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

struct Rig {
    m: Master<SocketLink>,
    sim: Lockstep<SocketLink>,
}

impl Rig {
    fn cycle(&mut self, targets: &[i32]) {
        let now = self.sim.now();
        test_support::arm_this_thread();
        self.m.cycle(targets, now.as_secs_f64());
        assert_eq!(
            test_support::disarm_this_thread(),
            0,
            "heap events in the cycle"
        );
        self.sim.advance_to(now);
        self.sim.advance_to(now + Duration::from_secs_f64(PERIOD));
    }

    fn enable(&mut self, targets: &[i32]) {
        self.m.set_goal(Goal::Enabled);
        for _ in 0..200 {
            self.cycle(targets);
            if self.m.all_in(State::OperationEnabled) {
                return;
            }
        }
        panic!("not enabled: {:?}", self.m.status());
    }

    /// The axis ramps 10 counts a cycle from `from`, the outputs on, at most `max` cycles
    /// or until `done`: whether it was.
    fn ramp(&mut self, from: i32, max: i32, done: impl Fn(&Master<SocketLink>) -> bool) -> bool {
        for k in 0..max {
            self.cycle(&[from + 10 * k, 0x01]);
            if done(&self.m) {
                return true;
            }
        }
        false
    }
}

/// An axis and the I/O module, the chain on input `BIT`, set up and enabled.
fn start(chain: EStopChain) -> Rig {
    let (mut link, drive_end) = SocketLink::pair().unwrap();
    let mut io = SimNodeConfig::io(id(IO));
    io.faults = Faults {
        estop_chain: Some(chain),
        ..Faults::default()
    };
    let sim = vec![SimNodeConfig::new(id(AXIS)), io];
    let mut sim = Lockstep::new(drive_end, sim, PERIOD);
    let setups = [
        NodeSetup::Position(id(AXIS), Protections::default()),
        NodeSetup::Io(id(IO)),
    ];
    let mut opts = SetupOptions::new(PERIOD);
    opts.boot_timeout = Duration::from_millis(500);
    let initial =
        configure_nodes(&mut link, &setups, &opts, &mut sim, &mut |_| {}).expect("set-up");
    let kinds: Vec<_> = setups.iter().map(|s| (s.node(), s.kind())).collect();
    let sup = Supervision {
        heartbeat_timeout_s: 0.35,
        feedback_timeout_cycles: 25,
    };
    let now = sim.now().as_secs_f64();
    let mut m = Master::with_kinds(link, &kinds, &initial, sup, now).unwrap();
    assert_eq!(
        m.watch_estop(id(AXIS), INPUT),
        Err(EStopRefused::NotIo(AXIS))
    );
    assert_eq!(m.watch_estop(id(IO), 9), Err(EStopRefused::Input(9)));
    assert_eq!(m.watch_estop(id(IO), 0), Err(EStopRefused::Input(0)));
    m.watch_estop(id(IO), INPUT).expect("the module's input");
    let mut rig = Rig { m, sim };
    rig.enable(&[0, 0]);
    rig
}

fn stopped(m: &Master<SocketLink>) -> bool {
    m.fault().is_some()
        && m.goal() == Goal::Disabled
        && m.status()[0].state == Some(State::SwitchOnDisabled)
}

#[test]
fn the_chain_opening_stops_the_machine_and_reset_waits_for_it_to_close() {
    let mut rig = start(EStopChain {
        bit: BIT,
        opens: Some(300),
        closes: Some(900),
    });
    assert!(rig.ramp(0, 2000, stopped), "stopped");
    let f = *rig.m.fault().expect("an e-stop");
    assert_eq!(f.node, IO, "{f}");
    assert_eq!(f.cause, FaultCause::EStop(EStop::Input { input: INPUT }));
    assert_eq!(
        f.to_string(),
        "node 7: e-stop: input 4 open (the e-stop chain)"
    );
    assert_eq!(rig.m.status()[1].target, 0, "the outputs off");
    // Open: the reset is refused, and changes nothing.
    let held = [rig.m.status()[0].actual, 0];
    assert_eq!(
        rig.m.reset(),
        Err(ResetRefused::EStopOpen {
            node: IO,
            input: INPUT
        })
    );
    assert!(rig.m.fault().is_some());
    // Released: reset, enable where it stands, and on.
    while rig.m.status()[1].actual & (1 << BIT) == 0 {
        rig.cycle(&held);
    }
    test_support::arm_this_thread();
    let reset = rig.m.reset();
    assert_eq!(
        test_support::disarm_this_thread(),
        0,
        "heap events in the reset"
    );
    assert_eq!(reset, Ok(f));
    for _ in 0..(RESET_CYCLES as usize) {
        rig.cycle(&held);
        assert!(rig.m.fault().is_none(), "{:?}", rig.m.fault());
    }
    assert_eq!(rig.m.status()[0].state, Some(State::SwitchOnDisabled));
    rig.enable(&held);
    assert_eq!(rig.m.status()[0].actual, held[0], "enabling moved nothing");
    assert!(
        !rig.ramp(held[0], 500, |m| m.fault().is_some()),
        "{:?}",
        rig.m.fault()
    );
}

#[test]
fn the_operators_e_stop_stops_the_machine_until_reset() {
    let mut rig = start(EStopChain {
        bit: BIT,
        opens: None,
        closes: None,
    });
    assert!(!rig.ramp(0, 300, |m| m.fault().is_some()));
    test_support::arm_this_thread();
    rig.m.estop();
    assert_eq!(
        test_support::disarm_this_thread(),
        0,
        "heap events in the e-stop"
    );
    assert!(rig.ramp(3000, 2000, stopped), "stopped");
    let f = *rig.m.fault().expect("the e-stop");
    assert_eq!(f.node, DriveFault::OPERATOR);
    assert_eq!(f.to_string(), "operator: e-stop requested");
    let held = [rig.m.status()[0].actual, 0];
    assert_eq!(rig.m.reset(), Ok(f));
    for _ in 0..20 {
        rig.cycle(&held);
    }
    rig.enable(&held);
    assert!(
        !rig.ramp(held[0], 300, |m| m.fault().is_some()),
        "{:?}",
        rig.m.fault()
    );
}
