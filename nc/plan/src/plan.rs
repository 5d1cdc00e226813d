//! Feed planning outside the real-time thread, in windows of bounded look-ahead
//! ([`window`]: each window runs the steps below over its own stretch of path).
//!
//! 1. **Stations.** Each segment is sampled at stations about one period of travel apart
//!    (16..=4096 per segment; 2 or more along a line with a fixed tool axis, whose joints
//!    move at constant rates; eight times as many, up to 4096, where a rotary axis's rate
//!    changes 8x from one interval to the next). At each station the machine joints q(s)
//!    are computed through the kinematics (with rotary continuity), and dq/ds, d2q/ds2,
//!    d3q/ds3 by finite differences (at a joint of two segments, each side's).
//! 2. **Velocity ceiling** at each station, the least of: the programmed feed; the chord-error
//!    limit `2 sqrt(2 rho delta - delta^2) / Ts` (rho = 1/curvature, delta = tolerance); the
//!    centripetal limit `sqrt(A / curvature)`; for every axis j `vmax_j / |dq_j/ds|` and
//!    `sqrt(amax_j / (2 |d2q_j/ds2|))` (at least half the axis acceleration is left for the
//!    path acceleration, see 4). Near the vertical tool dC/ds grows like 1/sin(A), so this is what
//!    slows the path and keeps the C axis within its limits.
//! 3. **Corners.** Where segments meet with a kink in some axis (dq/ds jumps by d_j), the
//!    joint is passed at `min_j amax_j Ts / d_j`: each axis's velocity then changes by at
//!    most one period's worth of its acceleration. A G2-continuous joint has d = 0 and is
//!    passed at speed. Where the cutter path turns by phi there, also at most
//!    `2 tol / (Ts sin(phi / 2))`: the chord that straddles the corner then keeps the
//!    tolerance whatever the sampling phase (after a hold, too). The path starts and ends
//!    at rest, and rests where a move waits (a dwell, the operator, the spindle).
//! 4. **S-curves between critical points.** Critical points are the start, the end, the
//!    joints, the local minima of the ceiling, and the stations next to where the rates
//!    jump (the path acceleration they allow falls or rises 8x from what it was on the
//!    stretch leaving the last critical point: a tool arriving at the vertical, or leaving
//!    it), which would otherwise hold the ramps beside them.
//!    Backward and forward passes make each point's speed reachable from its neighbours;
//!    then each section gets a jerk-limited accelerate / cruise / decelerate profile with
//!    the highest cruise speed that fits. Its two ramps' path acceleration and jerk are
//!    what each axis's share (90 %) leaves after the curvature terms, over the stretch each
//!    ramp can cover and at the speeds it can have there, and never less than half the
//!    axis's ([`limits`]). Wherever a section's speed exceeds the ceiling at a station,
//!    that station becomes a critical point and the plan is redone.
//! 5. **The setpoint check** measures every axis's velocity, acceleration and jerk by finite
//!    differences at the period ([`crate::verify`]); where one is over its limit the
//!    ceilings there are lowered (and for jerk the path's share, to half) and the window is
//!    planned again. Where the caps stop changing the plan, they go to the stations on
//!    either side, unless that would make the path crawl to them: then the path's share is
//!    lowered, or the ceilings the violation holds go on down from where they are, and the
//!    window falls back to the widened caps if that ends in a refusal ([`remedy`]). No cap
//!    goes below the floor speed [`V_FLOOR`] but a joint's, down to [`V_JOINT_FLOOR`].
//!
//! The result is a [`FeedProfile`]: constant-jerk phases over the whole path, evaluated per
//! period without allocation.

use crate::config::PlanConfig;
use crate::profile::FeedProfile;
use crate::verify::{Quantity, Violation, MAX_CYCLES};
use nc_geom::kinematics::Tilt;
use nc_geom::kinematics::{Joints, MachineKinematics};
use nc_geom::limits::{JERK_RISE, V_FLOOR};
use nc_geom::program::SrcPos;
use nc_geom::scurve::{push_section, reachable, Phase, Ramps};
use nc_geom::segment::{Path, Segment};

