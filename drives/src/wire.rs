//! CANopen (CiA-301) wire codecs: pure functions between [`CanFrame`]s and typed values.
//!
//! One module per service, each in the same shape: encoders take validated values and are
//! infallible; decoders check the COB-ID, the data length and every field, and return a
//! [`DecodeError`] for anything else. Nothing here allocates, blocks, reads a clock or panics,
//! whatever the frame contains: decoders read fixed positions of [`CanFrame::raw_data`] only
//! after checking the length.
//!
//! COB-IDs are those of the CiA-301 predefined connection set (docs/canopen.md): the top
//! four bits of the 11-bit identifier are the function code, the low seven bits the node id.
//!
//! | service            | COB-ID          | module        |
//! |--------------------|-----------------|---------------|
//! | NMT                | 0x000           | [`nmt`]       |
//! | SYNC               | 0x080           | [`sync`]      |
//! | EMCY               | 0x080 + node    | [`emcy`]      |
//! | TPDO1..4           | 0x180/0x280/0x380/0x480 + node | [`pdo`] |
//! | RPDO1..4           | 0x200/0x300/0x400/0x500 + node | [`pdo`] |
//! | SDO response (tx)  | 0x580 + node    | [`sdo`]       |
//! | SDO request (rx)   | 0x600 + node    | [`sdo`]       |
//! | heartbeat, boot-up | 0x700 + node    | [`heartbeat`] |
//!
//! Node ids are validated once into [`NodeId`] (1..=127); NMT's broadcast address 0 is
//! [`nmt::Target::All`]. "tx"/"rx", "TPDO"/"RPDO" are seen from the drive, as in CiA-301.
#![forbid(unsafe_code)]

use core::fmt;

use crate::frame::CanFrame;

mod abort;
pub mod emcy;
pub mod heartbeat;
pub mod nmt;
pub mod pdo;
pub mod sdo;
pub mod sync;

pub use abort::AbortCode;

/// COB-ID bases of the predefined connection set.
pub mod cob {
    pub const NMT: u16 = 0x000;
    pub const SYNC: u16 = 0x080;
    pub const EMCY: u16 = 0x080;
    pub const TIME: u16 = 0x100;
    pub const TPDO: [u16; 4] = [0x180, 0x280, 0x380, 0x480];
    pub const RPDO: [u16; 4] = [0x200, 0x300, 0x400, 0x500];
    pub const SDO_TX: u16 = 0x580;
    pub const SDO_RX: u16 = 0x600;
    pub const HEARTBEAT: u16 = 0x700;
}

/// A CANopen node id, 1..=127.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub struct NodeId(u8);

impl NodeId {
    pub const MIN: u8 = 1;
    pub const MAX: u8 = 127;

    /// `None` unless `id` is in 1..=127.
    pub const fn new(id: u8) -> Option<Self> {
        if id >= Self::MIN && id <= Self::MAX {
            Some(Self(id))
        } else {
            None
        }
    }

    pub const fn get(self) -> u8 {
        self.0
    }

    /// `base + node`: this node's COB-ID for one of the [`cob`] bases (at most 0x77F).
    /// Wraps instead of panicking for a base near `u16::MAX`, which no service has.
    pub const fn cob_id(self, base: u16) -> u16 {
        base.wrapping_add(self.0 as u16)
    }

    /// The node of a COB-ID `base + node`; `None` if `cob_id` is not in that range.
    pub(crate) fn from_cob_id(cob_id: u16, base: u16) -> Option<Self> {
        let node = cob_id.checked_sub(base)?;
        Self::new(u8::try_from(node).ok()?)
    }
}

impl TryFrom<u8> for NodeId {
    type Error = DecodeError;

    fn try_from(node: u8) -> Result<Self, DecodeError> {
        Self::new(node).ok_or(DecodeError::NodeId { node })
    }
}

impl fmt::Display for NodeId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

/// Why a frame could not be decoded. Shared by all services; `Copy`, no heap, with the
/// offending value as context.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    #[error("COB-ID 0x{id:03X} is not {service}")]
    CobId { id: u16, service: &'static str },
    #[error("COB-ID 0x{id:03X}: {len} data bytes, expected {min}..={max}")]
    Length { id: u16, len: u8, min: u8, max: u8 },
    #[error("node id {node} is outside 1..=127")]
    NodeId { node: u8 },
    #[error("unknown NMT command specifier 0x{cs:02X}")]
    NmtCommand { cs: u8 },
    #[error("unknown NMT state 0x{state:02X} in a heartbeat")]
    NmtState { state: u8 },
    #[error("SYNC counter {counter} is outside 1..=240")]
    SyncCounter { counter: u8 },
    #[error("SDO command specifier 0x{cs:02X} is not valid here")]
    SdoCommand { cs: u8 },
    #[error("SDO command specifier 0x{cs:02X} is a segmented or block transfer (only expedited transfers are supported)")]
    SdoNotExpedited { cs: u8 },
}

