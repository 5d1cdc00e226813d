//! Drive configuration, outside the real-time thread, for every node of one bus:
//!
//! 1. NMT reset communication, then wait for each node's boot-up message;
//! 2. SDO: modes of operation 0x6060 = 8 (CSP), read back from 0x6061;
//! 3. SDO: interpolation time period 0x60C2 = the machine period (value * 10^exponent s);
//! 4. PDO mapping exactly as CiA-301 prescribes (docs/canopen.md): RPDO1 = controlword
//!    0x6040 + target 0x607A, TPDO1 = statusword 0x6041 + actual 0x6064, both disabled while
//!    mapped, transmission type 1 (every SYNC), then re-enabled;
//! 5. SDO: heartbeat producer 0x1017;
//! 6. SDO: read the actual position 0x6064, so the first target equals it (no jump);
//! 7. NMT start.
//!
//! Every SDO transfer has a timeout and a bounded number of retries. Frames that arrive in
//! between (heartbeats, EMCY) are not lost: they are handed to an observer.

use crate::link::{CanLink, LinkError};
use crate::od;
use crate::wire::heartbeat::{self, NmtState};
use crate::wire::nmt::{self, NmtCommand, Target};
use crate::wire::pdo::{PdoKind, RPDO1_CSP_MAPPING, TPDO1_CSP_MAPPING};
use crate::wire::sdo::{self, SdoResponse, SdoValue};
use crate::wire::{classify, AbortCode, NodeId, Received};
use crate::CanFrame;
use std::time::{Duration, Instant};

/// Timeouts and retries of the set-up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SetupOptions {
    /// Interpolation period, s.
    pub period_s: f64,
    /// Wait for one SDO response.
    pub sdo_timeout: Duration,
    /// Further attempts after a timed-out SDO transfer.
    pub sdo_retries: u32,
    /// Wait for all boot-up messages after the NMT reset.
    pub boot_timeout: Duration,
    /// Heartbeat producer time written to 0x1017, ms.
    pub heartbeat_ms: u16,
}

impl SetupOptions {
    pub fn new(period_s: f64) -> Self {
        SetupOptions {
            period_s,
            sdo_timeout: Duration::from_millis(200),
            sdo_retries: 2,
            boot_timeout: Duration::from_secs(3),
            heartbeat_ms: 100,
        }
    }
}

/// What went wrong with which node.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum SetupErrorKind {
    #[error("no boot-up message (0x{cob:03X}) within {ms} ms of the NMT reset")]
    NoBootUp { cob: u16, ms: u128 },
    #[error("no SDO response within {ms} ms ({attempts} attempts)")]
    SdoTimeout { ms: u128, attempts: u32 },
    #[error("SDO abort {0}")]
    Abort(AbortCode),
    #[error("read back {got}, expected {expected}")]
    Mismatch { expected: i64, got: i64 },
    #[error("the SDO response does not fit the request")]
    BadResponse,
    #[error("the machine period {0} s cannot be written as value * 10^exp with value <= 255")]
    Period(f64),
    #[error("CAN link: {0}")]
    Link(LinkError),
}

/// A set-up failure naming the node and, for SDO, the object.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub struct SetupError {
    pub node: u8,
    pub object: Option<(u16, u8)>,
    pub kind: SetupErrorKind,
}

impl std::fmt::Display for SetupError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.object {
            Some((index, sub)) => write!(
                f,
                "node {}, object 0x{index:04X}:{sub:02X}: {}",
                self.node, self.kind
            ),
            None => write!(f, "node {}: {}", self.node, self.kind),
        }
    }
}

/// `period_s` as the 0x60C2 pair (value, exponent): period = value * 10^exponent.
pub fn interpolation_period(period_s: f64) -> Option<(u8, i8)> {
    (-6i8..=0).rev().find_map(|exp| {
        let v = period_s / 10f64.powi(i32::from(exp));
        let r = v.round();
        ((v - r).abs() < 1e-6 * r.max(1.0) && (1.0..=255.0).contains(&r)).then_some((r as u8, exp))
    })
}

struct Session<'a, L: CanLink> {
    link: &'a mut L,
    opts: SetupOptions,
    observe: &'a mut dyn FnMut(&CanFrame),
}

