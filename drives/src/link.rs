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
//! * [`CanLink::recv`] returns `None` when nothing is waiting. Remote and error frames are
//!   counted and skipped (at most [`MAX_SKIPPED`] per call, so the loop is bounded).

use crate::frame::CanFrame;
use crossbeam_queue::ArrayQueue;
use socketcan::{CanSocket, EmbeddedFrame, Id, Socket, StandardId};
use std::io::{self, ErrorKind};
use std::os::fd::OwnedFd;
use std::sync::Arc;

/// Most non-data frames skipped in one `recv` call before it returns `None`.
pub const MAX_SKIPPED: usize = 64;

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
    #[error("CAN link closed by the other end")]
    Closed,
}

impl LinkError {
    fn from_io(e: &io::Error) -> LinkError {
        match e.kind() {
            ErrorKind::UnexpectedEof | ErrorKind::BrokenPipe | ErrorKind::ConnectionReset => {
                LinkError::Closed
            }
            _ => LinkError::Os(e.raw_os_error().unwrap_or(0)),
        }
    }
}

/// A CAN bus as the master and the simulated drives see it.
pub trait CanLink {
    /// Queue one frame for transmission without blocking.
    fn send(&mut self, frame: &CanFrame) -> Result<Sent, LinkError>;
    /// The next received data frame, or `None` if none is waiting. Never blocks.
    fn recv(&mut self) -> Result<Option<CanFrame>, LinkError>;
}

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

/// A non-blocking SocketCAN socket (or one end of an in-process link).
#[derive(Debug)]
pub struct SocketLink {
    sock: CanSocket,
    dropped: u64,
    skipped: u64,
}

impl SocketLink {
    /// Open a SocketCAN interface. Outside the real-time thread.
    pub fn open(interface: &str) -> io::Result<SocketLink> {
        SocketLink::new(CanSocket::open(interface)?)
    }

    /// Two connected ends of an in-process link (AF_UNIX SOCK_SEQPACKET socketpair).
    pub fn pair() -> io::Result<(SocketLink, SocketLink)> {
        use nix::sys::socket::{socketpair, AddressFamily, SockFlag, SockType};
        let (a, b) = socketpair(
            AddressFamily::Unix,
            SockType::SeqPacket,
            None,
            SockFlag::SOCK_CLOEXEC,
        )
        .map_err(io::Error::from)?;
        Ok((SocketLink::from_fd(a)?, SocketLink::from_fd(b)?))
    }

    /// Wrap an already connected socket that carries raw `can_frame` structs.
    pub fn from_fd(fd: OwnedFd) -> io::Result<SocketLink> {
        SocketLink::new(CanSocket::from(fd))
    }

    fn new(sock: CanSocket) -> io::Result<SocketLink> {
        sock.set_nonblocking(true)?;
        Ok(SocketLink {
            sock,
            dropped: 0,
            skipped: 0,
        })
    }

    /// Frames not sent because the transmit queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Remote and error frames received and skipped.
    pub fn skipped(&self) -> u64 {
        self.skipped
    }
}

impl CanLink for SocketLink {
    fn send(&mut self, frame: &CanFrame) -> Result<Sent, LinkError> {
        // Every CanFrame holds an 11-bit id and <= 8 bytes, so both conversions succeed;
        // were they ever to fail, the frame is counted as dropped rather than panicking.
        let Some(out) =
            StandardId::new(frame.id()).and_then(|id| socketcan::CanFrame::new(id, frame.data()))
        else {
            self.dropped += 1;
            return Ok(Sent::Dropped);
        };
        match self.sock.write_frame(&out) {
            Ok(()) => Ok(Sent::Queued),
            Err(e)
                if e.kind() == ErrorKind::WouldBlock
                    || e.raw_os_error() == Some(nix::libc::ENOBUFS) =>
            {
                self.dropped += 1;
                Ok(Sent::Dropped)
            }
            Err(e) => Err(LinkError::from_io(&e)),
        }
    }

