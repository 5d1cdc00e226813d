//! CANopen CiA-402 master for the drives of a 5-axis machine, in cyclic synchronous position
//! (CSP) mode over SocketCAN.
//!
//! # Layers
//!
//! ```text
//!  rt-loop (per cycle)             setup (pre-operational)
//!        |                               |
//!  cia402::Sequencer  -- controlword -->  |          pure: state + goal -> controlword
//!        |                               |
//!  wire::{pdo, sync, nmt, sdo, heartbeat, emcy}     pure: values <-> CanFrame
//!        |                               |
//!  frame::CanFrame                                  pure: 11-bit id + 0..=8 bytes, candump text
//!        |
//!  link::SocketLink                                 the only module touching sockets
//! ```
//!
//! - [`frame`]: the CAN frame and its `candump -L` / `cansend` text form, which is also how
//!   test vectors are written.
//! - [`wire`]: one sans-I/O codec per CANopen service ([`wire::classify`] sorts received
//!   frames by COB-ID). Encoders take validated values ([`NodeId`]) and cannot fail;
//!   decoders return a `Copy` [`DecodeError`] for anything malformed.
//! - [`cia402`]: the device-control state machine, the master's [`Sequencer`] and a
//!   drive-side [`DriveModel`] for the simulated drive.
//! - [`od`]: object dictionary indices used by the master.
//! - [`link`]: the non-blocking CAN link: SocketCAN, an in-process socketpair, or memory.
//! - [`sim`]: simulated CiA-402 drives (the slave side of the bus, sans-I/O), for
//!   `dnurbs sim-drives` and for testing the master. Not real-time: it allocates.
//!
//! The worst-case bus load of the cyclic traffic (vcan cannot measure it) is computed where
//! machine files are validated, in `config::bus`.
//!
//! Nothing in these modules allocates (`sim` excepted), blocks, reads a clock or panics on
//! any input; time, when it matters (SDO timeouts, heartbeat supervision), will be passed in by the transport
//! layer. `unsafe` is denied crate-wide; the only exception is in `link`: the two
//! `sendmmsg`/`recvmmsg` wrappers that batch a cycle's frames into one system call each,
//! each with its SAFETY argument.
#![deny(unsafe_code)]

pub mod cia402;
pub mod frame;
pub mod link;
pub mod master;
pub mod od;
pub mod sim;
pub mod wire;

pub use cia402::{Controlword, DriveModel, Goal, Sequencer, State, Statusword};
pub use frame::{CanFrame, ParseFrameError};
pub use wire::{classify, AbortCode, DecodeError, NodeId, Received};
