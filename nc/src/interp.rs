//! The per-period interpolation step: the paper's Fig. 6 data flow for one period.
//!
//! feed profile -> path position -> parameter update -> C(u), CT(u) -> tool axis ->
//! rotary angles -> inverse kinematics -> five machine axis positions.
//!
//! Parameter update methods (`Method`):
//! * `ArcLength` (default): the profile gives the path position s(t) exactly; u(s) comes from
//!   the block's arc-length table with Newton refinement ([`crate::arclen`]). The cutter moves
//!   the commanded distance each period, to within the table's residual.
//! * `Taylor1`, paper eq. 9: `u+ = u + V Ts / |C'|`.
//! * `Taylor2`, paper eq. 10 with the feed-acceleration term. From `du/dt = V / |C'|`,
//!   `d2u/dt2 = a / |C'| - V^2 (C'.C'') / |C'|^4`, so
//!   `u+ = u + V Ts / |C'| + a Ts^2 / (2 |C'|) - (V Ts)^2 (C'.C'') / (2 |C'|^4)`.
//!   V and a are the commanded feed and its rate at the start of the period.
//!
//! The Taylor methods integrate u, so their position drifts from the planned s(t); a block
//! ends when its u reaches the end of the knot range, and the overshoot is carried into the
//! next block as distance. If the profile has come to rest before a Taylor run reaches the end
//! of the program, the last stretch is travelled at the creep speed (one period's worth of
//! path acceleration) so the program still ends exactly at its end point.
//!
//! `step` allocates nothing, takes the time from its own cycle counter, and its loops are
//! bounded by the number of segments and phases.

use crate::kinematics::{Joints, MachineKinematics, RotaryLimits};
use crate::plan::FeedProfile;
use crate::scurve::Motion;
use crate::segment::{Geometry, Path, Pose};
use nalgebra::Vector3;

/// Parameter update method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method {
    #[default]
    ArcLength,
    Taylor1,
    Taylor2,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::ArcLength => "arclength",
            Method::Taylor1 => "taylor1",
            Method::Taylor2 => "taylor2",
        }
    }
}

/// What one period produces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setpoint {
    pub cycle: u64,
    /// Time since the start of the program, s.
    pub t: f64,
    /// 1-based NC block index.
    pub block: u32,
    /// Curve parameter of a NURBS block.
    pub u: Option<f64>,
    /// Cutter centre, workpiece frame, mm.
    pub p: Vector3<f64>,
    /// Unit tool axis, workpiece frame.
    pub tool: Vector3<f64>,
    /// Commanded path feed, path units per second.
    pub feed: f64,
    /// Machine axes: X Y Z (mm), tilt and C (radians).
    pub joints: Joints,
    /// The program's end point has been reached; this is the last setpoint.
    pub done: bool,
}

/// The interpolator's state between periods.
#[derive(Clone, Debug)]
pub struct Interpolator<'a> {
    path: &'a Path,
    profile: &'a FeedProfile,
    kin: MachineKinematics,
    lim: RotaryLimits,
    method: Method,
    period: f64,
    creep: f64,
    cycle: u64,
    phase: usize,
    seg: usize,
    /// Taylor state: the current segment's curve parameter, or local distance for lines.
    u: f64,
    line_s: f64,
    prev_motion: Motion,
    joints: Joints,
    done: bool,
}

