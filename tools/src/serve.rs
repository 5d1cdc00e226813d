//! `dnurbs serve`, the long-lived controller (issue 55): its machine states and the rules
//! between them ([`state`]) and the JSON-lines protocol operators and `dnurbs ctl` speak to
//! it ([`protocol`]). The process that owns the bus and the real-time thread and serves
//! them over the control socket is not built yet.

pub mod args;
pub mod hub;
pub mod machine;
pub mod process;
pub mod protocol;
pub mod server;
pub mod state;
pub mod work;

pub use state::{Command, Controller, Event, Refused, State};
