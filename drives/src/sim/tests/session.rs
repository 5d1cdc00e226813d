//! A whole master session, scripted step by step as the master will run it: boot, set-up
//! over SDO, PDO mapping exactly as docs/canopen.md, start, enable, then 1000 cycles of a ramp.

use super::*;
use crate::wire::heartbeat::NmtState;

const LAG_S: f64 = 0.010;

/// The reference the motor must follow: `x_k = x_(k-1) + a (d_(k-1) - x_(k-1))`, with the
/// demand `d` being the previous cycle's target.
fn first_order(start: f64, targets: &[i32], lag_s: f64) -> Vec<i32> {
    let a = if lag_s > 0.0 {
        1.0 - (-PERIOD / lag_s).exp()
    } else {
        1.0
    };
    let mut x = start;
    let mut demand = start;
    targets
        .iter()
        .map(|&t| {
            x += a * (demand - x);
            demand = f64::from(t);
            x.round() as i32
        })
        .collect()
}

#[test]
fn a_scripted_master_runs_a_csp_session() {
    let mut m = Master::new(vec![
        SimNodeConfig {
            lag_s: LAG_S,
            initial_position: 1000,
            ..SimNodeConfig::new(node(1))
        },
        SimNodeConfig::new(node(2)),
    ]);

    // Power-on, then NMT reset node to all: each time one boot-up per node.
    assert_eq!(text(&m.power_on()), ["701#00", "702#00"]);
    assert!(m.send_str("000#8100").is_empty());
    assert_eq!(m.bus.node_state(node(1)).unwrap().0, NmtState::BootUp);
    assert_eq!(text(&m.poll()), ["701#00", "702#00"]);
    assert!(m.poll().is_empty(), "one boot-up per reset");

    for id in [1, 2] {
        let n = node(id);
        assert_eq!(m.read_u32(n, 0x1000, 0), 0x0002_0192);
        assert_eq!(
            m.read_u32(n, od::STATUSWORD, 0),
            0x0240,
            "switch on disabled"
        );
        assert_eq!(m.read_u32(n, od::MODES_OF_OPERATION_DISPLAY, 0), 0);
    }
    // Modes of operation = 8 as a candump vector, then read back through the display.
    assert_eq!(m.send_str("601#2F60600008000000"), ["581#6060600000000000"]);
    assert_eq!(m.send_str("601#4061600000000000"), ["581#4F61600008000000"]);
    m.sdo_write(node(2), od::MODES_OF_OPERATION, 0, SdoValue::I8(8))
        .unwrap();

    for id in [1, 2] {
        let n = node(id);
        let period = od::INTERPOLATION_TIME_PERIOD;
        m.sdo_write(n, period, 1, SdoValue::U8(1)).unwrap();
        m.sdo_write(n, period, 2, SdoValue::I8(-3)).unwrap();
        assert_eq!(m.sdo_read(n, period, 2).unwrap().to_i8(), Some(-3));
        m.map_csp(n);
        assert_eq!(m.read_u32(n, od::RPDO1_MAPPING, 0), 2);
        assert_eq!(m.read_u32(n, od::RPDO1_MAPPING, 2), 0x607A_0020);
        assert_eq!(m.read_u32(n, od::TPDO1_MAPPING, 1), 0x6041_0010);
        assert_eq!(
            m.read_u32(n, od::TPDO1_COMMUNICATION, 1),
            0x180 + u32::from(id)
        );
        assert_eq!(m.read_u32(n, od::TPDO1_COMMUNICATION, 2), 1);
        m.sdo_write(n, od::HEARTBEAT_PRODUCER, 0, SdoValue::U16(100))
            .unwrap();
    }
    // No PDOs in pre-operational, nor a record.
    assert!(m.cycle(&[(1, 0x06, 1000)]).is_empty());
    assert!(m.bus.records().is_empty());

    assert!(m.send_str("000#0100").is_empty());
    let statuswords = m.enable(1);
    assert_eq!(
        statuswords,
        [0x0221, 0x0233, 0x1237],
        "ready, switched on, enabled"
    );
    assert_eq!(m.enable(2), [0x0221, 0x0233, 0x1237]);
    assert_eq!(m.drive_state(1), State::OperationEnabled);

    // 1000 cycles of a ramp of 50 counts per cycle on node 1, -20 on node 2.
    let skip = m.bus.records().len();
    let start_sync = m.bus.syncs();
    let mut frames = Vec::new();
    let mut sent = Vec::new();
    let mut seen = Vec::new();
    for k in 1..=1000 {
        let t1 = 1000 + 50 * k;
        let t2 = -20 * k;
        m.send(pdo::rpdo1_csp(node(1), 0x0F, t1));
        m.send(pdo::rpdo1_csp(node(2), 0x0F, t2));
        sent.push((t1, t2));
        let got = m.sync();
        for (n, fb) in got.iter().filter_map(|fr| pdo::decode_tpdo1_csp(fr).ok()) {
            seen.push((n.get(), fb));
        }
        frames.extend(got);
    }
    assert_eq!(seen.len(), 2000, "one TPDO per node per SYNC");

    let targets1: Vec<i32> = sent.iter().map(|s| s.0).collect();
    let expected1 = first_order(1000.0, &targets1, LAG_S);
    let actual1: Vec<i32> = seen
        .iter()
        .filter(|s| s.0 == 1)
        .map(|s| s.1.actual)
        .collect();
    for (k, (a, e)) in actual1.iter().zip(&expected1).enumerate() {
        assert!((a - e).abs() <= 1, "cycle {k}: actual {a}, reference {e}");
    }
    // Steady state: the target leads by v / a, about v * (lag / period + 1/2).
    let a = 1.0 - (-PERIOD / LAG_S).exp();
    let lead = f64::from(targets1[999] - actual1[999]);
    assert!((lead - 50.0 / a).abs() <= 1.0, "lead {lead} counts");
    // Without lag, the actual position is the previous cycle's target.
    let actual2: Vec<i32> = seen
        .iter()
        .filter(|s| s.0 == 2)
        .map(|s| s.1.actual)
        .collect();
    assert_eq!(actual2[0], 0);
    for k in 1..1000 {
        assert_eq!(actual2[k], sent[k - 1].1, "cycle {k}");
    }
    assert!(seen.iter().all(|(_, fb)| fb.statusword == 0x1237));

    // The records are what the TPDOs said, with the targets the master sent.
    let records = &m.bus.records()[skip..];
    assert_eq!(records.len(), 2000);
    for (k, pair) in records.chunks(2).enumerate() {
        let sync = start_sync + k as u64 + 1;
        let (t1, t2) = sent[k];
        let expect = |node, target, actual| Record {
            sync,
            node,
            target_counts: target,
            actual_counts: actual,
            statusword: 0x1237,
        };
        assert_eq!(pair[0], expect(1, t1, actual1[k]));
        assert_eq!(pair[1], expect(2, t2, actual2[k]));
    }

    // Heartbeats every 100 ms in operational, from both nodes, over the 1 s of cycles.
    let beats = heartbeats(&frames);
    assert!(beats.iter().all(|&(_, s)| s == NmtState::Operational));
    for id in [1, 2] {
        let count = beats.iter().filter(|b| b.0 == id).count();
        assert!((9..=11).contains(&count), "node {id}: {count} heartbeats");
    }
    assert_eq!(m.bus.counters(node(1)), Some(NodeCounters::default()));
}

#[test]
fn records_are_written_as_csv() {
    let mut m = Master::with_nodes(&[3]);
    m.operational(&[3]);
    m.enable(3);
    m.cycle(&[(3, 0x0F, -7)]);
    let mut csv = Vec::new();
    m.bus.write_records(&mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "sync,node,target_counts,actual_counts,statusword");
    assert_eq!(lines[1], "1,3,0,0,545"); // 0x0221 after Shutdown
    assert_eq!(lines.last(), Some(&"4,3,-7,0,4663")); // 0x1237, the target effective
    assert_eq!(lines.len(), 5);
    assert_eq!(m.bus.take_records().len(), 4);
    assert!(m.bus.records().is_empty());
}
