//! [`SocketLink`]: a non-blocking SocketCAN socket, or one end of a socketpair.

use super::mmsg::{recvmmsg, sendmmsg, RawFrame};
use super::{BusErrors, CanLink, LinkError, Sent, BATCH, ERR_MASK, MAX_SKIPPED};
use crate::frame::CanFrame;
use socketcan::{CanSocket, EmbeddedFrame, Frame, Id, Socket, SocketOptions, StandardId};
use std::io::{self, ErrorKind};
use std::os::fd::{AsRawFd, OwnedFd};

/// A non-blocking SocketCAN socket (or one end of an in-process link).
#[derive(Debug)]
pub struct SocketLink {
    sock: CanSocket,
    dropped: u64,
    skipped: u64,
    errors: BusErrors,
}

impl SocketLink {
    /// Open a SocketCAN interface, asking for every class of error frame ([`ERR_MASK`]).
    /// Outside the real-time thread.
    pub fn open(interface: &str) -> io::Result<SocketLink> {
        let sock = CanSocket::open(interface)?;
        sock.set_error_filter(ERR_MASK)?;
        SocketLink::new(sock)
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
            errors: BusErrors::default(),
        })
    }

    /// Frames not sent because the transmit queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Remote and extended frames received and skipped (error frames are counted in
    /// [`CanLink::errors`]).
    pub fn skipped(&self) -> u64 {
        self.skipped
    }
}

impl AsRawFd for SocketLink {
    fn as_raw_fd(&self) -> std::os::fd::RawFd {
        self.sock.as_raw_fd()
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
                match (r.to_frame(), r.error()) {
                    (Some(f), _) => {
                        out[n] = f;
                        n += 1;
                    }
                    (None, Some((id, data))) => self.errors.record(id, &data),
                    (None, None) => self.skipped += 1,
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
                Ok(socketcan::CanFrame::Error(e)) => {
                    let mut data = [0; 8];
                    let d = e.data();
                    data[..d.len().min(8)].copy_from_slice(&d[..d.len().min(8)]);
                    self.errors.record(e.id_word(), &data);
                }
                Ok(_) => self.skipped += 1,
                Err(e) if e.kind() == ErrorKind::WouldBlock => return Ok(None),
                Err(e) => return Err(LinkError::from_io(&e)),
            }
        }
        Ok(None)
    }

    fn errors(&self) -> BusErrors {
        self.errors
    }
}