    fn recv(&mut self) -> Result<Option<CanFrame>, LinkError> {
        for _ in 0..MAX_SKIPPED {
            match self.sock.read_frame() {
                Ok(socketcan::CanFrame::Data(d)) => {
                    if let Id::Standard(id) = d.id() {
                        if let Some(f) = CanFrame::new(id.as_raw(), d.data()) {
                            return Ok(Some(f));
                        }
                    }
                    self.skipped += 1; // extended identifiers are not CANopen's
                }
                Ok(_) => self.skipped += 1,
                Err(e) if e.kind() == ErrorKind::WouldBlock => return Ok(None),
                Err(e) => return Err(LinkError::from_io(&e)),
            }
        }
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(s: &str) -> CanFrame {
        s.parse().expect("test vector")
    }

    #[test]
    fn frames_cross_the_in_process_link_unchanged() {
        let (mut master, mut drives) = SocketLink::pair().unwrap();
        assert_eq!(drives.recv(), Ok(None));
        for v in [
            "000#0100",
            "080#",
            "605#2B40600006000000",
            "201#0F00A0860100",
            "7FF#0102030405060708",
        ] {
            assert_eq!(master.send(&f(v)), Ok(Sent::Queued));
        }
        for v in [
            "000#0100",
            "080#",
            "605#2B40600006000000",
            "201#0F00A0860100",
            "7FF#0102030405060708",
        ] {
            assert_eq!(drives.recv(), Ok(Some(f(v))));
        }
        assert_eq!(drives.recv(), Ok(None));
        assert_eq!(drives.send(&f("701#05")), Ok(Sent::Queued));
        assert_eq!(master.recv(), Ok(Some(f("701#05"))));
    }

    #[test]
    fn a_full_queue_is_counted_not_fatal() {
        let (mut master, _drives) = SocketLink::pair().unwrap();
        let frame = f("080#");
        let mut sent = 0u64;
        // The socket buffer holds a few hundred frames; the rest are dropped and counted.
        for _ in 0..100_000 {
            if master.send(&frame) == Ok(Sent::Queued) {
                sent += 1;
            }
        }
        assert!(
            sent > 0 && master.dropped() > 0,
            "sent {sent}, dropped {}",
            master.dropped()
        );
        assert_eq!(sent + master.dropped(), 100_000);
    }

    #[test]
    fn the_memory_link_carries_frames_in_order_and_counts_a_full_queue() {
        let (mut master, mut drives) = MemLink::pair(4);
        assert_eq!(drives.recv(), Ok(None));
        let seq = [
            "000#0100",
            "080#",
            "605#2B40600006000000",
            "201#0F00A0860100",
        ];
        for v in seq {
            assert_eq!(master.send(&f(v)), Ok(Sent::Queued));
        }
        assert_eq!(master.send(&f("7FF#01")), Ok(Sent::Dropped));
        assert_eq!(master.dropped(), 1);
        for v in seq {
            assert_eq!(drives.recv(), Ok(Some(f(v))));
        }
        assert_eq!(drives.recv(), Ok(None));
        assert_eq!(drives.send(&f("701#05")), Ok(Sent::Queued));
        assert_eq!(master.recv(), Ok(Some(f("701#05"))));
        // Across threads, every frame arrives once and in order.
        let (mut a, mut b) = MemLink::pair(16);
        let sender = std::thread::spawn(move || {
            for i in 0..10_000u32 {
                let frame = CanFrame::new(0x201, &i.to_le_bytes()).expect("valid frame");
                while a.send(&frame) != Ok(Sent::Queued) {
                    std::thread::yield_now();
                }
            }
            a
        });
        let mut next = 0u32;
        while next < 10_000 {
            match b.recv() {
                Ok(Some(fr)) => {
                    assert_eq!(fr.data(), &next.to_le_bytes());
                    next += 1;
                }
                Ok(None) => std::thread::yield_now(),
                Err(e) => panic!("{e}"),
            }
        }
        sender.join().expect("the sending thread finishes");
    }

    #[test]
    fn a_closed_memory_peer_is_an_error() {
        let (mut master, mut drives) = MemLink::pair(4);
        assert_eq!(drives.send(&f("701#05")), Ok(Sent::Queued));
        drop(drives);
        assert_eq!(master.send(&f("080#")), Err(LinkError::Closed));
        // What was sent before the peer left can still be read, then the link reports it.
        assert_eq!(master.recv(), Ok(Some(f("701#05"))));
        assert_eq!(master.recv(), Err(LinkError::Closed));
    }

    #[test]
    fn a_closed_peer_is_an_error() {
        let (mut master, drives) = SocketLink::pair().unwrap();
        drop(drives);
        assert!(master.recv().is_err() || master.recv() == Ok(None));
        assert!(master.send(&f("080#")).is_err());
    }

    /// Two sockets on the real vcan0 of the PREEMPT_RT guest (tests/vcan/run): the kernel's
    /// loopback hands every frame one socket sends to the other.
    #[test]
    #[ignore = "needs a SocketCAN interface: run by tests/vcan/run in the PREEMPT_RT guest"]
    fn vcan_link_round_trip_on_a_real_interface() {
        let iface = std::env::var("DNURBS_VCAN").unwrap_or_else(|_| "vcan0".into());
        let mut a = SocketLink::open(&iface).expect("open the vcan interface");
        let mut b = SocketLink::open(&iface).expect("open the vcan interface twice");
        let seq = [
            "000#8200",
            "701#00",
            "601#2F60600008000000",
            "581#6060600000000000",
            "080#",
            "201#0F00A0860100",
            "181#3712A0860100",
        ];
        for v in seq {
            assert_eq!(a.send(&f(v)), Ok(Sent::Queued));
        }
        let mut got = Vec::new();
        for _ in 0..1000 {
            if let Ok(Some(fr)) = b.recv() {
                got.push(fr);
                if got.len() == seq.len() {
                    break;
                }
            } else {
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
        }
        assert_eq!(got, seq.map(f));
        // The sender does not receive its own frames (CAN_RAW_RECV_OWN_MSGS is off).
        assert_eq!(a.recv(), Ok(None));
    }
}
