//! Each injected fault, as the master sees it on the bus.

use super::*;
use crate::wire::emcy;
use crate::wire::heartbeat::NmtState;

fn with_faults(id: u8, faults: Faults) -> SimNodeConfig {
    SimNodeConfig {
        faults,
        ..SimNodeConfig::new(node(id))
    }
}

#[test]
fn fault_at_sync_sends_emcy_and_reports_fault() {
    let mut m = Master::new(vec![
        with_faults(
            1,
            Faults {
                fault_at_sync: Some(10),
                ..Faults::default()
            },
        ),
        SimNodeConfig::new(node(2)),
    ]);
    m.operational(&[1, 2]);
    m.enable(1);
    m.enable(2);
    assert_eq!(m.bus.syncs(), 6);
    for k in 7..=9 {
        m.cycle(&[(1, 0x0F, 100 * k), (2, 0x0F, 100 * k)]);
    }
    // SYNC 10: EMCY 0x8611 with error register 0x81, then the TPDO in Fault reaction
    // active; the motor has reached the previous target and stops there.
    m.send(pdo::rpdo1_csp(node(1), 0x0F, 1000));
    m.send(pdo::rpdo1_csp(node(2), 0x0F, 1000));
    let got = text(&m.sync());
    assert_eq!(
        got,
        [
            "081#1186810000000000",
            "181#0F0284030000",
            "182#371284030000"
        ]
    );
    let (_, e) = emcy::decode(&f(&got[0])).unwrap();
    assert_eq!(
        e.to_string(),
        "EMCY 0x8611 (monitoring: following error), error register 0x81"
    );
    assert_eq!(m.read_u32(node(1), 0x1001, 0), 0x81);
    for k in 11..=20 {
        let fb = m.cycle(&[(1, 0x0F, 100 * k), (2, 0x0F, 100 * k)]);
        assert_eq!(fb[0].1.statusword & 0x4F, 0x08, "Fault at SYNC {k}");
        assert_eq!(fb[0].1.actual, 900, "the faulted drive ignores targets");
        assert_eq!(fb[1].1.actual, 100 * (k - 1), "node 2 goes on");
    }
    assert_eq!(m.drive_state(1), State::Fault);
    let last = m.bus.records().iter().rev().find(|r| r.node == 1).unwrap();
    assert_eq!((last.target_counts, last.actual_counts), (2000, 900));
    assert_eq!(last.statusword, 0x0208);

    // Fault reset (rising edge of bit 7): EMCY 0x0000, Switch on disabled; once only.
    let got = text(&m.send(pdo::rpdo1_csp(node(1), 0x80, 900)));
    assert!(got.is_empty(), "synchronous RPDO: takes effect at SYNC");
    let got = text(&m.sync());
    assert_eq!(got[0], "081#0000000000000000");
    assert_eq!(m.drive_state(1), State::SwitchOnDisabled);
    assert_eq!(m.read_u32(node(1), 0x1001, 0), 0);
    m.cycle(&[(1, 0x00, 900)]);
    assert_eq!(m.enable(1), [0x0221, 0x0233, 0x1237]);
    for target in [950, 1000] {
        assert_eq!(m.cycle(&[(1, 0x0F, target)])[0].1.statusword, 0x1237);
    }
    assert_eq!(m.bus.node_state(node(1)).unwrap().2, 950);
}

