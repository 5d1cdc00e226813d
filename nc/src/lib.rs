//! NC core: the NC language, double-NURBS evaluation, feed planning, kinematics and the
//! allocation-free per-period interpolation step.
//!
//! Data flow (the paper's Fig. 6), one module per job:
//!
//! ```text
//! NC text --parse--> Program --segment::build--> Path --plan::plan--> FeedProfile
//!                                                  \                     /
//!                                                   interp::Interpolator::step  (per period)
//!                       profile s(t) -> u(s) (arclen) or Taylor update -> C(u), CT(u) (nurbs)
//!                       -> tool axis -> A/C and machine XYZ (kinematics) -> Setpoint
//! ```
//!
//! `parse::Entries` and `segment::Builder` do the first two steps a line and a block at a
//! time, for a program of any length (`prepass` checks one that way before anything moves).
//!
//! Everything left of `step` runs outside the real-time thread and may allocate; `step`
//! itself allocates nothing (proved by `tests/no_alloc.rs`) and has bounded loops.
#![forbid(unsafe_code)]

pub mod arclen;
pub mod bezier;
pub mod fit;
pub mod fixtures;
pub mod interp;
pub mod kinematics;
pub mod nurbs;
pub mod parse;
pub mod plan;
pub mod prepass;
pub mod program;
pub mod scurve;
pub mod segment;
pub mod split;
pub mod stream;
pub mod verify;
