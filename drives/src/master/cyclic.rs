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

use crate::cia402::{Goal, Sequencer, State, Statusword};
use crate::frame::CanFrame;
use crate::link::{CanLink, LinkError};
use crate::wire::emcy::{self, Emcy};
use crate::wire::heartbeat::{self, NmtState};
use crate::wire::pdo::{decode_tpdo1_csp, rpdo1_csp};
use crate::wire::{classify, sync, NodeId, Received};
use heapless::Vec as HVec;

/// Most drives on one bus (a 1 Mbit/s bus carries about 8 at 1 ms; 16 leaves room).
pub const MAX_NODES: usize = 16;
/// Most frames consumed per cycle.
pub const MAX_RX_PER_CYCLE: usize = 8 * MAX_NODES + 16;
/// Frames received per [`CanLink::recv_all`] call.
const RX_BATCH: usize = 32;

/// What the master knows of one drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeStatus {
    pub node: NodeId,
    pub state: Option<State>,
    pub statusword: u16,
    /// Position actual value, counts.
    pub actual: i32,
    /// Last target sent, counts.
    pub target: i32,
    pub nmt: Option<NmtState>,
    /// Time of the last heartbeat, s (the clock passed to `cycle`).
    pub last_heartbeat: Option<f64>,
    pub last_emcy: Option<Emcy>,
    /// Cycles since the last TPDO1.
    pub cycles_without_feedback: u32,
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
}

/// A fault with the node it came from.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("node {node}: {cause}")]
pub struct DriveFault {
    pub node: u8,
    pub cause: FaultCause,
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
    nodes: HVec<NodeStatus, MAX_NODES>,
    goal: Goal,
    fault: Option<DriveFault>,
    sup: Supervision,
    cycles: u64,
    dropped: u64,
}

impl<L: CanLink> Master<L> {
    /// `initial` holds each node's actual position from set-up, in the order of `nodes`.
    /// Returns `None` if there are more than [`MAX_NODES`] nodes or the slices differ in length.
    pub fn new(
        link: L,
        nodes: &[NodeId],
        initial: &[i32],
        sup: Supervision,
        now: f64,
    ) -> Option<Self> {
        if nodes.len() != initial.len() {
            return None;
        }
        let mut v = HVec::new();
        for (&node, &actual) in nodes.iter().zip(initial) {
            v.push(NodeStatus {
                node,
                state: None,
                statusword: 0,
                actual,
                target: actual,
                nmt: None,
                last_heartbeat: Some(now),
                last_emcy: None,
                cycles_without_feedback: 0,
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

    /// Whether every node is in `state`.
    pub fn all_in(&self, state: State) -> bool {
        self.nodes.iter().all(|n| n.state == Some(state))
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

    fn raise(&mut self, node: u8, cause: FaultCause) {
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
                    let node = self.nodes.first().map_or(0, |n| n.node.get());
                    self.raise(node, FaultCause::Link(e));
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
            | Received::Heartbeat { node } => self.nodes.iter().position(|n| n.node == node),
            _ => None,
        }) else {
            return;
        };
        let n = &mut self.nodes[i];
        match classify(frame) {
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
                }
            }
            _ => {}
        }
    }

    fn supervise(&mut self, now: f64) {
        for i in 0..self.nodes.len() {
            let n = self.nodes[i];
            let node = n.node.get();
            let cause = match n.state {
                Some(state @ (State::Fault | State::FaultReactionActive)) => {
                    Some(FaultCause::DriveFault {
                        state,
                        statusword: n.statusword,
                    })
                }
                _ if Statusword(n.statusword).following_error()
                    && n.state == Some(State::OperationEnabled) =>
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
                    ) => Some(FaultCause::NotOperational(s)),
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
        // After a quick stop has taken every drive out of motion, take the power off.
        if self.fault.is_some()
            && self.goal == Goal::QuickStop
            && self.nodes.iter().all(|n| {
                matches!(
                    n.state,
                    Some(
                        State::QuickStopActive
                            | State::Fault
                            | State::SwitchOnDisabled
                            | State::ReadyToSwitchOn
                            | State::SwitchedOn
                    )
                ) || n.cycles_without_feedback > self.sup.feedback_timeout_cycles
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
        self.supervise(now);
        let goal = self.goal;
        let hold = self.fault.is_some();
        let mut out: HVec<CanFrame, { MAX_NODES + 1 }> = HVec::new();
        for (i, n) in self.nodes.iter_mut().enumerate() {
            let state = n.state.unwrap_or(State::SwitchOnDisabled);
            let cw = n.seq.step(state, goal);
            n.target = match (state, targets.get(i)) {
                // After a fault: the last commanded target, whatever the state. A drive
                // behind its target (its own lag) would otherwise see the target step back
                // to where it is, a velocity reversal beyond any limit.
                _ if hold => n.target,
                (State::OperationEnabled, Some(&t)) => t,
                _ => n.actual,
            };
            // At most MAX_NODES nodes: there is room.
            let _ = out.push(rpdo1_csp(n.node, cw.0, n.target));
        }
        let _ = out.push(sync::encode());
        // The RPDOs and the SYNC in one batch (one system call on a socket).
        if let Ok(dropped) = self.link.send_all(&out) {
            self.dropped += dropped as u64;
        }
        self.fault
    }
}
