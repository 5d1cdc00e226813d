//! The limits checked on the setpoints themselves, as the drives will receive them.
//!
//! The planner's ceilings (`crate::plan`) come from stations along the path; a peak of
//! curvature, of an axis derivative or of the C rate near the vertical tool can fall between
//! two stations. So the plan is not trusted: [`check`] runs the interpolator over the whole
//! plan at the machine period, exactly as `dnurbs simulate` and the real-time thread do, and
//! measures every axis on the setpoints it produces, by finite differences at the period:
//!
//! * velocity `(q[k] - q[k-1]) / Ts`, acceleration `(q[k] - 2 q[k-1] + q[k-2]) / Ts^2` and
//!   jerk `(q[k] - 3 q[k-1] + 3 q[k-2] - q[k-3]) / Ts^3` of every axis against its limit. The
//!   drives hold the start before the first setpoint and the end after the last, so the
//!   sequence is padded with copies of both; a step at the start or end counts.
//!   Jerk is not limited over a junction whose joint path is not G2-continuous (a corner
//!   or a change of curvature between blocks): there the velocity or the acceleration
//!   changes direction within one period by design (the corner policy in `crate::plan`).
//!   At such a junction the acceleration is also measured on the stencil centred on the
//!   junction itself, its worst phase ([`corner`]): a hold or an override shifts the phase at
//!   which the drives' setpoints meet a corner, and the limit must hold at any phase. And
//!   the jerk is measured on each side of it, on the four setpoints that end on the
//!   junction and the four that start there: the bound between phases ([`reserve`]) needs
//!   the jerk within its limit up to the corner, and a step of a joint at the junction
//!   (which no speed makes small) shows there.
//! * chord error: the largest distance of the cutter path between two setpoints from the
//!   straight chord between them (the drives interpolate linearly), measured at the quarter
//!   points of a curve's parameter interval and at every segment junction the chord spans.
//! * travel: every setpoint of every axis within the machine's travel.
//!
//! What it finds drives the planner (`crate::plan::plan` lowers the speed where a limit is
//! broken and plans again) and, where slowing cannot help, the refusal of the program.

use crate::config::PlanConfig;
use crate::interp::{Interpolator, Mark, Method};
use crate::profile::FeedProfile;
use nalgebra::Vector3;
use nc_geom::kinematics::{Joints, MachineKinematics};
use nc_geom::limits::{reserve, Margins};
use nc_geom::scurve::Phase;
use nc_geom::segment::{Geometry, Path, Segment};
use nc_geom::setpoint::Setpoint;

/// What a limit bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    Velocity,
    Acceleration,
    Jerk,
    Chord,
    Travel,
    /// The rotary axes change solution within one period for the same tool axis: the
    /// other tilt sign with C half a turn on, or C a whole turn on. The kinematics does that
    /// only where following the tool on would leave a rotary travel; no feed can fix it.
    Branch,
}

impl Quantity {
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Velocity => "velocity",
            Quantity::Acceleration => "acceleration",
            Quantity::Jerk => "jerk",
            Quantity::Chord => "chord error",
            Quantity::Travel => "travel",
            Quantity::Branch => "rotary branch",
        }
    }

    /// How the quantity scales with the path speed: v^n (travel does not).
    pub fn speed_power(self) -> Option<i32> {
        match self {
            Quantity::Velocity => Some(1),
            Quantity::Acceleration | Quantity::Chord => Some(2),
            Quantity::Jerk => Some(3),
            Quantity::Travel | Quantity::Branch => None,
        }
    }
}

/// One broken limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Violation {
    pub quantity: Quantity,
    /// Joint index (X Y Z tilt C); 5 for the chord error of the cutter path.
    pub axis: usize,
    /// Cycle of the newest setpoint in the stencil, and its time (s).
    pub cycle: u64,
    pub t: f64,
    /// Segment of the newest setpoint.
    pub segment: usize,
    /// Path positions the stencil spans.
    pub s: (f64, f64),
    /// Highest planned path speed over the stencil.
    pub v: f64,
    /// The measured value and its limit (absolute; radians for rotary axes).
    pub value: f64,
    pub limit: f64,
    /// For [`Quantity::Branch`]: (tilt, C) before and after the change, radians.
    pub rotary: [[f64; 2]; 2],
    /// The acceleration of a kink at its worst phase ([`corner`]): the velocity jump, so
    /// the value, grows linearly with the speed `v` at the junction.
    pub kink: bool,
}

