//! Planning in windows of bounded length, the planner's look-ahead.
//!
//! A window runs from a joint where the plan so far arrives (its speed there, no
//! acceleration) over [`COMMIT_STOPS`] + 1 stopping distances of the path's top speed, and
//! ends at rest: whatever lies beyond it, the window's plan is one the machine can follow
//! to a stop. The window is scheduled and checked at the period (`crate::verify`, resuming
//! at the committed plan's last mark), and capped and planned again where a limit breaks,
//! as the whole path was. Then the plan up to the first joint past [`COMMIT_STOPS`]
//! stopping distances is final, and the next window starts there. Since the next window
//! reaches at least as far ahead as this one did, it can always keep that speed in
//! principle; where its check or its stations say otherwise (a cap that needs a slower
//! start), the previous window's own plan, already checked to its stop, is taken as it
//! is and the next window starts from rest there: a stop the program did not ask for, but
//! never a limit broken. A window that starts at rest and cannot hold a limit refuses the
//! program, as before.
//!
//! Every window costs time in proportion to its own length, so the plan is linear in the
//! program; and a window needs nothing from the path behind its start but the check's
//! last mark, the ground for planning a program as it streams in.

use super::{
    refuse, schedule, section_limits, stations, too_long, with_dwells, FeedProfile, PlanConfig,
    PlanError, Station, CAP_MARGIN, VERIFY_ROUNDS, V_FLOOR,
};
use crate::kinematics::MachineKinematics;
use crate::scurve::{change_dist, reachable, Phase};
use crate::segment::Path;
use crate::verify::{check_from, Checked, Earlier, Margins, Quantity, Trace, MAX_CYCLES};

/// Stopping distances from the top speed that a window commits; one more lies ahead of
/// what it commits.
const COMMIT_STOPS: f64 = 3.0;

/// Where a window starts: a joint station, the time the plan reaches it and its speed.
#[derive(Clone, Copy, Debug)]
struct Start {
    station: usize,
    t: f64,
    v: f64,
}

/// A window's checked plan: its phases (from `offset` in the profile), check and trace.
struct WindowPlan {
    offset: usize,
    phases: Vec<Phase>,
    checked: Checked,
    trace: Trace,
}

impl WindowPlan {
    fn earlier(&self) -> Earlier<'_> {
        Earlier {
            offset: self.offset,
            phases: &self.phases,
            checked: &self.checked,
            trace: &self.trace,
        }
    }
}

/// The look-ahead distance: a stop from the highest ceiling of any station, at the path's
/// acceleration and jerk shared as the sections share them (`super::section_limits`).
fn reach(st: &[Station], cfg: &PlanConfig) -> f64 {
    let vtop = st.iter().map(|s| s.vlim).fold(0.0, f64::max);
    let (mut a, mut j) = (cfg.path_acc, cfg.path_jerk);
    for (k, ax) in cfg.axes.iter().enumerate().take(3) {
        let dq = st.iter().map(|s| s.dq[k]).fold(0.0, f64::max);
        if dq > 1e-15 {
            a = a.min(ax.acceleration / (2.0 * dq));
            j = j.min(ax.jerk / (2.0 * dq));
        }
    }
    change_dist(vtop, 0.0, a.max(1e-3), j.max(1e-3))
}

/// The first joint after joint `starts[kc]` far enough ahead that a stop there does not
/// slow the plan at `starts[kc]`: going back from it at rest (the backward pass, over the
/// joints), the speed reaches a joint's own ceiling before `starts[kc]`. Looked for at
/// `reach`, twice that, and so on; the last station if the path ends first.
fn window_end(
    st: &[Station],
    starts: &[usize],
    cfg: &PlanConfig,
    kc: usize,
    reach: f64,
    fixed: bool,
) -> usize {
    let last = st.len() - 1;
    let c = starts[kc];
    let mut reach = reach.max(1e-9);
    loop {
        let ke = kc + 1 + starts[kc + 1..].partition_point(|&i| st[i].s < st[c].s + reach);
        let Some(&end) = starts.get(ke) else {
            return last;
        };
        if fixed {
            return end;
        }
        let mut v = 0.0;
        for k in (kc..ke).rev() {
            let (a, b) = (starts[k], starts[k + 1]);
            let (acc, jerk) = section_limits(st, a, b, cfg);
            v = reachable(v, st[b].s - st[a].s, acc, jerk);
            if v >= st[a].vlim {
                return end;
            }
        }
        reach *= 2.0;
    }
}