/// Checks the data length of `frame` against `min..=max`.
pub(crate) fn check_len(frame: &CanFrame, min: u8, max: u8) -> Result<(), DecodeError> {
    let len = frame.len() as u8;
    if (min..=max).contains(&len) {
        Ok(())
    } else {
        Err(DecodeError::Length {
            id: frame.id(),
            len,
            min,
            max,
        })
    }
}

/// The node of `frame` if its COB-ID is `base + node`, else a [`DecodeError::CobId`].
pub(crate) fn node_of(
    frame: &CanFrame,
    base: u16,
    service: &'static str,
) -> Result<NodeId, DecodeError> {
    NodeId::from_cob_id(frame.id(), base).ok_or(DecodeError::CobId {
        id: frame.id(),
        service,
    })
}

/// What a received frame is, by COB-ID alone (the data is not looked at).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Received {
    Nmt,
    Sync,
    Emcy {
        node: NodeId,
    },
    /// Process data sent by a drive; `n` is 1..=4.
    Tpdo {
        n: u8,
        node: NodeId,
    },
    /// Process data received by a drive; `n` is 1..=4.
    Rpdo {
        n: u8,
        node: NodeId,
    },
    /// Server to client: an SDO response from `node`.
    SdoResponse {
        node: NodeId,
    },
    /// Client to server: an SDO request to `node`.
    SdoRequest {
        node: NodeId,
    },
    Heartbeat {
        node: NodeId,
    },
    /// TIME (0x100), LSS (0x7E4/0x7E5), node 0 where a node is required, or an identifier
    /// outside the predefined connection set.
    Unknown,
}

/// Sorts a frame by COB-ID range into the services of the predefined connection set.
pub fn classify(frame: &CanFrame) -> Received {
    let id = frame.id();
    let function = id >> 7;
    let Some(node) = NodeId::new((id & 0x7F) as u8) else {
        return match id {
            cob::NMT => Received::Nmt,
            cob::SYNC => Received::Sync,
            _ => Received::Unknown,
        };
    };
    match function {
        0x1 => Received::Emcy { node },
        0x3 | 0x5 | 0x7 | 0x9 => Received::Tpdo {
            n: ((function - 1) / 2) as u8,
            node,
        },
        0x4 | 0x6 | 0x8 | 0xA => Received::Rpdo {
            n: ((function - 2) / 2) as u8,
            node,
        },
        0xB => Received::SdoResponse { node },
        0xC => Received::SdoRequest { node },
        0xE => Received::Heartbeat { node },
        _ => Received::Unknown,
    }
}

#[cfg(test)]
pub(crate) fn frame(s: &str) -> CanFrame {
    s.parse().unwrap()
}