impl Violation {
    /// Factor by which the path speed must drop for this limit to hold, if slowing helps.
    pub fn speed_factor(&self) -> Option<f64> {
        let n = if self.kink {
            1
        } else {
            self.quantity.speed_power()?
        };
        Some((self.limit / self.value).powf(1.0 / f64::from(n)))
    }
}

/// The result of [`check`]: the margins, and at most one violation per cycle (the worst).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Checked {
    pub margins: Margins,
    pub violations: Vec<Violation>,
}

/// Relative slack for rounding: a value within it of the limit holds.
const SLACK: f64 = 1e-9;

/// The most any plan the planner accepts can reach: the shares of the axes' velocity and
/// acceleration that [`reserve`] leaves, the whole jerk and chord tolerance (with the
/// check's rounding slack). A plan streamed to the real-time thread is bounded by it before
/// it is whole.
pub fn ceiling(cfg: &PlanConfig) -> Margins {
    let share = |f: fn((f64, f64)) -> f64| -> [f64; 5] {
        core::array::from_fn(|j| f(reserve(&cfg.axes[j], cfg.period)) * (1.0 + SLACK))
    };
    Margins {
        velocity: share(|r| r.0),
        acceleration: share(|r| r.1),
        jerk: [1.0 + SLACK; 5],
        chord: 1.0 + SLACK,
        cycles: 0,
    }
}

/// Most periods a plan may take (24 h at 1 ms): a longer plan is refused, so neither the
/// check nor `dnurbs simulate` ever stops short of the program's end.
pub const MAX_CYCLES: u64 = 86_400_000;

/// A setpoint with what the check needs beside it.
#[derive(Clone, Copy, Debug)]
struct Sample {
    q: Joints,
    p: Vector3<f64>,
    u: Option<f64>,
    seg: usize,
    s: f64,
    v: f64,
    cycle: u64,
    t: f64,
}

/// Run the interpolator over `profile` at the period and measure every limit on its
/// setpoints. `smooth[k]` tells whether the junction at the start of segment k is
/// G2-continuous in the joints (from [`smooth_junctions`]).
pub fn check(
    path: &Path,
    profile: &FeedProfile,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    smooth: &[bool],
) -> Checked {
    check_from(path, profile, kin, cfg, smooth, None).0
}

/// Periods between two [`Trace`] marks.
const MARK_EVERY: u64 = 256;

/// A check's state every [`MARK_EVERY`] periods, to start the next round's check where the
/// replanned profile first differs ([`check_from`]).
#[derive(Clone, Debug, Default)]
pub struct Trace {
    marks: Vec<TraceMark>,
}

impl Trace {
    /// Forget the marks no later check will start from: all but the last before time `t`,
    /// when the plan before `t` is final (the planner's committed windows).
    pub fn forget_before(&mut self, t: f64) {
        let n = self.marks.partition_point(|m| m.win[3].t < t);
        self.marks.drain(..n.saturating_sub(1));
    }

    /// What a check resuming from the oldest mark reads behind it: the first segment its
    /// samples lie on, the first phase its cursors stand at, and the time of its oldest
    /// sample. None unless that mark's newest sample comes before time `until` (without
    /// one, a check starts from the program's start).
    pub fn oldest(&self, until: f64) -> Option<(usize, usize, f64)> {
        let m = self.marks.first().filter(|m| m.win[3].t < until)?;
        let seg = m.win.iter().map(|w| w.seg).fold(m.ip.segment(), usize::min);
        Some((seg, m.cursor.min(m.ip.phase()), m.win[0].t))
    }

