//! The real-time side of dnurbs: Linux real-time set-up ([`os`]), preallocated latency
//! histograms ([`stats`]) handed to a reporter without locks ([`interval`]), the loop without
//! work ([`latency`]: like cyclictest, to characterise a controller PC before deploying), and
//! the machine's period ([`pipeline`]: streamed interpolation, drive counts, RPDOs + SYNC),
//! and the operator's commands and status ([`control`]).

pub mod control;
pub mod interval;
pub mod latency;
pub mod os;
pub mod pipeline;
pub mod report;
pub mod stats;
