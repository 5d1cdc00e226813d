//! The real-time side of dnurbs: Linux real-time set-up ([`os`]), preallocated latency
//! histograms ([`stats`]) handed to a reporter without locks ([`interval`]), the loop without
//! work ([`latency`]: like cyclictest, to characterise a controller PC before deploying), and
//! the machine's period ([`pipeline`]: streamed interpolation, drive counts, RPDOs + SYNC),
//! and the operator's commands and status ([`control`]). [`thread::spawn_rt`] starts and sets
//! up the real-time thread for both loops.
//!
//! # What runs in the SCHED_FIFO thread
//!
//! Exactly what the body given to [`thread::spawn_rt`] calls: [`latency::periodic`] for
//! `dnurbs latency`; [`pipeline::drive_loop`] for `run` and `demo`, and through it
//! `Pipeline::{rehearse, prepare, cycle, publish}`, `nc_follow::Follower::{advance,
//! evaluate, rehearse}`, `drives::master::Master::cycle` and the link's `send_all` /
//! `recv_all`, and [`interval::Recorder`]. Each of these says "Real-time thread" in its
//! documentation; none allocates, locks, prints or panics (`tests/no_alloc.rs`,
//! `tests/pipeline_no_alloc.rs` count allocations and page faults over >= 100 000 periods).
//! Everything else (set-up, planner, reporter, control socket) runs in ordinary threads.

pub mod clock;
pub mod control;
pub mod interval;
pub mod latency;
pub mod life;
pub mod os;
pub mod pipeline;
pub mod report;
pub mod stats;
pub mod thread;
pub mod trace;
