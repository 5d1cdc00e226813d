//! The CANopen master for one bus: configuration before motion ([`setup`]) and the
//! allocation-free exchange of every cycle ([`cyclic`]).
//!
//! Errors and faults always name the node and the cause (and for SDO the object as
//! `index:sub` and the abort code in words), so that an integrator can act on them.

pub mod cyclic;
pub mod estop;
pub mod health;
mod home;
pub mod homing;
mod reset;
pub mod setup;

pub use cyclic::{
    DriveFault, EStop, FaultCause, Master, NodeKind, NodeStatus, Supervision, MAX_NODES,
};
pub use estop::EStopRefused;
pub use health::{BusCondition, BusHealth, Reaction};
pub use home::HomeRefused;
pub use homing::{HomeRequest, HomingError, HomingState};
pub use reset::{ResetRefused, RESET_CYCLES};
pub use setup::{
    configure, configure_nodes, Clock, NodeSetup, Protections, SetupError, SetupErrorKind,
    SetupOptions, VelocitySetup, WallClock, FOLLOWING_OFF,
};
