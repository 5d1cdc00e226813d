//! One window's planning rounds: schedule the stations' ceilings, check the plan at the
//! period, and where a limit breaks, cap the stations the violation holds and plan again.
//!
//! Where a round's caps changed nothing, the window escalates ([`Stuck`]): first what the
//! violations themselves ask for where the caps would hold a stretch to a crawl
//! ([`Remedy`]), then the caps widened to the stations on either side, then it is final (a
//! window that starts moving gives up, for a start from rest; one that starts at rest
//! refuses the program). Where the remedies end in a refusal, the window goes back to the
//! stations and plan from before them and on without them ([`Remedies`]).

use super::error::{refuse, too_long};
use super::remedy::{below_floor, cap_for, cap_widened, lower_share, widening, Remedy};
use super::schedule::{schedule, with_dwells};
use super::V_JOINT_FLOOR;
use super::{PlanError, Station, VERIFY_ROUNDS};
use crate::config::PlanConfig;
use crate::profile::FeedProfile;
use crate::verify::{check_from, Checked, Earlier, Quantity, Trace, MAX_CYCLES};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::limits::V_FLOOR;
use nc_geom::scurve::Phase;
use nc_geom::segment::Path;

/// Where a window starts: a joint station, the time the plan reaches it and its speed.
#[derive(Clone, Copy, Debug)]
pub(super) struct Start {
    pub(super) station: usize,
    pub(super) t: f64,
    pub(super) v: f64,
}

/// A window's checked plan: its phases (from `offset` in the profile), check and trace.
pub(super) struct WindowPlan {
    pub(super) offset: usize,
    pub(super) phases: Vec<Phase>,
    pub(super) checked: Checked,
    pub(super) trace: Trace,
}

impl WindowPlan {
    pub(super) fn earlier(&self) -> Earlier<'_> {
        Earlier {
            offset: self.offset,
            phases: &self.phases,
            checked: &self.checked,
            trace: &self.trace,
        }
    }
}

/// How far a window has escalated since its plan last changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stuck {
    /// The last round changed the plan.
    No,
    /// The caps changed nothing, and the remedies were tried (or may not be).
    Remedied,
    /// ... and then the caps were widened.
    Widened,
}

/// The remedies of [`Remedy`]: not tried yet, being tried (with the stations, the plan and
/// the round from before them), or given up.
enum Remedies {
    Allowed,
    Trying(Box<Saved>),
    Spent,
}

/// Where the window stood before the remedies.
struct Saved {
    stations: Vec<Station>,
    plan: Option<WindowPlan>,
    round: usize,
}

/// A window's rounds so far.
struct Rounds {
    /// The last round's checked plan, with its violations.
    last: Option<WindowPlan>,
    round: usize,
    stuck: Stuck,
    remedies: Remedies,
}

/// What one round came to.
enum Round {
    /// Caps were applied: plan again.
    Again,
    /// Planned and checked, within every limit.
    Planned(WindowPlan),
    /// It cannot go on: `None` where the window cannot keep its start's speed (only when
    /// that speed is not zero), or the program's refusal.
    Failed(Result<Option<WindowPlan>, PlanError>),
}

/// A window: where it starts and ends, what it follows in the profile.
struct Window<'w> {
    from: Start,
    end: usize,
    committed: usize,
    before: Option<&'w WindowPlan>,
}

/// What every window of one path shares.
pub(super) struct Windows<'a> {
    pub(super) path: &'a Path,
    pub(super) kin: &'a MachineKinematics,
    pub(super) cfg: &'a PlanConfig,
    pub(super) smooth: &'a [bool],
    pub(super) starts: &'a [usize],
}