#[cfg(test)]
pub(crate) fn node(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_ids_are_1_to_127() {
        assert_eq!(NodeId::new(0), None);
        assert_eq!(NodeId::new(128), None);
        assert_eq!(NodeId::new(255), None);
        assert_eq!(NodeId::new(127).map(NodeId::get), Some(127));
        assert_eq!(NodeId::try_from(0), Err(DecodeError::NodeId { node: 0 }));
        assert_eq!(node(5).cob_id(cob::SDO_RX), 0x605);
        assert_eq!(NodeId::from_cob_id(0x580, cob::SDO_TX), None);
        assert_eq!(NodeId::from_cob_id(0x57F, cob::SDO_TX), None);
        assert_eq!(NodeId::from_cob_id(0x600, cob::SDO_TX), None);
    }

    #[test]
    fn classifies_the_predefined_connection_set() {
        let cases = [
            ("000#0100", Received::Nmt),
            ("080#", Received::Sync),
            ("081#1086000000000000", Received::Emcy { node: node(1) }),
            ("0FF#0000000000000000", Received::Emcy { node: node(127) }),
            ("100#000000000000", Received::Unknown),
            (
                "185#370200000000",
                Received::Tpdo {
                    n: 1,
                    node: node(5),
                },
            ),
            (
                "285#00",
                Received::Tpdo {
                    n: 2,
                    node: node(5),
                },
            ),
            (
                "385#00",
                Received::Tpdo {
                    n: 3,
                    node: node(5),
                },
            ),
            (
                "485#00",
                Received::Tpdo {
                    n: 4,
                    node: node(5),
                },
            ),
            (
                "205#0F0000000000",
                Received::Rpdo {
                    n: 1,
                    node: node(5),
                },
            ),
            (
                "305#00",
                Received::Rpdo {
                    n: 2,
                    node: node(5),
                },
            ),
            (
                "405#00",
                Received::Rpdo {
                    n: 3,
                    node: node(5),
                },
            ),
            (
                "505#00",
                Received::Rpdo {
                    n: 4,
                    node: node(5),
                },
            ),
            (
                "585#6040600000000000",
                Received::SdoResponse { node: node(5) },
            ),
            (
                "605#4041600000000000",
                Received::SdoRequest { node: node(5) },
            ),
            ("705#00", Received::Heartbeat { node: node(5) }),
            ("77F#7F", Received::Heartbeat { node: node(127) }),
            // Node 0 where a node is required, unused function codes, LSS.
            ("001#00", Received::Unknown),
            ("07F#00", Received::Unknown),
            ("180#00", Received::Unknown),
            ("580#00", Received::Unknown),
            ("700#00", Received::Unknown),
            ("685#00", Received::Unknown),
            ("7E4#00", Received::Unknown),
            ("7E5#00", Received::Unknown),
        ];
        for (s, expected) in cases {
            assert_eq!(classify(&frame(s)), expected, "{s}");
        }
    }

    /// Every identifier, every length, a few data patterns: no decoder panics, and what
    /// decodes re-encodes to the same frame (SDO excepted: it ignores unused bits).
    #[test]
    fn decoders_never_panic_and_round_trip() {
        let mut state = 0x2545_F491_u32;
        let mut random = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state.to_le_bytes()[0]
        };
        for id in 0..=0x7FF {
            for len in 0..=8 {
                for pattern in 0..6 {
                    let data: [u8; 8] = core::array::from_fn(|i| match pattern {
                        0 => 0,
                        1 => 0xFF,
                        2 => i as u8,
                        _ => random(),
                    });
                    let f = CanFrame::new(id, &data[..len]).unwrap();
                    let _ = classify(&f);
                    if let Ok((cmd, target)) = nmt::decode(&f) {
                        assert_eq!(nmt::encode(cmd, target), f);
                    }
                    if let Ok(Some(counter)) = sync::decode(&f) {
                        assert_eq!(sync::encode_with_counter(counter), Some(f));
                    }
                    if let Ok((n, state)) = heartbeat::decode(&f) {
                        assert_eq!(heartbeat::encode(n, state), f);
                    }
                    if let Ok((n, e)) = emcy::decode(&f) {
                        assert_eq!(emcy::encode(n, &e), f);
                    }
                    if let Ok((n, c)) = pdo::decode_rpdo1_csp(&f) {
                        assert_eq!(pdo::rpdo1_csp(n, c.controlword, c.target), f);
                    }
                    if let Ok((n, fb)) = pdo::decode_tpdo1_csp(&f) {
                        assert_eq!(pdo::tpdo1_csp(n, fb.statusword, fb.actual), f);
                    }
                    let n = NodeId::new((id & 0x7F) as u8).unwrap_or(node(1));
                    if let Ok(r) = sdo::decode_response(n, &f) {
                        let again = match r {
                            sdo::SdoResponse::DownloadAck { index, sub } => {
                                sdo::download_ack(n, index, sub)
                            }
                            sdo::SdoResponse::Uploaded { index, sub, data } => {
                                sdo::upload_response(n, index, sub, data)
                            }
                            sdo::SdoResponse::Abort { index, sub, code } => {
                                sdo::abort(n, index, sub, code)
                            }
                        };
                        assert_eq!(sdo::decode_response(n, &again), Ok(r));
                    }
                    let _ = sdo::decode_request(n, &f);
                }
            }
        }
    }

    #[test]
    fn errors_display_their_context() {
        let e = DecodeError::Length {
            id: 0x185,
            len: 2,
            min: 6,
            max: 6,
        };
        assert_eq!(e.to_string(), "COB-ID 0x185: 2 data bytes, expected 6..=6");
    }
}
