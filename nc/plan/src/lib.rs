//! The feed planner: from segments to a feed plan every axis can follow, and from the plan
//! to the chunks the real-time follower takes.
//!
//! ```text
//! blocks --nc_geom::segment--> Path --plan::Planner--> FeedProfile (checked at the period)
//!                                          \--stream::Cutter--> nc_follow::Chunk --> queue
//! ```
//!
//! * [`config`]: what the planner plans for (period, tolerances, every axis's limits);
//!   [`profile`]: the planned feed s(t).
//! * [`interp`]: the offline interpolator, the per-period step over a whole plan (used by
//!   `dnurbs simulate` and by the check); [`verify`] runs it over a plan and measures every
//!   limit on its setpoints by finite differences at the period.
//! * [`plan`]: stations along the path, velocity ceilings, jerk-limited S-curves between
//!   critical points, planned in windows of bounded look-ahead, each checked by [`verify`]
//!   and lowered where a limit is broken.
//! * [`stream`]: the cutter (committed phases and segments into chunks) and the source that
//!   chains the streaming stages, program lines in, chunks out; [`rolling`] is the same
//!   chain ending in the offline interpolator (`dnurbs simulate` of a program of any length).
//! * [`prepass`]: a whole program read through the language and the segment builder in
//!   bounded memory (`dnurbs check`).
//!
//! Nothing here runs in the real-time thread; `nc_follow` does, and does not depend on
//! this crate.
#![forbid(unsafe_code)]

pub mod config;
#[cfg(any(test, feature = "fixtures"))]
pub mod fixtures;
pub mod interp;
pub mod plan;
pub mod prepass;
pub mod profile;
pub mod rolling;
pub mod stream;
pub mod verify;
