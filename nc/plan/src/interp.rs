//! The per-period interpolation step: the paper's Fig. 6 data flow for one period.
//!
//! feed profile -> path position -> parameter update -> C(u), CT(u) -> tool axis ->
//! rotary angles -> inverse kinematics -> five machine axis positions.
//!
//! Parameter update methods (`Method`):
//! * `ArcLength` (default): the profile gives the path position s(t) exactly; u(s) comes from
//!   the block's arc-length table with Newton refinement ([`nc_geom::arclen`]). The cutter moves
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

use crate::profile::FeedProfile;
use nc_geom::kinematics::{Joints, MachineKinematics, RotaryLimits};
use nc_geom::nurbs::Ders;
use nc_geom::scurve::Motion;
use nc_geom::segment::{Geometry, Path, Pose};

use nc_geom::setpoint::Setpoint;

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

/// Parameter increment over one period by a Taylor method (paper eq. 9 / eq. 10 with the
/// feed-acceleration term), from C' and C'' at the current u, feed `v` and its rate `a`.
/// `ArcLength` is treated as `Taylor2` here (it does not use this function).
pub fn taylor_du(method: Method, d: &Ders, v: f64, a: f64, ts: f64) -> f64 {
    let sp = d.d1.norm().max(1e-12);
    let vt = v * ts;
    match method {
        Method::Taylor1 => vt / sp,
        Method::Taylor2 | Method::ArcLength => {
            vt / sp + a * ts * ts / (2.0 * sp) - vt * vt * d.d1.dot(&d.d2) / (2.0 * sp.powi(4))
        }
    }
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

/// Where an [`Interpolator`] stands between two periods ([`Interpolator::mark`]). It can
/// go on from there on another profile whose phases up to the mark's time are the same
/// ([`Interpolator::resume`]): the planner's check uses that to re-measure only what a
/// round of replanning changed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mark {
    cycle: u64,
    phase: usize,
    seg: usize,
    u: f64,
    line_s: f64,
    prev_motion: Motion,
    joints: Joints,
    done: bool,
}

impl Mark {
    /// Cycle of the next setpoint.
    pub fn next_cycle(&self) -> u64 {
        self.cycle
    }

    /// The segment and the profile phase the interpolator stands at.
    pub(crate) fn segment(&self) -> usize {
        self.seg
    }

    pub(crate) fn phase(&self) -> usize {
        self.phase
    }

    /// The path's first `segments` and the profile's first `phases` were dropped (a
    /// streaming planner's buffers): count from there.
    pub(crate) fn rebase(&mut self, segments: usize, phases: usize) {
        self.seg -= segments;
        self.phase -= phases;
    }
}

impl<'a> Interpolator<'a> {
    /// Where the interpolator stands: the next [`Interpolator::step`] gives cycle
    /// `mark.next_cycle()`.
    pub fn mark(&self) -> Mark {
        Mark {
            cycle: self.cycle,
            phase: self.phase,
            seg: self.seg,
            u: self.u,
            line_s: self.line_s,
            prev_motion: self.prev_motion,
            joints: self.joints,
            done: self.done,
        }
    }

    /// Go on from `mark`, taken from an interpolator over the same path, method and period.
    /// The setpoints that follow are those of this interpolator's own profile as long as
    /// that profile's phases are the same as the marked one's up to the mark's time.
    pub fn resume(&mut self, mark: &Mark) {
        self.cycle = mark.cycle;
        self.phase = mark.phase;
        self.seg = mark.seg;
        self.u = mark.u;
        self.line_s = mark.line_s;
        self.prev_motion = mark.prev_motion;
        self.joints = mark.joints;
        self.done = mark.done;
    }

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

    /// Index of the segment the last setpoint lies on.
    pub fn segment(&self) -> usize {
        self.seg
    }