/// [`super::plan`]; with `fixed_reach`, every window looks ahead just that far (path
/// units) however much slower its stop makes the plan (for the tests).
pub(super) fn plan_in_windows(
    path: &Path,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    fixed_reach: Option<f64>,
) -> Result<FeedProfile, PlanError> {
    let mut seg_start = Vec::with_capacity(path.segments.len() + 1);
    let mut total = 0.0;
    for seg in &path.segments {
        seg_start.push(total);
        total += seg.length;
    }
    seg_start.push(total);
    let smooth = crate::verify::smooth_junctions(path, kin, cfg);
    let mut profile = FeedProfile {
        phases: Vec::new(),
        seg_start,
        length: total,
        duration: 0.0,
        margins: Margins::default(),
    };
    if path.segments.is_empty() {
        // Nothing to plan; the start pose itself is checked (its travel).
        let (checked, _) = check_from(path, &profile, kin, cfg, &smooth, None);
        return match checked.violations.first() {
            None => Ok(FeedProfile {
                margins: checked.margins,
                ..profile
            }),
            Some(v) => Err(refuse(path, kin, cfg, v)),
        };
    }
    let (mut st, starts) = stations(path, kin, cfg);
    let reach_min = fixed_reach.unwrap_or_else(|| reach(&st, cfg));
    let mut ahead = reach_min;
    let last = st.len() - 1;
    let w = Windows {
        path,
        kin,
        cfg,
        smooth: &smooth,
        starts: &starts,
    };
    let mut from = Start {
        station: 0,
        t: 0.0,
        v: 0.0,
    };
    // Phases before this index are final.
    let mut committed = 0;
    // The last window's checked plan, which covers the committed phases and goes on to a
    // stop at `stop`.
    let mut before: Option<WindowPlan> = None;
    let mut stop = from;
    loop {
        let s0 = st[from.station].s;
        // Joints after the start; the commit point and the window's end are joints.
        let k0 = starts.partition_point(|&i| i <= from.station);
        let kc = k0 + starts[k0..].partition_point(|&i| st[i].s < s0 + COMMIT_STOPS * ahead);
        let (c, end) = match starts.get(kc) {
            Some(&c) => {
                // Looked for from half the last window's look-ahead: the path ahead is
                // likely much like the path behind.
                let from_reach = match fixed_reach {
                    Some(r) => r,
                    None => (0.5 * ahead).max(reach_min),
                };
                let end = window_end(&st, &starts, cfg, kc, from_reach, fixed_reach.is_some());
                // The next window commits in proportion to what this one looked ahead.
                ahead = (st[end].s - st[c].s).max(reach_min);
                (c, end)
            }
            None => (last, last),
        };
        match w.window(&mut st, from, end, &mut profile, committed, before.as_ref())? {
            Some(mut done) => {
                if end == last {
                    profile.margins = done.checked.margins;
                    return Ok(profile);
                }
                // Commit up to the joint c; the window's stop is the fallback.
                let eps = 1e-9 * total.max(1.0);
                let split = done.phases.partition_point(|p| p.s0 < st[c].s - eps);
                let next = done.phases[split];
                committed = done.offset + split;
                stop = Start {
                    station: end,
                    t: profile.duration,
                    v: 0.0,
                };
                from = Start {
                    station: c,
                    t: next.t0,
                    v: next.v0,
                };
                done.trace.forget_before(next.t0);
                before = Some(done);
            }
            None => {
                // The window cannot keep the committed speed: take the last window's plan
                // through its stop, and go on from rest there.
                let done = before
                    .as_ref()
                    .expect("a window that starts moving follows a checked one");
                profile.phases.truncate(done.offset);
                profile.phases.extend_from_slice(&done.phases);
                profile.duration = stop.t;
                profile.length = st[stop.station].s;
                committed = profile.phases.len();
                from = stop;
            }
        }
    }
}

