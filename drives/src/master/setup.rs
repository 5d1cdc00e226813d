//! Drive configuration, outside the real-time thread, for every node of one bus:
//!
//! 1. NMT reset communication, then wait for each node's boot-up message;
//! 2. SDO: modes of operation 0x6060 = 8 (CSP), read back from 0x6061; then what the drive
//!    guards by itself ([`Protections`]: 0x6065, 0x6066, 0x605A, 0x605E, 0x607D), each
//!    read back;
//! 3. SDO: interpolation time period 0x60C2 = the machine period (value * 10^exponent s);
//! 4. PDO mapping exactly as CiA-301 prescribes (docs/canopen.md): RPDO1 = controlword
//!    0x6040 + target 0x607A, TPDO1 = statusword 0x6041 + actual 0x6064, both disabled while
//!    mapped, transmission type 1 (every SYNC), then re-enabled;
//! 5. SDO: heartbeat producer 0x1017;
//! 6. SDO: read the actual position 0x6064, so the first target equals it (no jump);
//! 7. NMT start.
//!
//! A spindle ([`NodeSetup::Velocity`]) gets modes of operation 3 (profile velocity), RPDO1 =
//! controlword + target velocity 0x60FF, TPDO1 = statusword + velocity actual 0x606C, its
//! ramps 0x6083/0x6084/0x6085 and velocity window 0x606D/0x606E, and its velocity actual is
//! read in step 6. An I/O module ([`NodeSetup::Io`], CiA-401) gets only the PDO mapping
//! (RPDO1 = digital outputs 0x6200:01, TPDO1 = digital inputs 0x6000:01) and the
//! heartbeat; its inputs are read in step 6.
//!
//! Every SDO transfer has a timeout and a bounded number of retries. Frames that arrive in
//! between (heartbeats, EMCY) are not lost: they are handed to an observer.
//!
//! Time is the caller's ([`Clock`]): the set-up measures its timeouts on it and hands it the
//! waits, never reading the system clock or sleeping itself. [`WallClock`] is the real one;
//! a bus of simulated drives on a virtual clock (`crate::sim::Lockstep`) steps its nodes
//! instead, so a test of the whole set-up takes no time and does not depend on the machine.

use crate::link::{CanLink, LinkError};
use crate::master::NodeKind;
use crate::od;
use crate::wire::heartbeat::{self, NmtState};
use crate::wire::nmt::{self, NmtCommand, Target};
use crate::wire::pdo::{
    PdoKind, RPDO1_CSP_MAPPING, RPDO1_IO_MAPPING, RPDO1_PV_MAPPING, TPDO1_CSP_MAPPING,
    TPDO1_IO_MAPPING, TPDO1_PV_MAPPING,
};
use crate::wire::sdo::{self, SdoResponse, SdoValue};
use crate::wire::{classify, AbortCode, NodeId, Received};
use crate::CanFrame;
use std::time::{Duration, Instant};

/// The set-up's sense of time.
pub trait Clock {
    /// Time since an arbitrary origin.
    fn now(&self) -> Duration;
    /// Nothing has arrived that the set-up waits for (or the link's queue is full): let time
    /// pass. A wall clock sleeps briefly; simulated drives answer and the clock moves on.
    fn idle(&mut self);
}

/// Wall time: [`Instant`], and a short sleep while idle.
#[derive(Clone, Copy, Debug)]
pub struct WallClock {
    t0: Instant,
    pause: Duration,
}

impl WallClock {
    /// A clock that sleeps `pause` while the set-up waits (100 to 200 µs answer a drive
    /// within a small share of an SDO timeout without spinning a CPU).
    pub fn new(pause: Duration) -> Self {
        WallClock {
            t0: Instant::now(),
            pause,
        }
    }
}

impl Default for WallClock {
    fn default() -> Self {
        WallClock::new(Duration::from_micros(100))
    }
}