    /// The segments and phases before `segments` and `phases` are gone from the planner's
    /// buffers: every index the marks hold counts from there now. Nothing a mark points at
    /// may lie before them ([`Trace::oldest`]).
    pub fn rebase(&mut self, segments: usize, phases: usize) {
        for m in &mut self.marks {
            m.ip.rebase(segments, phases);
            m.cursor -= phases;
            for w in &mut m.win {
                w.seg -= segments;
            }
        }
    }
}

#[derive(Clone, Debug)]
struct TraceMark {
    ip: Mark,
    win: [Sample; 4],
    cursor: usize,
    margins: Margins,
    /// Violations recorded before the mark.
    violations: usize,
}

/// A check of an earlier profile of the same path: its phases, result and trace.
pub struct Earlier<'a> {
    /// Phases before this index are the same in both profiles (the planner's committed
    /// windows), so the comparison starts there.
    pub offset: usize,
    /// The earlier profile's phases from `offset` on.
    pub phases: &'a [Phase],
    pub checked: &'a Checked,
    pub trace: &'a Trace,
}

/// As [`check`], and where `earlier` is given, start from its last mark before the first
/// phase in which `profile` differs from it: up to there the interpolator computes the same
/// setpoints, so their measurements (margins and violations) are taken over. Returns the
/// trace for the next round.
pub fn check_from(
    path: &Path,
    profile: &FeedProfile,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    smooth: &[bool],
    earlier: Option<Earlier>,
) -> (Checked, Trace) {
    check_marked(path, profile, kin, cfg, smooth, earlier, MARK_EVERY)
}

/// [`check_from`] with a mark every `every` periods.
fn check_marked(
    path: &Path,
    profile: &FeedProfile,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    smooth: &[bool],
    earlier: Option<Earlier>,
    every: u64,
) -> (Checked, Trace) {
    let ctx = Ctx {
        path,
        profile,
        kin,
        cfg,
        smooth,
    };
    let mut out = Checked::default();
    let mut trace = Trace::default();
    let ts = cfg.period;
    let mut ip = Interpolator::new(path, profile, *kin, cfg.rotary, Method::ArcLength, ts, 0.0);
    let mut cursor = 0;
    // The last four samples, newest last; padded with the start pose (the drives are there).
    let first = sample(&ip.step(), 0, profile, &mut cursor);
    let mut win = [first; 4];
    // Padding past the end: three more copies of the last setpoint.
    let mut tail = 0;
    let mut done = first.cycle == 0 && path.segments.is_empty();
    out.margins.cycles = 1;
    check_travel(&first, cfg, &mut out);
    if let Some(e) = earlier {
        let now = profile.phases.get(e.offset..).unwrap_or(&[]);
        let same = e.phases.iter().zip(now).take_while(|(a, b)| a == b).count();
        let t0 = |p: &[Phase]| p.get(same).map_or(f64::INFINITY, |x| x.t0);
        let changed = t0(e.phases).min(t0(now));
        // The mark's own and earlier setpoints were computed before the change.
        let usable = e
            .trace
            .marks
            .iter()
            .take_while(|m| (m.win[3].t + ts) < changed)
            .count();
        if let Some(m) = usable.checked_sub(1).map(|i| &e.trace.marks[i]) {
            ip.resume(&m.ip);
            win = m.win;
            cursor = m.cursor;
            out.margins = m.margins;
            out.violations = e.checked.violations[..m.violations].to_vec();
            trace.marks = e.trace.marks[..usable].to_vec();
        }
    }
    while tail < 3 {
        let next = if done {
            tail += 1;
            Sample {
                cycle: win[3].cycle + 1,
                t: win[3].t + ts,
                v: 0.0,
                ..win[3]
            }
        } else {
            let sp = ip.step();
            done = sp.done || sp.cycle >= MAX_CYCLES;
            out.margins.cycles += 1;
            sample(&sp, ip.segment(), profile, &mut cursor)
        };
        win = [win[1], win[2], win[3], next];
        check_travel(&next, cfg, &mut out);
        check_window(&win, &ctx, &mut out);
        if !done && next.cycle % every == 0 {
            trace.marks.push(TraceMark {
                ip: ip.mark(),
                win,
                cursor,
                margins: out.margins,
                violations: out.violations.len(),
            });
        }
    }
    (out, trace)
}

