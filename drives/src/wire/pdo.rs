//! Process data objects (CiA-301 7.2.2) and the cyclic-synchronous-position layout this
//! project maps.
//!
//! RPDOn (received by the drive) has COB-ID 0x200/0x300/0x400/0x500 + node, TPDOn (transmitted
//! by the drive) 0x180/0x280/0x380/0x480 + node. Only PDO 1 is used, mapped in
//! pre-operational (docs/canopen.md) to six bytes, little-endian, transmission type 1:
//!
//! ```text
//! RPDO1  205#0F00A0860100   controlword 0x6040 (u16) | target position 0x607A (i32)
//! TPDO1  185#37120000FFFF   statusword  0x6041 (u16) | position actual 0x6064 (i32)
//! ```
//!
//! A spindle drive in profile velocity mode (0x6060 = 3) uses the same layout with target
//! velocity 0x60FF and velocity actual 0x606C in place of the positions ([`rpdo1_csp`] and
//! [`decode_tpdo1_csp`] serve both). A CiA-401 I/O module maps one byte each way:
//!
//! ```text
//! RPDO1  207#03             digital outputs 1..8 0x6200:01 (u8)
//! TPDO1  187#03             digital inputs  1..8 0x6000:01 (u8)
//! ```
//!
//! The decoders require exactly six bytes: any other length means the drive's mapping is not
//! the one configured, which must not be read as positions.

use super::{check_len, cob, node_of, DecodeError, NodeId};
use crate::frame::CanFrame;

/// Which direction of PDO, seen from the drive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PdoKind {
    /// Received by the drive (master to drive).
    Rpdo,
    /// Transmitted by the drive (drive to master).
    Tpdo,
}

/// COB-ID of PDO `n` (1..=4) of `kind` for `node` in the predefined connection set;
/// `None` if `n` is outside 1..=4.
pub fn pdo_cob_id(kind: PdoKind, n: u8, node: NodeId) -> Option<u16> {
    let bases = match kind {
        PdoKind::Rpdo => cob::RPDO,
        PdoKind::Tpdo => cob::TPDO,
    };
    let base = bases.get(usize::from(n).checked_sub(1)?)?;
    Some(node.cob_id(*base))
}

/// A PDO mapping entry (objects 0x1600.., 0x1A00..): `index << 16 | sub << 8 | bits`.
pub const fn mapping_entry(index: u16, sub: u8, bits: u8) -> u32 {
    (index as u32) << 16 | (sub as u32) << 8 | bits as u32
}

/// RPDO1 mapping for CSP: controlword 0x6040 (16 bits), target position 0x607A (32 bits).
pub const RPDO1_CSP_MAPPING: [u32; 2] = [0x6040_0010, 0x607A_0020];
/// TPDO1 mapping for CSP: statusword 0x6041 (16 bits), position actual 0x6064 (32 bits).
pub const TPDO1_CSP_MAPPING: [u32; 2] = [0x6041_0010, 0x6064_0020];
/// RPDO1 mapping for a spindle in profile velocity mode: controlword, target velocity 0x60FF.
pub const RPDO1_PV_MAPPING: [u32; 2] = [0x6040_0010, 0x60FF_0020];
/// TPDO1 mapping for a spindle in profile velocity mode: statusword, velocity actual 0x606C.
pub const TPDO1_PV_MAPPING: [u32; 2] = [0x6041_0010, 0x606C_0020];
/// RPDO1 mapping of a CiA-401 I/O module: digital outputs 1..8 (0x6200:01, 8 bits).
pub const RPDO1_IO_MAPPING: [u32; 1] = [0x6200_0108];
/// TPDO1 mapping of a CiA-401 I/O module: digital inputs 1..8 (0x6000:01, 8 bits).
pub const TPDO1_IO_MAPPING: [u32; 1] = [0x6000_0108];
/// Data bytes of both CSP PDOs.
pub const CSP_PDO_LEN: u8 = 6;

/// What the master sends each cycle: RPDO1 contents.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CspCommand {
    pub controlword: u16,
    /// Target position 0x607A, increments.
    pub target: i32,
}

/// What the drive answers each cycle: TPDO1 contents.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CspFeedback {
    pub statusword: u16,
    /// Position actual value 0x6064, increments.
    pub actual: i32,
}

