//! The path acceleration and jerk a section of the plan is allowed (step 4 of [`super`]).
//!
//! Along the path an axis moves with `q'' = q_s s'' + q_ss s'^2` and
//! `q''' = q_s s''' + 3 q_ss s' s'' + q_sss s'^3` (derivatives of the joints by path length
//! at the stations, `s'` the path speed). The path terms `q_s s''` and `q_s s'''` get what
//! the curvature terms leave of each axis's share, at the highest speed the section can
//! have at each station: a straight stretch gets the whole share, a curved one less. The
//! jerk's term `3 q_ss s' s''` is taken at the most `s' s''` an S-curve ramp can reach
//! there ([`speed_times_acc`]), not at the highest speed and acceleration at once.

use super::stations::{Rates, Station, AXIS_SHARE_LEAST};
use super::A_FLOOR;
use crate::config::PlanConfig;
use nc_geom::limits::AxisLimit;
use nc_geom::scurve::{change_time, Ramps};

/// Rounds of [`section_ramps`]: each narrows the stretch a ramp is limited over.
const RAMP_ROUNDS: usize = 3;

/// The rates of `stations[i]` on the stretch's side: a stretch starts after its first
/// station and ends before its last (only these can be joints of two segments).
fn side(stations: &[Station], i: usize) -> &Rates {
    if i == 0 {
        &stations[i].after
    } else {
        &stations[i].before
    }
}

/// Path acceleration and jerk allowed over `stations`, at most `speed(station)` there, in a
/// section no faster than `vmax`.
fn limits_over(
    stations: &[Station],
    cfg: &PlanConfig,
    speed: impl Fn(&Station) -> f64,
    vmax: f64,
) -> (f64, f64) {
    let acc = least_left(
        stations,
        cfg,
        &speed,
        cfg.path_acc,
        |ax| ax.acceleration,
        |r, j, v| r.d2(j) * v * v,
    );
    // The ramps' jerk is at most this pass's result, itself at most the path's (or the
    // floor): the bound at that jerk holds for any of them.
    let most = cfg.path_jerk.max(A_FLOOR);
    let jerk = least_left(
        stations,
        cfg,
        &speed,
        cfg.path_jerk,
        |ax| ax.planned_jerk(cfg.period),
        |r, j, v| 3.0 * r.d2(j) * speed_times_acc(v, vmax, acc, most) + r.d3(j) * v * v * v,
    );
    (acc, jerk)
}

/// The least, over `stations` and the axes that move there, of what each station's share of
/// `limit(axis)` leaves after `curving(rates, axis, speed)` (never less than the least
/// share, or the station's own share where the check lowered it below that), per unit of
/// `|dq/ds|`; at most `cap`, at least [`A_FLOOR`].
fn least_left(
    stations: &[Station],
    cfg: &PlanConfig,
    speed: &impl Fn(&Station) -> f64,
    cap: f64,
    limit: impl Fn(&AxisLimit) -> f64,
    curving: impl Fn(&Rates, usize, f64) -> f64,
) -> f64 {
    let mut out = cap;
    for (i, s) in stations.iter().enumerate() {
        let r = side(stations, i);
        // The speed only matters where the rates change (and costs a root to bound).
        let v = if r.curving() { speed(s) } else { 0.0 };
        let share = s.share as f64;
        for (j, ax) in cfg.axes.iter().enumerate() {
            if r.d1(j) > 1e-15 {
                let l = limit(ax);
                let left = (l * share - curving(r, j, v)).max(l * share.min(AXIS_SHARE_LEAST));
                out = out.min(left / r.d1(j));
            }
        }
    }
    out.max(A_FLOOR)
}