/// What every window of one path shares.
struct Windows<'a> {
    path: &'a Path,
    kin: &'a MachineKinematics,
    cfg: &'a PlanConfig,
    smooth: &'a [bool],
    starts: &'a [usize],
}

impl Windows<'_> {
    /// Plan and check the window from `from` to station `end` (where it stops), after the
    /// profile's first `committed` phases. None where it cannot start at `from`'s speed
    /// (only when that speed is not zero).
    fn window(
        &self,
        st: &mut [Station],
        from: Start,
        end: usize,
        profile: &mut FeedProfile,
        committed: usize,
        before: Option<&WindowPlan>,
    ) -> Result<Option<WindowPlan>, PlanError> {
        let (path, kin, cfg) = (self.path, self.kin, self.cfg);
        let moving = from.v > 0.0;
        let s_from = st[from.station].s;
        let eps = 1e-9 * st[st.len() - 1].s.max(1.0);
        let segs = {
            let seg = |i: usize| self.starts.partition_point(|&x| x <= i).saturating_sub(1);
            let b = if end + 1 == st.len() {
                path.segments.len()
            } else {
                seg(end)
            };
            seg(from.station)..b
        };
        let mut last: Option<WindowPlan> = None;
        let mut round = 0;
        loop {
            let Some(phases) = schedule(st, self.starts, cfg, (from.station, from.t, from.v), end)
            else {
                return Ok(None);
            };
            let phases = with_dwells(phases, path, &profile.seg_start, segs.clone());
            if let Some(prev) = &last {
                if prev.phases == phases {
                    // The caps changed nothing: the violation lies where this window
                    // cannot slow.
                    return match moving {
                        true => Ok(None),
                        false => Err(refuse(path, kin, cfg, &prev.checked.violations[0])),
                    };
                }
            }
            let duration = phases.last().map_or(from.t, |p| p.t0 + p.dur);
            if duration.is_nan() || duration / cfg.period > MAX_CYCLES as f64 {
                return Err(too_long(
                    path,
                    &profile.seg_start,
                    &phases,
                    duration,
                    cfg.period,
                ));
            }
            profile.phases.truncate(committed);
            profile.phases.extend_from_slice(&phases);
            profile.duration = duration;
            // The profile ends where the window stops (its position from then on).
            profile.length = st[end].s;
            let earlier = last.as_ref().or(before).map(WindowPlan::earlier);
            let (checked, trace) = check_from(path, profile, kin, cfg, self.smooth, earlier);
            if checked.violations.is_empty() {
                return Ok(Some(WindowPlan {
                    offset: committed,
                    phases,
                    checked,
                    trace,
                }));
            }
            // Travel: slowing cannot help. Report the farthest excursion of the first block
            // that leaves the travel.
            let travel = checked
                .violations
                .iter()
                .filter(|v| v.quantity == Quantity::Travel);
            if let Some(first) = travel.clone().next() {
                let worst = travel
                    .filter(|v| v.segment == first.segment)
                    .fold(first, |w, v| {
                        if (v.value - v.limit).abs() > (w.value - w.limit).abs() {
                            v
                        } else {
                            w
                        }
                    });
                return Err(refuse(path, kin, cfg, worst));
            }
            for v in &checked.violations {
                let factor = match v.speed_factor() {
                    Some(f)
                        if v.v > V_FLOOR * 1.01 && round + 1 < VERIFY_ROUNDS && f.is_finite() =>
                    {
                        f
                    }
                    _ if moving => return Ok(None),
                    _ => return Err(refuse(path, kin, cfg, v)),
                };
                if moving && v.s.1 < s_from + eps {
                    // Behind the window's start: only a slower start would help.
                    return Ok(None);
                }
                super::cap_stations(st, v.s, v.v * factor * CAP_MARGIN);
            }
            last = Some(WindowPlan {
                offset: committed,
                phases,
                checked,
                trace,
            });
            round += 1;
        }
    }
}
