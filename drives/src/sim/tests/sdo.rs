//! The SDO server: the object dictionary's defaults and one test per abort rule, mostly as
//! candump vectors (request on 0x605, answer on 0x585).

use super::*;

/// Node 5, booted, in pre-operational.
fn preop() -> Master {
    let mut m = Master::with_nodes(&[5]);
    m.power_on();
    m
}

/// `(request, expected answer)` pairs, one SDO each.
fn exchange(m: &mut Master, cases: &[(&str, &str)]) {
    for (request, answer) in cases {
        assert_eq!(m.send_str(request), [*answer], "request {request}");
    }
}

fn abort(m: &mut Master, index: u16, sub: u8, value: SdoValue) -> AbortCode {
    m.sdo_write(node(5), index, sub, value)
        .expect_err("the write must be refused")
}

/// Disables RPDO1 (bit 31 of the COB-ID) and sets its mapping count to 0.
fn rpdo_disabled(m: &mut Master) {
    let n = node(5);
    m.sdo_write(n, 0x1400, 1, SdoValue::U32(0x8000_0205))
        .unwrap();
    m.sdo_write(n, 0x1600, 0, SdoValue::U8(0)).unwrap();
}

#[test]
fn reads_the_object_dictionary_defaults() {
    let mut m = Master::new(vec![SimNodeConfig {
        initial_position: -1234,
        ..SimNodeConfig::new(node(5))
    }]);
    m.power_on();
    let n = node(5);
    let cases: [(u16, u8, u8, u32); 37] = [
        (0x1000, 0, 4, 0x0002_0192),
        (0x1001, 0, 1, 0),
        (0x1017, 0, 2, 0),
        (0x1400, 0, 1, 2),
        (0x1400, 1, 4, 0x205),
        (0x1400, 2, 1, 0xFF),
        (0x1600, 0, 1, 1),
        (0x1600, 1, 4, 0x6040_0010),
        (0x1600, 2, 4, 0),
        (0x1600, 3, 4, 0),
        (0x1600, 4, 4, 0),
        (0x1600, 5, 4, 0),
        (0x1600, 6, 4, 0),
        (0x1600, 7, 4, 0),
        (0x1600, 8, 4, 0),
        (0x1800, 0, 1, 2),
        (0x1800, 1, 4, 0x185),
        (0x1800, 2, 1, 0xFF),
        (0x1A00, 0, 1, 1),
        (0x1A00, 1, 4, 0x6041_0010),
        (0x1A00, 2, 4, 0),
        (0x1A00, 3, 4, 0),
        (0x1A00, 4, 4, 0),
        (0x1A00, 5, 4, 0),
        (0x1A00, 6, 4, 0),
        (0x1A00, 7, 4, 0),
        (0x1A00, 8, 4, 0),
        (0x6040, 0, 2, 0),
        (0x6041, 0, 2, 0x0240),
        (0x6060, 0, 1, 0),
        (0x6061, 0, 1, 0),
        (0x6064, 0, 4, -1234i32 as u32),
        (0x6065, 0, 4, 0),
        (0x607A, 0, 4, -1234i32 as u32),
        (0x60C2, 0, 1, 2),
        (0x60C2, 1, 1, 1),
        (0x60C2, 2, 1, 0xFD),
    ];
    for (index, sub, len, value) in cases {
        let data = m.sdo_read(n, index, sub).unwrap();
        assert_eq!(data.as_bytes().len(), usize::from(len), "{index:04X}:{sub}");
        assert_eq!(m.read_u32(n, index, sub), value, "{index:04X}:{sub}");
    }
}

#[test]
fn writes_are_acknowledged_and_read_back() {
    let mut m = preop();
    exchange(
        &mut m,
        &[
            ("605#2B17100064000000", "585#6017100000000000"),
            ("605#4017100000000000", "585#4B17100064000000"),
            ("605#2365600010270000", "585#6065600000000000"),
            ("605#237A6000FFFFFFFF", "585#607A600000000000"),
            ("605#407A6000FFFFFFFF", "585#437A6000FFFFFFFF"),
            // Size not indicated (0x22): four bytes.
            ("605#2265600020000000", "585#6065600000000000"),
            ("605#4065600000000000", "585#4365600020000000"),
        ],
    );
}

