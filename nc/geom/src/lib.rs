//! The geometry of the NC core and the vocabulary its stages share.
//!
//! Below the planner, the real-time follower and the language alike (the paper's Fig. 6
//! reads left to right; this crate is what every arrow carries):
//!
//! * [`program`]: the canonical blocks the language emits (straight moves, double-NURBS
//!   blocks, the spindle, coolant and stops that go with them), with their source positions;
//! * [`nurbs`] evaluates both curves of a block and their derivatives from one basis
//!   evaluation; [`split`] cuts a large block into pieces of known size by knot insertion;
//!   [`bezier`] evaluates a span's Bezier piece; [`arclen`] tabulates and inverts arc length;
//! * [`segment`] turns blocks into segments (geometry, tooling, the arc-length table) and
//!   [`kinematics`] turns a pose into machine axes;
//! * [`scurve`]: jerk-limited phases, what a feed profile is made of;
//! * [`limits`]: axis limits, the reserve a plan leaves for holds, and the margins a plan
//!   reports; [`setpoint`]: what one period produces.
//!
//! Nothing here plans, parses or touches an operating-system resource; everything the
//! real-time thread evaluates (a segment's pose, the arc-length inverse, inverse
//! kinematics, an S-curve phase) allocates nothing.
#![forbid(unsafe_code)]

pub mod arclen;
pub mod bezier;
#[cfg(any(test, feature = "fixtures"))]
pub mod fixtures;
pub mod kinematics;
pub mod limits;
pub mod nurbs;
pub mod program;
pub mod scurve;
pub mod segment;
pub mod setpoint;
pub mod split;
