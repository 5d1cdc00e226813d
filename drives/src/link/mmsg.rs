//! The crate's only `unsafe` code: the kernel's `struct can_frame` and batched
//! `sendmmsg`/`recvmmsg` on a raw socket descriptor.

use super::BATCH;
use crate::frame::CanFrame;
use std::os::fd::RawFd;

/// The kernel's `struct can_frame` (linux/can.h): 32-bit id with flags, length, padding,
/// 8 data bytes aligned to 8. SocketCAN and the socketpair both carry exactly this.
#[repr(C, align(8))]
#[derive(Clone, Copy, Default)]
pub(super) struct RawFrame {
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
    pub(super) fn to_frame(self) -> Option<CanFrame> {
        if self.can_id & CAN_FLAGS != 0 || self.can_id > 0x7FF || self.len > 8 {
            return None;
        }
        CanFrame::new(self.can_id as u16, &self.data[..usize::from(self.len)])
    }

    /// An error frame's id and data, or `None` for any other frame.
    pub(super) fn error(&self) -> Option<(u32, [u8; 8])> {
        (self.can_id & super::CAN_ERR_FLAG != 0).then_some((self.can_id, self.data))
    }

    /// A frame with this raw id and data (tests write error frames with it).
    #[cfg(test)]
    pub(super) fn raw(can_id: u32, data: [u8; 8]) -> RawFrame {
        RawFrame {
            can_id,
            len: 8,
            data,
            ..RawFrame::default()
        }
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
pub(super) fn sendmmsg(fd: RawFd, frames: &[RawFrame]) -> Result<usize, i32> {
    use nix::libc;
    let mut h = Headers::new();
    let n = h.aim(frames.as_ptr().cast_mut(), frames.len());
    // SAFETY: h.msgs[..n] point at n live iovecs, each at one live 16-byte frame that the
    // kernel only reads; all of them outlive the call.
    counted(unsafe { libc::sendmmsg(fd, h.msgs.as_mut_ptr(), n as _, libc::MSG_DONTWAIT as _) })
}

/// `recvmmsg(2)` into `frames`, non-blocking: how many arrived, or the errno.
#[allow(unsafe_code)]
pub(super) fn recvmmsg(fd: RawFd, frames: &mut [RawFrame]) -> Result<usize, i32> {
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