mod limits;
mod remedy;
mod rounds;
mod stations;
mod window;

use limits::section_ramps;
use stations::{Rates, Station};

pub use window::{Finished, Planner, Sink};

/// Slowest speed a joint is passed at where an axis's rate jumps there by more than the
/// floor speed allows (path units/s): the jump is taken in one period at that speed.
pub const V_JOINT_FLOOR: f64 = 1e-7;
/// Likewise for a section's path acceleration and jerk.
const A_FLOOR: f64 = 1e-3;
/// Replanning rounds before every violating station is made critical at once.
const ROUNDS_WORST_ONLY: usize = 60;
const ROUNDS_MAX: usize = 400;

/// The phase of `phases` that holds path position `s`, and the time into it (bisection).
fn state_at(phases: &[Phase], s: f64) -> Option<(&Phase, f64)> {
    let i = phases.partition_point(|p| p.s0 <= s).saturating_sub(1);
    let p = phases.get(i)?;
    let (mut lo, mut hi) = (0.0, p.dur);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if p.at(mid).s < s {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some((p, 0.5 * (lo + hi)))
}

/// Speed of a section's phases at path position `s`.
fn speed_at(phases: &[Phase], s: f64) -> f64 {
    state_at(phases, s).map_or(0.0, |(p, tau)| p.at(tau).v)
}

/// Planning rounds with the setpoint check before the program is refused.
const VERIFY_ROUNDS: usize = 40;
/// A lowered ceiling aims this far below what the measured violation needs.
const CAP_MARGIN: f64 = 0.97;

/// A program the planner cannot run within the machine's limits.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{pos}: {kind}")]
pub struct PlanError {
    pub pos: SrcPos,
    pub kind: PlanErrorKind,
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanErrorKind {
    #[error("the program would take {hours:.1} h at the feeds the limits allow, more than the {max_cycles} periods dnurbs plans ({max_hours:.1} h at this period)")]
    TooLong {
        hours: f64,
        max_cycles: u64,
        max_hours: f64,
    },
    #[error("the {axis} axis would leave its travel: {value:.4} {unit} at t = {t:.3} s (travel {min} .. {max} {unit})")]
    Travel {
        axis: char,
        unit: &'static str,
        value: f64,
        min: f64,
        max: f64,
        t: f64,
    },
    #[error("the rotary axes would change solution in one period at t = {t:.3} s, for the same tool axis: {tilt} {from_tilt:.3} -> {to_tilt:.3} deg, C {from_c:.3} -> {to_c:.3} deg; following the tool axis on would leave the travel of {tilt} ({}) or C ({})", travel(*.tilt_min, *.tilt_max, "deg"), travel(*.c_min, *.c_max, "deg"))]
    Branch {
        tilt: char,
        from_tilt: f64,
        to_tilt: f64,
        from_c: f64,
        to_c: f64,
        t: f64,
        tilt_min: f64,
        tilt_max: f64,
        c_min: f64,
        c_max: f64,
    },
    #[error("the {} {} would reach {value:.4e} {unit} at t = {t:.3} s, {:.3}x {}, {}{hint}", subject(*.axis), .quantity.name(), .value / .limit, against(*.quantity, *.limit, *.machine, .unit), slowest(*.floor, *.v, .path_unit))]
    Limit {
        /// The axis, or `None` for the chord error of the cutter path.
        axis: Option<char>,
        quantity: Quantity,
        unit: &'static str,
        value: f64,
        /// What the plan's setpoints may reach: the machine file's limit, less the check's
        /// reserve ([`nc_geom::limits::reserve`]) or at the planned jerk
        /// ([`AxisLimit::planned_jerk`]).
        limit: f64,
        /// The machine file's limit.
        machine: f64,
        t: f64,
        v: f64,
        path_unit: &'static str,
        hint: &'static str,
        /// `v` is the slowest feed the planner schedules ([`V_FLOOR`]); else the planner
        /// got no slower there.
        floor: bool,
    },
}

/// How slow the planner went where it refuses: to its floor, or only as far as it got (its
/// rounds of slowing ran out, or a lower ceiling no longer changed its plan there): a slower
/// pass might hold, but the program is refused, not crawled through.
fn slowest(floor: bool, v: f64, path_unit: &str) -> String {
    if floor {
        format!("even at the slowest feed the planner schedules there ({v:.3e} {path_unit}/s)")
    } else {
        format!("at {v:.3e} {path_unit}/s, the slowest the planner reached there")
    }
}

/// An axis's travel for a message: an axis without limits (a C that turns endlessly has
/// -inf .. inf) says so, not "-inf .. inf".
pub(crate) fn travel(min: f64, max: f64, unit: &str) -> String {
    match (min.is_finite(), max.is_finite()) {
        (true, true) => format!("{min} .. {max} {unit}"),
        (true, false) => format!("from {min} {unit}, no upper limit"),
        (false, true) => format!("up to {max} {unit}, no lower limit"),
        (false, false) => "no travel limit".to_string(),
    }
}

/// The limit a refusal measures against. Where the plan may use less than the machine
/// file's limit, both are named: a refusal that said "its limit of 2.94e5 mm/s^3" of an
/// axis whose file says 1e9 read as a misparsed file.
fn against(quantity: Quantity, limit: f64, machine: f64, unit: &str) -> String {
    if (limit - machine).abs() <= 1e-9 * machine.abs() {
        return format!("its limit of {limit:.4e} {unit}");
    }
    let why = match quantity {
        Quantity::Jerk => {
            format!("a plan's jerk is at most {JERK_RISE} x the acceleration per period")
        }
        _ => format!(
            "{:.1} %: the rest is kept for feed holds and overrides",
            100.0 * limit / machine
        ),
    };
    format!("the {limit:.4e} {unit} a plan may use of its limit of {machine:.4e} {unit} ({why})")
}

fn subject(axis: Option<char>) -> String {
    axis.map_or_else(|| "cutter path".to_string(), |c| format!("{c} axis"))
}

fn axis_name(kin: &MachineKinematics, j: usize) -> char {
    match (j, kin.tilt_kind()) {
        (0, _) => 'X',
        (1, _) => 'Y',
        (2, _) => 'Z',
        (3, Tilt::A) => 'A',
        (3, Tilt::B) => 'B',
        _ => 'C',
    }
}

fn refuse(path: &Path, kin: &MachineKinematics, cfg: &PlanConfig, v: &Violation) -> PlanError {
    let pos = if v.cycle == 0 {
        path.start_src
    } else {
        path.segments
            .get(v.segment)
            .map_or(path.start_src, |s| s.src)
    };
    let rotary = (3..5).contains(&v.axis);
    let conv = |x: f64| if rotary { x.to_degrees() } else { x };
    let base = if v.axis == 5 {
        "mm"
    } else if rotary {
        "deg"
    } else {
        "mm"
    };
    let kind = match v.quantity {
        Quantity::Branch => PlanErrorKind::Branch {
            tilt: axis_name(kin, 3),
            from_tilt: v.rotary[0][0].to_degrees(),
            to_tilt: v.rotary[1][0].to_degrees(),
            from_c: v.rotary[0][1].to_degrees(),
            to_c: v.rotary[1][1].to_degrees(),
            t: v.t,
            tilt_min: cfg.travel[3].0.to_degrees(),
            tilt_max: cfg.travel[3].1.to_degrees(),
            c_min: cfg.travel[4].0.to_degrees(),
            c_max: cfg.travel[4].1.to_degrees(),
        },
        Quantity::Travel => PlanErrorKind::Travel {
            axis: axis_name(kin, v.axis),
            unit: base,
            value: conv(v.value),
            min: conv(cfg.travel[v.axis].0),
            max: conv(cfg.travel[v.axis].1),
            t: v.t,
        },
        q => {
            let unit = match (q, rotary) {
                (Quantity::Velocity, true) => "deg/s",
                (Quantity::Velocity, false) => "mm/s",
                (Quantity::Acceleration, true) => "deg/s^2",
                (Quantity::Acceleration, false) => "mm/s^2",
                (Quantity::Jerk, true) => "deg/s^3",
                (Quantity::Jerk, false) => "mm/s^3",
                _ => base,
            };
            let rotary_only = path.segments.get(v.segment).is_some_and(|s| s.rotary_only);
            PlanErrorKind::Limit {
                axis: (v.axis < 5).then(|| axis_name(kin, v.axis)),
                quantity: q,
                unit,
                value: conv(v.value),
                limit: conv(v.limit),
                machine: conv(match (q, cfg.axes.get(v.axis)) {
                    (Quantity::Velocity, Some(ax)) => ax.velocity,
                    (Quantity::Acceleration, Some(ax)) => ax.acceleration,
                    (Quantity::Jerk, Some(ax)) => ax.jerk,
                    _ => v.limit,
                }),
                t: v.t,
                v: v.v,
                path_unit: if rotary_only { "deg" } else { "mm" },
                floor: v.v <= V_FLOOR * 1.01,
                hint: if v.v <= 0.0 {
                    ": the axis steps while the path stands still (a jump of the rotary solution between blocks)"
                } else if rotary {
                    ": the tool axis passes too close to the vertical, where C turns by up to 180 degrees"
                } else {
                    ""
                },
            }
        }
    };
    PlanError { pos, kind }
}

fn too_long(path: &Path, seg_start: &[f64], phases: &[Phase], duration: f64, ts: f64) -> PlanError {
    // Name the block the plan is in when the limit runs out.
    let t_max = MAX_CYCLES as f64 * ts;
    let i = phases.partition_point(|p| p.t0 <= t_max).saturating_sub(1);
    let s = phases.get(i).map_or(0.0, |p| p.at(t_max - p.t0).s);
    let k = seg_start.partition_point(|&x| x <= s).saturating_sub(1);
    PlanError {
        pos: path.segments.get(k).map_or(path.start_src, |seg| seg.src),
        kind: PlanErrorKind::TooLong {
            hours: duration / 3600.0,
            max_cycles: MAX_CYCLES,
            max_hours: t_max / 3600.0,
        },
    }
}

/// Why a parsed program cannot run on a machine: its geometry, or its plan.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProgramError {
    #[error(transparent)]
    Build(#[from] nc_geom::segment::BuildError),
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// The interpolation did not reach the program's end within [`MAX_CYCLES`] periods
    /// (a Taylor method creeping to the end): an error, never a silently short run.
    #[error("the interpolation did not reach the program's end within {0} periods")]
    Unfinished(u64),
}

/// The stations in `s0..=s1`, or the two around it: `st[a..b]`.
fn stations_over(st: &[Station], (s0, s1): (f64, f64)) -> (usize, usize) {
    let a = st.partition_point(|x| x.s < s0);
    let b = st.partition_point(|x| x.s <= s1);
    if a < b {
        (a, b)
    } else {
        (a.saturating_sub(1), (b + 1).min(st.len()))
    }
}

/// Lower the ceiling to `cap` at the stations in `s0..=s1`, or at the two around it, but
/// not below `floor`.
fn cap_stations(st: &mut [Station], s: (f64, f64), (cap, floor): (f64, f64), share: Option<f64>) {
    let (a, b) = stations_over(st, s);
    for x in &mut st[a..b] {
        // (Never raised: a joint's ceiling can be below the floor, `V_JOINT_FLOOR`.)
        x.vlim = x.vlim.min(cap).max(floor.min(x.vlim));
        if let Some(share) = share {
            x.share = x.share.min(share as f32);
        }
    }
}

/// Plan the feed over the whole path: stations, ceilings and S-curves, then the check of the
/// setpoints at the period ([`crate::verify::check`]). Where a limit is broken the ceiling
/// there drops by the factor the measurement asks for and the plan is made again; a limit
/// that slowing cannot bring within its bound (travel, a step at rest, a violation at the
/// slowest feed) refuses the program with the position of its block. The path is planned
/// in windows of bounded length ([`window`]), each checked as it is planned, by the
/// [`Planner`] a streamed program goes through, fed the whole path.
pub fn plan(
    path: &Path,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
) -> Result<FeedProfile, PlanError> {
    plan_whole(path, Planner::new(start_of(path), kin, cfg))
}

/// [`plan`] with windows that look ahead just `reach` (path units) past what they commit,
/// however much the stop at their end slows the plan: short windows for the tests, which
/// stop and start more often, and must hold every limit all the same.
pub fn plan_looking_ahead(
    path: &Path,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    reach: f64,
) -> Result<FeedProfile, PlanError> {
    plan_whole(
        path,
        Planner::new(start_of(path), kin, cfg).looking_ahead(reach),
    )
}

/// A path's start, as [`Planner::new`] takes it.
pub fn start_of(path: &Path) -> (nc_geom::segment::Pose, SrcPos, Joints) {
    (path.start, path.start_src, path.start_joints)
}

/// The phases a [`Planner`] sends, collected; its segments let go.
#[derive(Default)]
pub struct Collect {
    pub phases: Vec<Phase>,
}

impl Sink for Collect {
    fn segment(&mut self, _: Segment) {}
    fn phases(&mut self, phases: &[Phase]) {
        self.phases.extend_from_slice(phases);
    }
}

/// Feed `planner` every segment of `path` and collect its plan as one profile.
pub fn plan_whole(path: &Path, mut planner: Planner) -> Result<FeedProfile, PlanError> {
    let mut sink = Collect::default();
    for seg in &path.segments {
        planner.push(seg.clone(), &mut sink)?;
    }
    let end = planner.finish(&mut sink)?;
    let mut seg_start = Vec::with_capacity(path.segments.len() + 1);
    let mut total = 0.0;
    for seg in &path.segments {
        seg_start.push(total);
        total += seg.length;
    }
    seg_start.push(total);
    Ok(FeedProfile {
        phases: sink.phases,
        seg_start,
        length: end.length,
        duration: end.duration,
        margins: end.margins,
    })
}

/// The dwells (`G04`) of segments `segs` as rest phases: a segment that waits starts at rest
/// (it is a stop), and the plan stays there for the dwell before it goes on; later phases
/// shift in time.
fn with_dwells(
    phases: Vec<Phase>,
    path: &Path,
    seg_start: &[f64],
    segs: core::ops::Range<usize>,
) -> Vec<Phase> {
    let mut waits = path.segments[segs.clone()]
        .iter()
        .zip(&seg_start[segs])
        .filter(|(seg, _)| seg.wait.dwell_s > 0.0)
        .map(|(seg, &at)| (at, seg.wait.dwell_s))
        .peekable();
    if waits.peek().is_none() {
        return phases;
    }
    let eps = 1e-9 * seg_start.last().copied().unwrap_or(0.0).max(1.0);
    let mut out = Vec::with_capacity(2 * phases.len());
    let mut shift = 0.0;
    for p in phases {
        while let Some(&(at, dwell)) = waits.peek() {
            if p.s0 < at - eps {
                break;
            }
            out.push(Phase {
                t0: p.t0 + shift,
                dur: dwell,
                s0: at,
                v0: 0.0,
                a0: 0.0,
                j: 0.0,
            });
            shift += dwell;
            waits.next();
        }
        out.push(Phase {
            t0: p.t0 + shift,
            ..p
        });
    }
    out
}

/// The S-curve phases through the stations' ceilings from station `from`, reached at time
/// `t0` at speed `v0` with no acceleration (a joint, or the start), to station `last`, where
/// the path comes to rest. None if the stations ahead cannot be reached from `v0`.
fn schedule(
    st: &[Station],
    starts: &[usize],
    cfg: &PlanConfig,
    (from, t0, v0): (usize, f64, f64),
    last: usize,
) -> Option<Vec<Phase>> {
    // Critical points: (station index, speed).
    let mut crit: Vec<(usize, f64)> = vec![(from, v0)];
    // The joints walked in step with the stations (a search per station over the whole
    // program's joints made the plan n log n).
    let mut joint = starts.partition_point(|&x| x <= from);
    // What the rates allow the path (`limits::rates_acc`) on the stretch leaving the last
    // critical point, and on the stretch arriving at station i + 1.
    let acc = |r: &Rates| limits::rates_acc(r, cfg);
    let mut at_crit = acc(&st[from].after);
    for i in from + 1..last {
        while starts.get(joint).is_some_and(|&x| x < i) {
            joint += 1;
        }
        let is_joint = starts.get(joint) == Some(&i);
        let is_min = st[i].vlim < st[i - 1].vlim && st[i].vlim <= st[i + 1].vlim;
        let (next, after) = (acc(&st[i + 1].before), acc(&st[i].after));
        // The last station before the rates allow the path RATES_JUMP times less than on
        // the stretch leaving the last critical point (a tool coming onto the vertical), or
        // the first where they allow it that much more (leaving it): the ramps on either
        // side are not held to the other's limits. Measured from the last critical point,
        // not the station before: the rates of a block that ends on the vertical grow like
        // one over the distance to its end, and stations dense enough to resolve them
        // never see a jump. (From its leaving side: a joint's arriving side is the block
        // before, and a move whose rates jump at its start had its next station taken for
        // a fall, a critical point at its ceiling that the caps could not lower.)
        let is_edge = limits::rates_jump(at_crit, next) || limits::rates_jump(after, at_crit);
        if is_joint || is_min || is_edge {
            crit.push((i, st[i].vlim));
            at_crit = after;
        }
    }
    crit.push((last, 0.0));

    let mut phases = Vec::new();
    for round in 0..ROUNDS_MAX {
        // Every speed a section can have: its stations' ceilings, and its ends' speeds (the
        // window's start is at the committed speed, which a ceiling lowered since may be
        // below).
        let vmax: Vec<f64> = crit
            .windows(2)
            .map(|w| {
                st[w[0].0..=w[1].0]
                    .iter()
                    .map(|x| x.vlim)
                    .fold(w[0].1.max(w[1].1), f64::max)
            })
            .collect();
        let limits: Vec<Ramps> = crit
            .windows(2)
            .zip(&vmax)
            .map(|(w, &v)| section_ramps(st, w[0], w[1], v, cfg))
            .collect();
        // Backward then forward: every point's speed reachable within its sections (a
        // slow-down by the ramp into the section's end, a speed-up by the one from its
        // start).
        for k in (0..crit.len() - 1).rev() {
            let len = st[crit[k + 1].0].s - st[crit[k].0].s;
            let (a, j) = limits[k].end;
            crit[k].1 = crit[k].1.min(reachable(crit[k + 1].1, len, a, j));
        }
        // The start's speed is the committed plan's: it cannot drop. (A rounding's worth
        // is given back; the setpoint check measures the join either way.)
        if crit[0].1 < v0 * (1.0 - 1e-12) {
            return None;
        }
        crit[0].1 = v0;
        for k in 1..crit.len() {
            let len = st[crit[k].0].s - st[crit[k - 1].0].s;
            let (a, j) = limits[k - 1].start;
            crit[k].1 = crit[k].1.min(reachable(crit[k - 1].1, len, a, j));
        }
        phases.clear();
        let mut t = t0;
        let mut inserts = Vec::new();
        for (k, w) in crit.windows(2).enumerate() {
            let ((ia, va), (ib, vb)) = (w[0], w[1]);
            let first = phases.len();
            t = push_section(
                &mut phases,
                t,
                st[ia].s,
                (va, vb),
                st[ib].s - st[ia].s,
                vmax[k],
                limits[k],
            );
            let sec = &phases[first..];
            let vc = sec.iter().map(|p| p.v0).fold(va.max(vb), f64::max);
            let mut worst: Option<(usize, f64)> = None;
            for (i, x) in st.iter().enumerate().take(ib).skip(ia + 1) {
                if x.vlim >= vc {
                    continue;
                }
                let excess = speed_at(sec, x.s) - x.vlim;
                if excess > 1e-9 * x.vlim.max(1.0) {
                    if round >= ROUNDS_WORST_ONLY {
                        inserts.push(i);
                    } else if worst.is_none_or(|(_, e)| excess > e) {
                        worst = Some((i, excess));
                    }
                }
            }
            inserts.extend(worst.map(|w| w.0));
        }
        if inserts.is_empty() {
            break;
        }
        for i in inserts {
            let pos = crit.partition_point(|c| c.0 < i);
            crit.insert(pos, (i, st[i].vlim));
        }
    }
    Some(phases)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nc_geom::limits::AxisLimit;

    /// Only a refusal at the planner's floor says no slower feed is scheduled; one above it
    /// says how slow the planner got (a refusal at 5.9 mm/s once read as if no speed would
    /// do).
    #[test]
    fn a_refusal_says_whether_the_planner_reached_its_floor() {
        let limit = |v: f64, floor: bool| PlanErrorKind::Limit {
            axis: Some('Y'),
            quantity: Quantity::Jerk,
            unit: "mm/s^3",
            value: 50574.0,
            limit: 50000.0,
            machine: 50000.0,
            t: 4.066,
            v,
            path_unit: "mm",
            hint: "",
            floor,
        };
        let above = limit(5.924, false).to_string();
        assert!(
            above.contains("at 5.924e0 mm/s, the slowest the planner reached there")
                && !above.contains("even at the slowest feed"),
            "{above}"
        );
        let at = limit(V_FLOOR, true).to_string();
        assert!(at.contains("1.011x its limit of 5.0000e4 mm/s^3,"), "{at}");
        assert!(
            at.contains("even at the slowest feed the planner schedules there (1.000e-3 mm/s)"),
            "{at}"
        );
    }

    /// Where the plan may use less than the machine file says, a refusal names both: the
    /// mill with its jerks set to 1e9 is planned at 2.94e5 mm/s^3, and "its limit of
    /// 2.9400e5" read as if the file had been misread.
    #[test]
    fn a_refusal_names_the_planned_limit_beside_the_files() {
        let x = AxisLimit {
            velocity: 300.0,
            acceleration: 3000.0,
            jerk: 1e9,
        };
        let refusal = |quantity, unit, value, limit, machine| {
            PlanErrorKind::Limit {
                axis: Some('X'),
                quantity,
                unit,
                value,
                limit,
                machine,
                t: 1.0,
                v: 2.0,
                path_unit: "mm",
                hint: "",
                floor: false,
            }
            .to_string()
        };
        let msg = refusal(
            Quantity::Jerk,
            "mm/s^3",
            3.0e5,
            x.planned_jerk(1e-3),
            x.jerk,
        );
        assert!(
            msg.contains(
                "1.020x the 2.9400e5 mm/s^3 a plan may use of its limit of 1.0000e9 mm/s^3 \
                 (a plan's jerk is at most 0.098 x the acceleration per period)"
            ),
            "{msg}"
        );
        let share = nc_geom::limits::reserve(&x, 1e-3).1;
        let msg = refusal(
            Quantity::Acceleration,
            "mm/s^2",
            2900.0,
            3000.0 * share,
            3000.0,
        );
        assert!(
            msg.contains(
                "of its limit of 3.0000e3 mm/s^2 (95.0 %: the rest is kept for feed holds and overrides)"
            ),
            "{msg}"
        );
    }
}
