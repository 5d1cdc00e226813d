//! Segments: the parsed blocks turned into geometry that can be evaluated at a path position.
//!
//! Each motion block becomes one [`Segment`] measured by its own path length `s`:
//! * a NURBS block by the arc length of its cutter curve (with an [`ArcTable`]);
//! * a `G00`/`G01` by its straight length in mm. A move that turns the tool without moving the
//!   cutter centre ("rotary only") is measured in degrees of tool rotation instead, and its
//!   feed is read as degrees per minute, as CNC controls conventionally do.
//!
//! The builder checks what needs the geometry (the parser checked the syntax and the nets):
//! the orientation curve stays away from the cutter curve along the whole block, the tool
//! axis at a block's start equals the current one (a difference would be a jump of the
//! rotary axes), and angle words suit the machine's tilt axis.

use crate::arclen::ArcTable;
use crate::kinematics::{Joints, Kinematics, MachineKinematics, RotaryLimits};
use crate::nurbs::DoubleNurbs;
use crate::program::{Aux, InputWait, Program, SrcPos, Wait, MAX_INPUT_WAITS};
use nalgebra::Vector3;

mod builder;
mod curve;
mod straight;
mod vertical;

pub use builder::Builder;
pub use vertical::follow;

/// Smallest allowed |CT(u) - C(u)| along a G06.5 block, mm.
pub const MIN_TOOL_VECTOR_MM: f64 = 1e-3;
/// Largest allowed difference between the tool axis a block starts with and the current one.
pub const MAX_ORIENTATION_STEP_DEG: f64 = 0.01;
/// Moves shorter than this (mm, and degrees for the tool) are no motion at all.
const NULL_MOVE: f64 = 1e-9;
/// Shortest NURBS block, mm: below it the arc-length parametrisation is meaningless.
pub const NULL_MOVE_MM: f64 = 1e-6;

/// How a segment's tool orientation varies.
#[derive(Clone, Debug, PartialEq)]
pub enum Tooling {
    /// Rotary angles (radians) interpolated linearly in path length (`G01 A_ C_`, and an
    /// arc with angle words, each of its segments over its share of the arc).
    Angles { from: (f64, f64), to: (f64, f64) },
    /// Unit tool axis along the great circle (`G01 I_ J_ K_`), `angle` between the ends.
    Slerp {
        from: Vector3<f64>,
        to: Vector3<f64>,
        angle: f64,
    },
    /// Constant tool axis (G06.2 and moves that keep the orientation).
    Fixed(Vector3<f64>),
    /// The block's own orientation curve (G06.5).
    Curve,
}

/// Where the segment's cutter point comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    Line {
        from: Vector3<f64>,
        to: Vector3<f64>,
    },
    Nurbs {
        curve: Box<DoubleNurbs>,
        table: Box<ArcTable>,
    },
}

/// The tool orientation at a point: a unit vector in the workpiece frame, or machine angles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tool {
    Axis(Vector3<f64>),
    Angles(f64, f64),
}

/// A point of the path: cutter centre, tool, and the curve parameter for NURBS segments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub p: Vector3<f64>,
    pub tool: Tool,
    pub u: Option<f64>,
    /// Tool length carried by the machine's Z axis here, mm (`G43`/`G43.4`).
    pub z: f64,
}

impl Pose {
    /// Machine joints for this pose; `prev` picks the rotary solution.
    pub fn joints(&self, kin: &MachineKinematics, prev: &Joints, lim: &RotaryLimits) -> Joints {
        match self.tool {
            Tool::Axis(t) => {
                let mut j = kin.inverse(&self.p, &t, prev, lim);
                j[2] += self.z;
                j
            }
            Tool::Angles(a, c) => {
                let m = kin.place(&self.p, a, c);
                [m.x, m.y, m.z + self.z, a, c]
            }
        }
    }