fn word_and_position(id: u16, word: u16, position: i32) -> CanFrame {
    let [w0, w1] = word.to_le_bytes();
    let [p0, p1, p2, p3] = position.to_le_bytes();
    CanFrame::from_array(id, [w0, w1, p0, p1, p2, p3])
}

fn decode_word_and_position(
    frame: &CanFrame,
    base: u16,
    service: &'static str,
) -> Result<(NodeId, u16, i32), DecodeError> {
    let node = node_of(frame, base, service)?;
    check_len(frame, CSP_PDO_LEN, CSP_PDO_LEN)?;
    let [w0, w1, p0, p1, p2, p3, ..] = frame.raw_data();
    Ok((
        node,
        u16::from_le_bytes([w0, w1]),
        i32::from_le_bytes([p0, p1, p2, p3]),
    ))
}

/// Master side: the RPDO1 carrying `controlword` and `target` to `node`.
pub fn rpdo1_csp(node: NodeId, controlword: u16, target: i32) -> CanFrame {
    word_and_position(node.cob_id(cob::RPDO[0]), controlword, target)
}

/// Master side: a drive's TPDO1.
pub fn decode_tpdo1_csp(frame: &CanFrame) -> Result<(NodeId, CspFeedback), DecodeError> {
    let (node, statusword, actual) = decode_word_and_position(frame, cob::TPDO[0], "a TPDO1")?;
    Ok((node, CspFeedback { statusword, actual }))
}

/// Drive side: the TPDO1 carrying `statusword` and `actual` from `node`.
pub fn tpdo1_csp(node: NodeId, statusword: u16, actual: i32) -> CanFrame {
    word_and_position(node.cob_id(cob::TPDO[0]), statusword, actual)
}

/// Drive side: an RPDO1 from the master.
pub fn decode_rpdo1_csp(frame: &CanFrame) -> Result<(NodeId, CspCommand), DecodeError> {
    let (node, controlword, target) = decode_word_and_position(frame, cob::RPDO[0], "an RPDO1")?;
    Ok((
        node,
        CspCommand {
            controlword,
            target,
        },
    ))
}

/// Master side: the RPDO1 carrying an I/O module's digital outputs 1..8 (bit 0 = output 1).
pub fn rpdo1_io(node: NodeId, outputs: u8) -> CanFrame {
    CanFrame::from_array(node.cob_id(cob::RPDO[0]), [outputs])
}

/// Master side: an I/O module's TPDO1, its digital inputs 1..8. Exactly one byte.
pub fn decode_tpdo1_io(frame: &CanFrame) -> Result<(NodeId, u8), DecodeError> {
    let node = node_of(frame, cob::TPDO[0], "a TPDO1")?;
    check_len(frame, 1, 1)?;
    Ok((node, frame.raw_data()[0]))
}

/// Drive side: the TPDO1 of an I/O module carrying its inputs.
pub fn tpdo1_io(node: NodeId, inputs: u8) -> CanFrame {
    CanFrame::from_array(node.cob_id(cob::TPDO[0]), [inputs])
}

