//! The master's side of homing ([`super::homing`]): [`Master::home`] starts an axis's job,
//! [`Master::homing`] says where it is, and the cycle's part sends each job's SDO requests,
//! routes the answers and records how each job ended.

use super::cyclic::{Master, NodeKind, MAX_NODES};
use super::homing::{HomeRequest, HomingState, Job};
use crate::cia402::{Goal, State};
use crate::frame::CanFrame;
use crate::link::CanLink;
use crate::wire::sdo;
use heapless::Vec as HVec;

/// Why [`Master::home`] refuses to start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum HomeRefused {
    #[error("no axis drive at index {0}")]
    NoSuchAxis(usize),
    #[error("node {0} is not Operation enabled")]
    NotEnabled(u8),
    #[error("node {0} is already homing")]
    Busy(u8),
    #[error("the master has a fault: reset it first")]
    Faulted,
}

impl<L: CanLink> Master<L> {
    /// Start homing the axis drive at `i` (the master's node order). It must be Operation
    /// enabled, not homing, and the master without a fault. [`Master::homing`] says how it
    /// goes; meanwhile the drive is sent its own position as the target.
    pub fn home(&mut self, i: usize, req: HomeRequest) -> Result<(), HomeRefused> {
        let n = self
            .nodes
            .get(i)
            .filter(|n| n.kind == NodeKind::Position)
            .ok_or(HomeRefused::NoSuchAxis(i))?;
        let node = n.node.get();
        if self.fault.is_some() {
            return Err(HomeRefused::Faulted);
        }
        if n.state != Some(State::OperationEnabled) || self.goal != Goal::Enabled {
            return Err(HomeRefused::NotEnabled(node));
        }
        if self.jobs[i].is_some() {
            return Err(HomeRefused::Busy(node));
        }
        self.jobs[i] = Some(Job::new(req));
        self.homing[i] = HomingState::Running;
        Ok(())
    }

    /// Stop the homing of the node at `i`, if it is homing (the operator's stop): the start
    /// bit drops and the drive is put back in cyclic synchronous position where it stands,
    /// not homed ([`HomingState::Failed`] with [`super::HomingError::Stopped`]).
    pub fn stop_homing(&mut self, i: usize) {
        if let Some(Some(job)) = self.jobs.get_mut(i) {
            job.cancel();
        }
    }

    /// Where the homing of the node at `i` is.
    pub fn homing(&self, i: usize) -> HomingState {
        self.homing.get(i).copied().unwrap_or(HomingState::Idle)
    }

    /// Whether the node at `i` is homing (its target is its own position meanwhile).
    pub(super) fn is_homing(&self, i: usize) -> bool {
        self.jobs.get(i).is_some_and(Option::is_some)
    }

    /// Whether the node at `i` is (perhaps) in homing mode: its statusword bit 13 is the
    /// homing error, not a following error.
    pub(super) fn in_homing_mode(&self, i: usize) -> bool {
        self.jobs
            .get(i)
            .is_some_and(|j| j.is_some_and(|j| j.homing_mode()))
    }

    /// The start bit belongs in the node's controlword this cycle.
    pub(super) fn homing_start_bit(&self, i: usize) -> bool {
        self.jobs
            .get(i)
            .is_some_and(|j| j.is_some_and(|j| j.start_bit()))
    }

    /// An SDO answer from the node at `i`.
    pub(super) fn homing_answer(&mut self, i: usize, frame: &CanFrame) {
        let node = self.nodes[i].node;
        if let (Some(Some(job)), Ok(r)) = (self.jobs.get_mut(i), sdo::decode_response(node, frame))
        {
            job.on_sdo(r);
        }
    }

    /// One cycle of every homing under way: the SDO requests to send, jobs ended recorded.
    pub(super) fn homing_cycle(&mut self) -> HVec<CanFrame, MAX_NODES> {
        let mut out = HVec::new();
        let stopped = self.fault.is_some() || self.goal != Goal::Enabled;
        for (i, n) in self.nodes.iter().enumerate() {
            let Some(job) = self.jobs[i].as_mut() else {
                continue;
            };
            if stopped || n.state != Some(State::OperationEnabled) {
                job.interrupt();
            }
            if let Some(f) = job.poll(n.node, n.statusword) {
                // At most one request per node: there is room.
                let _ = out.push(f);
            }
            if let Some(end) = job.outcome() {
                self.homing[i] = match end {
                    Ok(()) => HomingState::Attained { position: n.actual },
                    Err(e) => HomingState::Failed(e),
                };
                self.jobs[i] = None;
            }
        }
        out
    }
}
