//! Limits of a feed hold, a stop and an override change: the path acceleration and jerk
//! a hold adds, and the bounds on the override's rate and its change that keep every
//! axis's acceleration and jerk within its limit (see the crate's text).

use nc_geom::limits::{AxisLimit, Margins, HOLD_RESERVE, JERK_RESERVE};

/// Feed-hold and stop limits, in path units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoldConfig {
    pub period: f64,
    /// Path acceleration and jerk a hold may add to the plan's.
    pub acc: f64,
    pub jerk: f64,
    /// The axes' limits (X Y Z tilt C), which a hold keeps (see the module's text).
    pub axes: [AxisLimit; 5],
}

/// Share of each axis's spare acceleration `A (1 - f k^2)` the override's rate may use; the
/// rest covers the difference between the continuous argument and setpoints one period
/// apart.
pub const HOLD_SHARE: f64 = 0.9;

/// Share of each axis's jerk limit the plan's own jerk and a hold's together may use; the
/// rest covers setpoints one period apart, and plan phases the check did not sample.
pub const HOLD_JERK_SHARE: f64 = 0.97;

// A plan from `plan` keeps its jerk within `1 - JERK_RESERVE` of the limit: the floor on
// what a hold is left must never cut into it.
const _: () = assert!(0.9 * HOLD_JERK_SHARE > (1.0 - JERK_RESERVE) * (1.0 + 1e-6));

/// Intervals of k in [`AxisHold::time_to_zero`]'s sum.
const STOP_STEPS: usize = 24;

/// Per axis, what bounds the override's rate `k'` and its change `k''` (see the crate's
/// text): `c = HOLD_SHARE * A / w` (infinite for an axis the plan does not move), `f` the
/// plan's acceleration fraction, and for the jerk the plan's largest speed `w`,
/// acceleration `a` and jerk `p` on the axis and the jerk `l` the two may share.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AxisHold {
    c: [f64; 5],
    f: [f64; 5],
    w: [f64; 5],
    a: [f64; 5],
    p: [f64; 5],
    l: [f64; 5],
    /// Least c and greatest f: a lower bound of the acceleration's rate bound, for the stop
    /// distance.
    c_min: f64,
    f_max: f64,
}

impl AxisHold {
    pub(crate) fn new(hold: &HoldConfig, margins: &Margins) -> Self {
        let w: [f64; 5] =
            core::array::from_fn(|j| (margins.velocity[j] * hold.axes[j].velocity).max(0.0));
        let c: [f64; 5] = core::array::from_fn(|j| {
            if w[j] > 0.0 && w[j].is_finite() {
                HOLD_SHARE * hold.axes[j].acceleration / w[j]
            } else {
                f64::INFINITY
            }
        });
        // A fraction at or above 1 would leave no room: k could never leave 1. A plan from
        // `plan` keeps HOLD_RESERVE, unless the jerk term is over half the limit (an axis
        // that reaches its acceleration within a period); then the floor keeps a stop
        // possible.
        // The plan's acceleration at any phase: what its check measured, plus the most the
        // phase can add ([`nc_geom::limits::reserve`]).
        let f: [f64; 5] = core::array::from_fn(|j| {
            let ax = &hold.axes[j];
            let jerk = ax.planned_jerk(hold.period);
            let f = margins.acceleration[j] + jerk * hold.period / (2.0 * ax.acceleration);
            if f.is_finite() {
                f.clamp(0.0, 1.0 - HOLD_RESERVE)
            } else {
                1.0 - HOLD_RESERVE
            }
        });
        let a: [f64; 5] = core::array::from_fn(|j| f[j] * hold.axes[j].acceleration);
        let l: [f64; 5] = core::array::from_fn(|j| HOLD_JERK_SHARE * hold.axes[j].jerk);
        // The plan's jerk: what its check measured (a share of the planned jerk, which
        // keeps JERK_RESERVE), never so much that nothing is left (a plan not from `plan`).
        let p: [f64; 5] = core::array::from_fn(|j| {
            let p = margins.jerk[j] * hold.axes[j].planned_jerk(hold.period);
            if p.is_finite() {
                p.max(0.0).min(0.9 * l[j])
            } else {
                0.9 * l[j]
            }
        });
        AxisHold {
            c,
            f,
            w,
            a,
            p,
            l,
            c_min: c.iter().copied().fold(f64::INFINITY, f64::min),
            f_max: f.iter().copied().fold(0.0, f64::max),
        }
    }

    /// The jerk axis `j` leaves a hold at override k: `l - p k^3`.
    fn budget(&self, j: usize, k: f64) -> f64 {
        (self.l[j] - self.p[j] * k * k * k).max(0.0)
    }

    /// Highest |dk/dt| that keeps every axis's acceleration within its limit at override k,
    /// and half its spare jerk for the term `3 k k' a` (at k and at any lower k).
    pub(crate) fn rate(&self, k: f64) -> f64 {
        let k2 = k * k;
        let acc = (0..5)
            .map(|j| self.c[j] * (1.0 - self.f[j] * k2).max(0.0))
            .fold(f64::INFINITY, f64::min);
        acc.min(self.jerk_rate(k))
    }

    /// The jerk's part of [`Self::rate`]: `budget / (6 k a)`, least over the axes.
    fn jerk_rate(&self, k: f64) -> f64 {
        (0..5)
            .map(|j| {
                let den = 6.0 * k * self.a[j];
                if den > 0.0 {
                    self.budget(j, k) / den
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Highest |d2k/dt2| at override k (and at any lower k): the other half of every axis's
    /// spare jerk, for the term `k'' w`.
    pub(crate) fn jerk(&self, k: f64) -> f64 {
        (0..5)
            .map(|j| {
                if self.w[j] > 0.0 {
                    self.budget(j, k) / (2.0 * self.w[j])
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Upper bound of the time to bring the override from `kk` to 0 at a rate of at most
    /// min(r, rate(k)). With `1 / min(x, y) <= 1 / x + 1 / y`: the integral of
    /// dk / min(r, c_min (1 - f_max k^2)) (closed form; it has a logarithmic singularity
    /// at k = 1 no sum would bound well), plus the sum over [`STOP_STEPS`] steps of k of
    /// dk / (the jerk's bound at the step's top), that bound falling as k rises.
    pub(crate) fn time_to_zero(&self, kk: f64, r: f64) -> f64 {
        if kk <= 0.0 {
            return 0.0;
        }
        if r.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return f64::INFINITY;
        }
        let dk = kk / STOP_STEPS as f64;
        let jerk: f64 = (1..=STOP_STEPS)
            .map(|i| dk / self.jerk_rate(i as f64 * dk).max(1e-12))
            .sum();
        self.acc_time(kk, r) + jerk
    }

    /// The integral of dk / min(r, c_min (1 - f_max k^2)) from 0 to `kk`.
    fn acc_time(&self, kk: f64, r: f64) -> f64 {
        let (c, f) = (self.c_min, self.f_max.min(1.0 - 1e-12));
        if !c.is_finite() {
            return kk / r;
        }
        if f <= 0.0 {
            return kk / r.min(c);
        }
        // Below k_star the axes allow at least r.
        let k_star = if r >= c {
            0.0
        } else {
            ((1.0 - r / c) / f).sqrt()
        };
        let sf = f.sqrt();
        let mut t = kk.min(k_star) / r;
        if kk > k_star {
            t += ((sf * kk).atanh() - (sf * k_star).atanh()) / (c * sf);
        }
        t
    }
}
