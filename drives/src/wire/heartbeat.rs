//! Heartbeat and boot-up (CiA-301 7.2.8.3.2): COB-ID 0x700 + node, one byte, the producer's
//! NMT state. Boot-up is the same frame with state 0x00, sent once after a reset.
//!
//! Node guarding, which reuses this COB-ID with a toggle bit in bit 7, is not used by this
//! project: a state byte with bit 7 set (other than 0x7F) is an unknown state here.

use super::{check_len, cob, node_of, DecodeError, NodeId};
use crate::frame::CanFrame;

/// NMT state as reported in a heartbeat.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum NmtState {
    BootUp = 0x00,
    Stopped = 0x04,
    Operational = 0x05,
    PreOperational = 0x7F,
}

impl NmtState {
    pub const fn from_u8(state: u8) -> Option<Self> {
        match state {
            0x00 => Some(Self::BootUp),
            0x04 => Some(Self::Stopped),
            0x05 => Some(Self::Operational),
            0x7F => Some(Self::PreOperational),
            _ => None,
        }
    }
}

/// The heartbeat (or, with [`NmtState::BootUp`], boot-up) frame of `node`.
pub fn encode(node: NodeId, state: NmtState) -> CanFrame {
    CanFrame::from_array(node.cob_id(cob::HEARTBEAT), [state as u8])
}

/// Decodes a heartbeat into the producing node and its state.
pub fn decode(frame: &CanFrame) -> Result<(NodeId, NmtState), DecodeError> {
    let node = node_of(frame, cob::HEARTBEAT, "a heartbeat")?;
    check_len(frame, 1, 1)?;
    let [state, ..] = frame.raw_data();
    let state = NmtState::from_u8(state).ok_or(DecodeError::NmtState { state })?;
    Ok((node, state))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{frame, node};

    #[test]
    fn encodes_the_candump_vectors() {
        let cases = [
            (1, NmtState::BootUp, "701#00"),
            (1, NmtState::Stopped, "701#04"),
            (1, NmtState::Operational, "701#05"),
            (127, NmtState::PreOperational, "77F#7F"),
        ];
        for (n, state, s) in cases {
            assert_eq!(encode(node(n), state).to_string(), s);
            assert_eq!(decode(&frame(s)), Ok((node(n), state)), "{s}");
        }
    }

    #[test]
    fn rejects_malformed_frames() {
        let cob = |id| DecodeError::CobId {
            id,
            service: "a heartbeat",
        };
        let len = |id, len| DecodeError::Length {
            id,
            len,
            min: 1,
            max: 1,
        };
        let cases = [
            ("700#05", cob(0x700)),
            ("680#05", cob(0x680)),
            ("780#05", cob(0x780)),
            ("185#05", cob(0x185)),
            ("705#", len(0x705, 0)),
            ("705#0500", len(0x705, 2)),
            ("705#01", DecodeError::NmtState { state: 0x01 }),
            ("705#85", DecodeError::NmtState { state: 0x85 }),
            ("705#FF", DecodeError::NmtState { state: 0xFF }),
        ];
        for (s, e) in cases {
            assert_eq!(decode(&frame(s)), Err(e), "{s}");
        }
    }
}
