//! [`MemLink`]: the in-memory bus between two threads of one process.

use super::{BusErrors, CanLink, LinkError, LinkFaults, Sent};
use crate::frame::CanFrame;
use crossbeam_queue::ArrayQueue;
use std::sync::Arc;

/// One end of an in-memory CAN bus between two threads: frames sent at one end are received,
/// in order, at the other. Each direction is a bounded lock-free queue allocated by
/// [`MemLink::pair`]; `send` and `recv` never allocate, lock or make a system call.
/// A full queue drops and counts the frame, like a full socket buffer. Faults a real
/// interface meets can be injected through [`MemLink::faults`].
#[derive(Debug)]
pub struct MemLink {
    tx: Arc<ArrayQueue<CanFrame>>,
    rx: Arc<ArrayQueue<CanFrame>>,
    faults: Arc<LinkFaults>,
    /// The first end [`MemLink::pair`] returns (the master's, by every caller's use).
    first: bool,
    dropped: u64,
}

impl MemLink {
    /// Two connected ends, each direction holding up to `capacity` frames (at least 1).
    pub fn pair(capacity: usize) -> (MemLink, MemLink) {
        let a = Arc::new(ArrayQueue::new(capacity.max(1)));
        let b = Arc::new(ArrayQueue::new(capacity.max(1)));
        let faults = Arc::new(LinkFaults::default());
        let end = |tx: &Arc<_>, rx: &Arc<_>, first| MemLink {
            tx: Arc::clone(tx),
            rx: Arc::clone(rx),
            faults: Arc::clone(&faults),
            first,
            dropped: 0,
        };
        (end(&a, &b, true), end(&b, &a, false))
    }

    /// Frames not sent because the other end's queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// The pair's fault injection: error frames and the interface down, which both ends
    /// see (both are on the one interface), and a full transmit queue, the first end's.
    pub fn faults(&self) -> Arc<LinkFaults> {
        Arc::clone(&self.faults)
    }

    /// The other end has been dropped (each queue is shared by exactly the two ends).
    fn peer_gone(&self) -> bool {
        Arc::strong_count(&self.tx) < 2
    }
}

impl CanLink for MemLink {
    fn send(&mut self, frame: &CanFrame) -> Result<Sent, LinkError> {
        if self.peer_gone() {
            return Err(LinkError::Closed);
        }
        if self.faults.down() {
            return Err(LinkError::Down(nix::libc::ENETDOWN));
        }
        if self.first && self.faults.tx_full() {
            self.dropped += 1;
            return Ok(Sent::Dropped);
        }
        match self.tx.push(*frame) {
            Ok(()) => Ok(Sent::Queued),
            Err(_) => {
                self.dropped += 1;
                Ok(Sent::Dropped)
            }
        }
    }

    fn recv(&mut self) -> Result<Option<CanFrame>, LinkError> {
        if self.faults.down() {
            return Err(LinkError::Down(nix::libc::ENETDOWN));
        }
        match self.rx.pop() {
            Some(f) => Ok(Some(f)),
            None if self.peer_gone() => Err(LinkError::Closed),
            None => Ok(None),
        }
    }

    fn errors(&self) -> BusErrors {
        self.faults.errors()
    }
}