impl Clock for WallClock {
    fn now(&self) -> Duration {
        self.t0.elapsed()
    }

    fn idle(&mut self) {
        std::thread::sleep(self.pause);
    }
}

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

/// The profile-velocity parameters of a spindle drive, in drive velocity units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VelocitySetup {
    /// Profile acceleration 0x6083 and deceleration 0x6084, units/s.
    pub ramp: u32,
    /// Quick stop deceleration 0x6085, units/s.
    pub quick_stop: u32,
    /// Velocity window 0x606D, units.
    pub window: u16,
    /// Velocity window time 0x606E, ms.
    pub window_ms: u16,
}

mod protect;

pub use protect::{Protections, FOLLOWING_OFF};

/// One node to configure, with what it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeSetup {
    /// An axis drive, cyclic synchronous position, and what it guards by itself.
    Position(NodeId, Protections),
    /// The spindle drive, profile velocity.
    Velocity(NodeId, VelocitySetup),
    /// A CiA-401 digital I/O module.
    Io(NodeId),
}

impl NodeSetup {
    pub fn node(&self) -> NodeId {
        match *self {
            NodeSetup::Position(n, _) | NodeSetup::Velocity(n, _) | NodeSetup::Io(n) => n,
        }
    }

    pub fn kind(&self) -> NodeKind {
        match self {
            NodeSetup::Position(..) => NodeKind::Position,
            NodeSetup::Velocity(..) => NodeKind::Velocity,
            NodeSetup::Io(_) => NodeKind::Io,
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

struct Session<'a, L: CanLink, C: Clock> {
    link: &'a mut L,
    clock: &'a mut C,
    opts: SetupOptions,
    observe: &'a mut dyn FnMut(&CanFrame),
}

impl<L: CanLink, C: Clock> Session<'_, L, C> {
    fn send(&mut self, node: NodeId, frame: &CanFrame) -> Result<(), SetupError> {
        // Outside the RT thread a full queue is waited out briefly, not dropped.
        for _ in 0..100 {
            match self.link.send(frame) {
                Ok(crate::link::Sent::Queued) => return Ok(()),
                Ok(crate::link::Sent::Dropped) => self.clock.idle(),
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
            let deadline = self.clock.now() + self.opts.sdo_timeout;
            while self.clock.now() < deadline {
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
                    None => self.clock.idle(),
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

    fn map_pdo(&mut self, node: NodeId, kind: PdoKind, entries: &[u32]) -> Result<(), SetupError> {
        let (comm, map) = match kind {
            PdoKind::Rpdo => (od::RPDO1_COMMUNICATION, od::RPDO1_MAPPING),
            PdoKind::Tpdo => (od::TPDO1_COMMUNICATION, od::TPDO1_MAPPING),
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

    /// Modes of operation, written and read back.
    fn mode(&mut self, node: NodeId, mode: i8) -> Result<(), SetupError> {
        self.write(node, od::MODES_OF_OPERATION, 0, SdoValue::I8(mode))?;
        let shown = self.read_i32(node, od::MODES_OF_OPERATION_DISPLAY, 0)?;
        if shown != i32::from(mode) {
            let kind = SetupErrorKind::Mismatch {
                expected: i64::from(mode),
                got: i64::from(shown),
            };
            return Err(SetupError {
                node: node.get(),
                object: Some((od::MODES_OF_OPERATION_DISPLAY, 0)),
                kind,
            });
        }
        Ok(())
    }

    /// Steps 2 to 6 for one node; returns what the first cyclic target starts from.
    fn node(&mut self, setup: &NodeSetup, period: (u8, i8)) -> Result<i32, SetupError> {
        let node = setup.node();
        let (rpdo, tpdo): (&[u32], &[u32]) = match setup {
            NodeSetup::Position(..) => (&RPDO1_CSP_MAPPING, &TPDO1_CSP_MAPPING),
            NodeSetup::Velocity(..) => (&RPDO1_PV_MAPPING, &TPDO1_PV_MAPPING),
            NodeSetup::Io(_) => (&RPDO1_IO_MAPPING, &TPDO1_IO_MAPPING),
        };
        match setup {
            NodeSetup::Position(_, protections) => {
                self.mode(node, od::MODE_CSP)?;
                self.protections(node, protections)?;
                self.write(
                    node,
                    od::INTERPOLATION_TIME_PERIOD,
                    1,
                    SdoValue::U8(period.0),
                )?;
                self.write(
                    node,
                    od::INTERPOLATION_TIME_PERIOD,
                    2,
                    SdoValue::I8(period.1),
                )?;
            }
            NodeSetup::Velocity(_, v) => {
                self.mode(node, od::MODE_PV)?;
                self.write(node, od::PROFILE_ACCELERATION, 0, SdoValue::U32(v.ramp))?;
                self.write(node, od::PROFILE_DECELERATION, 0, SdoValue::U32(v.ramp))?;
                self.write(
                    node,
                    od::QUICK_STOP_DECELERATION,
                    0,
                    SdoValue::U32(v.quick_stop),
                )?;
                self.write(node, od::VELOCITY_WINDOW, 0, SdoValue::U16(v.window))?;
                self.write(
                    node,
                    od::VELOCITY_WINDOW_TIME,
                    0,
                    SdoValue::U16(v.window_ms),
                )?;
            }
            NodeSetup::Io(_) => {}
        }
        self.map_pdo(node, PdoKind::Rpdo, rpdo)?;
        self.map_pdo(node, PdoKind::Tpdo, tpdo)?;
        self.write(
            node,
            od::HEARTBEAT_PRODUCER,
            0,
            SdoValue::U16(self.opts.heartbeat_ms),
        )?;
        match setup {
            NodeSetup::Position(..) => self.read_i32(node, od::POSITION_ACTUAL, 0),
            NodeSetup::Velocity(..) => self.read_i32(node, od::VELOCITY_ACTUAL, 0),
            NodeSetup::Io(_) => Ok(self.read_i32(node, od::DIGITAL_INPUTS, 1)? & 0xFF),
        }
    }
}

/// Configure every node on one bus, all axis drives, and start them. Returns each node's
/// actual position (counts), in the order of `nodes`, for the first cyclic targets.
/// `observe` sees every frame that is not the answer being waited for (heartbeats, EMCY,
/// stray PDOs).
pub fn configure<L: CanLink>(
    link: &mut L,
    nodes: &[NodeId],
    opts: &SetupOptions,
    clock: &mut impl Clock,
    observe: &mut dyn FnMut(&CanFrame),
) -> Result<Vec<i32>, SetupError> {
    let setups: Vec<NodeSetup> = nodes
        .iter()
        .map(|&n| NodeSetup::Position(n, Protections::default()))
        .collect();
    configure_nodes(link, &setups, opts, clock, observe)
}

/// As [`configure`], each node as what it is (axis, spindle, I/O module). Returns what each
/// node's first cyclic target starts from: actual position, velocity actual, inputs.
pub fn configure_nodes<L: CanLink>(
    link: &mut L,
    setups: &[NodeSetup],
    opts: &SetupOptions,
    clock: &mut impl Clock,
    observe: &mut dyn FnMut(&CanFrame),
) -> Result<Vec<i32>, SetupError> {
    let nodes: Vec<NodeId> = setups.iter().map(NodeSetup::node).collect();
    let nodes = &nodes[..];
    let first = nodes.first().map_or(0, |n| n.get());
    let mut s = Session {
        link,
        clock,
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
    let deadline = s.clock.now() + opts.boot_timeout;
    while booted.iter().any(|b| !b) && s.clock.now() < deadline {
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
            None => s.clock.idle(),
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
    for setup in setups {
        actual.push(s.node(setup, (value, exp))?);
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