fn sample(sp: &Setpoint, seg: usize, profile: &FeedProfile, cursor: &mut usize) -> Sample {
    let m = profile.at(sp.t, cursor);
    Sample {
        q: sp.joints,
        p: sp.p,
        u: sp.u,
        seg,
        s: m.s,
        v: m.v,
        cycle: sp.cycle,
        t: sp.t,
    }
}

fn violation(q: Quantity, axis: usize, w: &[Sample], value: f64, limit: f64) -> Violation {
    let last = &w[w.len() - 1];
    Violation {
        quantity: q,
        axis,
        cycle: last.cycle,
        t: last.t,
        segment: last.seg,
        s: (w[0].s, last.s),
        v: w.iter().map(|x| x.v).fold(0.0, f64::max),
        value,
        limit,
        rotary: [[0.0; 2]; 2],
        kink: false,
    }
}

/// Keep the worst violation of a cycle: the one that needs the largest slow-down.
fn record(out: &mut Checked, v: Violation) {
    if let Some(last) = out.violations.last_mut() {
        if last.cycle == v.cycle {
            let worse = match (v.speed_factor(), last.speed_factor()) {
                (None, _) => true,
                (Some(_), None) => false,
                (Some(a), Some(b)) => a < b,
            };
            if worse {
                *last = v;
            }
            return;
        }
    }
    out.violations.push(v);
}

fn check_travel(x: &Sample, cfg: &PlanConfig, out: &mut Checked) {
    for j in 0..5 {
        let (lo, hi) = cfg.travel[j];
        let q = x.q[j];
        if !(q >= lo - SLACK * lo.abs().max(1.0) && q <= hi + SLACK * hi.abs().max(1.0)) {
            let limit = if q < lo { lo } else { hi };
            record(out, violation(Quantity::Travel, j, &[*x], q, limit));
        }
    }
}

/// Does the stencil `w` cross a junction that is not G2-continuous?
fn crosses_corner(w: &[Sample], smooth: &[bool]) -> bool {
    let (a, b) = (w[0].seg, w[w.len() - 1].seg);
    (a + 1..=b).any(|k| !smooth.get(k).copied().unwrap_or(false))
}

/// What a check measures against: the path, its plan, the machine, and which junctions
/// are G2-continuous.
struct Ctx<'a> {
    path: &'a Path,
    profile: &'a FeedProfile,
    kin: &'a MachineKinematics,
    cfg: &'a PlanConfig,
    smooth: &'a [bool],
}

