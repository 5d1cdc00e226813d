//! A CiA-401 digital I/O module (the coolant valves), set up and run as the master will:
//! the dictionary, the SDO aborts, outputs by RPDO1 and inputs by TPDO1, NMT, faults.

use super::*;
use crate::wire::emcy;
use crate::wire::heartbeat::NmtState;
use crate::wire::pdo::{decode_tpdo1_io, rpdo1_io, RPDO1_IO_MAPPING, TPDO1_IO_MAPPING};

const ID: u8 = 7;

fn module(faults: Faults) -> Master {
    Master::new(vec![SimNodeConfig {
        faults,
        ..SimNodeConfig::io(node(ID))
    }])
}

/// Boot, then the master's set-up: the I/O mapping with transmission type 1 both ways,
/// heartbeat every 100 ms, NMT start.
fn operational(m: &mut Master) {
    m.power_on();
    m.map_pdos(node(ID), &RPDO1_IO_MAPPING, &TPDO1_IO_MAPPING);
    m.sdo_write(node(ID), od::HEARTBEAT_PRODUCER, 0, SdoValue::U16(100))
        .unwrap();
    m.nmt(NmtCommand::Start, nmt::Target::Node(node(ID)));
}

/// One period: the RPDO1 with `outputs` (if any), then SYNC; the module's TPDO1s as inputs.
fn cycle(m: &mut Master, outputs: Option<u8>) -> Vec<u8> {
    if let Some(outputs) = outputs {
        assert!(m.send(rpdo1_io(node(ID), outputs)).is_empty());
    }
    m.sync()
        .iter()
        .filter_map(|fr| decode_tpdo1_io(fr).ok())
        .map(|(n, inputs)| {
            assert_eq!(n, node(ID));
            inputs
        })
        .collect()
}

fn last_record(m: &Master) -> Record {
    *m.bus.records().last().expect("a record")
}

#[test]
fn device_type_and_dictionary_defaults() {
    let mut m = module(Faults::default());
    assert_eq!(text(&m.power_on()), ["707#00"]);
    let n = node(ID);
    let cases: [(u16, u8, usize, u32); 15] = [
        (0x1000, 0, 4, 0x0003_0191),
        (0x1001, 0, 1, 0),
        (0x1017, 0, 2, 0),
        (0x1400, 0, 1, 2),
        (0x1400, 1, 4, 0x207),
        (0x1400, 2, 1, 0xFF),
        (0x1600, 0, 1, 1),
        (0x1600, 1, 4, 0x6200_0108),
        (0x1800, 1, 4, 0x187),
        (0x1A00, 0, 1, 1),
        (0x1A00, 1, 4, 0x6000_0108),
        (0x6000, 0, 1, 1),
        (0x6000, 1, 1, 0),
        (0x6200, 0, 1, 1),
        (0x6200, 1, 1, 0),
    ];
    for (index, sub, len, value) in cases {
        let data = m.sdo_read(n, index, sub).unwrap();
        assert_eq!(data.as_bytes().len(), len, "{index:04X}:{sub}");
        assert_eq!(m.read_u32(n, index, sub), value, "{index:04X}:{sub}");
    }
    assert_eq!(DEVICE_TYPE_IO, 0x0003_0191);
    assert_eq!(m.bus.nmt_state(n), Some(NmtState::PreOperational));
    assert_eq!(m.bus.node_state(n), None, "no drive state");
    assert_eq!(m.bus.io_outputs(n), Some(0));
    assert_eq!(m.bus.io_outputs(node(8)), None, "not simulated");
}

#[test]
fn outputs_take_effect_at_sync_and_the_inputs_follow() {
    let mut m = module(Faults::default());
    operational(&mut m);
    assert_eq!(cycle(&mut m, None), [0x00]);

    // Synchronous: 207#03 waits for the SYNC; its TPDO1 and the next carry the inputs.
    assert!(m.send_str("207#03").is_empty());
    assert_eq!(m.bus.io_outputs(node(ID)), Some(0), "not before the SYNC");
    assert_eq!(m.send_str("080#"), ["187#03"]);
    assert_eq!(m.bus.io_outputs(node(ID)), Some(3));
    assert_eq!(text(&m.send(sync::encode())), ["187#03"]);
    let r = last_record(&m);
    assert_eq!(
        (r.node, r.target_counts, r.actual_counts, r.statusword),
        (ID, 3, 3, 0),
        "outputs 3, inputs 3"
    );

    // Every pattern, one per period, read back at the SYNC that applies it.
    let skip = m.bus.records().len();
    for outputs in 0..=255 {
        assert_eq!(cycle(&mut m, Some(outputs)), [outputs]);
    }
    let records = &m.bus.records()[skip..];
    assert_eq!(records.len(), 256);
    for (outputs, r) in (0..=255).zip(records) {
        assert_eq!((r.target_counts, r.actual_counts), (outputs, outputs));
    }

    // Heartbeats every 100 ms, and the module answers SDO in operational.
    let beats = heartbeats(&m.wait(0.35));
    assert!((3..=4).contains(&beats.len()), "{beats:?}");
    assert!(beats.iter().all(|&b| b == (ID, NmtState::Operational)));
    assert_eq!(m.read_u32(node(ID), od::DIGITAL_INPUTS, 1), 255);
}

