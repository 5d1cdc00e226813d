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
//! * [`CanLink::send_all`] and [`CanLink::recv_all`] move a cycle's frames in batches. On a
//!   [`SocketLink`] each is one `sendmmsg`/`recvmmsg` system call instead of one call per
//!   frame (the master sends 5 RPDOs and a SYNC and reads as many frames per period); these
//!   two wrappers are the crate's only `unsafe` code.

use crate::frame::CanFrame;
use crossbeam_queue::ArrayQueue;
use socketcan::{CanSocket, EmbeddedFrame, Id, Socket, StandardId};
use std::io::{self, ErrorKind};
use std::os::fd::{AsRawFd, OwnedFd, RawFd};
use std::sync::Arc;

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
    #[error("CAN link closed by the other end")]
    Closed,
}

impl LinkError {
    fn from_errno(e: i32) -> LinkError {
        match e {
            nix::libc::EPIPE | nix::libc::ECONNRESET => LinkError::Closed,
            _ => LinkError::Os(e),
        }
    }

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

    /// One `sendmmsg` for the whole batch (a few more only if the queue fills part-way).
    fn send_all(&mut self, frames: &[CanFrame]) -> Result<usize, LinkError> {
        let mut raw = [RawFrame::default(); BATCH];
        let mut dropped = 0;
        for chunk in frames.chunks(BATCH) {
            for (r, f) in raw.iter_mut().zip(chunk) {
                *r = RawFrame::from(f);
            }
            let mut done = 0;
            // Each pass sends at least one frame or drops one: at most chunk.len() passes.
            while done < chunk.len() {
                match sendmmsg(self.sock.as_raw_fd(), &raw[done..chunk.len()]) {
                    Ok(n) => done += n.max(1),
                    Err(e) if e == nix::libc::EAGAIN || e == nix::libc::ENOBUFS => {
                        done += 1;
                        dropped += 1;
                        self.dropped += 1;
                    }
                    Err(e) => return Err(LinkError::from_errno(e)),
                }
            }
        }
        Ok(dropped)
    }

