//! A `G06.2`/`G06.5` block as segments: the curve cut into pieces of known size, each
//! with its arc-length table, checked for an orientation curve clear of the cutter curve.

use super::{
    BuildError, BuildErrorKind, BuildLimits, Geometry, Pose, Segment, Tooling,
    MAX_ORIENTATION_STEP_DEG, MIN_TOOL_VECTOR_MM, NULL_MOVE, NULL_MOVE_MM,
};
use crate::arclen::ArcTable;
use crate::kinematics::{Joints, MachineKinematics};
use crate::nurbs::DoubleNurbs;
use crate::program::{Aux, NurbsBlock, NurbsKind, Wait, MAX_INPUT_WAITS};

pub(super) fn nurbs(
    block: u32,
    b: &NurbsBlock,
    pose: &Pose,
    joints: &Joints,
    kin: &MachineKinematics,
    limits: &BuildLimits,
) -> Result<Vec<Segment>, BuildError> {
    let err = |kind| BuildError { pos: b.pos, kind };
    let pieces = crate::split::split(
        b.degree as usize,
        &b.ctrl,
        &b.tool_ctrl,
        &b.weights,
        &b.knots,
    )
    .map_err(|e| err(e.into()))?;
    let current = pose.axis(kin);
    let mut out = Vec::with_capacity(pieces.len());
    let mut length = 0.0;
    for (i, piece) in pieces.into_iter().enumerate() {
        let curve = piece.curve;
        let table = ArcTable::new(&curve);
        length += table.length();
        let tooling = match b.kind {
            NurbsKind::G062 => Tooling::Fixed(current),
            NurbsKind::G065 => {
                tool_clear(&curve).map_err(err)?;
                if i == 0 {
                    let (u0, _) = curve.range();
                    let (c, d) = curve.cutter_and_tool(u0, 0);
                    let start = d.p.normalize();
                    let angle = current.cross(&start).norm().atan2(current.dot(&start));
                    if angle.to_degrees() > MAX_ORIENTATION_STEP_DEG {
                        return Err(err(BuildErrorKind::OrientationJump {
                            deg: angle.to_degrees(),
                        }));
                    }
                    // A post prints I J K to a few decimals: the curve's own start axis is a
                    // hair off. Turn the tool there at rest, within the rotary limits,
                    // rather than step the rotary axes in the block's first period (a jerk
                    // no feed can bring within the limit).
                    if angle >= NULL_MOVE {
                        out.push(Segment {
                            block,
                            src: b.pos,
                            length: angle.to_degrees(),
                            // The rotary axes' limits, and the top feed in degrees a second.
                            feed: limits.speed_cap(),
                            rapid: false,
                            rotary_only: true,
                            stop: false,
                            wait: Wait::default(),
                            inputs: [None; MAX_INPUT_WAITS],
                            z: (pose.z, pose.z),
                            aux: Aux::default(),
                            geometry: Geometry::Line { from: c.p, to: c.p },
                            tooling: Tooling::Slerp {
                                from: current,
                                to: start,
                                angle,
                            },
                        });
                    }
                }
                Tooling::Curve
            }
        };
        out.push(Segment {
            block,
            src: b.pos,
            length: table.length(),
            feed: (b.feed_mm_min / 60.0).min(limits.max_feed_mm_s),
            rapid: false,
            rotary_only: false,
            stop: piece.corner,
            wait: Wait::default(),
            inputs: [None; MAX_INPUT_WAITS],
            z: (pose.z, pose.z),
            aux: Aux::default(),
            geometry: Geometry::Nurbs {
                curve: Box::new(curve),
                table: Box::new(table),
            },
            tooling,
        });
    }
    // The length of the cutter curve (the turn at rest above is in degrees, not counted).
    if length.is_nan() || length < NULL_MOVE_MM {
        return Err(err(BuildErrorKind::ZeroLength(length)));
    }
    // A piece too short to parametrise by arc length (a sliver between two kinks) is no
    // motion: leave it out, the pieces on both sides meet at its (sub-micrometre) ends.
    let keep = |s: &Segment| s.rotary_only || s.length >= NULL_MOVE_MM;
    if !out.iter().all(keep) {
        let mut stop = false;
        out.retain_mut(|s| {
            if keep(s) {
                s.stop |= std::mem::take(&mut stop);
                true
            } else {
                stop = true;
                false
            }
        });
    }
    if let Some((r1, r2)) = b.turn_to {
        turn_along(
            &mut out,
            (joints[3], joints[4]),
            (r1.to_radians(), r2.to_radians()),
        );
    }
    Ok(out)
}

/// An arc that turns the tool: its rotary angles go from `from` to `to` linearly in the
/// arc's length, each segment over its own share, so they are continuous at every joint.
pub(super) fn turn_along(segments: &mut [Segment], from: (f64, f64), to: (f64, f64)) {
    let total: f64 = segments.iter().map(|s| s.length).sum();
    let at = |f: f64| (from.0 + (to.0 - from.0) * f, from.1 + (to.1 - from.1) * f);
    let mut done = 0.0;
    for s in segments.iter_mut() {
        let f0 = done / total;
        done += s.length;
        let f1 = if done >= total { 1.0 } else { done / total };
        s.tooling = Tooling::Angles {
            from: at(f0),
            to: at(f1),
        };
    }
}

/// The orientation curve must stay clear of the cutter curve everywhere, not only at the
/// control points the parser saw.
pub(super) fn tool_clear(curve: &DoubleNurbs) -> Result<(), BuildErrorKind> {
    let (u0, u1) = curve.range();
    let n = 2048;
    for i in 0..=n {
        let u = u0 + (u1 - u0) * i as f64 / n as f64;
        let (_, d) = curve.cutter_and_tool(u, 0);
        let dist = d.p.norm();
        if dist.is_nan() || dist < MIN_TOOL_VECTOR_MM {
            return Err(BuildErrorKind::ToolVectorTooShort { u, dist });
        }
    }
    Ok(())
}
