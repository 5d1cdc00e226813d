//! NMT, heartbeats, PDO mapping and transmission types, and a session through the real
//! socket code path.

use super::*;
use crate::link::{CanLink, Sent, SocketLink};
use crate::wire::heartbeat::NmtState;

#[test]
fn resets_restore_defaults_and_boot_again() {
    let mut m = Master::with_nodes(&[5]);
    let n = node(5);
    m.operational(&[5]);
    m.sdo_write(n, od::HEARTBEAT_PRODUCER, 0, SdoValue::U16(10))
        .unwrap();
    m.enable(5);
    m.cycle(&[(5, 0x0F, 300)]);

    // Reset communication: mapping and heartbeat back to defaults, the drive untouched.
    assert!(m.send_str("000#8205").is_empty());
    assert_eq!(m.bus.node_state(n).unwrap().0, NmtState::BootUp);
    assert!(
        m.send_str("605#4000100000000000").is_empty(),
        "initialising"
    );
    assert_eq!(text(&m.poll()), ["705#00"]);
    assert_eq!(m.read_u32(n, 0x1600, 0), 1);
    assert_eq!(m.read_u32(n, 0x1600, 1), 0x6040_0010);
    assert_eq!(m.read_u32(n, 0x1017, 0), 0);
    assert_eq!(m.read_u32(n, 0x6060, 0), 8);
    assert_eq!(m.drive_state(5), State::OperationEnabled);
    assert!(heartbeats(&m.wait(0.1)).is_empty(), "heartbeat off again");

    // Reset node (to all): the application too; the motor stays where it is.
    m.sync();
    assert!(m.send_str("000#8100").is_empty());
    assert_eq!(text(&m.poll()), ["705#00"]);
    assert_eq!(m.read_u32(n, 0x6060, 0), 0);
    assert_eq!(m.drive_state(5), State::SwitchOnDisabled);
    assert_eq!(m.read_u32(n, 0x6064, 0), 300);
    assert_eq!(m.read_u32(n, 0x607A, 0), 300);
}

#[test]
fn nmt_commands_switch_states_as_heartbeats_report() {
    let mut m = Master::with_nodes(&[1, 2]);
    m.power_on();
    for id in [1, 2] {
        m.sdo_write(node(id), 0x1017, 0, SdoValue::U16(20)).unwrap();
    }
    let beats = |m: &mut Master, cmd: &str| {
        m.send_str(cmd);
        heartbeats(&m.wait(0.02))
    };
    use NmtState::*;
    assert_eq!(
        beats(&mut m, "000#0101"),
        [(1, Operational), (2, PreOperational)]
    );
    assert_eq!(beats(&mut m, "000#0200"), [(1, Stopped), (2, Stopped)]);
    assert_eq!(
        beats(&mut m, "000#8002"),
        [(1, Stopped), (2, PreOperational)]
    );
    assert_eq!(
        beats(&mut m, "000#0100"),
        [(1, Operational), (2, Operational)]
    );
    // Malformed NMT frames change nothing.
    for bad in ["000#02", "000#020100", "000#0301", "000#0280"] {
        assert_eq!(
            beats(&mut m, bad),
            [(1, Operational), (2, Operational)],
            "{bad}"
        );
    }
}

#[test]
fn pdos_run_only_in_operational() {
    let mut m = Master::with_nodes(&[1]);
    m.operational(&[1]);
    assert_eq!(m.cycle(&[(1, 0x06, 0)]).len(), 1);
    m.send_str("000#8001");
    assert!(m.cycle(&[(1, 0x07, 0)]).is_empty(), "pre-operational");
    m.send_str("000#0201");
    assert!(m.cycle(&[(1, 0x07, 0)]).is_empty(), "stopped");
    assert_eq!(m.drive_state(1), State::ReadyToSwitchOn, "no RPDO taken");
    m.send_str("000#0101");
    let fb = m.cycle(&[(1, 0x07, 0)]);
    assert_eq!(fb[0].1.statusword, 0x0233);
    assert_eq!(m.bus.records().len(), 2, "records in operational only");
}

