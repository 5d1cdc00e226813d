//! Where the tool is vertical on an A/C or B/C table, C is free: what C a segment needs
//! where it leaves the vertical, where it arrives at it, and the joints a segment ends with
//! when followed the way the interpolator follows it.

use super::{BuildLimits, Geometry, Pose, Segment, Tooling};
use crate::kinematics::{Joints, Kinematics, MachineKinematics, RotaryLimits, VERTICAL_RHO};
use nalgebra::Vector3;

/// Joints at the end of `seg`, reached from `prev` at its start by following the tool
/// through the segment finely enough (at most 0.25 degree of tool rotation a step) that the
/// rotary branch is the one the interpolator, stepping along the same path, ends on. A
/// segment that ends with the tool vertical ends with C where the interpolator last
/// follows it ([`vertical_edge`]), not where the last step happened to be: a fitted curve
/// still turns about the vertical as it arrives (0.0037 degrees over its last 1/1024 on a
/// generated post, a step the first turn after it took in one period, 1.07x C's
/// acceleration).
pub fn follow(seg: &Segment, kin: &MachineKinematics, prev: &Joints, lim: &RotaryLimits) -> Joints {
    let steps = match &seg.tooling {
        Tooling::Fixed(_) | Tooling::Angles { .. } => 1,
        Tooling::Slerp { angle, .. } => {
            ((angle.to_degrees() * 4.0).ceil() as usize).clamp(16, 4096)
        }
        Tooling::Curve => 1024,
    };
    let mut q = *prev;
    for i in 1..steps {
        q = seg
            .pose(seg.length * i as f64 / steps as f64)
            .joints(kin, &q, lim);
    }
    if let Some(edge) = vertical_edge(seg, kin, End::Last) {
        q = edge.joints(kin, &q, lim);
    }
    seg.pose(seg.length).joints(kin, &q, lim)
}

/// A rotary-only move that turns C from `joints` to `c` at the start of `seg`, at rest,
/// with the tool vertical: planned like any other move under the C axis limits (and no
/// faster than [`BuildLimits::speed_cap`] degrees a second).
pub(super) fn turn_c(seg: &Segment, joints: &Joints, c: f64, limits: &BuildLimits) -> Segment {
    let p = seg.pose(0.0).p;
    Segment {
        block: seg.block,
        src: seg.src,
        length: (c - joints[4]).abs().to_degrees(),
        // Limited by the C axis, and by the top feed in degrees a second.
        feed: limits.speed_cap(),
        rapid: false,
        rotary_only: true,
        stop: seg.stop,
        wait: seg.wait,
        inputs: seg.inputs,
        z: (seg.z.0, seg.z.0),
        aux: seg.aux,
        geometry: Geometry::Line { from: p, to: p },
        tooling: Tooling::Angles {
            from: (joints[3], joints[4]),
            to: (joints[3], c),
        },
    }
}

/// The tool axis is within [`VERTICAL_TOL`] of the vertical: a segment end the C look-ahead
/// treats as vertical (looser than [`is_vertical`](crate::kinematics::is_vertical), where the
/// kinematics leave C as it was).
pub(super) fn near_vertical(t: &Vector3<f64>) -> bool {
    t.x.hypot(t.y) < VERTICAL_TOL
}

/// Below this |(Tx, Ty)| a segment's end counts as a vertical tool for the C look-ahead.
pub(super) const VERTICAL_TOL: f64 = 1e-9;

/// The C a segment needs where it leaves the vertical, if it starts vertical and leaves it.
pub(super) fn c_leaving_vertical(
    seg: &Segment,
    kin: &MachineKinematics,
    prev: &Joints,
    lim: &RotaryLimits,
) -> Option<f64> {
    let t = vertical_edge(seg, kin, End::First)?.axis(kin);
    Some(kin.angles(&t, (prev[3], prev[4]), lim).1)
}

/// An end of a segment.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum End {
    First,
    Last,
}

/// Where a segment that starts (ends) with the tool vertical and turns it (or arrives
/// from a turned tool) crosses the tilt at which the interpolator starts (stops) following
/// C: the tilt reaching [`VERTICAL_RHO`] nearest that end. Below it the interpolator keeps
/// C, above it C follows the tool, so C taken anywhere else is off by what C turns on the
/// way, and the path would step by that much at the segment's end (C turns fast off the
/// vertical when the tool curve's first horizontal derivative is small: 5.6e-5 rad in the
/// long run's seed 7 000 006). None for a segment whose tool does not turn, or whose end is
/// not vertical.
pub(super) fn vertical_edge(seg: &Segment, kin: &MachineKinematics, end: End) -> Option<Pose> {
    if !matches!(seg.tooling, Tooling::Curve | Tooling::Slerp { .. }) {
        return None;
    }
    let at = if end == End::First { 0.0 } else { seg.length };
    if !near_vertical(&seg.pose(at).axis(kin)) {
        return None;
    }
    // Along the curve's own parameter where there is one: a cutter that starts at rest
    // in u (a repeated first control point) makes s a power of u, too fine near 0 for the
    // arc-length table. `x` runs from the end inward.
    let (span, pose): (f64, &dyn Fn(f64) -> Pose) = match &seg.geometry {
        Geometry::Nurbs { curve, table } => {
            let (u0, u1) = (table.u_of_s(curve, 0.0), table.u_of_s(curve, seg.length));
            let from = move |x: f64| if end == End::First { u0 + x } else { u1 - x };
            (u1 - u0, &move |x| seg.pose_u(curve, table, from(x)))
        }
        Geometry::Line { .. } => {
            let from = move |x: f64| if end == End::First { x } else { seg.length - x };
            (seg.length, &move |x| seg.pose(from(x)))
        }
    };
    let tilt = |x: f64| {
        let t = pose(x).axis(kin);
        t.x.hypot(t.y)
    };
    // Walk in from the end in decades until the tool has left the vertical.
    let mut out = span * 1e-9;
    while tilt(out) < VERTICAL_RHO {
        if out >= span {
            return None;
        }
        out = (out * 10.0).min(span);
    }
    // Halve down all the way (a tool can come back near the vertical before it leaves:
    // the crossing nearest the end is the one), then bisect.
    let (mut lo, mut hi) = (0.0, out);
    let mut x = out;
    for _ in 0..1100 {
        x *= 0.5;
        if x == 0.0 {
            break;
        }
        if tilt(x) >= VERTICAL_RHO {
            (lo, hi) = (0.0, x);
        } else if lo == 0.0 {
            lo = x;
        }
    }
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if lo == 0.0 || mid <= lo || mid >= hi {
            break;
        }
        if tilt(mid) >= VERTICAL_RHO {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(pose(hi))
}
