//! Scheduling a stretch of stations: the jerk-limited S-curve sections between critical
//! points under the stations' ceilings (step 5 of [`super`]), the dwells put in, and the
//! ceilings capped where the check asks.

use super::limits::{self, section_ramps};
use super::stations::{Rates, Station};
use super::{ROUNDS_MAX, ROUNDS_WORST_ONLY};
use crate::config::PlanConfig;
use nc_geom::scurve::{push_section, reachable, Phase, Ramps};
use nc_geom::segment::Path;

/// The phase of `phases` that holds path position `s`, and the time into it (bisection).
pub(super) fn state_at(phases: &[Phase], s: f64) -> Option<(&Phase, f64)> {
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
pub(super) fn speed_at(phases: &[Phase], s: f64) -> f64 {
    state_at(phases, s).map_or(0.0, |(p, tau)| p.at(tau).v)
}

/// The stations in `s0..=s1`, or the two around it: `st[a..b]`.
pub(super) fn stations_over(st: &[Station], (s0, s1): (f64, f64)) -> (usize, usize) {
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
pub(super) fn cap_stations(
    st: &mut [Station],
    s: (f64, f64),
    (cap, floor): (f64, f64),
    share: Option<f64>,
) {
    let (a, b) = stations_over(st, s);
    for x in &mut st[a..b] {
        // (Never raised: a joint's ceiling can be below the floor, `V_JOINT_FLOOR`.)
        x.vlim = x.vlim.min(cap).max(floor.min(x.vlim));
        if let Some(share) = share {
            x.share = x.share.min(share as f32);
        }
    }
}

/// The dwells (`G04`) of segments `segs` as rest phases: a segment that waits starts at rest
/// (it is a stop), and the plan stays there for the dwell before it goes on; later phases
/// shift in time.
pub(super) fn with_dwells(
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
pub(super) fn schedule(
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