    /// One `recvmmsg` per [`BATCH`] frames; remote, error and extended frames are skipped.
    fn recv_all(&mut self, out: &mut [CanFrame]) -> Result<usize, LinkError> {
        let mut raw = [RawFrame::default(); BATCH];
        let mut n = 0;
        // Bounded: each pass reads up to BATCH frames, at most MAX_SKIPPED of them skipped.
        for _ in 0..out.len() + MAX_SKIPPED {
            let want = (out.len() - n).min(BATCH);
            if want == 0 {
                break;
            }
            let got = match recvmmsg(self.sock.as_raw_fd(), &mut raw[..want]) {
                Ok(0) => break,
                Ok(got) => got,
                Err(e) if e == nix::libc::EAGAIN => break,
                Err(e) => return Err(LinkError::from_errno(e)),
            };
            for r in &raw[..got] {
                match r.to_frame() {
                    Some(f) => {
                        out[n] = f;
                        n += 1;
                    }
                    None => self.skipped += 1,
                }
            }
            if got < want {
                break;
            }
        }
        Ok(n)
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

/// The kernel's `struct can_frame` (linux/can.h): 32-bit id with flags, length, padding,
/// 8 data bytes aligned to 8. SocketCAN and the socketpair both carry exactly this.
#[repr(C, align(8))]
#[derive(Clone, Copy, Default)]
struct RawFrame {
    can_id: u32,
    len: u8,
    pad: u8,
    res0: u8,
    len8_dlc: u8,
    data: [u8; 8],
}

const _: () = assert!(std::mem::size_of::<RawFrame>() == 16);

/// Flags in `can_id`: extended identifier, remote request, error frame.
const CAN_FLAGS: u32 = 0xE000_0000;

impl From<&CanFrame> for RawFrame {
    fn from(f: &CanFrame) -> RawFrame {
        let mut r = RawFrame {
            can_id: u32::from(f.id()),
            len: f.data().len() as u8,
            ..RawFrame::default()
        };
        r.data[..f.data().len()].copy_from_slice(f.data());
        r
    }
}

impl RawFrame {
    /// A standard-identifier data frame, or `None` for anything CANopen does not use.
    fn to_frame(self) -> Option<CanFrame> {
        if self.can_id & CAN_FLAGS != 0 || self.can_id > 0x7FF || self.len > 8 {
            return None;
        }
        CanFrame::new(self.can_id as u16, &self.data[..usize::from(self.len)])
    }
}

/// The headers of one `sendmmsg`/`recvmmsg` call, message i carrying one frame. Once aimed,
/// each header points at its own iovec: built and used in place, never moved.
struct Headers {
    iov: [nix::libc::iovec; BATCH],
    msgs: [nix::libc::mmsghdr; BATCH],
}

impl Headers {
    #[allow(unsafe_code)]
    fn new() -> Headers {
        // SAFETY: all-zero is a valid iovec and mmsghdr (null pointers, zero lengths).
        unsafe { std::mem::zeroed() }
    }

    /// Aim the first messages at the `len` frames from `base`; how many (at most BATCH).
    fn aim(&mut self, base: *mut RawFrame, len: usize) -> usize {
        let n = len.min(BATCH);
        for i in 0..n {
            self.iov[i].iov_base = base.wrapping_add(i).cast();
            self.iov[i].iov_len = std::mem::size_of::<RawFrame>();
            self.msgs[i].msg_hdr.msg_iov = &mut self.iov[i];
            self.msgs[i].msg_hdr.msg_iovlen = 1;
        }
        n
    }
}

/// A system call's count, or its errno.
fn counted(r: nix::libc::c_int) -> Result<usize, i32> {
    usize::try_from(r).map_err(|_| nix::errno::Errno::last_raw())
}

/// `sendmmsg(2)` of `frames`, non-blocking: how many the kernel took, or the errno.
#[allow(unsafe_code)]
fn sendmmsg(fd: RawFd, frames: &[RawFrame]) -> Result<usize, i32> {
    use nix::libc;
    let mut h = Headers::new();
    let n = h.aim(frames.as_ptr().cast_mut(), frames.len());
    // SAFETY: h.msgs[..n] point at n live iovecs, each at one live 16-byte frame that the
    // kernel only reads; all of them outlive the call.
    counted(unsafe { libc::sendmmsg(fd, h.msgs.as_mut_ptr(), n as _, libc::MSG_DONTWAIT as _) })
}

/// `recvmmsg(2)` into `frames`, non-blocking: how many arrived, or the errno.
#[allow(unsafe_code)]
fn recvmmsg(fd: RawFd, frames: &mut [RawFrame]) -> Result<usize, i32> {
    use nix::libc;
    let mut h = Headers::new();
    let n = h.aim(frames.as_mut_ptr(), frames.len());
    // SAFETY: h.msgs[..n] point at n live iovecs, each at one live, exclusively borrowed
    // 16-byte frame; the kernel writes at most iov_len bytes into each.
    let got = counted(unsafe {
        libc::recvmmsg(
            fd,
            h.msgs.as_mut_ptr(),
            n as _,
            libc::MSG_DONTWAIT as _,
            std::ptr::null_mut(),
        )
    })?;
    // A datagram shorter than a can_frame is not one: mark it for skipping.
    for (f, m) in frames.iter_mut().zip(&h.msgs).take(got) {
        if (m.msg_len as usize) < std::mem::size_of::<RawFrame>() {
            f.can_id = CAN_FLAGS;
        }
    }
    Ok(got)
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
    fn batches_cross_the_socketpair_unchanged_and_skip_what_canopen_does_not_use() {
        use nix::sys::socket::{socketpair, AddressFamily, SockFlag, SockType};
        let (a, b) = socketpair(
            AddressFamily::Unix,
            SockType::SeqPacket,
            None,
            SockFlag::SOCK_CLOEXEC,
        )
        .unwrap();
        // One end through socketcan directly, to send what SocketLink never sends.
        let raw = CanSocket::from(a);
        let mut link = SocketLink::from_fd(b).unwrap();
        let mut out = [f("080#"); 8];
        assert_eq!(link.recv_all(&mut out), Ok(0));
        let rtr = socketcan::CanFrame::new_remote(StandardId::new(0x181).unwrap(), 0).unwrap();
        let ext =
            socketcan::CanFrame::new(socketcan::ExtendedId::new(0x1234).unwrap(), &[1]).unwrap();
        let data = |v: &str| {
            let c = f(v);
            socketcan::CanFrame::new(StandardId::new(c.id()).unwrap(), c.data()).unwrap()
        };
        for fr in [
            data("181#3712A0860100"),
            rtr,
            data("701#05"),
            ext,
            data("081#0000"),
        ] {
            raw.write_frame(&fr).unwrap();
        }
        assert_eq!(link.recv_all(&mut out), Ok(3));
        assert_eq!(
            out[..3],
            [f("181#3712A0860100"), f("701#05"), f("081#0000")]
        );
        assert_eq!(link.skipped(), 2);
        // A batch sent in one call arrives whole and in order, and more than BATCH frames
        // are split across calls.
        let batch: Vec<CanFrame> = (0..BATCH as u16 + 7)
            .map(|i| CanFrame::new(0x200 + (i % 16), &i.to_le_bytes()).unwrap())
            .collect();
        assert_eq!(link.send_all(&batch), Ok(0));
        for want in &batch {
            let got = raw.read_frame().unwrap();
            assert_eq!(got.id(), Id::Standard(StandardId::new(want.id()).unwrap()));
            assert_eq!(got.data(), want.data());
        }
    }

    #[test]
    fn a_full_queue_drops_and_counts_the_rest_of_a_batch() {
        let (mut master, mut drives) = SocketLink::pair().unwrap();
        let batch = [f("201#0F00A0860100"); 6];
        let mut queued = 0usize;
        let mut dropped = 0usize;
        for _ in 0..20_000 {
            let d = master.send_all(&batch).unwrap();
            dropped += d;
            queued += batch.len() - d;
        }
        assert!(
            queued > 0 && dropped > 0,
            "queued {queued}, dropped {dropped}"
        );
        assert_eq!(master.dropped() as usize, dropped);
        // Exactly the queued ones arrive.
        let mut out = [f("080#"); 64];
        let mut got = 0;
        loop {
            let n = drives.recv_all(&mut out).unwrap();
            if n == 0 {
                break;
            }
            got += n;
        }
        assert_eq!(got, queued);
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
        // Said at once, both ways (the assertion used to accept "nothing received" too).
        assert_eq!(master.recv(), Err(LinkError::Closed));
        assert_eq!(master.send(&f("080#")), Err(LinkError::Closed));
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
        // The same through the batched calls (sendmmsg / recvmmsg), as the master uses them.
        assert_eq!(a.send_all(&seq.map(f)), Ok(0));
        let mut buf = [f("080#"); 16];
        let mut got = Vec::new();
        for _ in 0..1000 {
            let n = b.recv_all(&mut buf).unwrap();
            got.extend_from_slice(&buf[..n]);
            if got.len() >= seq.len() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        assert_eq!(got, seq.map(f));
        // The sender does not receive its own frames (CAN_RAW_RECV_OWN_MSGS is off).
        assert_eq!(a.recv(), Ok(None));
        assert_eq!(a.recv_all(&mut buf), Ok(0));
    }
}