#[test]
fn rpdos_are_split_per_the_current_mapping() {
    let mut m = Master::with_nodes(&[1]);
    let n = node(1);
    m.power_on();
    m.send_str("000#0101");
    // The default mapping has the controlword only: a CSP RPDO is the wrong length.
    m.send(pdo::rpdo1_csp(n, 0x06, 5));
    assert_eq!(m.bus.counters(n).unwrap().rpdo_length_errors, 1);
    m.send(f("201#0600")); // type 0xFF: at once
    assert_eq!(m.drive_state(1), State::ReadyToSwitchOn);

    // Target first, then the controlword: the bytes follow the mapping, not a fixed layout.
    m.send_str("000#8001");
    m.sdo_write(n, 0x1400, 1, SdoValue::U32(0x8000_0201))
        .unwrap();
    m.sdo_write(n, 0x1600, 0, SdoValue::U8(0)).unwrap();
    m.sdo_write(n, 0x1600, 1, SdoValue::U32(0x607A_0020))
        .unwrap();
    m.sdo_write(n, 0x1600, 2, SdoValue::U32(0x6040_0010))
        .unwrap();
    m.sdo_write(n, 0x1600, 0, SdoValue::U8(2)).unwrap();
    m.sdo_write(n, 0x1400, 2, SdoValue::U8(1)).unwrap();
    m.sdo_write(n, 0x1400, 1, SdoValue::U32(0x201)).unwrap();
    m.send_str("000#0101");
    m.send(f("201#1027000007"));
    assert_eq!(m.bus.counters(n).unwrap().rpdo_length_errors, 2, "5 bytes");
    m.send(f("201#102700000700"));
    assert_eq!(m.read_u32(n, 0x6040, 0), 0x06, "type 1: not before SYNC");
    m.sync();
    assert_eq!(m.read_u32(n, 0x6040, 0), 0x07);
    assert_eq!(m.read_u32(n, 0x607A, 0), 10_000);
    assert_eq!(m.drive_state(1), State::SwitchedOn);
    assert_eq!(m.bus.counters(n).unwrap().rpdo_length_errors, 2);
}

#[test]
fn tpdo_transmission_types() {
    let mut m = Master::with_nodes(&[1]);
    m.operational(&[1]);
    let n = node(1);
    let tpdos = |m: &mut Master, syncs| (0..syncs).map(|_| m.cycle(&[]).len()).collect();
    m.send_str("000#8001");
    m.sdo_write(n, 0x1800, 2, SdoValue::U8(3)).unwrap();
    m.send_str("000#0101");
    let every_third: Vec<usize> = tpdos(&mut m, 6);
    assert_eq!(every_third, [0, 0, 1, 0, 0, 1]);
    // Type 0xFF: at a SYNC where the mapped values changed since the last TPDO.
    m.sdo_write(n, 0x1800, 2, SdoValue::U8(0xFF)).unwrap();
    let on_change: Vec<usize> = tpdos(&mut m, 3);
    assert_eq!(on_change, [0, 0, 0]);
    m.send(f("201#060000000000"));
    assert_eq!(m.cycle(&[]).len(), 1, "the statusword changed");
    // Invalid: never.
    m.sdo_write(n, 0x1800, 1, SdoValue::U32(0x8000_0181))
        .unwrap();
    m.send(f("201#070000000000"));
    assert!(m.cycle(&[]).is_empty());
}

#[test]
fn statusword_bits_12_and_13_in_csp() {
    let mut m = Master::with_nodes(&[1]);
    m.operational(&[1]);
    let n = node(1);
    m.sdo_write(n, od::FOLLOWING_ERROR_WINDOW, 0, SdoValue::U32(30))
        .unwrap();
    m.enable(1);
    let statusword = |m: &mut Master, target| m.cycle(&[(1, 0x0F, target)])[0].1.statusword;
    assert_eq!(statusword(&mut m, 20), 0x1237, "|20 - 0| within the window");
    assert_eq!(statusword(&mut m, 70), 0x3237, "|70 - 20| > 30");
    assert_eq!(statusword(&mut m, 70), 0x1237, "caught up");
    // An SDO controlword applies at once; only Operation enabled has bit 12.
    m.sdo_write(n, od::CONTROLWORD, 0, SdoValue::U16(0x07))
        .unwrap();
    assert_eq!(m.read_u32(n, od::STATUSWORD, 0), 0x0233);
}

/// The following error counts only once it has stayed over the window longer than 0x6066
/// (1 ms periods here); 2^32 - 1 switches it off; 0x607D bounds the demand.
#[test]
fn following_error_time_and_software_position_limits() {
    let mut m = Master::with_nodes(&[1]);
    m.operational(&[1]);
    let n = node(1);
    m.sdo_write(n, od::FOLLOWING_ERROR_WINDOW, 0, SdoValue::U32(30))
        .unwrap();
    m.sdo_write(n, od::FOLLOWING_ERROR_TIMEOUT, 0, SdoValue::U16(3))
        .unwrap();
    m.enable(1);
    let bit13 = |m: &mut Master, target| m.cycle(&[(1, 0x0F, target)])[0].1.statusword & 0x2000;
    // 40 counts a period: over the window every period, reported from the fourth (> 3 ms).
    let seen: Vec<u16> = (1..=6).map(|k| bit13(&mut m, 40 * k)).collect();
    assert_eq!(seen, [0, 0, 0, 0x2000, 0x2000, 0x2000]);
    assert_eq!(bit13(&mut m, 240), 0, "caught up");
    m.sdo_write(n, od::FOLLOWING_ERROR_WINDOW, 0, SdoValue::U32(u32::MAX))
        .unwrap();
    let off: Vec<u16> = (7..=12).map(|k| bit13(&mut m, 40 * k)).collect();
    assert!(off.iter().all(|&b| b == 0), "off: {off:?}");
    // Limits: the drive stops at 500 whatever the target.
    m.sdo_write(n, od::SOFTWARE_POSITION_LIMIT, 2, SdoValue::I32(500))
        .unwrap();
    for _ in 0..5 {
        m.cycle(&[(1, 0x0F, 900)]);
    }
    assert_eq!(m.drive_state_position(1), 500);
}