#[test]
fn an_rpdo_of_the_wrong_length_is_ignored_and_counted() {
    let mut m = module(Faults::default());
    operational(&mut m);
    assert_eq!(cycle(&mut m, Some(0x21)), [0x21]);
    for frame in ["207#0300", "207#", "207#0102030405060708"] {
        assert!(m.send_str(frame).is_empty(), "{frame}");
    }
    assert_eq!(m.bus.counters(node(ID)).unwrap().rpdo_length_errors, 3);
    assert_eq!(cycle(&mut m, None), [0x21], "the outputs are unchanged");
}

#[test]
fn sdo_aborts_follow_the_drives_rules() {
    let mut m = module(Faults::default());
    m.power_on();
    let exchange = |m: &mut Master, request: &str, answer: &str| {
        assert_eq!(m.send_str(request), [answer], "{request}");
    };
    // The inputs are read-only (0x06010002), as are both counts.
    exchange(&mut m, "607#2F00600103000000", "587#8000600102000106");
    exchange(&mut m, "607#2F00620001000000", "587#8000620002000106");
    // No CiA-402 objects (0x06020000); no 0x6200:02 (0x06090011).
    exchange(&mut m, "607#4040600000000000", "587#8040600000000206");
    exchange(&mut m, "607#2B40600006000000", "587#8040600000000206");
    exchange(&mut m, "607#2F60600003000000", "587#8060600000000206");
    exchange(&mut m, "607#4000620200000000", "587#8000620211000906");
    // The outputs are one byte (0x06070010); readable and writable.
    exchange(&mut m, "607#2B00620103000000", "587#8000620110000706");
    exchange(&mut m, "607#2F00620103000000", "587#6000620100000000");
    exchange(&mut m, "607#4000600100000000", "587#4F00600103000000");
    // The mapping of a valid PDO cannot change (0x06010000).
    exchange(&mut m, "607#2F00160000000000", "587#8000160000000106");

    // Only the outputs into the RPDO and the inputs into the TPDO, 8 bits (0x06040041).
    let n = node(ID);
    m.sdo_write(n, 0x1400, 1, SdoValue::U32(0x8000_0207))
        .unwrap();
    m.sdo_write(n, 0x1600, 0, SdoValue::U8(0)).unwrap();
    for entry in [0x6000_0108, 0x6200_0110, 0x6200_0008, 0x6040_0010] {
        let code = m.sdo_write(n, 0x1600, 1, SdoValue::U32(entry));
        assert_eq!(code, Err(AbortCode::CannotMapToPdo), "RPDO {entry:08X}");
    }
    m.sdo_write(n, 0x1800, 1, SdoValue::U32(0x8000_0187))
        .unwrap();
    m.sdo_write(n, 0x1A00, 0, SdoValue::U8(0)).unwrap();
    for entry in [0x6200_0108, 0x6041_0010] {
        let code = m.sdo_write(n, 0x1A00, 1, SdoValue::U32(entry));
        assert_eq!(code, Err(AbortCode::CannotMapToPdo), "TPDO {entry:08X}");
    }
    m.sdo_write(n, 0x1A00, 1, SdoValue::U32(0x6000_0108))
        .unwrap();
    m.sdo_write(n, 0x1A00, 0, SdoValue::U8(1)).unwrap();
}

#[test]
fn nmt_stop_switches_the_outputs_off() {
    let mut m = module(Faults::default());
    operational(&mut m);
    assert_eq!(cycle(&mut m, Some(0x05)), [0x05]);
    m.send_str("000#0207");
    assert_eq!(m.bus.io_outputs(node(ID)), Some(0));
    assert!(m.send_str("607#4000620100000000").is_empty(), "stopped");
    assert!(cycle(&mut m, Some(0x05)).is_empty(), "no PDOs");
    assert_eq!(heartbeats(&m.wait(0.1)), [(ID, NmtState::Stopped)]);
    assert_eq!(m.bus.io_outputs(node(ID)), Some(0));

    // Started again: off until the master writes them.
    m.send_str("000#0107");
    assert_eq!(cycle(&mut m, None), [0x00]);
    assert_eq!(last_record(&m).target_counts, 0);
    assert_eq!(cycle(&mut m, Some(0x05)), [0x05]);

    // Pre-operational keeps them.
    m.send_str("000#8007");
    assert_eq!(m.bus.io_outputs(node(ID)), Some(0x05));
    assert_eq!(m.read_u32(node(ID), od::DIGITAL_INPUTS, 1), 0x05);
}

