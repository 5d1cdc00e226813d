//! The e-stop: an input of the bus's I/O module wired to the machine's e-stop chain
//! ([`Master::watch_estop`]), and the operator's command ([`Master::estop`]). Either is a
//! fault of its own kind ([`FaultCause::EStop`]): every drive is sent Quick stop, then
//! Disable voltage once all have stopped, the outputs go off, and the machine stays so
//! until [`Master::reset`], which is refused while the chain is open.
//!
//! The chain is normally closed (the input reads 1); a pressed button or a broken wire
//! opens it, and the input reads 0. It is read from the module's inputs every cycle, as
//! they last arrived (a module that stops answering is a fault of its own).

use super::cyclic::{DriveFault, EStop, FaultCause, Master, NodeKind};
use crate::link::CanLink;
use crate::wire::NodeId;

/// Why an e-stop input cannot be watched.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EStopRefused {
    #[error(
        "node {0} is not an I/O module of this bus: the e-stop chain must be one of its inputs"
    )]
    NotIo(u8),
    #[error("input {0}: the I/O module has inputs 1..=8")]
    Input(u8),
}

impl<L: CanLink> Master<L> {
    /// Watch input `input` (1..=8) of I/O module `node` as the e-stop chain (closed: 1).
    pub fn watch_estop(&mut self, node: NodeId, input: u8) -> Result<(), EStopRefused> {
        if !(1..=8).contains(&input) {
            return Err(EStopRefused::Input(input));
        }
        let i = self
            .nodes
            .iter()
            .position(|n| n.node == node && n.kind == NodeKind::Io)
            .ok_or(EStopRefused::NotIo(node.get()))?;
        self.estop_input = Some((i, input));
        Ok(())
    }

    /// The operator's e-stop: every drive quick-stopped, then disabled.
    ///
    /// Real-time thread.
    pub fn estop(&mut self) {
        // Already faulted, the stop is under way or over (the goal cannot be Enabled while
        // a fault is latched): the first fault stays the one reported.
        self.raise(DriveFault::OPERATOR, FaultCause::EStop(EStop::Requested));
    }

    /// The chain's node and input, if it is open now.
    pub(super) fn estop_open(&self) -> Option<(u8, u8)> {
        let (i, input) = self.estop_input?;
        let n = self.nodes.get(i)?;
        (n.actual & (1 << (input - 1)) == 0).then_some((n.node.get(), input))
    }

    /// Raised when the chain is open.
    pub(super) fn supervise_estop(&mut self) {
        if let Some((node, input)) = self.estop_open() {
            self.raise(node, FaultCause::EStop(EStop::Input { input }));
        }
    }
}