#[test]
fn unknown_index_aborts_with_0602_0000() {
    let mut m = preop();
    exchange(
        &mut m,
        &[
            ("605#4000200000000000", "585#8000200000000206"),
            ("605#2F00200001000000", "585#8000200000000206"),
            ("605#4002180000000000", "585#8002180000000206"),
        ],
    );
}

#[test]
fn unknown_sub_index_aborts_with_0609_0011() {
    let mut m = preop();
    exchange(
        &mut m,
        &[
            ("605#4000140300000000", "585#8000140311000906"),
            ("605#4040600100000000", "585#8040600111000906"),
            ("605#40C2600300000000", "585#80C2600311000906"),
            ("605#4F00160900000000", "585#8000160911000906"),
        ],
    );
}

#[test]
fn writing_a_read_only_object_aborts_with_0601_0002() {
    let mut m = preop();
    exchange(
        &mut m,
        &[
            ("605#2B41600037020000", "585#8041600002000106"),
            ("605#2300100000000000", "585#8000100002000106"),
            ("605#2364600000000000", "585#8064600002000106"),
            ("605#2F61600008000000", "585#8061600002000106"),
            ("605#2F00140003000000", "585#8000140002000106"),
            ("605#2F01100000000000", "585#8001100002000106"),
        ],
    );
}

#[test]
fn a_wrong_data_length_aborts_with_0607_0010() {
    let mut m = preop();
    exchange(
        &mut m,
        &[
            // Controlword (U16) written with 4 and 1 bytes, mode (I8) with 2.
            ("605#234060000F000000", "585#8040600010000706"),
            ("605#2F4060000F000000", "585#8040600010000706"),
            ("605#2B60600008000000", "585#8060600010000706"),
            ("605#2B7A600000000000", "585#807A600010000706"),
        ],
    );
}

#[test]
fn a_mode_the_drive_does_not_have_aborts_with_0609_0030() {
    let mut m = preop();
    // It has CSP (8), profile velocity (3) and homing (6).
    for mode in [0, 1, 2, 4, 5, 7, 9, -1, i8::MIN] {
        let code = abort(&mut m, od::MODES_OF_OPERATION, 0, SdoValue::I8(mode));
        assert_eq!(code, AbortCode::ValueRangeExceeded, "mode {mode}");
    }
    assert_eq!(
        m.read_u32(node(5), 0x6061, 0),
        0,
        "the display did not follow"
    );
    exchange(&mut m, &[("605#2F60600008000000", "585#6060600000000000")]);
}

#[test]
fn mapping_an_object_not_mappable_aborts_with_0604_0041() {
    let mut m = preop();
    rpdo_disabled(&mut m);
    // Statusword or position actual into the RPDO, a wrong bit length, an unknown object.
    for entry in [
        0x6041_0010,
        0x6064_0020,
        0x6040_0020,
        0x607A_0010,
        0x2000_0008,
        0,
    ] {
        let code = abort(&mut m, 0x1600, 1, SdoValue::U32(entry));
        assert_eq!(code, AbortCode::CannotMapToPdo, "RPDO entry {entry:08X}");
    }
    m.sdo_write(node(5), 0x1800, 1, SdoValue::U32(0x8000_0185))
        .unwrap();
    m.sdo_write(node(5), 0x1A00, 0, SdoValue::U8(0)).unwrap();
    for entry in [0x6040_0010, 0x607A_0020, 0x6041_0020, 0x6060_0008] {
        let code = abort(&mut m, 0x1A00, 1, SdoValue::U32(entry));
        assert_eq!(code, AbortCode::CannotMapToPdo, "TPDO entry {entry:08X}");
    }
    // A count that would enable an empty entry is refused the same way.
    let code = abort(&mut m, 0x1A00, 0, SdoValue::U8(2));
    assert_eq!(code, AbortCode::CannotMapToPdo);
    assert_eq!(m.read_u32(node(5), 0x1A00, 0), 0);
}