#[test]
fn heartbeat_stops_after_the_configured_sync() {
    let mut m = Master::new(vec![
        with_faults(
            1,
            Faults {
                heartbeat_stops_at: Some(50),
                ..Faults::default()
            },
        ),
        SimNodeConfig::new(node(2)),
    ]);
    m.operational(&[1, 2]);
    for id in [1, 2] {
        m.sdo_write(node(id), od::HEARTBEAT_PRODUCER, 0, SdoValue::U16(10))
            .unwrap();
    }
    let mut first = Vec::new();
    for _ in 0..50 {
        first.extend(heartbeats(&m.sync()));
    }
    let mut later = Vec::new();
    for _ in 0..100 {
        later.extend(heartbeats(&m.sync()));
    }
    let count = |beats: &[(u8, NmtState)], id| beats.iter().filter(|b| b.0 == id).count();
    assert!(
        count(&first, 1) >= 4,
        "node 1 beats before SYNC 50: {first:?}"
    );
    assert_eq!(count(&later, 1), 0, "node 1 is silent after SYNC 50");
    assert!(count(&later, 2) >= 9, "node 2 goes on");
    assert!(later.iter().all(|b| b.1 == NmtState::Operational));
    // The node itself still works: it answers SDO and sends its TPDOs.
    assert_eq!(m.read_u32(node(1), 0x1017, 0), 10);
    assert_eq!(m.cycle(&[]).len(), 2);
}

#[test]
fn a_node_that_never_boots_stays_silent() {
    let mut m = Master::new(vec![
        SimNodeConfig::new(node(1)),
        with_faults(
            2,
            Faults {
                never_boots: true,
                ..Faults::default()
            },
        ),
    ]);
    assert_eq!(text(&m.power_on()), ["701#00"]);
    assert!(
        m.send_str("602#4000100000000000").is_empty(),
        "no SDO answer"
    );
    m.send_str("000#8100");
    assert_eq!(text(&m.poll()), ["701#00"], "a reset does not help");
    m.send_str("000#0100");
    m.send(pdo::rpdo1_csp(node(2), 0x06, 0));
    let got = m.sync();
    assert!(got.iter().all(|fr| fr.id() & 0x7F == 1), "{got:?}");
    m.wait(1.0);
    let (nmt, drive, _) = m.bus.node_state(node(2)).unwrap();
    assert_eq!(nmt, NmtState::BootUp);
    assert_eq!(drive, State::NotReadyToSwitchOn);
    assert!(m.bus.records().iter().all(|r| r.node == 1));
}

#[test]
fn every_nth_frame_is_dropped() {
    let mut m = Master::new(vec![with_faults(
        4,
        Faults {
            drop_every: Some(3),
            ..Faults::default()
        },
    )]);
    // Boot-up is frame 1. Reads 2..=7: the 3rd and 6th frames are lost.
    assert_eq!(text(&m.power_on()), ["704#00"]);
    let answered: Vec<bool> = (0..6)
        .map(|_| !m.send_str("604#4000100000000000").is_empty())
        .collect();
    assert_eq!(answered, [true, false, true, true, false, true]);
    assert_eq!(m.bus.counters(node(4)).unwrap().dropped, 2);

    // In operation the TPDOs miss every third frame, but the records are complete.
    // Default mapping: RPDO1 = controlword, applied at once (type 0xFF); TPDO1 =
    // statusword, sent at a SYNC where it changed. Toggling Shutdown / Disable voltage
    // changes it at every SYNC.
    m.send_str("000#0104");
    let mut sent = 0;
    for _ in 0..30 {
        m.send(f("204#0600"));
        sent += m.sync().len();
        m.send(f("204#0000"));
        sent += m.sync().len();
    }
    assert_eq!(m.bus.records().len(), 60);
    let dropped = m.bus.counters(node(4)).unwrap().dropped - 2;
    assert_eq!(
        sent as u64 + dropped,
        60,
        "every TPDO is either sent or dropped"
    );
    assert_eq!(dropped, 20, "frames 9, 12, ..., 66 of the node's 67");
}

#[test]
fn drop_every_zero_drops_nothing() {
    let mut m = Master::new(vec![with_faults(
        4,
        Faults {
            drop_every: Some(0),
            ..Faults::default()
        },
    )]);
    assert_eq!(m.power_on().len(), 1);
    for _ in 0..10 {
        assert_eq!(m.send_str("604#4000100000000000").len(), 1);
    }
}