/// The most `s' |s''|` can be at a station the section passes at most at `v`, in a section
/// no faster than `vmax` whose ramps reach at most acceleration `acc` and change it at most
/// at `jerk`. A ramp at acceleration `x` is at least `x^2 / (2 jerk)` below the speed it
/// rises to or falls from (in each of its phases the acceleration must still fall to zero
/// or has risen from it), so `s' |s''| <= x min(v, vmax - x^2 / (2 jerk))` over `x` in
/// `0..=acc`: `x v` up to where the two meet, then `x (vmax - x^2 / (2 jerk))`, which
/// peaks at `x = sqrt(2 jerk vmax / 3)`. Near the feed the acceleration is low, and near
/// the highest acceleration the speed is.
fn speed_times_acc(v: f64, vmax: f64, acc: f64, jerk: f64) -> f64 {
    // (`max` and `min` rather than `clamp`, which panics on NaN: an infinite jerk at v = vmax.)
    let meet = (2.0 * jerk * (vmax - v).max(0.0)).sqrt().max(0.0);
    if acc <= meet {
        return acc * v;
    }
    let x = (2.0 * jerk * vmax / 3.0).sqrt().max(meet).min(acc);
    (x * (vmax - x * x / (2.0 * jerk)).max(0.0)).max(meet * v)
}

/// Path acceleration and jerk allowed over stations `a..=b` at their ceilings.
pub(super) fn section_limits(st: &[Station], a: usize, b: usize, cfg: &PlanConfig) -> (f64, f64) {
    let stations = &st[a..=b];
    let vmax = stations.iter().map(|x| x.vlim).fold(0.0, f64::max);
    limits_over(stations, cfg, |s| s.vlim, vmax)
}

/// What rates `r` allow the path at `share` without the curvature terms: no stretch of path that
/// holds them is allowed more.
fn bare_limits(r: &Rates, share: f64, cfg: &PlanConfig) -> (f64, f64) {
    let (mut acc, mut jerk) = (cfg.path_acc, cfg.path_jerk);
    for (j, ax) in cfg.axes.iter().enumerate() {
        if r.d1(j) > 1e-15 {
            acc = acc.min(ax.acceleration * share / r.d1(j));
            jerk = jerk.min(ax.planned_jerk(cfg.period) * share / r.d1(j));
        }
    }
    (acc.max(A_FLOOR), jerk.max(A_FLOOR))
}

/// Factor by which the path acceleration the rates allow may fall (or rise) from the last
/// critical point before the station before the fall (or the one at the rise) is made
/// one (`super::schedule`).
const RATES_JUMP: f64 = 8.0;

/// The path acceleration rates `r` allow at the axes' whole limits, without the curvature
/// terms: what [`rates_jump`] compares between the stretch leaving a critical point and
/// the stations after it.
pub(super) fn rates_acc(r: &Rates, cfg: &PlanConfig) -> f64 {
    bare_limits(r, 1.0, cfg).0
}

/// The path acceleration the rates allow drops from `from` to less than 1/[`RATES_JUMP`]
/// of it at `to` ([`rates_acc`] of each). A section's ramp is held to the least its
/// stations allow over the stretch it may cover, and a slow ramp covers the section: where
/// a block brought the tool onto the vertical, the rates at its end (C's, turning the tool
/// about the vertical) held the whole 14 mm block to 0.077 mm/s^2, where no axis came near
/// its limits: 42.2 s against 20.7 s as posted.
pub(super) fn rates_jump(from: f64, to: f64) -> bool {
    to * RATES_JUMP < from
}

/// An upper bound of the speed any motion starting at `v0` with no acceleration, within
/// acceleration and jerk `(a, j)`, has after `d`: the one that raises its acceleration at
/// `j` up to `a` and keeps it (mid-ramp a motion can be faster than a whole change to
/// acceleration zero reaches, `reachable`).
fn fastest(v0: f64, d: f64, (a, j): (f64, f64)) -> f64 {
    if d <= 0.0 {
        return v0;
    }
    // The jerk phase: t = a / j, over v0 t + j t^3 / 6.
    let t1 = a / j;
    let d1 = v0 * t1 + j * t1.powi(3) / 6.0;
    if d >= d1 {
        let v1 = v0 + 0.5 * a * t1;
        return (v1 * v1 + 2.0 * a * (d - d1)).sqrt();
    }
    // v0 t + j t^3 / 6 = d, convex and rising in t: Newton from above stays above the
    // root, so stopping early only raises the bound.
    let mut t = (6.0 * d / j).cbrt();
    if v0 > 0.0 {
        t = t.min(d / v0);
    }
    for _ in 0..8 {
        let f = v0 * t + j * t.powi(3) / 6.0 - d;
        let df = v0 + 0.5 * j * t * t;
        if f <= 0.0 || df <= 0.0 {
            break;
        }
        t -= f / df;
    }
    v0 + 0.5 * j * t * t
}

