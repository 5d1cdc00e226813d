//! The master's part of every cycle, called by the real-time loop: allocation-free, no
//! blocking, bounded loops, time passed in.
//!
//! [`Master::cycle`]:
//! 1. consumes what arrived since the last cycle: TPDO1 (statusword, actual position),
//!    EMCY, heartbeats; at most [`MAX_RX_PER_CYCLE`] frames;
//! 2. supervises every node: Fault or Fault reaction active, an EMCY, the following-error
//!    bit, a heartbeat older than its timeout or not Operational, no TPDO for
//!    `feedback_timeout_cycles` cycles. The first fault is kept with its node and cause and
//!    switches every node's goal to Quick stop, then to Disabled once all have stopped;
//! 3. steps each node's CiA-402 sequencer toward the goal and sends one RPDO1 per node
//!    (controlword + target) and one SYNC.
//!
//! Before it is Operation enabled a drive is sent its own actual position as target, so
//! that enabling cannot make it jump. After a fault every drive is sent its last commanded
//! target, held: the commanded position never moves again, in particular never back to a
//! lagging actual position (a step against the motion), while each drive stops by its own
//! quick-stop ramp and is disabled.
//!
//! Besides the axes ([`NodeKind::Position`]) a bus may carry the spindle, a CiA-402 drive in
//! profile velocity mode ([`NodeKind::Velocity`]: its target is a velocity, 0 until it is
//! Operation enabled and from a fault on), and a CiA-401 I/O module ([`NodeKind::Io`]: its
//! RPDO1 carries the digital outputs, all off until the goal is Enabled and from a fault on;
//! its TPDO1 the inputs; it has no CiA-402 state machine and is supervised by heartbeat,
//! NMT state, EMCY and feedback only).

use super::health::{BusCondition, BusHealth, Reaction};
use super::homing::{HomingState, Job, START};
use crate::cia402::{Goal, Sequencer, State, Statusword};
use crate::frame::CanFrame;
use crate::link::{CanLink, LinkError};
use crate::wire::emcy::{self, Emcy};
use crate::wire::heartbeat::{self, NmtState};
use crate::wire::pdo::{decode_tpdo1_csp, decode_tpdo1_io, rpdo1_csp, rpdo1_io};
use crate::wire::{classify, sync, NodeId, Received};
use heapless::Vec as HVec;

/// Most drives on one bus (a 1 Mbit/s bus carries about 8 at 1 ms; 16 leaves room).
pub const MAX_NODES: usize = 16;
/// Most frames consumed per cycle.
pub const MAX_RX_PER_CYCLE: usize = 8 * MAX_NODES + 16;
/// Frames received per [`CanLink::recv_all`] call.
const RX_BATCH: usize = 32;

/// What a node on the bus is to the master.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NodeKind {
    /// A CiA-402 drive in cyclic synchronous position mode: an axis.
    #[default]
    Position,
    /// A CiA-402 drive in profile velocity mode: the spindle.
    Velocity,
    /// A CiA-401 digital I/O module: the coolant valves.
    Io,
}

/// What the master knows of one node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeStatus {
    pub node: NodeId,
    pub kind: NodeKind,
    /// CiA-402 state (`None` for an I/O module, or before the first TPDO).
    pub state: Option<State>,
    pub statusword: u16,
    /// Position actual value, counts; the velocity actual value for a
    /// [`NodeKind::Velocity`] drive; the digital inputs for an I/O module.
    pub actual: i32,
    /// Last target sent: counts, velocity units, or the digital outputs.
    pub target: i32,
    pub nmt: Option<NmtState>,
    /// Time of the last heartbeat, s (the clock passed to `cycle`).
    pub last_heartbeat: Option<f64>,
    pub last_emcy: Option<Emcy>,
    /// Cycles since the last TPDO1.
    pub cycles_without_feedback: u32,
    /// An Operational heartbeat has come since the master took over. Until then a
    /// pre-operational, stopped or boot-up heartbeat may be one the node sent during the
    /// set-up, before its NMT start, still queued in the socket: it is a fault only once
    /// the heartbeat timeout has passed without an Operational one.
    pub operational_seen: bool,
    seq: Sequencer,
}