    /// Compute the next period's setpoint. After the last one (`done`), further calls repeat
    /// the end point.
    pub fn step(&mut self) -> Setpoint {
        let t = self.cycle as f64 * self.period;
        let motion = self.profile.at(t, &mut self.phase);
        let pose = if self.cycle == 0 || self.path.segments.is_empty() {
            // Nothing to move along (a program that is only its start pose) stays put.
            self.done |= self.path.segments.is_empty();
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
            aux: self
                .path
                .segments
                .get(self.seg)
                .map_or_else(Default::default, |s| s.aux),
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
                    let du = match c {
                        Some(dist) => dist / d.d1.norm().max(1e-12),
                        None => taylor_du(self.method, &d, m.v, m.a, ts),
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
                    (self.line_s >= seg.length).then_some(self.line_s - seg.length)
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
            Geometry::Nurbs { curve, table } => seg.pose_u(curve, table, self.u),
            Geometry::Line { .. } => seg.pose(self.line_s),
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::config::PlanConfig;
    use crate::plan::plan;
    use nc_geom::arclen::ArcTable;
    use nc_geom::fixtures::paper;
    use nc_geom::kinematics::Kinematics;
    use nc_geom::program::{
        Block, LinearMove, NurbsBlock, NurbsKind, Orientation, Program, SrcPos,
    };
    use nc_geom::segment::{build, BuildLimits};

    /// The paper's example as the parser produces it (built by hand here so these tests do
    /// not depend on the parser).
    pub(crate) fn paper_program() -> Program {
        let (c, t) = (nc_geom::fixtures::PAPER_C, nc_geom::fixtures::PAPER_T);
        let mut b = NurbsBlock {
            pos: SrcPos { line: 2, col: 1 },
            n: Some(30),
            kind: NurbsKind::G065,
            degree: 3,
            ctrl: Default::default(),
            tool_ctrl: Default::default(),
            ctrl_pos: Default::default(),
            weights: Default::default(),
            knots: Default::default(),
            feed_mm_min: 400.0,
            tooling: Default::default(),
            turn_to: None,
        };
        for i in 0..5 {
            b.ctrl.push(c[i]);
            b.tool_ctrl.push(t[i]);
            b.weights.push(1.0);
            b.ctrl_pos.push(SrcPos::default());
        }
        b.knots.extend_from_slice(&nc_geom::fixtures::PAPER_K);
        let dir = [t[0][0] - c[0][0], t[0][1] - c[0][1], t[0][2] - c[0][2]];
        let n = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        Program {
            blocks: vec![
                Block::Linear(LinearMove {
                    pos: SrcPos { line: 1, col: 1 },
                    n: Some(20),
                    rapid: false,
                    end: c[0],
                    orientation: Orientation::Vector([dir[0] / n, dir[1] / n, dir[2] / n]),
                    feed_mm_min: 400.0,
                    inverse_time: false,
                    tooling: Default::default(),
                }),
                Block::Nurbs(b),
            ],
            end: None,
            actions: Vec::new(),
            tilt_word: None,
            rerun: Vec::new(),
        }
    }

    pub(crate) fn machine() -> (MachineKinematics, PlanConfig, BuildLimits) {
        let (cfg, bl) = crate::fixtures::small_mill(0.002);
        (MachineKinematics::Paper, cfg, bl)
    }

    fn run(method: Method) -> (Path, FeedProfile, Vec<Setpoint>) {
        let (kin, cfg, bl) = machine();
        let path = build(&paper_program(), &kin, &bl).unwrap();
        let profile = plan(&path, &kin, &cfg).unwrap();
        let mut out = Vec::new();
        {
            let mut ip = Interpolator::new(
                &path,
                &profile,
                kin,
                cfg.rotary,
                method,
                cfg.period,
                cfg.path_acc * cfg.period,
            );
            for _ in 0..100_000 {
                let sp = ip.step();
                out.push(sp);
                if sp.done {
                    break;
                }
            }
        }
        (path, profile, out)
    }

    /// Largest relative difference between the arc length per period and feed x period,
    /// over periods at constant commanded feed.
    fn fluctuation(path: &Path, sps: &[Setpoint]) -> (f64, usize) {
        let (curve, table) = path.segments[0].nurbs().unwrap();
        let mut worst = 0.0f64;
        let mut n = 0;
        for w in sps.windows(2) {
            if let (Some(ua), Some(ub)) = (w[0].u, w[1].u) {
                if w[0].feed == w[1].feed && w[1].feed > 0.0 && !w[1].done {
                    let ds = table.s_of_u(curve, ub) - table.s_of_u(curve, ua);
                    worst = worst.max((ds - w[1].feed * 0.002).abs() / (w[1].feed * 0.002));
                    n += 1;
                }
            }
        }
        (worst, n)
    }

    #[test]
    fn arclength_keeps_the_feed_within_1e4_and_ends_on_the_end_point() {
        let (path, profile, sps) = run(Method::ArcLength);
        let (worst, n) = fluctuation(&path, &sps);
        assert!(n > 1000, "too few constant-feed periods: {n}");
        assert!(worst < 1e-4, "feed fluctuation {worst:e}");
        let last = sps.last().unwrap();
        assert!(last.done);
        let end = path.segments[0].pose(path.segments[0].length).p;
        assert!((last.p - end).norm() < 1e-9, "{} vs {end}", last.p);
        assert!((last.p - nalgebra::Vector3::new(-1.6963, 163.6796, 5.8369)).norm() < 1e-9);
        // Starts at the start pose, at rest.
        assert_eq!(sps[0].p, path.start.p);
        assert_eq!(sps[0].feed, 0.0);
        // Never faster than programmed.
        assert!(sps.iter().all(|s| s.feed <= 400.0 / 60.0 + 1e-9));
        assert!((profile.length - path.segments[0].length).abs() < 1e-12);
    }

    #[test]
    fn setpoints_lie_on_both_curves() {
        let (_, _, sps) = run(Method::ArcLength);
        let c = paper();
        for sp in sps.iter().filter(|s| s.u.is_some()) {
            let (p, d) = c.cutter_and_tool(sp.u.unwrap(), 0);
            assert!((sp.p - p.p).norm() < 1e-12);
            let axis = d.p.normalize();
            assert!((sp.tool - axis).norm() < 1e-12);
            // Paper kinematics: machine XYZ = workpiece XYZ, A/C reproduce the tool axis.
            let k = MachineKinematics::Paper;
            assert!((k.tool_axis(sp.joints[3], sp.joints[4]) - axis).norm() < 1e-12);
        }
    }

    #[test]
    fn taylor_methods_rank_as_the_paper_says() {
        let (p1, _, s1) = run(Method::Taylor1);
        let (p2, _, s2) = run(Method::Taylor2);
        let (f1, _) = fluctuation(&p1, &s1);
        let (f2, _) = fluctuation(&p2, &s2);
        assert!(f2 < f1, "taylor2 {f2:e} should beat taylor1 {f1:e}");
        assert!(s1.last().unwrap().done && s2.last().unwrap().done);
        let end = nalgebra::Vector3::new(-1.6963, 163.6796, 5.8369);
        assert!((s2.last().unwrap().p - end).norm() < 1e-9);
    }

    #[test]
    fn taylor2_acceleration_term_is_what_a_varying_feed_needs() {
        // One period from u0 with feed v and acceleration a: the exact step ends at arc
        // length s(u0) + v Ts + a Ts^2 / 2. Without the a-term the error is O(a Ts^2), with
        // it O(Ts^3).
        let c = paper();
        let table = ArcTable::new(&c);
        let ts = 0.002;
        for &(u0, v, a) in &[
            (0.2, 50.0, 1000.0),
            (0.6, 20.0, -800.0),
            (0.45, 100.0, 2000.0),
        ] {
            let d = c.cutter(u0, 2);
            let exact = table.u_of_s(&c, table.s_of_u(&c, u0) + v * ts + a * ts * ts / 2.0) - u0;
            let with = taylor_du(Method::Taylor2, &d, v, a, ts);
            let without = taylor_du(Method::Taylor2, &d, v, 0.0, ts);
            let e_with = (with - exact).abs();
            let e_without = (without - exact).abs();
            assert!(
                e_with * 20.0 < e_without,
                "u0={u0}: with {e_with:e}, without {e_without:e}"
            );
            // Taylor1 ignores curvature and acceleration alike.
            assert!((taylor_du(Method::Taylor1, &d, v, a, ts) - exact).abs() > e_with);
        }
    }

    #[test]
    fn profile_respects_path_limits_and_is_continuous() {
        let (kin, cfg, bl) = machine();
        let path = build(&paper_program(), &kin, &bl).unwrap();
        let p = plan(&path, &kin, &cfg).unwrap();
        for w in p.phases.windows(2) {
            let e = w[0].end();
            assert!(
                (e.s - w[1].s0).abs() < 1e-9
                    && (e.v - w[1].v0).abs() < 1e-9
                    && (e.a - w[1].a0).abs() < 1e-6
            );
            assert!((w[0].t0 + w[0].dur - w[1].t0).abs() < 1e-12);
        }
        for ph in &p.phases {
            assert!(ph.j.abs() <= cfg.path_jerk * (1.0 + 1e-12));
            assert!(ph.a0.abs() <= cfg.path_acc * (1.0 + 1e-9));
            assert!(ph.v0 <= 400.0 / 60.0 + 1e-9 && ph.v0 >= -1e-9);
        }
        let last = p.phases.last().unwrap().end();
        assert!((last.s - p.length).abs() < 1e-6 && last.v.abs() < 1e-9);
    }
}