impl<L: CanLink> Session<'_, L> {
    fn send(&mut self, node: NodeId, frame: &CanFrame) -> Result<(), SetupError> {
        // Outside the RT thread a full queue is waited out briefly, not dropped.
        for _ in 0..100 {
            match self.link.send(frame) {
                Ok(crate::link::Sent::Queued) => return Ok(()),
                Ok(crate::link::Sent::Dropped) => std::thread::sleep(Duration::from_micros(200)),
                Err(e) => {
                    return Err(SetupError {
                        node: node.get(),
                        object: None,
                        kind: SetupErrorKind::Link(e),
                    })
                }
            }
        }
        Err(SetupError {
            node: node.get(),
            object: None,
            kind: SetupErrorKind::Link(LinkError::Os(nix::libc::ENOBUFS)),
        })
    }

    /// One SDO request/response with timeout and retries.
    fn sdo(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        request: CanFrame,
    ) -> Result<SdoResponse, SetupError> {
        let err = |kind| SetupError {
            node: node.get(),
            object: Some((index, sub)),
            kind,
        };
        let attempts = self.opts.sdo_retries + 1;
        for _ in 0..attempts {
            self.send(node, &request)?;
            let deadline = Instant::now() + self.opts.sdo_timeout;
            while Instant::now() < deadline {
                match self.link.recv().map_err(|e| err(SetupErrorKind::Link(e)))? {
                    Some(f) if classify(&f) == (Received::SdoResponse { node }) => {
                        let response = sdo::decode_response(node, &f)
                            .map_err(|_| err(SetupErrorKind::BadResponse))?;
                        return match response {
                            SdoResponse::Abort { code, .. } => {
                                Err(err(SetupErrorKind::Abort(code)))
                            }
                            r => Ok(r),
                        };
                    }
                    Some(f) => (self.observe)(&f),
                    None => std::thread::sleep(Duration::from_micros(100)),
                }
            }
        }
        Err(err(SetupErrorKind::SdoTimeout {
            ms: self.opts.sdo_timeout.as_millis(),
            attempts,
        }))
    }

    fn write(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        value: SdoValue,
    ) -> Result<(), SetupError> {
        match self.sdo(
            node,
            index,
            sub,
            sdo::download_request(node, index, sub, value),
        )? {
            SdoResponse::DownloadAck { .. } => Ok(()),
            _ => Err(SetupError {
                node: node.get(),
                object: Some((index, sub)),
                kind: SetupErrorKind::BadResponse,
            }),
        }
    }

    fn read_i32(&mut self, node: NodeId, index: u16, sub: u8) -> Result<i32, SetupError> {
        let bad = SetupError {
            node: node.get(),
            object: Some((index, sub)),
            kind: SetupErrorKind::BadResponse,
        };
        match self.sdo(node, index, sub, sdo::upload_request(node, index, sub))? {
            SdoResponse::Uploaded { data, .. } => match data.as_bytes().len() {
                1 => data.to_i8().map(i32::from).ok_or(bad),
                2 => data.to_i16().map(i32::from).ok_or(bad),
                _ => data.to_i32().ok_or(bad),
            },
            _ => Err(bad),
        }
    }

    fn map_pdo(&mut self, node: NodeId, kind: PdoKind) -> Result<(), SetupError> {
        let (comm, map, entries) = match kind {
            PdoKind::Rpdo => (
                od::RPDO1_COMMUNICATION,
                od::RPDO1_MAPPING,
                RPDO1_CSP_MAPPING,
            ),
            PdoKind::Tpdo => (
                od::TPDO1_COMMUNICATION,
                od::TPDO1_MAPPING,
                TPDO1_CSP_MAPPING,
            ),
        };
        let cob = u32::from(crate::wire::pdo::pdo_cob_id(kind, 1, node).unwrap_or(0));
        self.write(node, comm, 1, SdoValue::U32(cob | od::PDO_COB_ID_INVALID))?;
        self.write(node, map, 0, SdoValue::U8(0))?;
        for (i, &entry) in entries.iter().enumerate() {
            self.write(node, map, i as u8 + 1, SdoValue::U32(entry))?;
        }
        self.write(node, map, 0, SdoValue::U8(entries.len() as u8))?;
        self.write(node, comm, 2, SdoValue::U8(od::TRANSMISSION_EVERY_SYNC))?;
        self.write(node, comm, 1, SdoValue::U32(cob))
    }
}

