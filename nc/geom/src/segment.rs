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
use crate::kinematics::{Joints, Kinematics, MachineKinematics, RotaryLimits, VERTICAL_RHO};
use crate::nurbs::DoubleNurbs;
use crate::program::{Aux, LinearMove, NurbsBlock, NurbsKind, Orientation, Program, SrcPos, Wait};
use nalgebra::Vector3;

mod builder;
pub use builder::Builder;

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
    #[error("the program has no motion block: the first block must be G00/G01 with X Y Z (the start pose)")]
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

/// Two waits in a row: the dwells add up, the first operator stop counts.
fn merge(a: Wait, b: Wait) -> Wait {
    Wait {
        dwell_s: a.dwell_s + b.dwell_s,
        operator: a.operator.or(b.operator),
        spindle: a.spindle || b.spindle,
    }
}

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
fn turn_c(seg: &Segment, joints: &Joints, c: f64, limits: &BuildLimits) -> Segment {
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
fn near_vertical(t: &Vector3<f64>) -> bool {
    t.x.hypot(t.y) < VERTICAL_TOL
}

/// Below this |(Tx, Ty)| a segment's end counts as a vertical tool for the C look-ahead.
const VERTICAL_TOL: f64 = 1e-9;

/// The C a segment needs where it leaves the vertical, if it starts vertical and leaves it.
fn c_leaving_vertical(
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
enum End {
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
fn vertical_edge(seg: &Segment, kin: &MachineKinematics, end: End) -> Option<Pose> {
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

fn linear_tool(m: &LinearMove) -> Tool {
    match m.orientation {
        Orientation::Vector(v) => Tool::Axis(Vector3::from(v).normalize()),
        Orientation::Angles { r1_deg, r2_deg } => {
            Tool::Angles(r1_deg.to_radians(), r2_deg.to_radians())
        }
    }
}

fn linear(
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
        z: (pose.z, m.tooling.tool_length),
        aux: Aux::default(),
        geometry: Geometry::Line { from, to },
        tooling,
    }))
}

fn nurbs(
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
fn turn_along(segments: &mut [Segment], from: (f64, f64), to: (f64, f64)) {
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
fn tool_clear(curve: &DoubleNurbs) -> Result<(), BuildErrorKind> {
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
