//! The drive's own protections (issue 56): set-up writes the following-error window and
//! time, the quick-stop and fault-reaction option codes and the software position limits to
//! every axis drive and reads each back; a drive that keeps another value is refused with
//! its node and object. Against the simulated nodes over the in-process socket link, on a
//! virtual clock.

use drives::link::SocketLink;
use drives::master::{configure_nodes, NodeSetup, Protections, SetupErrorKind, SetupOptions};
use drives::od;
use drives::sim::{Faults, Lockstep, SimNodeConfig};
use drives::wire::NodeId;
use std::time::Duration;

const PERIOD: f64 = 0.002;

fn id(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

const GUARD: Protections = Protections {
    following_window: 500,
    following_timeout_ms: 20,
    quick_stop_option: 5,
    fault_reaction_option: 1,
    position_limits: Some((-1000, 100_000)),
};

/// Two axis drives set up with `GUARD` (the second without limits), node 2 with `faults`.
fn set_up(
    faults: Faults,
) -> (
    Result<Vec<i32>, drives::master::SetupError>,
    Lockstep<SocketLink>,
) {
    let (mut link, drive_end) = SocketLink::pair().unwrap();
    let mut second = SimNodeConfig::new(id(2));
    second.faults = faults;
    let mut sim = Lockstep::new(drive_end, vec![SimNodeConfig::new(id(1)), second], PERIOD);
    let endless = Protections {
        position_limits: None,
        ..GUARD
    };
    let setups = [
        NodeSetup::Position(id(1), GUARD),
        NodeSetup::Position(id(2), endless),
    ];
    let mut opts = SetupOptions::new(PERIOD);
    opts.boot_timeout = Duration::from_millis(500);
    let r = configure_nodes(&mut link, &setups, &opts, &mut sim, &mut |_| {});
    (r, sim)
}

#[test]
fn every_axis_drive_is_told_its_protections_and_they_are_read_back() {
    let (r, sim) = set_up(Faults::default());
    r.expect("set-up");
    let get = |n: u8, index: u16, sub: u8| sim.bus().object(id(n), index, sub).unwrap();
    for n in [1, 2] {
        assert_eq!(get(n, od::FOLLOWING_ERROR_WINDOW, 0), 500);
        assert_eq!(get(n, od::FOLLOWING_ERROR_TIMEOUT, 0), 20);
        assert_eq!(get(n, od::QUICK_STOP_OPTION, 0), 5);
        assert_eq!(get(n, od::FAULT_REACTION_OPTION, 0), 1);
    }
    assert_eq!(get(1, od::SOFTWARE_POSITION_LIMIT, 1) as i32, -1000);
    assert_eq!(get(1, od::SOFTWARE_POSITION_LIMIT, 2) as i32, 100_000);
    // The endless axis keeps the drive's own limits.
    assert_eq!(get(2, od::SOFTWARE_POSITION_LIMIT, 1) as i32, i32::MIN);
    assert_eq!(get(2, od::SOFTWARE_POSITION_LIMIT, 2) as i32, i32::MAX);
}

#[test]
fn a_drive_that_keeps_another_value_is_refused_naming_the_object() {
    for (object, expected) in [
        ((od::FOLLOWING_ERROR_WINDOW, 0), 500),
        ((od::QUICK_STOP_OPTION, 0), 5),
    ] {
        let faults = Faults {
            keeps_object: Some(object),
            ..Faults::default()
        };
        let (r, _) = set_up(faults);
        let e = r.expect_err("refused");
        assert_eq!((e.node, e.object), (2, Some(object)), "{e}");
        assert!(
            matches!(e.kind, SetupErrorKind::Mismatch { expected: x, .. } if x == expected),
            "{e}"
        );
        assert!(e.to_string().contains("read back"), "{e}");
    }
}
