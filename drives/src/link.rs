//! The one module that touches sockets: a non-blocking CAN link.
//!
//! [`MemLink`] is the in-memory bus of `dnurbs demo` and of tests that need no kernel:
//! two bounded lock-free queues between the threads of one process.
//!
//! [`SocketLink`] wraps a `socketcan::CanSocket`. On a controller it is opened on a SocketCAN
//! interface (`can0`, `vcan0`). For tests on a host without CAN support it is built on one
//! end of an AF_UNIX `SOCK_SEQPACKET` socketpair ([`SocketLink::pair`]): each `can_frame`
//! struct the crate writes arrives whole at the other end, so the same read and write code
//! path runs as on a real bus (filters do not work there; nothing here uses them).
//!
//! Both directions are non-blocking and allocation-free, for the real-time loop:
//! * [`CanLink::send`] reports a full transmit queue (`ENOBUFS` from a CAN driver, `EAGAIN`
//!   from a socketpair) as [`Sent::Dropped`] and counts it: the cycle goes on, the caller
//!   decides what a lost frame means.
//! * [`CanLink::recv`] returns `None` when nothing is waiting. Remote frames are counted and
//!   skipped, error frames counted by kind in [`BusErrors`] ([`CanLink::errors`]; at most
//!   [`MAX_SKIPPED`] per call, so the loop is bounded).
//! * An interface that is down (`ENETDOWN`, `ENODEV`) is [`LinkError::Down`].
//! * [`CanLink::send_all`] and [`CanLink::recv_all`] move a cycle's frames in batches. On a
//!   [`SocketLink`] each is one `sendmmsg`/`recvmmsg` system call instead of one call per
//!   frame (the master sends 5 RPDOs and a SYNC and reads as many frames per period); these
//!   two wrappers (`mmsg.rs`) are the crate's only `unsafe` code.
//!
//! Files: this one (the trait and its types), `mem.rs` ([`MemLink`]), `socket.rs`
//! ([`SocketLink`]), `mmsg.rs` (the raw `can_frame` and the two system calls), `errors.rs`
//! (error frames by kind, and the in-memory link's fault injection).

pub mod errors;
mod mem;
mod mmsg;
mod socket;

pub use errors::{BusErrors, LinkFaults, CAN_ERR_FLAG, ERR_MASK};
pub use mem::MemLink;
pub use socket::SocketLink;

use crate::frame::CanFrame;
use std::io::{self, ErrorKind};

/// Most non-data frames skipped in one `recv` call before it returns `None`.
pub const MAX_SKIPPED: usize = 64;
/// Frames per `sendmmsg` / `recvmmsg` call of [`SocketLink`].
pub const BATCH: usize = 32;

/// What happened to a frame handed to [`CanLink::send`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sent {
    Queued,
    /// The transmit queue was full; the frame was not sent (counted).
    Dropped,
}

/// A socket failure other than a full queue or an empty receive buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LinkError {
    #[error("CAN socket error (errno {0})")]
    Os(i32),
    /// The interface is down or gone (`ENETDOWN`, `ENODEV`): nothing reaches the bus.
    #[error("CAN interface down ({})", if *.0 == nix::libc::ENODEV { "ENODEV" } else { "ENETDOWN" })]
    Down(i32),
    #[error("CAN link closed by the other end")]
    Closed,
}

impl LinkError {
    fn from_errno(e: i32) -> LinkError {
        match e {
            nix::libc::EPIPE | nix::libc::ECONNRESET => LinkError::Closed,
            nix::libc::ENETDOWN | nix::libc::ENODEV => LinkError::Down(e),
            _ => LinkError::Os(e),
        }
    }

    pub(crate) fn from_io(e: &io::Error) -> LinkError {
        match e.kind() {
            ErrorKind::UnexpectedEof | ErrorKind::BrokenPipe | ErrorKind::ConnectionReset => {
                LinkError::Closed
            }
            _ => LinkError::from_errno(e.raw_os_error().unwrap_or(0)),
        }
    }
}

/// A CAN bus as the master and the simulated drives see it.
pub trait CanLink {
    /// Queue one frame for transmission without blocking.
    fn send(&mut self, frame: &CanFrame) -> Result<Sent, LinkError>;
    /// The next received data frame, or `None` if none is waiting. Never blocks.
    fn recv(&mut self) -> Result<Option<CanFrame>, LinkError>;

    /// The error frames received so far, by kind (none on a link that has no controller).
    fn errors(&self) -> BusErrors {
        BusErrors::default()
    }

    /// Queue `frames` in order without blocking; returns how many were dropped (full queue).
    /// A link may batch them into fewer system calls; the default sends one by one.
    fn send_all(&mut self, frames: &[CanFrame]) -> Result<usize, LinkError> {
        let mut dropped = 0;
        for f in frames {
            if self.send(f)? == Sent::Dropped {
                dropped += 1;
            }
        }
        Ok(dropped)
    }

    /// Fill `out` with waiting data frames, in order; returns how many. Never blocks; 0 when
    /// none is waiting. The default receives one by one.
    fn recv_all(&mut self, out: &mut [CanFrame]) -> Result<usize, LinkError> {
        let mut n = 0;
        for slot in out.iter_mut() {
            match self.recv()? {
                Some(f) => *slot = f,
                None => break,
            }
            n += 1;
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests;