impl Windows<'_> {
    /// Plan and check the window from `from` to station `end` (where it stops), after the
    /// profile's first `committed` phases. None where it cannot start at `from`'s speed
    /// (only when that speed is not zero).
    pub(super) fn window(
        &self,
        st: &mut [Station],
        from: Start,
        end: usize,
        profile: &mut FeedProfile,
        committed: usize,
        before: Option<&WindowPlan>,
    ) -> Result<Option<WindowPlan>, PlanError> {
        let w = Window {
            from,
            end,
            committed,
            before,
        };
        let mut r = Rounds {
            last: None,
            round: 0,
            stuck: Stuck::No,
            remedies: Remedies::Allowed,
        };
        loop {
            match self.round(st, &w, profile, &mut r) {
                Round::Again => {}
                Round::Planned(plan) => return Ok(Some(plan)),
                // The remedies ended in a refusal: back to where they began, and on without
                // them (as the window would have gone).
                Round::Failed(failed) => match core::mem::replace(&mut r.remedies, Remedies::Spent)
                {
                    Remedies::Trying(saved) => {
                        st.copy_from_slice(&saved.stations);
                        (r.last, r.round, r.stuck) = (saved.plan, saved.round, Stuck::Remedied);
                    }
                    _ => return failed,
                },
            }
        }
    }

    /// One round: schedule, check, and cap (or escalate) where a limit breaks.
    fn round(
        &self,
        st: &mut [Station],
        w: &Window<'_>,
        profile: &mut FeedProfile,
        r: &mut Rounds,
    ) -> Round {
        let (path, kin, cfg) = (self.path, self.kin, self.cfg);
        let from = w.from;
        let moving = from.v > 0.0;
        let Some(phases) = schedule(st, self.starts, cfg, (from.station, from.t, from.v), w.end)
        else {
            return Round::Failed(Ok(None));
        };
        let phases = with_dwells(phases, path, &profile.seg_start, self.segments(st, w));
        if let Some(prev) = &r.last {
            if prev.phases == phases {
                return self.unchanged(st, moving, r);
            }
        }
        let duration = phases.last().map_or(from.t, |p| p.t0 + p.dur);
        if duration.is_nan() || duration / cfg.period > MAX_CYCLES as f64 {
            let e = too_long(path, &profile.seg_start, &phases, duration, cfg.period);
            return Round::Failed(Err(e));
        }
        profile.phases.truncate(w.committed);
        profile.phases.extend_from_slice(&phases);
        profile.duration = duration;
        // The profile ends where the window stops (its position from then on).
        profile.length = st[w.end].s;
        let earlier = r.last.as_ref().or(w.before).map(WindowPlan::earlier);
        let (checked, trace) = check_from(path, profile, kin, cfg, self.smooth, earlier);
        if checked.violations.is_empty() {
            return Round::Planned(WindowPlan {
                offset: w.committed,
                phases,
                checked,
                trace,
            });
        }
        // Travel: slowing cannot help. Report the farthest excursion of the first block that
        // leaves the travel.
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
            return Round::Failed(Err(refuse(path, kin, cfg, worst)));
        }
        let s_from = st[from.station].s;
        let eps = 1e-9 * s_from.abs().max(1.0);
        for v in &checked.violations {
            let factor = match v.speed_factor() {
                Some(f)
                    if (v.v > V_FLOOR * 1.01 || below_floor(v) && v.v > V_JOINT_FLOOR * 1.01)
                        && r.round + 1 < VERIFY_ROUNDS
                        && f.is_finite() =>
                {
                    f
                }
                _ if moving => return Round::Failed(Ok(None)),
                _ if r.round + 1 < VERIFY_ROUNDS && lower_share(st, v) => continue,
                _ => return Round::Failed(Err(refuse(path, kin, cfg, v))),
            };
            if moving && v.s.1 < s_from + eps {
                // Behind the window's start: only a slower start would help.
                return Round::Failed(Ok(None));
            }
            cap_for(st, v, factor);
        }
        r.last = Some(WindowPlan {
            offset: w.committed,
            phases,
            checked,
            trace,
        });
        r.round += 1;
        r.stuck = Stuck::No;
        Round::Again
    }

    /// The caps changed nothing. A violation's stencil can reach past the stations it holds,
    /// onto a ramp the next station's ceiling sets (an X jerk 1.09x its limit at 11.3 mm/s
    /// past a station capped to 10.6): once, the caps go to the stations on either side
    /// too. Where that would hold the stretches to them to a crawl, first what the violation
    /// itself asks for ([`Remedy`]). Then the violation lies where this window cannot slow.
    fn unchanged(&self, st: &mut [Station], moving: bool, r: &mut Rounds) -> Round {
        let Some(prev) = &r.last else {
            return Round::Failed(Ok(None));
        };
        if r.stuck == Stuck::No && !matches!(r.remedies, Remedies::Spent) {
            r.stuck = Stuck::Remedied;
            let asked: Vec<Remedy> = prev
                .checked
                .violations
                .iter()
                .filter_map(|v| Remedy::for_crawl(st, v))
                .collect();
            if !asked.is_empty() {
                if matches!(r.remedies, Remedies::Allowed) {
                    r.remedies = Remedies::Trying(Box::new(Saved {
                        stations: st.to_vec(),
                        plan: r.last.take(),
                        round: r.round,
                    }));
                }
                for remedy in asked {
                    remedy.apply(st);
                }
                return Round::Again;
            }
        }
        if r.stuck != Stuck::Widened {
            r.stuck = Stuck::Widened;
            for v in &prev.checked.violations {
                if let Some(w) = widening(st, v) {
                    cap_widened(st, v, &w);
                }
            }
            return Round::Again;
        }
        Round::Failed(match moving {
            true => Ok(None),
            false => Err(refuse(
                self.path,
                self.kin,
                self.cfg,
                &prev.checked.violations[0],
            )),
        })
    }

    /// The segments a window spans.
    fn segments(&self, st: &[Station], w: &Window<'_>) -> core::ops::Range<usize> {
        let seg = |i: usize| self.starts.partition_point(|&x| x <= i).saturating_sub(1);
        let b = if w.end + 1 == st.len() {
            self.path.segments.len()
        } else {
            seg(w.end)
        };
        seg(w.from.station)..b
    }
}