/// Configure every node on one bus and start them. Returns each node's actual position
/// (counts), in the order of `nodes`, for the first cyclic targets. `observe` sees every
/// frame that is not the answer being waited for (heartbeats, EMCY, stray PDOs).
pub fn configure<L: CanLink>(
    link: &mut L,
    nodes: &[NodeId],
    opts: &SetupOptions,
    observe: &mut dyn FnMut(&CanFrame),
) -> Result<Vec<i32>, SetupError> {
    let first = nodes.first().map_or(0, |n| n.get());
    let mut s = Session {
        link,
        opts: *opts,
        observe,
    };
    let (value, exp) = interpolation_period(opts.period_s).ok_or(SetupError {
        node: first,
        object: None,
        kind: SetupErrorKind::Period(opts.period_s),
    })?;

    // 1. Reset communication of all nodes, then collect the boot-ups of ours.
    for &node in nodes {
        s.send(
            node,
            &nmt::encode(NmtCommand::ResetCommunication, Target::Node(node)),
        )?;
    }
    let mut booted = vec![false; nodes.len()];
    let deadline = Instant::now() + opts.boot_timeout;
    while booted.iter().any(|b| !b) && Instant::now() < deadline {
        match s.link.recv().map_err(|e| SetupError {
            node: first,
            object: None,
            kind: SetupErrorKind::Link(e),
        })? {
            Some(f) => match heartbeat::decode(&f) {
                Ok((node, NmtState::BootUp)) => {
                    if let Some(i) = nodes.iter().position(|&n| n == node) {
                        booted[i] = true;
                    }
                }
                _ => (s.observe)(&f),
            },
            None => std::thread::sleep(Duration::from_micros(200)),
        }
    }
    if let Some(i) = booted.iter().position(|b| !b) {
        let node = nodes[i];
        let cob = 0x700 + u16::from(node.get());
        return Err(SetupError {
            node: node.get(),
            object: None,
            kind: SetupErrorKind::NoBootUp {
                cob,
                ms: opts.boot_timeout.as_millis(),
            },
        });
    }

    // 2.-6. Per node, over SDO.
    let mut actual = Vec::with_capacity(nodes.len());
    for &node in nodes {
        s.write(node, od::MODES_OF_OPERATION, 0, SdoValue::I8(od::MODE_CSP))?;
        let shown = s.read_i32(node, od::MODES_OF_OPERATION_DISPLAY, 0)?;
        if shown != i32::from(od::MODE_CSP) {
            let kind = SetupErrorKind::Mismatch {
                expected: i64::from(od::MODE_CSP),
                got: i64::from(shown),
            };
            return Err(SetupError {
                node: node.get(),
                object: Some((od::MODES_OF_OPERATION_DISPLAY, 0)),
                kind,
            });
        }
        s.write(node, od::INTERPOLATION_TIME_PERIOD, 1, SdoValue::U8(value))?;
        s.write(node, od::INTERPOLATION_TIME_PERIOD, 2, SdoValue::I8(exp))?;
        s.map_pdo(node, PdoKind::Rpdo)?;
        s.map_pdo(node, PdoKind::Tpdo)?;
        s.write(
            node,
            od::HEARTBEAT_PRODUCER,
            0,
            SdoValue::U16(opts.heartbeat_ms),
        )?;
        actual.push(s.read_i32(node, od::POSITION_ACTUAL, 0)?);
    }

    // 7. Start.
    for &node in nodes {
        s.send(node, &nmt::encode(NmtCommand::Start, Target::Node(node)))?;
    }
    Ok(actual)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_period_encodings() {
        assert_eq!(interpolation_period(0.002), Some((2, -3)));
        assert_eq!(interpolation_period(0.0005), Some((5, -4)));
        assert_eq!(interpolation_period(0.01), Some((1, -2)));
        assert_eq!(interpolation_period(0.00125), Some((125, -5)));
        assert_eq!(interpolation_period(0.0), None);
    }

    #[test]
    fn errors_name_node_object_and_abort_in_words() {
        let e = SetupError {
            node: 3,
            object: Some((0x6060, 0)),
            kind: SetupErrorKind::Abort(AbortCode::from_u32(0x0609_0030)),
        };
        let text = e.to_string();
        assert!(
            text.starts_with("node 3, object 0x6060:00: SDO abort 0x06090030"),
            "{text}"
        );
    }
}