/// Why a node is considered faulty.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum FaultCause {
    #[error("drive in {state:?} (statusword 0x{statusword:04X})")]
    DriveFault { state: State, statusword: u16 },
    #[error("EMCY {0}")]
    Emcy(Emcy),
    #[error("following error (statusword bit 13, 0x{0:04X})")]
    FollowingError(u16),
    #[error("heartbeat lost: none for {age_ms:.0} ms (timeout {timeout_ms:.0} ms)")]
    HeartbeatLost { age_ms: f64, timeout_ms: f64 },
    #[error("NMT state {0:?} instead of Operational")]
    NotOperational(NmtState),
    #[error("no TPDO feedback for {0} cycles")]
    NoFeedback(u32),
    #[error("CAN link: {0}")]
    Link(LinkError),
    #[error("{0}")]
    Bus(BusCondition),
    #[error("{0}")]
    EStop(EStop),
}

/// What stopped the machine at an e-stop (`estop.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EStop {
    #[error("e-stop requested")]
    Requested,
    /// The chain on module input `input` (1..=8) opened.
    #[error("e-stop: input {input} open (the e-stop chain)")]
    Input { input: u8 },
}

/// A fault with the node it came from ([`DriveFault::BUS`] for the bus itself).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("{}: {cause}", NodeName(*node))]
pub struct DriveFault {
    pub node: u8,
    pub cause: FaultCause,
}

impl DriveFault {
    /// The node of a fault of the bus or the link, not of one drive (CANopen nodes are
    /// 1..=127).
    pub const BUS: u8 = 0;
    /// The "node" of an e-stop the operator asked for ([`Master::estop`]).
    pub const OPERATOR: u8 = 128;
}

/// "node 3", or "CAN bus" for [`DriveFault::BUS`].
struct NodeName(u8);

impl core::fmt::Display for NodeName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.0 {
            DriveFault::BUS => write!(f, "CAN bus"),
            DriveFault::OPERATOR => write!(f, "operator"),
            n => write!(f, "node {n}"),
        }
    }
}

/// Supervision limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Supervision {
    /// A heartbeat older than this is a fault, s (0 = not supervised).
    pub heartbeat_timeout_s: f64,
    /// Cycles without TPDO1 before it is a fault.
    pub feedback_timeout_cycles: u32,
}

/// The cyclic master of one bus.
#[derive(Debug)]
pub struct Master<L: CanLink> {
    link: L,
    pub(super) nodes: HVec<NodeStatus, MAX_NODES>,
    pub(super) goal: Goal,
    pub(super) fault: Option<DriveFault>,
    /// Each node's homing under way, and how its last ended (`homing.rs`).
    pub(super) jobs: [Option<Job>; MAX_NODES],
    pub(super) homing: [HomingState; MAX_NODES],
    sup: Supervision,
    cycles: u64,
    dropped: u64,
    /// Frames the last cycle's send dropped.
    last_dropped: usize,
    health: BusHealth,
    /// The most severe feed hold or controlled stop the bus called for, until taken.
    bus_pending: Option<BusCondition>,
    /// The clock value the master was created at, s.
    started: f64,
    /// An operator's reset under way (`reset.rs`): the cycle by which every drive must
    /// have left Fault.
    pub(super) resetting: Option<u64>,
    /// The e-stop chain's input: the I/O node's index and the module input 1..=8
    /// (`estop.rs`).
    pub(super) estop_input: Option<(usize, u8)>,
}

impl<L: CanLink> Master<L> {
    /// Axes only: `initial` holds each node's actual position from set-up, in the order of
    /// `nodes`. Returns `None` if there are more than [`MAX_NODES`] nodes or the slices
    /// differ in length.
    pub fn new(
        link: L,
        nodes: &[NodeId],
        initial: &[i32],
        sup: Supervision,
        now: f64,
    ) -> Option<Self> {
        let mut kinds: HVec<(NodeId, NodeKind), MAX_NODES> = HVec::new();
        for &n in nodes {
            kinds.push((n, NodeKind::Position)).ok()?;
        }
        Self::with_kinds(link, &kinds, initial, sup, now)
    }

