//! [`MemLink`]: the in-memory bus between two threads of one process.

use super::{CanLink, LinkError, Sent};
use crate::frame::CanFrame;
use crossbeam_queue::ArrayQueue;
use std::sync::Arc;

/// One end of an in-memory CAN bus between two threads: frames sent at one end are received,
/// in order, at the other. Each direction is a bounded lock-free queue allocated by
/// [`MemLink::pair`]; `send` and `recv` never allocate, lock or make a system call.
/// A full queue drops and counts the frame, like a full socket buffer.
#[derive(Debug)]
pub struct MemLink {
    tx: Arc<ArrayQueue<CanFrame>>,
    rx: Arc<ArrayQueue<CanFrame>>,
    dropped: u64,
}

impl MemLink {
    /// Two connected ends, each direction holding up to `capacity` frames (at least 1).
    pub fn pair(capacity: usize) -> (MemLink, MemLink) {
        let a = Arc::new(ArrayQueue::new(capacity.max(1)));
        let b = Arc::new(ArrayQueue::new(capacity.max(1)));
        let end = |tx: &Arc<_>, rx: &Arc<_>| MemLink {
            tx: Arc::clone(tx),
            rx: Arc::clone(rx),
            dropped: 0,
        };
        (end(&a, &b), end(&b, &a))
    }

    /// Frames not sent because the other end's queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
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
        match self.tx.push(*frame) {
            Ok(()) => Ok(Sent::Queued),
            Err(_) => {
                self.dropped += 1;
                Ok(Sent::Dropped)
            }
        }
    }

    fn recv(&mut self) -> Result<Option<CanFrame>, LinkError> {
        match self.rx.pop() {
            Some(f) => Ok(Some(f)),
            None if self.peer_gone() => Err(LinkError::Closed),
            None => Ok(None),
        }
    }
}