#[test]
fn target_followed_needs_csp_mode() {
    let mut m = Master::with_nodes(&[1]);
    m.power_on();
    let n = node(1);
    for cw in [0x06, 0x07, 0x0F] {
        m.sdo_write(n, od::CONTROLWORD, 0, SdoValue::U16(cw))
            .unwrap();
    }
    assert_eq!(m.drive_state(1), State::OperationEnabled);
    assert_eq!(
        m.read_u32(n, od::STATUSWORD, 0),
        0x0237,
        "mode 0: no bit 12"
    );
    m.sdo_write(n, od::MODES_OF_OPERATION, 0, SdoValue::I8(8))
        .unwrap();
    assert_eq!(m.read_u32(n, od::STATUSWORD, 0), 0x1237);
}

#[test]
fn sync_counters_and_malformed_syncs() {
    let mut m = Master::with_nodes(&[1]);
    m.operational(&[1]);
    assert_eq!(m.send_str("080#01").len(), 1);
    assert_eq!(m.send_str("080#F0").len(), 1, "type 1: every SYNC");
    assert!(m.send_str("080#00").is_empty());
    assert!(m.send_str("080#0102").is_empty());
    assert_eq!(m.bus.syncs(), 2);
}

#[test]
fn duplicate_and_unknown_nodes() {
    let m = Master::new(vec![
        SimNodeConfig::new(node(1)),
        SimNodeConfig {
            initial_position: 7,
            ..SimNodeConfig::new(node(1))
        },
    ]);
    assert_eq!(m.bus.node_state(node(1)).unwrap().2, 0, "the first is kept");
    assert_eq!(m.bus.node_state(node(2)), None);
    assert_eq!(m.bus.counters(node(2)), None);
}

/// Moves every frame waiting at the drives' end through the bus and back.
fn pump(bus: &mut SimBus, drives: &mut SocketLink, now: f64) {
    let mut out = Vec::new();
    bus.poll(now, &mut |fr| out.push(fr));
    while let Ok(Some(frame)) = drives.recv() {
        bus.on_frame(&frame, now, &mut |fr| out.push(fr));
    }
    for frame in out {
        assert_eq!(drives.send(&frame), Ok(Sent::Queued));
    }
}

#[test]
fn a_session_through_the_socket_link() {
    let (mut master, mut drives) = SocketLink::pair().unwrap();
    let mut bus = SimBus::new(vec![SimNodeConfig::new(node(1))], PERIOD);
    let script: &[(&[&str], &[&str])] = &[
        (&[], &["701#00"]),
        (&["601#2F60600008000000"], &["581#6060600000000000"]),
        // the mapping procedure of docs/canopen.md, RPDO1 then TPDO1.
        (&["601#2300140101020080"], &["581#6000140100000000"]),
        (&["601#2F00160000000000"], &["581#6000160000000000"]),
        (&["601#2300160110004060"], &["581#6000160100000000"]),
        (&["601#2300160220007A60"], &["581#6000160200000000"]),
        (&["601#2F00160002000000"], &["581#6000160000000000"]),
        (&["601#2F00140201000000"], &["581#6000140200000000"]),
        (&["601#2300140101020000"], &["581#6000140100000000"]),
        (&["601#2300180181010080"], &["581#6000180100000000"]),
        (&["601#2F001A0000000000"], &["581#60001A0000000000"]),
        (&["601#23001A0110004160"], &["581#60001A0100000000"]),
        (&["601#23001A0220006460"], &["581#60001A0200000000"]),
        (&["601#2F001A0002000000"], &["581#60001A0000000000"]),
        (&["601#2F00180201000000"], &["581#6000180200000000"]),
        (&["601#2300180181010000"], &["581#6000180100000000"]),
        (&["000#0101"], &[]),
        (&["201#060000000000", "080#"], &["181#210200000000"]),
        (&["201#070000000000", "080#"], &["181#330200000000"]),
        (&["201#0F00E8030000", "080#"], &["181#371200000000"]),
        (&["201#0F00D0070000", "080#"], &["181#3712E8030000"]),
    ];
    for (step, (requests, answers)) in script.iter().enumerate() {
        for r in *requests {
            assert_eq!(master.send(&f(r)), Ok(Sent::Queued));
        }
        pump(&mut bus, &mut drives, step as f64 * PERIOD);
        let mut got = Vec::new();
        while let Ok(Some(frame)) = master.recv() {
            got.push(frame.to_string());
        }
        assert_eq!(got, *answers, "step {step}: {requests:?}");
    }
    assert_eq!(bus.records().len(), 4);
    assert_eq!(bus.node_state(node(1)).unwrap().2, 1000);
}