    /// As [`Master::new`], each node with its kind; `initial` holds what set-up read (the
    /// actual position, velocity or inputs).
    pub fn with_kinds(
        link: L,
        nodes: &[(NodeId, NodeKind)],
        initial: &[i32],
        sup: Supervision,
        now: f64,
    ) -> Option<Self> {
        if nodes.len() != initial.len() {
            return None;
        }
        let mut v = HVec::new();
        for (&(node, kind), &actual) in nodes.iter().zip(initial) {
            let target = if kind == NodeKind::Position {
                actual
            } else {
                0
            };
            v.push(NodeStatus {
                node,
                kind,
                state: None,
                statusword: 0,
                actual,
                target,
                nmt: None,
                last_heartbeat: Some(now),
                last_emcy: None,
                cycles_without_feedback: 0,
                operational_seen: false,
                seq: Sequencer::new(),
            })
            .ok()?;
        }
        Some(Master {
            link,
            nodes: v,
            goal: Goal::Disabled,
            fault: None,
            sup,
            cycles: 0,
            dropped: 0,
            last_dropped: 0,
            health: BusHealth::default(),
            bus_pending: None,
            jobs: [None; MAX_NODES],
            homing: [HomingState::Idle; MAX_NODES],
            started: now,
            resetting: None,
            estop_input: None,
        })
    }

    pub fn set_goal(&mut self, goal: Goal) {
        if self.fault.is_none() {
            self.goal = goal;
        }
    }

    pub fn goal(&self) -> Goal {
        self.goal
    }

    pub fn status(&self) -> &[NodeStatus] {
        &self.nodes
    }

    /// The first fault seen, if any. Once set, the master stops the drives by itself.
    pub fn fault(&self) -> Option<&DriveFault> {
        self.fault.as_ref()
    }

    /// Whether every CiA-402 drive is in `state` (I/O modules have no state).
    pub fn all_in(&self, state: State) -> bool {
        self.nodes
            .iter()
            .all(|n| n.kind == NodeKind::Io || n.state == Some(state))
    }

    /// Whether the node has been silent longer than its feedback supervision allows: lost,
    /// nothing more can be learnt of it or done with it on this bus.
    pub fn lost(&self, n: &NodeStatus) -> bool {
        n.cycles_without_feedback > self.sup.feedback_timeout_cycles
    }

