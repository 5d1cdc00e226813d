//! NC core: the NC language, double-NURBS evaluation, feed planning, kinematics and the
//! allocation-free per-period interpolation step.
#![forbid(unsafe_code)]

pub mod parse;
#[expect(
    clippy::large_enum_variant,
    reason = "Block::Nurbs is large on purpose: fixed-capacity, heap-free blocks for the RT queue"
)]
pub mod program;