/// Limits of the two ramps of the section from station `a` at speed `va` to station `b` at
/// `vb` (speeds the planner's passes can only lower), with ceilings up to `vmax`.
///
/// - **Speeds.** The start ramp is allowed no more than station `a` allows bare, so no speed
///   in the section exceeds what that allows from `va` within the distance from `a`
///   ([`fastest`]); likewise back from `b`. The curvature terms are taken at that speed where it is below
///   the ceiling: near a slow corner they take little.
/// - **Stretches.** A ramp covers at most `vmax` times the time of a change from rest to
///   `vmax`, so each is limited only over the stations within that distance of its end of
///   the section: on a
///   long section whose tightest stretch lies in its middle, the ramps are not held to it.
///   The distance shrinks as the limits grow; each round's limits hold over the last
///   round's distance, which covers the next.
pub(super) fn section_ramps(
    st: &[Station],
    (a, va): (usize, f64),
    (b, vb): (usize, f64),
    vmax: f64,
    cfg: &PlanConfig,
) -> Ramps {
    let (s_a, s_b) = (st[a].s, st[b].s);
    let ua = bare_limits(&st[a].after, st[a].share as f64, cfg);
    let ub = bare_limits(&st[b].before, st[b].share as f64, cfg);
    let speed = |x: &Station| {
        x.vlim
            .min(fastest(va, x.s - s_a, ua))
            .min(fastest(vb, s_b - x.s, ub))
    };
    let stations = &st[a..=b];
    let mut ramps = Ramps::both(limits_over(stations, cfg, speed, vmax));
    for _ in 0..RAMP_ROUNDS {
        // No change between speeds up to vmax takes longer than vmax * its time from
        // rest (one from 0.3 vmax up to vmax covers more than one from rest).
        let d0 = vmax * change_time(vmax, ramps.start.0, ramps.start.1);
        let d1 = vmax * change_time(vmax, ramps.end.0, ramps.end.1);
        if d0 + d1 >= s_b - s_a {
            break;
        }
        // Up to the first station at or past the distance (and likewise back from b).
        let hi = stations.partition_point(|x| x.s < s_a + d0).min(b - a);
        let lo = stations
            .partition_point(|x| x.s <= s_b - d1)
            .saturating_sub(1);
        ramps = Ramps {
            start: limits_over(&stations[..=hi], cfg, speed, vmax),
            end: limits_over(&stations[lo..], cfg, speed, vmax),
        };
    }
    ramps
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::schedule::state_at;
    use crate::plan::stations::AXIS_SHARE;
    use nc_geom::scurve::{change_dist, push_section, reachable};
    use proptest::prelude::*;

    fn station(s: f64, vlim: f64, d1: [f64; 5], d2: [f64; 5], d3: [f64; 5]) -> Station {
        let r = Rates::new(d1, d2, d3);
        Station {
            s,
            vlim,
            before: r,
            after: r,
            share: AXIS_SHARE as f32,
        }
    }

    /// Equal but for the single-precision share (0.9 is 0.8999999762 in it).
    fn near(x: f64, y: f64) -> bool {
        (x - y).abs() <= 1e-7 * y.abs()
    }

    fn config() -> PlanConfig {
        let (mut cfg, _) = crate::fixtures::small_mill(0.001);
        (cfg.path_acc, cfg.path_jerk) = (1e6, 1e8);
        cfg
    }

    /// A straight stretch along X gets X's whole share; one the check found over its jerk
    /// gets the least (as every section did before the curvature terms were counted), or
    /// the station's own where the check lowered it below that.
    #[test]
    fn a_straight_stretch_gets_the_axis_share() {
        let cfg = config();
        let x = [1.0, 0.0, 0.0, 0.0, 0.0];
        let mut st: Vec<Station> = (0..=10)
            .map(|i| station(i as f64, 50.0, x, [0.0; 5], [0.0; 5]))
            .collect();
        // X's planned jerk: its limit less the hold's reserve.
        let jx = cfg.axes[0].planned_jerk(cfg.period);
        assert!(near(jx, 0.85 * 50000.0), "{jx}");
        let (a, j) = section_limits(&st, 0, 10, &cfg);
        assert!(near(a, 0.9 * 2500.0) && near(j, 0.9 * jx), "{a} {j}");
        st[5].share = AXIS_SHARE_LEAST as f32;
        let (a, j) = section_limits(&st, 0, 10, &cfg);
        assert!(near(a, 0.5 * 2500.0) && near(j, 0.5 * jx), "{a} {j}");
        // Where the jerk stayed over at the slowest feed the check lowers it further.
        st[5].share = 0.01;
        let (a, j) = section_limits(&st, 0, 10, &cfg);
        assert!(near(a, 0.01 * 2500.0) && near(j, 0.01 * jx), "{a} {j}");
    }

    /// A 40 mm section whose middle turns C fast: its ramps are not held to the middle, and
    /// a ramp up from a slow corner counts the curvature at the speeds it can have.
    #[test]
    fn ramps_are_limited_by_the_stretch_they_cover() {
        let cfg = config();
        let st: Vec<Station> = (0..=400)
            .map(|i| {
                let s = i as f64 * 0.1;
                let tight = (15.0..25.0).contains(&s);
                let d1 = [1.0, 0.0, 0.0, 0.0, if tight { 0.05 } else { 0.001 }];
                // X curves hard over the first 0.2 mm: at the ceiling its term would
                // take more than X's share.
                let d2 = [if s < 0.2 { 2.0 } else { 0.0 }, 0.0, 0.0, 0.0, 0.0];
                station(s, 50.0, d1, d2, [0.0; 5])
            })
            .collect();
        // The whole section is held to C's share in the middle.
        let whole = section_limits(&st, 0, 400, &cfg);
        let c = 0.9 * 900f64.to_radians() / 0.05;
        assert!(near(whole.0, c), "{whole:?}");
        let ramps = section_ramps(&st, (0, 0.0), (400, 0.0), 50.0, &cfg);
        assert!(ramps.start.1 > 2.0 * whole.1, "{ramps:?} against {whole:?}");
        assert!(ramps.end.1 > 2.0 * whole.1, "{ramps:?} against {whole:?}");
        assert!(near(ramps.end.0, 0.9 * 2500.0), "{ramps:?}");
        // From rest the speed within 0.2 mm stays low, and so does X's curvature term
        // there: more than the least share, which it would get at the ceiling.
        assert!(ramps.start.0 > 0.6 * 2500.0, "{ramps:?}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]
        /// Whatever a section's speeds, length and limits, at every point of its plan the
        /// speed times the acceleration is within [`speed_times_acc`] of that speed and its
        /// ramp's limits (the bound the jerk's curvature term is taken at); and an infinite
        /// jerk at the highest speed gives a bound, not a panic.
        #[test]
        fn no_section_s_speed_times_acceleration_exceeds_the_bound(
            (fa, fb) in (0.0f64..1.0, 0.0f64..1.0),
            len in 0.01f64..50.0,
            vmax in 1.0f64..200.0,
            (a0, j0, a1, j1) in (10.0f64..5000.0, 100.0f64..100_000.0, 10.0f64..5000.0, 100.0f64..100_000.0),
            same in any::<bool>(),
        ) {
            let (a1, j1) = if same { (a0, j0) } else { (a1, j1) };
            prop_assert!(speed_times_acc(vmax, vmax, a0, f64::INFINITY).is_finite());
            let ramps = Ramps { start: (a0, j0), end: (a1, j1) };
            // The passes leave the lower end reachable from the other.
            let (mut va, mut vb) = (fa * vmax, fb * vmax);
            if va > vb {
                va = va.min(reachable(vb, len, a1, j1));
            } else {
                vb = vb.min(reachable(va, len, a0, j0));
            }
            let mut phases = Vec::new();
            push_section(&mut phases, 0.0, 0.0, (va, vb), len, vmax, ramps);
            // Every phase sampled in time (a short ramp in a long section is not missed).
            // The start ramp only rises and the end ramp only falls: a point speeding up is
            // held to the start ramp's bound, one slowing down to the end ramp's.
            for p in &phases {
                for i in 0..=20 {
                    let m = p.at(p.dur * i as f64 / 20.0);
                    let (a, j) = if m.a >= 0.0 { (a0, j0) } else { (a1, j1) };
                    let bound = speed_times_acc(m.v, vmax, a, j);
                    prop_assert!(
                        m.v * m.a.abs() <= bound * (1.0 + 1e-9) + 1e-9,
                        "at {}: v {} a {} bound {bound}", m.s, m.v, m.a
                    );
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        /// Whatever the joints' rates along a section, the section planned with its ramps'
        /// limits keeps, at every station, each axis's path terms within what the
        /// curvature terms leave of its share at the speed the plan has there (or the
        /// least share): the narrowed stretches and the speed bound never let a ramp use
        /// more than the stations it crosses allow.
        #[test]
        fn a_section_planned_with_its_ramps_keeps_every_station_s_share(
            rates in proptest::collection::vec(
                (proptest::array::uniform5(0.0f64..1.5),
                 proptest::array::uniform5(0.0f64..0.5),
                 proptest::array::uniform5(0.0f64..2.0)), 4..12),
            len in 0.5f64..40.0,
            vmax in 5.0f64..150.0,
            (fa, fb) in (0.0f64..1.0, 0.0f64..1.0),
        ) {
            let cfg = config();
            let n = 200;
            // Rates in stretches of the section, each held over a run of stations.
            let st: Vec<Station> = (0..=n)
                .map(|i| {
                    let (d1, d2, d3) = rates[i * rates.len() / (n + 1)];
                    station(len * i as f64 / n as f64, vmax, d1, d2, d3)
                })
                .collect();
            // Speeds the passes would leave: the lower end reachable from the other.
            let (mut va, mut vb) = (fa * vmax, fb * vmax);
            let first = section_ramps(&st, (0, va), (n, vb), vmax, &cfg);
            if va > vb {
                va = va.min(reachable(vb, len, first.end.0, first.end.1));
            } else {
                vb = vb.min(reachable(va, len, first.start.0, first.start.1));
            }
            let ramps = section_ramps(&st, (0, va), (n, vb), vmax, &cfg);
            let need = if va > vb { ramps.end } else { ramps.start };
            prop_assert!(change_dist(va, vb, need.0, need.1) <= len * (1.0 + 1e-12));
            let mut phases = Vec::new();
            push_section(&mut phases, 0.0, 0.0, (va, vb), len, vmax, ramps);
            for (i, x) in st.iter().enumerate() {
                let (p, tau) = state_at(&phases, x.s).expect("a phase at every station");
                let m = p.at(tau);
                let r = side(&st, i);
                for (j, ax) in cfg.axes.iter().enumerate() {
                    let acc_left = (ax.acceleration * AXIS_SHARE - r.d2(j) * m.v * m.v)
                        .max(ax.acceleration * AXIS_SHARE_LEAST);
                    prop_assert!(
                        r.d1(j) * m.a.abs() <= acc_left * (1.0 + 1e-9) + 1e-9,
                        "station {i} axis {j}: a {} v {} {ramps:?}", m.a, m.v
                    );
                    let jerk = ax.planned_jerk(cfg.period);
                    let jerk_left = (jerk * AXIS_SHARE
                        - 3.0 * r.d2(j) * m.v * m.a.abs()
                        - r.d3(j) * m.v.powi(3))
                    .max(jerk * AXIS_SHARE_LEAST);
                    prop_assert!(
                        r.d1(j) * p.j.abs() <= jerk_left * (1.0 + 1e-9) + 1e-9,
                        "station {i} axis {j}: j {} a {} v {} {ramps:?}", p.j, m.a, m.v
                    );
                }
            }
        }
    }
}
