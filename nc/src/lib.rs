//! NC core: the NC language, double-NURBS evaluation, feed planning, kinematics and the
//! allocation-free per-period interpolation step.
#![forbid(unsafe_code)]

pub mod arclen;
pub mod interp;
pub mod kinematics;
pub mod nurbs;
pub mod plan;
pub mod program;
pub mod scurve;
pub mod segment;
