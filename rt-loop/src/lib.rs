//! The real-time side of dnurbs: Linux real-time set-up ([`os`]), preallocated latency
//! histograms ([`stats`]) and the periodic loop ([`latency`]: the loop without interpolation
//! or bus, like cyclictest, to characterise a controller PC before deploying).
//!
//! The interpolating loop that drives the CAN bus (issue 4's `dnurbs run` and `dnurbs demo`)
//! builds on the same pieces.

pub mod interval;
pub mod latency;
pub mod os;
pub mod report;
pub mod stats;
