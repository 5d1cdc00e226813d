//! NMT node control (CiA-301 7.2.8.3.1): COB-ID 0x000, two bytes `[command, node]`, node 0
//! addressing all nodes. Sent only by the NMT master; a drive never answers it directly (its
//! next heartbeat shows the new state).

use super::{check_len, cob, DecodeError, NodeId};
use crate::frame::CanFrame;

/// NMT command specifier.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum NmtCommand {
    Start = 0x01,
    Stop = 0x02,
    PreOperational = 0x80,
    ResetNode = 0x81,
    ResetCommunication = 0x82,
}

impl NmtCommand {
    pub const fn from_u8(cs: u8) -> Option<Self> {
        match cs {
            0x01 => Some(Self::Start),
            0x02 => Some(Self::Stop),
            0x80 => Some(Self::PreOperational),
            0x81 => Some(Self::ResetNode),
            0x82 => Some(Self::ResetCommunication),
            _ => None,
        }
    }
}

/// Whom an NMT command addresses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// Node id 0: every node on the bus.
    All,
    Node(NodeId),
}

impl Target {
    /// 0 is [`Target::All`], 1..=127 a node; `None` above 127.
    pub const fn from_u8(node: u8) -> Option<Self> {
        if node == 0 {
            return Some(Self::All);
        }
        match NodeId::new(node) {
            Some(n) => Some(Self::Node(n)),
            None => None,
        }
    }

    pub const fn as_u8(self) -> u8 {
        match self {
            Self::All => 0,
            Self::Node(n) => n.get(),
        }
    }
}

/// The NMT frame sending `cmd` to `target`.
pub fn encode(cmd: NmtCommand, target: Target) -> CanFrame {
    CanFrame::from_array(cob::NMT, [cmd as u8, target.as_u8()])
}

/// Decodes an NMT frame.
pub fn decode(frame: &CanFrame) -> Result<(NmtCommand, Target), DecodeError> {
    if frame.id() != cob::NMT {
        return Err(DecodeError::CobId {
            id: frame.id(),
            service: "NMT",
        });
    }
    check_len(frame, 2, 2)?;
    let [cs, node, ..] = frame.raw_data();
    let cmd = NmtCommand::from_u8(cs).ok_or(DecodeError::NmtCommand { cs })?;
    let target = Target::from_u8(node).ok_or(DecodeError::NodeId { node })?;
    Ok((cmd, target))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{frame, node};

    #[test]
    fn encodes_the_candump_vectors() {
        let n5 = Target::Node(node(5));
        let cases = [
            (NmtCommand::Start, n5, "000#0105"),
            (NmtCommand::Stop, n5, "000#0205"),
            (NmtCommand::PreOperational, Target::All, "000#8000"),
            (NmtCommand::ResetNode, Target::Node(node(127)), "000#817F"),
            (NmtCommand::ResetCommunication, n5, "000#8205"),
            (NmtCommand::Start, Target::All, "000#0100"),
        ];
        for (cmd, target, s) in cases {
            assert_eq!(encode(cmd, target).to_string(), s);
            assert_eq!(decode(&frame(s)), Ok((cmd, target)), "{s}");
        }
    }

    #[test]
    fn targets() {
        assert_eq!(Target::from_u8(0), Some(Target::All));
        assert_eq!(Target::from_u8(3), Some(Target::Node(node(3))));
        assert_eq!(Target::from_u8(128), None);
    }

    #[test]
    fn rejects_malformed_frames() {
        let cases = [
            (
                "001#0105",
                DecodeError::CobId {
                    id: 0x001,
                    service: "NMT",
                },
            ),
            (
                "000#01",
                DecodeError::Length {
                    id: 0,
                    len: 1,
                    min: 2,
                    max: 2,
                },
            ),
            (
                "000#010500",
                DecodeError::Length {
                    id: 0,
                    len: 3,
                    min: 2,
                    max: 2,
                },
            ),
            ("000#0305", DecodeError::NmtCommand { cs: 0x03 }),
            ("000#0005", DecodeError::NmtCommand { cs: 0x00 }),
            ("000#0180", DecodeError::NodeId { node: 0x80 }),
        ];
        for (s, e) in cases {
            assert_eq!(decode(&frame(s)), Err(e), "{s}");
        }
    }
}