    /// Frames that could not be sent because the transmit queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    pub fn cycles(&self) -> u64 {
        self.cycles
    }

    pub fn link(&self) -> &L {
        &self.link
    }

    /// What the master has seen of the bus: error frames by kind, the reactions called for.
    pub fn health(&self) -> &BusHealth {
        &self.health
    }

    /// The feed hold or controlled stop the bus has called for since the last call, the
    /// most severe if several (quick stops are the master's own fault, [`Master::fault`]).
    pub fn take_bus_condition(&mut self) -> Option<BusCondition> {
        self.bus_pending.take()
    }

    /// The period's bus condition: a quick stop is a fault, a hold or a stop waits to be
    /// taken by the loop.
    fn watch_bus(&mut self) {
        let Some(c) = self.health.update(self.link.errors(), self.last_dropped) else {
            return;
        };
        match c.reaction() {
            Reaction::QuickStop => self.raise(DriveFault::BUS, FaultCause::Bus(c)),
            Reaction::Hold | Reaction::Stop => {
                if self.bus_pending.is_none_or(|p| c.reaction() > p.reaction()) {
                    self.bus_pending = Some(c);
                }
            }
            Reaction::Warn => {}
        }
    }

    pub(super) fn raise(&mut self, node: u8, cause: FaultCause) {
        if self.fault.is_none() {
            self.fault = Some(DriveFault { node, cause });
            self.goal = Goal::QuickStop;
        }
    }

    fn receive(&mut self, now: f64) {
        let mut buf = [sync::encode(); RX_BATCH];
        let mut total = 0;
        // Bounded: every pass that does not end the loop adds RX_BATCH or more to `total`.
        while total < MAX_RX_PER_CYCLE {
            let want = RX_BATCH.min(MAX_RX_PER_CYCLE - total);
            let n = match self.link.recv_all(&mut buf[..want]) {
                Ok(n) => n.min(want),
                Err(e) => {
                    self.raise(DriveFault::BUS, FaultCause::Link(e));
                    break;
                }
            };
            for frame in &buf[..n] {
                self.handle(frame, now);
            }
            total += want;
            if n < want {
                break;
            }
        }
    }

    fn handle(&mut self, frame: &CanFrame, now: f64) {
        let Some(i) = (match classify(frame) {
            Received::Tpdo { node, .. }
            | Received::Emcy { node }
            | Received::Heartbeat { node }
            | Received::SdoResponse { node } => self.nodes.iter().position(|n| n.node == node),
            _ => None,
        }) else {
            return;
        };
        if matches!(classify(frame), Received::SdoResponse { .. }) {
            self.homing_answer(i, frame);
            return;
        }
        let n = &mut self.nodes[i];
        match classify(frame) {
            Received::Tpdo { n: 1, .. } if n.kind == NodeKind::Io => {
                if let Ok((_, inputs)) = decode_tpdo1_io(frame) {
                    n.actual = i32::from(inputs);
                    n.cycles_without_feedback = 0;
                }
            }
            Received::Tpdo { n: 1, .. } => {
                if let Ok((_, fb)) = decode_tpdo1_csp(frame) {
                    n.statusword = fb.statusword;
                    n.actual = fb.actual;
                    n.state = State::from_statusword(fb.statusword);
                    n.cycles_without_feedback = 0;
                }
            }
            Received::Emcy { .. } => {
                if let Ok((_, e)) = emcy::decode(frame) {
                    n.last_emcy = Some(e);
                    if e.error_code != 0 {
                        let node = n.node.get();
                        self.raise(node, FaultCause::Emcy(e));
                    }
                }
            }
            Received::Heartbeat { .. } => {
                if let Ok((_, state)) = heartbeat::decode(frame) {
                    n.nmt = Some(state);
                    n.last_heartbeat = Some(now);
                    n.operational_seen |= state == NmtState::Operational;
                }
            }
            _ => {}
        }
    }

    fn supervise(&mut self, now: f64) {
        let grace_over = now - self.started > self.sup.heartbeat_timeout_s;
        for i in 0..self.nodes.len() {
            let n = self.nodes[i];
            let node = n.node.get();
            let state = if n.kind == NodeKind::Io {
                None
            } else {
                n.state
            };
            let cause = match state {
                // A reset under way: the fault-reset edge is on its way.
                Some(State::Fault | State::FaultReactionActive) if self.reset_pending() => None,
                Some(state @ (State::Fault | State::FaultReactionActive)) => {
                    Some(FaultCause::DriveFault {
                        state,
                        statusword: n.statusword,
                    })
                }
                _ if Statusword(n.statusword).following_error()
                    && n.state == Some(State::OperationEnabled)
                    && !self.in_homing_mode(i) =>
                {
                    Some(FaultCause::FollowingError(n.statusword))
                }
                _ if n.cycles_without_feedback > self.sup.feedback_timeout_cycles => {
                    Some(FaultCause::NoFeedback(n.cycles_without_feedback))
                }
                _ => match (n.nmt, n.last_heartbeat) {
                    (
                        Some(s @ (NmtState::Stopped | NmtState::PreOperational | NmtState::BootUp)),
                        _,
                    ) if n.operational_seen || grace_over => Some(FaultCause::NotOperational(s)),
                    (_, Some(t))
                        if self.sup.heartbeat_timeout_s > 0.0
                            && now - t > self.sup.heartbeat_timeout_s =>
                    {
                        Some(FaultCause::HeartbeatLost {
                            age_ms: (now - t) * 1e3,
                            timeout_ms: self.sup.heartbeat_timeout_s * 1e3,
                        })
                    }
                    _ => None,
                },
            };
            if let Some(cause) = cause {
                self.raise(node, cause);
            }
        }
        self.supervise_estop();
        // After a quick stop has taken every drive out of motion, take the power off.
        if self.fault.is_some()
            && self.goal == Goal::QuickStop
            && self.nodes.iter().all(|n| {
                n.kind == NodeKind::Io
                    || matches!(
                        n.state,
                        Some(
                            State::QuickStopActive
                                | State::Fault
                                | State::SwitchOnDisabled
                                | State::ReadyToSwitchOn
                                | State::SwitchedOn
                        )
                    )
                    || n.cycles_without_feedback > self.sup.feedback_timeout_cycles
            })
        {
            self.goal = Goal::Disabled;
        }
    }

    /// One cycle: receive, supervise, send RPDO1 per node (targets in counts, in the order
    /// of the nodes; ignored while a drive is not Operation enabled or after a fault) and
    /// SYNC. Returns the first fault, if any has occurred.
    ///
    /// Real-time thread.
    pub fn cycle(&mut self, targets: &[i32], now: f64) -> Option<DriveFault> {
        self.cycles += 1;
        for n in self.nodes.iter_mut() {
            n.cycles_without_feedback = n.cycles_without_feedback.saturating_add(1);
        }
        self.receive(now);
        self.watch_bus();
        self.supervise(now);
        self.reset_progress();
        let goal = self.goal;
        let hold = self.fault.is_some();
        // SDO requests of the homings under way first, then the RPDOs and the SYNC.
        let mut out: HVec<CanFrame, { 2 * MAX_NODES + 1 }> = HVec::new();
        for f in self.homing_cycle() {
            let _ = out.push(f);
        }
        let homing: [(bool, bool); MAX_NODES] =
            core::array::from_fn(|i| (self.is_homing(i), self.homing_start_bit(i)));
        for (i, n) in self.nodes.iter_mut().enumerate() {
            let state = n.state.unwrap_or(State::SwitchOnDisabled);
            if n.kind == NodeKind::Io {
                // Outputs on only while the machine is meant to run and nothing faulted.
                n.target = match targets.get(i) {
                    Some(&t) if !hold && goal == Goal::Enabled => t & 0xFF,
                    _ => 0,
                };
                let _ = out.push(rpdo1_io(n.node, n.target as u8));
                continue;
            }
            // A drive in Fault during a reset gets the fault-reset edge, whatever the goal.
            let node_goal = match state {
                State::Fault if self.resetting.is_some() => Goal::Enabled,
                _ => goal,
            };
            let mut cw = n.seq.step(state, node_goal);
            let (homes, start) = homing[i];
            if start && state == State::OperationEnabled {
                cw.0 |= START;
            }
            n.target = match (n.kind, state, targets.get(i)) {
                // After a fault: the last commanded target, whatever the state. A drive
                // behind its target (its own lag) would otherwise see the target step back
                // to where it is, a velocity reversal beyond any limit.
                (NodeKind::Position, ..) if hold => n.target,
                // Homing: where the drive stands, so that CSP resumes there.
                (NodeKind::Position, ..) if homes => n.actual,
                (_, State::OperationEnabled, Some(&t)) if !hold => t,
                (NodeKind::Position, ..) => n.actual,
                // A spindle stops: its drive ramps down (quick stop after a fault).
                _ => 0,
            };
            // At most MAX_NODES nodes: there is room.
            let _ = out.push(rpdo1_csp(n.node, cw.0, n.target));
        }
        let _ = out.push(sync::encode());
        // The RPDOs and the SYNC in one batch (one system call on a socket). A link that
        // fails (the interface down) is the bus's fault: nothing reaches the drives.
        self.last_dropped = 0;
        match self.link.send_all(&out) {
            Ok(dropped) => {
                self.dropped += dropped as u64;
                self.last_dropped = dropped;
            }
            Err(e) => self.raise(DriveFault::BUS, FaultCause::Link(e)),
        }
        self.fault
    }
}