impl<'a> Interpolator<'a> {
    /// `creep` is the speed (path units/s) used by the Taylor methods to finish the program
    /// after the profile has come to rest; pass the path acceleration times the period.
    pub fn new(
        path: &'a Path,
        profile: &'a FeedProfile,
        kin: MachineKinematics,
        lim: RotaryLimits,
        method: Method,
        period: f64,
        creep: f64,
    ) -> Self {
        let u = path
            .segments
            .first()
            .and_then(|s| s.nurbs())
            .map_or(0.0, |(c, _)| c.range().0);
        Interpolator {
            path,
            profile,
            kin,
            lim,
            method,
            period,
            creep,
            cycle: 0,
            phase: 0,
            seg: 0,
            u,
            line_s: 0.0,
            prev_motion: Motion::default(),
            joints: path.start_joints,
            done: path.segments.is_empty(),
        }
    }

    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Compute the next period's setpoint. After the last one (`done`), further calls repeat
    /// the end point.
    pub fn step(&mut self) -> Setpoint {
        let t = self.cycle as f64 * self.period;
        let motion = self.profile.at(t, &mut self.phase);
        let pose = if self.cycle == 0 {
            self.path.start
        } else {
            match self.method {
                Method::ArcLength => self.pose_arclength(motion.s),
                Method::Taylor1 | Method::Taylor2 => self.pose_taylor(t),
            }
        };
        if self.method == Method::ArcLength && t >= self.profile.duration {
            self.done = true;
        }
        self.prev_motion = motion;
        self.joints = pose.joints(&self.kin, &self.joints, &self.lim);
        let block = self.path.segments.get(self.seg).map_or(1, |s| s.block);
        let sp = Setpoint {
            cycle: self.cycle,
            t,
            block,
            u: pose.u,
            p: pose.p,
            tool: pose.axis(&self.kin),
            feed: if self.done { 0.0 } else { motion.v },
            joints: self.joints,
            done: self.done,
        };
        self.cycle += 1;
        sp
    }

    fn pose_arclength(&mut self, s: f64) -> Pose {
        let starts = &self.profile.seg_start;
        let n = self.path.segments.len();
        while self.seg + 1 < n && s > starts[self.seg + 1] {
            self.seg += 1;
        }
        let seg = &self.path.segments[self.seg];
        seg.pose(s - starts[self.seg])
    }

    fn pose_taylor(&mut self, t: f64) -> Pose {
        let segs = &self.path.segments;
        let mut m = self.prev_motion;
        if t - self.period >= self.profile.duration && !self.done {
            m = Motion {
                s: m.s,
                v: self.creep,
                a: 0.0,
            };
        }
        let ts = self.period;
        // Distance to carry into following segments; bounded by the segment count.
        let mut carry: Option<f64> = None;
        for _ in 0..=segs.len() {
            let seg = &segs[self.seg];
            let last = self.seg + 1 == segs.len();
            let overshoot = match (&seg.geometry, carry) {
                (Geometry::Nurbs { curve, .. }, c) => {
                    let (u0, u1) = curve.range();
                    let d = curve.cutter(self.u, 2);
                    let sp = d.d1.norm().max(1e-12);
                    let du = match (c, self.method) {
                        (Some(dist), _) => dist / sp,
                        (None, Method::Taylor1) => m.v * ts / sp,
                        (None, _) => {
                            let vt = m.v * ts;
                            vt / sp + m.a * ts * ts / (2.0 * sp)
                                - vt * vt * d.d1.dot(&d.d2) / (2.0 * sp.powi(4))
                        }
                    };
                    self.u = (self.u + du.max(0.0)).max(u0);
                    if self.u >= u1 {
                        let over = (self.u - u1) * curve.speed(u1);
                        self.u = u1;
                        Some(over)
                    } else {
                        None
                    }
                }
                (Geometry::Line { .. }, c) => {
                    self.line_s += c.unwrap_or(m.v * ts + m.a * ts * ts / 2.0).max(0.0);
                    (self.line_s >= seg.length).then(|| self.line_s - seg.length)
                }
            };
            match overshoot {
                Some(_) if last => {
                    self.done = true;
                    return seg.pose(seg.length);
                }
                Some(over) => {
                    self.seg += 1;
                    self.line_s = 0.0;
                    self.u = segs[self.seg].nurbs().map_or(0.0, |(c, _)| c.range().0);
                    carry = Some(over);
                }
                None => break,
            }
        }
        let seg = &segs[self.seg];
        match &seg.geometry {
            Geometry::Nurbs { curve, .. } => seg.pose_u(curve, self.u),
            Geometry::Line { .. } => seg.pose(self.line_s),
        }
    }
}