fn check_window(w: &[Sample; 4], ctx: &Ctx, out: &mut Checked) {
    let cfg = ctx.cfg;
    let (ts, m) = (cfg.period, &mut out.margins);
    let mut found: Option<Violation> = None;
    let keep = |v: Violation, found: &mut Option<Violation>| {
        let worse = match (
            found.as_ref().and_then(Violation::speed_factor),
            v.speed_factor(),
        ) {
            (_, None) => true,
            (None, Some(_)) => found.is_none(),
            (Some(a), Some(b)) => b < a,
        };
        if worse {
            *found = Some(v);
        }
    };
    let jerk_ok = !crosses_corner(w, ctx.smooth);
    let kink = if w[1].seg < w[2].seg {
        corner::stencil(w, ctx)
    } else {
        None
    };
    for (j, ax) in cfg.axes.iter().enumerate() {
        let (q0, q1, q2, q3) = (w[0].q[j], w[1].q[j], w[2].q[j], w[3].q[j]);
        let vel = ((q3 - q2) / ts).abs();
        let acc = ((q3 - 2.0 * q2 + q1) / (ts * ts)).abs();
        let (v_share, a_share) = reserve(ax, ts);
        let (vel_limit, acc_limit) = (ax.velocity * v_share, ax.acceleration * a_share);
        let jerk_limit = ax.planned_jerk(ts);
        let jerk = ((q3 - 3.0 * q2 + 3.0 * q1 - q0) / (ts * ts * ts)).abs();
        m.velocity[j] = m.velocity[j].max(vel / ax.velocity);
        m.acceleration[j] = m.acceleration[j].max(acc / ax.acceleration);
        if vel > vel_limit * (1.0 + SLACK) || vel.is_nan() {
            keep(
                violation(Quantity::Velocity, j, &w[2..], vel, vel_limit),
                &mut found,
            );
        }
        if acc > acc_limit * (1.0 + SLACK) || acc.is_nan() {
            keep(
                violation(Quantity::Acceleration, j, &w[1..], acc, acc_limit),
                &mut found,
            );
        }
        if let Some(c) = &kink {
            let [k0, k1, k2] = &c.q;
            let acc = ((k2[j] - 2.0 * k1[j] + k0[j]) / (ts * ts)).abs();
            m.acceleration[j] = m.acceleration[j].max(acc / ax.acceleration);
            if acc > acc_limit * (1.0 + SLACK) || acc.is_nan() {
                // The speed at the junction sets the jump: lower it there.
                let v = Violation {
                    s: (c.s, c.s),
                    v: c.v,
                    kink: true,
                    ..violation(Quantity::Acceleration, j, &w[1..], acc, acc_limit)
                };
                keep(v, &mut found);
            }
            for side in c.sides.iter().flatten() {
                let [k0, k1, k2, k3] = side.q.map(|x| x[j]);
                let jerk = ((k3 - 3.0 * k2 + 3.0 * k1 - k0) / (ts * ts * ts)).abs();
                m.jerk[j] = m.jerk[j].max(jerk / jerk_limit);
                if jerk > jerk_limit * (1.0 + SLACK) || jerk.is_nan() {
                    let v = Violation {
                        s: side.s,
                        v: side.v,
                        ..violation(Quantity::Jerk, j, w, jerk, jerk_limit)
                    };
                    keep(v, &mut found);
                }
            }
        }
        if jerk_ok {
            m.jerk[j] = m.jerk[j].max(jerk / jerk_limit);
            if jerk > jerk_limit * (1.0 + SLACK) || jerk.is_nan() {
                keep(
                    violation(Quantity::Jerk, j, w, jerk, jerk_limit),
                    &mut found,
                );
            }
        }
    }
    if let Some(v) = branch_change(w) {
        keep(v, &mut found);
    }
    let chord = chord_error(&w[2], &w[3], ctx.path);
    m.chord = m.chord.max(chord / cfg.chord_tol);
    if chord > cfg.chord_tol * (1.0 + SLACK) || chord.is_nan() {
        keep(
            violation(Quantity::Chord, 5, &w[2..], chord, cfg.chord_tol),
            &mut found,
        );
    }
    if let Some(v) = found {
        record(out, v);
    }
}

/// A change of rotary solution between the two newest setpoints (see [`Quantity::Branch`]).
/// A tool passing near the vertical swings C fast but continuously, with the tilt near zero;
/// it never steps C by exactly half a turn at a tilt of its own, nor by whole turns.
fn branch_change(w: &[Sample; 4]) -> Option<Violation> {
    use core::f64::consts::{PI, TAU};
    let (a, b) = (&w[2].q, &w[3].q);
    let (t0, t1, dc) = (a[3], b[3], b[4] - a[4]);
    let near = |x: f64, y: f64| (x - y).abs() < 1e-3;
    let flip = t0 * t1 < 0.0 && t0.abs() > 1e-3 && t1.abs() > 1e-3 && near(dc.abs(), PI);
    let wrap = dc.abs() > PI && near((dc / TAU).round() * TAU, dc) && near(t0, t1);
    (flip || wrap).then(|| Violation {
        rotary: [[t0, a[4]], [t1, b[4]]],
        ..violation(Quantity::Branch, 4, &w[2..], dc.abs(), 0.0)
    })
}

