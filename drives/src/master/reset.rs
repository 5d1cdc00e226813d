//! The operator's reset after a fault ([`Master::reset`]): once the quick stop that the
//! fault began is over and every drive is out of motion, the latched fault is acknowledged;
//! each drive still in Fault is sent the CiA-402 fault-reset edge (controlword bit 7 rising,
//! transition 15) and ends in Switch on disabled with the others. Nothing is enabled: the
//! caller asks for that with [`Master::set_goal`], and each drive then resumes cyclic
//! synchronous position where it stands.
//!
//! Refused while the e-stop chain is open. A cause that is still there is raised again
//! with its reason: a drive that stays in Fault
//! [`RESET_CYCLES`] after the reset, a node still silent, a heartbeat still lost.

use super::cyclic::{DriveFault, Master};
use crate::cia402::{Goal, State};
use crate::link::CanLink;

/// Cycles a drive has to leave Fault after a reset before it counts as faulted again.
pub const RESET_CYCLES: u64 = 250;

/// Why a reset is refused (nothing changes).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum ResetRefused {
    #[error("nothing to reset: no fault")]
    NoFault,
    #[error("the quick stop after the fault ({0}) is still under way: reset once the drives are out of motion")]
    Stopping(DriveFault),
    #[error(
        "the e-stop chain is open (input {input} of node {node} reads 0): release the e-stop first"
    )]
    EStopOpen { node: u8, input: u8 },
}

impl<L: CanLink> Master<L> {
    /// Acknowledge the latched fault: the fault it was. Refused while nothing is faulted
    /// or the quick stop is still under way.
    pub fn reset(&mut self) -> Result<DriveFault, ResetRefused> {
        let fault = self.fault.ok_or(ResetRefused::NoFault)?;
        if self.goal != Goal::Disabled {
            return Err(ResetRefused::Stopping(fault));
        }
        if let Some((node, input)) = self.estop_open() {
            return Err(ResetRefused::EStopOpen { node, input });
        }
        self.fault = None;
        self.resetting = Some(self.cycles().saturating_add(RESET_CYCLES));
        Ok(fault)
    }

    /// A reset is under way and its drives still have time to leave Fault.
    pub(super) fn reset_pending(&self) -> bool {
        self.resetting.is_some_and(|by| self.cycles() <= by)
    }

    /// The reset is over once no drive is in Fault (or its time ran out: supervision then
    /// raises the drive that stayed there).
    pub(super) fn reset_progress(&mut self) {
        let faulted = self
            .nodes
            .iter()
            .any(|n| matches!(n.state, Some(State::Fault | State::FaultReactionActive)));
        if !faulted || !self.reset_pending() {
            self.resetting = None;
        }
    }
}
