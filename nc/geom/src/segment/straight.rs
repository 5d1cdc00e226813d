//! A straight move (`G00`/`G01`, and the pieces of an arc) as a segment: its line, its
//! tooling (fixed, interpolated in angle or along the great circle) and its length.

use super::{
    BuildError, BuildErrorKind, BuildLimits, Geometry, Pose, Segment, Tool, Tooling, NULL_MOVE,
};
use crate::kinematics::{Joints, MachineKinematics};
use crate::program::{Aux, LinearMove, Orientation, Wait, MAX_INPUT_WAITS};
use nalgebra::Vector3;

pub(super) fn linear_tool(m: &LinearMove) -> Tool {
    match m.orientation {
        Orientation::Vector(v) => Tool::Axis(Vector3::from(v).normalize()),
        Orientation::Angles { r1_deg, r2_deg } => {
            Tool::Angles(r1_deg.to_radians(), r2_deg.to_radians())
        }
    }
}

pub(super) fn linear(
    block: u32,
    m: &LinearMove,
    pose: &Pose,
    joints: &Joints,
    kin: &MachineKinematics,
    limits: &BuildLimits,
) -> Result<Option<Segment>, BuildError> {
    let from = pose.p;
    let to = Vector3::from(m.end);
    let dist = (to - from).norm();
    let (tooling, turn_deg) = match m.orientation {
        Orientation::Angles { r1_deg, r2_deg } => {
            let a = (joints[3], joints[4]);
            let b = (r1_deg.to_radians(), r2_deg.to_radians());
            let turn = (b.0 - a.0).abs().max((b.1 - a.1).abs()).to_degrees();
            (Tooling::Angles { from: a, to: b }, turn)
        }
        Orientation::Vector(v) => {
            let a = pose.axis(kin);
            let b = Vector3::from(v).normalize();
            let angle = a.cross(&b).norm().atan2(a.dot(&b));
            if angle > core::f64::consts::PI - 1e-6 {
                return Err(BuildError {
                    pos: m.pos,
                    kind: BuildErrorKind::OppositeAxes,
                });
            }
            let tooling = if angle < NULL_MOVE {
                Tooling::Fixed(b)
            } else {
                Tooling::Slerp {
                    from: a,
                    to: b,
                    angle,
                }
            };
            (tooling, angle.to_degrees())
        }
    };
    // A tool-length change (`G43 Z.. H..`) may move the machine's Z alone while the tip
    // stands: then the path is measured by that Z travel.
    let dz = (m.tooling.tool_length - pose.z).abs();
    let still = dist < NULL_MOVE && turn_deg < NULL_MOVE;
    if still && dz < NULL_MOVE {
        return Ok(None);
    }
    let rotary_only = dist < NULL_MOVE && !still;
    let length = if still {
        dz
    } else if rotary_only {
        turn_deg
    } else {
        dist
    };
    let feed = if m.rapid {
        limits.rapid_mm_s
    } else {
        (m.feed_mm_min / 60.0).min(limits.max_feed_mm_s)
    };
    Ok(Some(Segment {
        block,
        src: m.pos,
        length,
        feed,
        rapid: m.rapid,
        rotary_only,
        stop: false,
        wait: Wait::default(),
        inputs: [None; MAX_INPUT_WAITS],
        z: (pose.z, m.tooling.tool_length),
        aux: Aux::default(),
        geometry: Geometry::Line { from, to },
        tooling,
    }))
}