    /// The unit tool axis in the workpiece frame.
    pub fn axis(&self, kin: &MachineKinematics) -> Vector3<f64> {
        match self.tool {
            Tool::Axis(t) => t,
            Tool::Angles(a, c) => kin.tool_axis(a, c),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    /// 1-based index of the NC block in the program (block 1 is the start pose).
    pub block: u32,
    pub src: SrcPos,
    /// Path length: mm, or degrees of tool rotation when `rotary_only`.
    pub length: f64,
    /// Programmed feed in path units per second.
    pub feed: f64,
    pub rapid: bool,
    pub rotary_only: bool,
    /// The path comes to rest where this segment starts: a kink of the cutter's tangent
    /// inside a NURBS block (a knot of multiplicity = degree, see `crate::split`), or a
    /// [`Wait`] before it.
    pub stop: bool,
    /// What happens at rest before the segment starts (`G04`, `M00`, `M01`, `M06`).
    pub wait: Wait,
    /// `M66` waits for digital inputs before the segment, in their order (the builder sets
    /// them from the program's actions, on the first segment after them).
    pub inputs: [Option<InputWait>; MAX_INPUT_WAITS],
    /// Tool length on the machine's Z axis at the start and end, mm; it changes linearly
    /// along a straight move (`G43 Z.. H..`) and stays constant along a curve.
    pub z: (f64, f64),
    /// Spindle and coolant commanded along the segment (the program's words before it).
    pub aux: Aux,
    pub geometry: Geometry,
    pub tooling: Tooling,
}

impl Segment {
    /// Pose at path position `s` in [0, length] (clamped). Allocation-free.
    /// The path stops at rest before the segment and waits there (dwell, operator,
    /// spindle, inputs).
    pub fn waits(&self) -> bool {
        self.wait.is_some() || self.inputs[0].is_some()
    }

    pub fn pose(&self, s: f64) -> Pose {
        let s = s.clamp(0.0, self.length);
        let f = if self.length > 0.0 {
            s / self.length
        } else {
            1.0
        };
        match &self.geometry {
            Geometry::Line { from, to } => Pose {
                p: from + (to - from) * f,
                tool: self.tool_at(f, None),
                u: None,
                z: self.z.0 + (self.z.1 - self.z.0) * f,
            },
            Geometry::Nurbs { curve, table } => self.pose_at(curve, table.u_of_s(curve, s), || f),
        }
    }

    /// Pose of a NURBS segment at curve parameter `u` (for the Taylor methods).
    pub fn pose_u(&self, curve: &DoubleNurbs, table: &ArcTable, u: f64) -> Pose {
        self.pose_at(curve, u, || {
            if self.length > 0.0 {
                (table.s_of_u(curve, u) / self.length).clamp(0.0, 1.0)
            } else {
                1.0
            }
        })
    }

    /// Pose at `u`; `fraction` gives the fraction of the segment's length there, needed
    /// only by an arc that turns the tool ([`Tooling::Angles`]).
    fn pose_at(&self, curve: &DoubleNurbs, u: f64, fraction: impl FnOnce() -> f64) -> Pose {
        let (c, d) = curve.cutter_and_tool(u, 0);
        let tool = match self.tooling {
            Tooling::Curve => self.tool_at(0.0, Some(d.p.normalize())),
            Tooling::Angles { .. } => self.tool_at(fraction(), None),
            _ => self.tool_at(0.0, None),
        };
        Pose {
            p: c.p,
            tool,
            u: Some(u),
            z: self.z.0,
        }
    }

    fn tool_at(&self, f: f64, curve_axis: Option<Vector3<f64>>) -> Tool {
        match &self.tooling {
            Tooling::Angles { from, to } => {
                Tool::Angles(from.0 + (to.0 - from.0) * f, from.1 + (to.1 - from.1) * f)
            }
            Tooling::Slerp { from, to, angle } => {
                if *angle < NULL_MOVE {
                    return Tool::Axis(*to);
                }
                let sa = angle.sin();
                Tool::Axis(from * (((1.0 - f) * angle).sin() / sa) + to * ((f * angle).sin() / sa))
            }
            Tooling::Fixed(t) => Tool::Axis(*t),
            Tooling::Curve => Tool::Axis(curve_axis.unwrap_or_else(Vector3::z)),
        }
    }

    pub fn nurbs(&self) -> Option<(&DoubleNurbs, &ArcTable)> {
        match &self.geometry {
            Geometry::Nurbs { curve, table } => Some((curve, table)),
            Geometry::Line { .. } => None,
        }
    }
}

/// A geometric rule the parser could not check.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BuildErrorKind {
    #[error("the program has no move: dnurbs plans and runs programs that move the machine, not one of only words without motion")]
    NoStart,
    #[error("the first block must be a G00/G01 start pose, not a NURBS block")]
    NurbsFirst,
    #[error("{word} angle words on a machine whose tilting axis is {machine}: the program is for another machine")]
    WrongTilt { word: char, machine: char },
    #[error("the orientation curve comes within {dist:.3e} mm of the cutter curve at u = {u:.6} (minimum {MIN_TOOL_VECTOR_MM} mm): the tool axis is undefined there")]
    ToolVectorTooShort { u: f64, dist: f64 },
    #[error("the tool axis at the start of the block differs from the current tool axis by {deg:.4} deg (at most {MAX_ORIENTATION_STEP_DEG} deg): the rotary axes would jump")]
    OrientationJump { deg: f64 },
    #[error("the tool axis turns by 180 degrees in one linear move: the great circle between opposite axes is undefined")]
    OppositeAxes,
    #[error("the cutter curve has length {0:.3e} mm: a NURBS block must move the cutter at least {NULL_MOVE_MM} mm")]
    ZeroLength(f64),
    #[error("{0}")]
    Curve(#[from] crate::nurbs::CurveError),
    #[error("G43.4 (tool-centre-point control) on a machine without RTCP kinematics: the paper machine places X Y Z as machine coordinates; use G43")]
    RtcpUnsupported,
    #[error("the rotary axes stand at tilt {tilt_deg:.4} deg, C {c_deg:.4} deg under G43 without tool-centre-point control: the post wrote X Y Z for another machine reading; program G43.4 for moves with the table tilted or turned")]
    RotaryWithoutRtcp { tilt_deg: f64, c_deg: f64 },
    #[error("the tool length changes from {from} to {to} mm at a curve: change it on a straight move before")]
    LengthChangeOnCurve { from: f64, to: f64 },
    #[error("more than {MAX_INPUT_WAITS} M66 waits between two moves: put a move between them")]
    TooManyInputWaits,
}

/// A [`BuildErrorKind`] at the position of the block that broke it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{pos}: {kind}")]
pub struct BuildError {
    pub pos: SrcPos,
    pub kind: BuildErrorKind,
}

/// Feeds for the segment builder, from the machine file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildLimits {
    pub rapid_mm_s: f64,
    pub max_feed_mm_s: f64,
    pub rotary: RotaryLimits,
}

impl BuildLimits {
    /// The highest feed any segment carries: the higher of the rapid and the top feed (a
    /// move that only turns the tool takes it in degrees a second). No plan is faster, so a
    /// program streamed to the real-time thread is bounded by it before it is planned.
    pub fn speed_cap(&self) -> f64 {
        self.rapid_mm_s.max(self.max_feed_mm_s)
    }
}

/// The start pose and the segments of a program.
#[derive(Clone, Debug, PartialEq)]
pub struct Path {
    pub start: Pose,
    /// Where the start pose was programmed.
    pub start_src: SrcPos,
    pub start_joints: Joints,
    pub segments: Vec<Segment>,
}

/// Turn a parsed program into segments for the given machine.
pub fn build(
    program: &Program,
    kin: &MachineKinematics,
    limits: &BuildLimits,
) -> Result<Path, BuildError> {
    let mut builder = Builder::new(kin, limits);
    builder.tilt_word(program.tilt_word)?;
    let mut segments = Vec::with_capacity(program.blocks.len());
    let mut actions = program.actions.iter().peekable();
    for (i, block) in program.blocks.iter().enumerate() {
        while let Some(a) = actions.next_if(|a| a.before_block <= i) {
            builder.action(a);
        }
        builder.block(i, block, &mut segments)?;
    }
    let (start, start_src, start_joints) = builder.start()?;
    Ok(Path {
        start,
        start_src,
        start_joints,
        segments,
    })
}