/// Distance from `p` to the segment a..b.
pub fn dist_to_chord(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    chord_foot(p, a, b).1
}

/// The foot of `p` on the segment a..b, as the fraction of the way from `a`, and the
/// distance from `p` to it.
pub fn chord_foot(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> (f64, f64) {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let f = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (f, (p - (a + ab * f)).norm())
}

/// Largest distance of the cutter path between setpoints `a` and `b` from their chord.
fn chord_error(a: &Sample, b: &Sample, path: &Path) -> f64 {
    let mut e = 0.0f64;
    if a.seg == b.seg {
        let Some(seg) = path.segments.get(a.seg) else {
            return e;
        };
        if let (Geometry::Nurbs { curve, .. }, Some(ua), Some(ub)) = (&seg.geometry, a.u, b.u) {
            for f in [0.25, 0.5, 0.75] {
                let p = curve.cutter(ua + (ub - ua) * f, 0).p;
                e = e.max(dist_to_chord(&p, &a.p, &b.p));
            }
        }
        return e;
    }
    // The chord spans junctions: every segment end between them is a point of the path.
    for seg in path.segments.get(a.seg..b.seg).unwrap_or(&[]) {
        if !seg.rotary_only {
            e = e.max(dist_to_chord(&seg.pose(seg.length).p, &a.p, &b.p));
        }
    }
    e
}

/// One-sided step used to compare the joint derivatives on both sides of a junction, mm.
const JUNCTION_STEP: f64 = 1e-4;

/// For every segment, whether the junction at its start is G2-continuous in the machine
/// joints: equal first and second derivatives dq/ds, d2q/ds2 from both sides (one-sided
/// finite differences), and no change between mm and degrees of path. Segment 0 (the
/// program start, from rest) counts as smooth.
pub fn smooth_junctions(path: &Path, kin: &MachineKinematics, cfg: &PlanConfig) -> Vec<bool> {
    let mut out = Vec::with_capacity(path.segments.len());
    out.push(true);
    for w in path.segments.windows(2) {
        out.push(g2(&w[0], &w[1], kin, cfg));
    }
    out
}

pub(crate) fn g2(a: &Segment, b: &Segment, kin: &MachineKinematics, cfg: &PlanConfig) -> bool {
    if a.rotary_only || b.rotary_only {
        return false;
    }
    let h = JUNCTION_STEP.min(a.length / 4.0).min(b.length / 4.0);
    if h <= 0.0 {
        return false;
    }
    let lim = &cfg.rotary;
    // Joints along a, then on into b, following one rotary branch.
    let mut prev = a.pose(a.length - 3.0 * h).joints(kin, &[0.0; 5], lim);
    let mut qa = [[0.0; 5]; 3];
    for (i, q) in qa.iter_mut().enumerate() {
        prev = a
            .pose(a.length - (2 - i) as f64 * h)
            .joints(kin, &prev, lim);
        *q = prev;
    }
    let mut qb = [[0.0; 5]; 3];
    for (i, q) in qb.iter_mut().enumerate() {
        prev = b.pose(i as f64 * h).joints(kin, &prev, lim);
        *q = prev;
    }
    (0..5).all(|j| {
        let d1a = (qa[2][j] - qa[1][j]) / h;
        let d1b = (qb[1][j] - qb[0][j]) / h;
        let d2a = (qa[2][j] - 2.0 * qa[1][j] + qa[0][j]) / (h * h);
        let d2b = (qb[2][j] - 2.0 * qb[1][j] + qb[0][j]) / (h * h);
        let scale = d2a.abs().max(d2b.abs()).max(1.0);
        (qa[2][j] - qb[0][j]).abs() < 1e-9
            && (d1a - d1b).abs() < 1e-3 * d1a.abs().max(d1b.abs()).max(1.0) + 4.0 * h * scale
            && (d2a - d2b).abs() < 1e-2 * scale
    })
}

mod corner;
#[cfg(test)]
mod tests;