/// Chosen: 0x06010000 (unsupported access), as CANopen stacks commonly answer; the same
/// code for an entry written while the count is not 0 (CiA-301's procedure sets it to 0
/// first).
#[test]
fn changing_a_valid_pdos_mapping_aborts_with_0601_0000() {
    let mut m = preop();
    exchange(
        &mut m,
        &[
            ("605#2F00160000000000", "585#8000160000000106"),
            ("605#2300160110004060", "585#8000160100000106"),
            ("605#2F001A0000000000", "585#80001A0000000106"),
            ("605#23001A0220006460", "585#80001A0200000106"),
        ],
    );
    // Disabled but the count not yet 0: entries are refused, the count is accepted.
    m.sdo_write(node(5), 0x1400, 1, SdoValue::U32(0x8000_0205))
        .unwrap();
    let code = abort(&mut m, 0x1600, 2, SdoValue::U32(0x607A_0020));
    assert_eq!(code, AbortCode::UnsupportedAccess);
    m.sdo_write(node(5), 0x1600, 0, SdoValue::U8(0)).unwrap();
    m.sdo_write(node(5), 0x1600, 2, SdoValue::U32(0x607A_0020))
        .unwrap();
}

#[test]
fn a_mapping_count_out_of_range_aborts() {
    let mut m = preop();
    rpdo_disabled(&mut m);
    let code = abort(&mut m, 0x1600, 0, SdoValue::U8(9));
    assert_eq!(code, AbortCode::ValueRangeExceeded);
    for sub in 1..=3 {
        m.sdo_write(node(5), 0x1600, sub, SdoValue::U32(0x607A_0020))
            .unwrap();
    }
    // Three 32-bit targets: 96 bits do not fit into 8 bytes.
    let code = abort(&mut m, 0x1600, 0, SdoValue::U8(3));
    assert_eq!(code, AbortCode::PdoLengthExceeded);
    m.sdo_write(node(5), 0x1600, 0, SdoValue::U8(2)).unwrap();
}

#[test]
fn an_invalid_cob_id_or_transmission_type_aborts_with_0609_0030() {
    let mut m = preop();
    let n = node(5);
    let range = AbortCode::ValueRangeExceeded;
    // Changing the identifier of a valid PDO.
    assert_eq!(abort(&mut m, 0x1400, 1, SdoValue::U32(0x305)), range);
    m.sdo_write(n, 0x1400, 1, SdoValue::U32(0x8000_0205))
        .unwrap();
    // Restricted identifiers (NMT, SYNC, SDO, heartbeat), 29-bit ones, above 11 bits.
    for cob_id in [0x000, 0x080, 0x605, 0x585, 0x705, 0x2000_0205, 0x800] {
        assert_eq!(abort(&mut m, 0x1400, 1, SdoValue::U32(cob_id)), range);
    }
    m.sdo_write(n, 0x1400, 1, SdoValue::U32(0x305)).unwrap();
    assert_eq!(m.read_u32(n, 0x1400, 1), 0x305);
    for tt in [241, 0xFC, 0xFD] {
        assert_eq!(abort(&mut m, 0x1800, 2, SdoValue::U8(tt)), range);
    }
    for tt in [0, 1, 240, 0xFE, 0xFF] {
        m.sdo_write(n, 0x1800, 2, SdoValue::U8(tt)).unwrap();
    }
}

#[test]
fn unsupported_command_specifiers_abort_with_0504_0001() {
    let mut m = preop();
    exchange(
        &mut m,
        &[
            // Segmented download initiate, upload segment, block download, ccs 7.
            ("605#2140600002000000", "585#8040600001000405"),
            ("605#6000000000000000", "585#8000000001000405"),
            ("605#C040600000000000", "585#8040600001000405"),
            ("605#E040600000000000", "585#8040600001000405"),
        ],
    );
    // A client abort and frames that are not 8 bytes get no answer.
    for request in ["605#8040600000000405", "605#4041600000", "605#"] {
        assert!(m.send_str(request).is_empty(), "{request}");
    }
}

#[test]
fn only_pre_operational_and_operational_nodes_answer() {
    let mut m = Master::with_nodes(&[5]);
    let read = "605#4041600000000000";
    assert!(m.send_str(read).is_empty(), "initialising");
    m.power_on();
    assert_eq!(m.send_str(read).len(), 1);
    m.send_str("000#0205");
    assert!(m.send_str(read).is_empty(), "stopped");
    m.send_str("000#0105");
    assert_eq!(m.send_str(read), ["585#4B41600040020000"]);
    // Another node's request is not answered.
    assert!(m.send_str("606#4041600000000000").is_empty());
}