/// Drive side: an I/O module's RPDO1 from the master, its outputs. Exactly one byte.
pub fn decode_rpdo1_io(frame: &CanFrame) -> Result<(NodeId, u8), DecodeError> {
    let node = node_of(frame, cob::RPDO[0], "an RPDO1")?;
    check_len(frame, 1, 1)?;
    Ok((node, frame.raw_data()[0]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{frame, node};

    #[test]
    fn cob_ids() {
        let n = node(5);
        let rpdo: [Option<u16>; 4] =
            core::array::from_fn(|i| pdo_cob_id(PdoKind::Rpdo, i as u8 + 1, n));
        let tpdo: [Option<u16>; 4] =
            core::array::from_fn(|i| pdo_cob_id(PdoKind::Tpdo, i as u8 + 1, n));
        assert_eq!(rpdo, [Some(0x205), Some(0x305), Some(0x405), Some(0x505)]);
        assert_eq!(tpdo, [Some(0x185), Some(0x285), Some(0x385), Some(0x485)]);
        assert_eq!(pdo_cob_id(PdoKind::Rpdo, 0, n), None);
        assert_eq!(pdo_cob_id(PdoKind::Tpdo, 5, n), None);
        assert_eq!(pdo_cob_id(PdoKind::Tpdo, 1, node(127)), Some(0x1FF));
    }

    #[test]
    fn mapping_entries_match_the_docs() {
        assert_eq!(
            RPDO1_CSP_MAPPING,
            [mapping_entry(0x6040, 0, 16), mapping_entry(0x607A, 0, 32)]
        );
        assert_eq!(
            TPDO1_CSP_MAPPING,
            [mapping_entry(0x6041, 0, 16), mapping_entry(0x6064, 0, 32)]
        );
    }

    #[test]
    fn rpdo1_vectors() {
        let cases = [
            (5, 0x000F, 100_000, "205#0F00A0860100"),
            (1, 0x0006, 0, "201#060000000000"),
            (127, 0x0080, -1, "27F#8000FFFFFFFF"),
            (2, 0x000F, i32::MIN, "202#0F0000000080"),
        ];
        for (n, controlword, target, s) in cases {
            assert_eq!(rpdo1_csp(node(n), controlword, target).to_string(), s);
            let cmd = CspCommand {
                controlword,
                target,
            };
            assert_eq!(decode_rpdo1_csp(&frame(s)), Ok((node(n), cmd)), "{s}");
        }
    }

    #[test]
    fn tpdo1_vectors() {
        let cases = [
            (5, 0x1237, -65536, "185#37120000FFFF"),
            (1, 0x0250, 0, "181#500200000000"),
            (3, 0x0218, 12345, "183#180239300000"),
        ];
        for (n, statusword, actual, s) in cases {
            assert_eq!(tpdo1_csp(node(n), statusword, actual).to_string(), s);
            let fb = CspFeedback { statusword, actual };
            assert_eq!(decode_tpdo1_csp(&frame(s)), Ok((node(n), fb)), "{s}");
        }
    }

    #[test]
    fn io_vectors_and_lengths() {
        assert_eq!(rpdo1_io(node(7), 0x03).to_string(), "207#03");
        assert_eq!(tpdo1_io(node(7), 0x81).to_string(), "187#81");
        assert_eq!(decode_rpdo1_io(&frame("207#02")), Ok((node(7), 0x02)));
        assert_eq!(decode_tpdo1_io(&frame("187#81")), Ok((node(7), 0x81)));
        let len = |id, len| DecodeError::Length {
            id,
            len,
            min: 1,
            max: 1,
        };
        assert_eq!(decode_tpdo1_io(&frame("187#0100")), Err(len(0x187, 2)));
        assert_eq!(decode_rpdo1_io(&frame("207#")), Err(len(0x207, 0)));
        assert_eq!(
            [RPDO1_PV_MAPPING, TPDO1_PV_MAPPING],
            [
                [mapping_entry(0x6040, 0, 16), mapping_entry(0x60FF, 0, 32)],
                [mapping_entry(0x6041, 0, 16), mapping_entry(0x606C, 0, 32)]
            ]
        );
        assert_eq!(RPDO1_IO_MAPPING, [mapping_entry(0x6200, 1, 8)]);
        assert_eq!(TPDO1_IO_MAPPING, [mapping_entry(0x6000, 1, 8)]);
    }

    #[test]
    fn rejects_malformed_frames() {
        let tpdo = |id| DecodeError::CobId {
            id,
            service: "a TPDO1",
        };
        let rpdo = |id| DecodeError::CobId {
            id,
            service: "an RPDO1",
        };
        let len = |id, len| DecodeError::Length {
            id,
            len,
            min: 6,
            max: 6,
        };
        let cases = [
            ("180#371200000000", tpdo(0x180)),
            ("285#371200000000", tpdo(0x285)),
            ("205#371200000000", tpdo(0x205)),
            ("185#3712", len(0x185, 2)),
            ("185#3712000000000000", len(0x185, 8)),
        ];
        for (s, e) in cases {
            assert_eq!(decode_tpdo1_csp(&frame(s)), Err(e), "{s}");
        }
        let cases = [
            ("200#0F0000000000", rpdo(0x200)),
            ("185#0F0000000000", rpdo(0x185)),
            ("280#0F0000000000", rpdo(0x280)),
            ("205#", len(0x205, 0)),
            ("205#0F000000000000", len(0x205, 7)),
        ];
        for (s, e) in cases {
            assert_eq!(decode_rpdo1_csp(&frame(s)), Err(e), "{s}");
        }
    }
}
