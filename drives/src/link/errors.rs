//! What the CAN controller says about the bus: SocketCAN error frames, counted by kind
//! ([`BusErrors`]), and the fault injection of the in-memory link ([`LinkFaults`]).
//!
//! A SocketCAN socket receives error frames only for the classes in its error mask
//! (`CAN_RAW_ERR_FILTER`); [`super::SocketLink::open`] asks for [`ERR_MASK`]. An error frame
//! has `CAN_ERR_FLAG` in its id, the error classes in the id's low bits and the details in
//! its eight data bytes (linux/can/error.h). Nothing here allocates or blocks.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

/// The error-frame flag in `can_id`.
pub const CAN_ERR_FLAG: u32 = 0x2000_0000;
/// Error classes in an error frame's id.
pub const ERR_TX_TIMEOUT: u32 = 0x001;
pub const ERR_LOSTARB: u32 = 0x002;
pub const ERR_CRTL: u32 = 0x004;
pub const ERR_PROT: u32 = 0x008;
pub const ERR_TRX: u32 = 0x010;
pub const ERR_ACK: u32 = 0x020;
pub const ERR_BUSOFF: u32 = 0x040;
pub const ERR_BUSERROR: u32 = 0x080;
pub const ERR_RESTARTED: u32 = 0x100;
/// The classes the link asks the kernel for: every class above.
pub const ERR_MASK: u32 = 0x1FF;
/// Controller status in `data[1]` of a [`ERR_CRTL`] frame.
pub const CRTL_RX_OVERFLOW: u8 = 0x01;
pub const CRTL_TX_OVERFLOW: u8 = 0x02;
pub const CRTL_RX_WARNING: u8 = 0x04;
pub const CRTL_TX_WARNING: u8 = 0x08;
pub const CRTL_RX_PASSIVE: u8 = 0x10;
pub const CRTL_TX_PASSIVE: u8 = 0x20;

/// Error frames received since the link was opened, by kind. A frame may count under
/// several kinds (its id carries several classes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BusErrors {
    /// The controller reached the warning level of its error counters (96).
    pub warning: u32,
    /// The controller went error passive (a counter at 128 or more).
    pub passive: u32,
    /// The controller went bus-off (transmit errors at 256): it has left the bus.
    pub bus_off: u32,
    /// The controller was restarted (after a bus-off).
    pub restarted: u32,
    /// A frame was not sent in time (reported by the driver).
    pub tx_timeout: u32,
    /// A frame lost arbitration (another node sent at the same time with a lower id).
    pub lost_arbitration: u32,
    /// Protocol violations, bus errors, transceiver problems, no acknowledgement.
    pub protocol: u32,
    /// The controller's receive or transmit buffer overflowed.
    pub overflow: u32,
}

/// The kinds in [`BusErrors`], in its field order, for counting one field at a time.
const KINDS: usize = 8;

impl BusErrors {
    /// Count the error frame with this id and data; ignores a frame without `CAN_ERR_FLAG`.
    pub fn record(&mut self, can_id: u32, data: &[u8; 8]) {
        let mut c = self.to_array();
        for (slot, n) in c.iter_mut().zip(classify(can_id, data)) {
            *slot = slot.saturating_add(n);
        }
        *self = BusErrors::from_array(c);
    }

    /// What happened between `earlier` and `self` (counts that only grow).
    pub fn since(&self, earlier: &BusErrors) -> BusErrors {
        let (a, b) = (self.to_array(), earlier.to_array());
        BusErrors::from_array(core::array::from_fn(|i| a[i].saturating_sub(b[i])))
    }

    /// Every error frame counted, whatever its kind.
    pub fn total(&self) -> u64 {
        self.to_array().iter().map(|&n| u64::from(n)).sum()
    }

    /// The counts with their names, for reports: `("bus-off", 1)`.
    pub fn named(&self) -> [(&'static str, u32); KINDS] {
        let c = self.to_array();
        core::array::from_fn(|i| (NAMES[i], c[i]))
    }

    fn to_array(self) -> [u32; KINDS] {
        [
            self.warning,
            self.passive,
            self.bus_off,
            self.restarted,
            self.tx_timeout,
            self.lost_arbitration,
            self.protocol,
            self.overflow,
        ]
    }

    fn from_array(c: [u32; KINDS]) -> BusErrors {
        BusErrors {
            warning: c[0],
            passive: c[1],
            bus_off: c[2],
            restarted: c[3],
            tx_timeout: c[4],
            lost_arbitration: c[5],
            protocol: c[6],
            overflow: c[7],
        }
    }
}

const NAMES: [&str; KINDS] = [
    "error warning",
    "error passive",
    "bus-off",
    "controller restarted",
    "TX timeout",
    "lost arbitration",
    "protocol or bus error",
    "controller overflow",
];

/// One error frame's counts, in [`BusErrors`]' field order.
fn classify(can_id: u32, data: &[u8; 8]) -> [u32; KINDS] {
    let mut c = [0; KINDS];
    if can_id & CAN_ERR_FLAG == 0 {
        return c;
    }
    let class = can_id & ERR_MASK;
    let has = |bit: u32| u32::from(class & bit != 0);
    if class & ERR_CRTL != 0 {
        let crtl = data[1];
        c[0] = u32::from(crtl & (CRTL_RX_WARNING | CRTL_TX_WARNING) != 0);
        c[1] = u32::from(crtl & (CRTL_RX_PASSIVE | CRTL_TX_PASSIVE) != 0);
        c[7] = u32::from(crtl & (CRTL_RX_OVERFLOW | CRTL_TX_OVERFLOW) != 0);
    }
    c[2] = has(ERR_BUSOFF);
    c[3] = has(ERR_RESTARTED);
    c[4] = has(ERR_TX_TIMEOUT);
    c[5] = has(ERR_LOSTARB);
    c[6] = u32::from(class & (ERR_PROT | ERR_BUSERROR | ERR_TRX | ERR_ACK) != 0);
    c
}

/// Faults injected into a [`super::MemLink`] from another thread, as a real interface would
/// meet them: error frames, the interface going down (`ENETDOWN`), a full transmit queue
/// (`ENOBUFS`). Shared by both ends of a pair; lock-free.
#[derive(Debug, Default)]
pub struct LinkFaults {
    errors: [AtomicU32; KINDS],
    down: AtomicBool,
    tx_full: AtomicBool,
}

impl LinkFaults {
    /// Deliver an error frame (id with `CAN_ERR_FLAG`, data as the kernel fills it).
    pub fn error_frame(&self, can_id: u32, data: [u8; 8]) {
        for (slot, n) in self.errors.iter().zip(classify(can_id, &data)) {
            slot.fetch_add(n, Ordering::Relaxed);
        }
    }

    /// The interface goes down (`true`) or comes back up.
    pub fn set_down(&self, down: bool) {
        self.down.store(down, Ordering::Relaxed);
    }

    /// Every frame the pair's first end (the master's) sends is dropped, as with a full
    /// transmit queue (`true`), or none.
    pub fn set_tx_full(&self, full: bool) {
        self.tx_full.store(full, Ordering::Relaxed);
    }

    pub(super) fn errors(&self) -> BusErrors {
        BusErrors::from_array(core::array::from_fn(|i| {
            self.errors[i].load(Ordering::Relaxed)
        }))
    }

    pub(super) fn down(&self) -> bool {
        self.down.load(Ordering::Relaxed)
    }

    pub(super) fn tx_full(&self) -> bool {
        self.tx_full.load(Ordering::Relaxed)
    }
}