#[test]
fn resets_and_sdo_writes_of_the_outputs() {
    let mut m = module(Faults::default());
    operational(&mut m);
    assert_eq!(cycle(&mut m, Some(0x09)), [0x09]);
    // Reset node: outputs and mapping back to the defaults, a new boot-up.
    m.send_str("000#8107");
    assert_eq!(m.bus.io_outputs(node(ID)), Some(0));
    assert_eq!(text(&m.poll()), ["707#00"]);
    assert_eq!(m.read_u32(node(ID), od::TPDO1_COMMUNICATION, 2), 0xFF);

    // An SDO write takes effect at once, in pre-operational too; reset communication
    // keeps the outputs.
    m.sdo_write(node(ID), od::DIGITAL_OUTPUTS, 1, SdoValue::U8(0x06))
        .unwrap();
    assert_eq!(m.bus.io_outputs(node(ID)), Some(0x06));
    assert_eq!(m.read_u32(node(ID), od::DIGITAL_INPUTS, 1), 0x06);
    m.send_str("000#8207");
    m.poll();
    assert_eq!(m.bus.io_outputs(node(ID)), Some(0x06));
}

#[test]
fn the_default_event_driven_pdos_work_unmapped() {
    // Without set-up: RPDO1 and TPDO1 already map the outputs and inputs, type 0xFF.
    let mut m = module(Faults::default());
    m.power_on();
    m.send_str("000#0107");
    assert!(m.send_str("207#01").is_empty());
    assert_eq!(m.bus.io_outputs(node(ID)), Some(1), "at once");
    assert_eq!(cycle(&mut m, None), [0x01], "changed since the last TPDO");
    assert!(cycle(&mut m, None).is_empty(), "unchanged");
    assert_eq!(cycle(&mut m, Some(0x02)), [0x02]);
    assert_eq!(m.bus.records().len(), 3);
}

#[test]
fn a_fault_sends_emcy_5000_and_holds_the_outputs_off() {
    let mut m = module(Faults {
        fault_at_sync: Some(5),
        ..Faults::default()
    });
    operational(&mut m);
    for _ in 1..=4 {
        assert_eq!(cycle(&mut m, Some(0xFF)), [0xFF]);
    }
    m.send(rpdo1_io(node(ID), 0xFF));
    let got = m.sync();
    assert_eq!(text(&got), ["087#0050810000000000", "187#00"]);
    let (_, e) = emcy::decode(&got[0]).unwrap();
    assert_eq!(
        e.to_string(),
        "EMCY 0x5000 (device hardware), error register 0x81"
    );
    assert_eq!(
        (last_record(&m).target_counts, last_record(&m).actual_counts),
        (0, 0)
    );
    for _ in 0..5 {
        assert_eq!(cycle(&mut m, Some(0xFF)), [0x00], "held off");
    }
    assert_eq!(m.read_u32(node(ID), 0x1001, 0), 0x81);
    m.sdo_write(node(ID), od::DIGITAL_OUTPUTS, 1, SdoValue::U8(3))
        .unwrap();
    assert_eq!(m.bus.io_outputs(node(ID)), Some(0));

    // Reset node clears it (the fault fires once).
    m.send_str("000#8107");
    operational(&mut m);
    assert_eq!(m.read_u32(node(ID), 0x1001, 0), 0);
    assert_eq!(cycle(&mut m, Some(0x0C)), [0x0C]);
}

#[test]
fn drives_and_modules_share_a_bus() {
    let mut m = Master::new(vec![
        SimNodeConfig::new(node(1)),
        SimNodeConfig::io(node(ID)),
    ]);
    m.power_on();
    m.sdo_write(node(1), od::MODES_OF_OPERATION, 0, SdoValue::I8(8))
        .unwrap();
    m.map_csp(node(1));
    m.map_pdos(node(ID), &RPDO1_IO_MAPPING, &TPDO1_IO_MAPPING);
    m.send_str("000#0100");
    assert_eq!(m.enable(1), [0x0221, 0x0233, 0x1237]);
    m.send(rpdo1_io(node(ID), 0x11));
    m.send(pdo::rpdo1_csp(node(1), 0x0F, 40));
    let got = text(&m.sync());
    assert_eq!(got, ["181#371200000000", "187#11"]);
    assert_eq!(
        m.bus.node_state(node(1)).unwrap().1,
        State::OperationEnabled
    );
    assert_eq!(m.bus.node_state(node(ID)), None);
    assert_eq!(m.bus.io_outputs(node(1)), None);
    assert_eq!(m.bus.nmt_state(node(ID)), Some(NmtState::Operational));
    let last: Vec<_> = m.bus.records().iter().rev().take(2).copied().collect();
    assert_eq!((last[1].node, last[1].target_counts), (1, 40));
    assert_eq!((last[0].node, last[0].target_counts), (ID, 0x11));
}

#[test]
fn any_frame_to_a_module_is_handled_without_panicking() {
    let mut m = module(Faults::default());
    operational(&mut m);
    for id in 1..=0x7FF_u16 {
        for len in [0, 1, 2, 8] {
            for fill in [0x00, 0xFF, 0x5A] {
                let frame = CanFrame::new(id, &[fill; 8][..len]).unwrap();
                m.send(frame);
            }
        }
        if id % 64 == 0 {
            m.sync();
        }
    }
    m.send_str("000#8107");
    operational(&mut m);
    assert_eq!(m.bus.nmt_state(node(ID)), Some(NmtState::Operational));
}
