//! Limits of a feed hold, a stop and an override change: the path acceleration and jerk
//! a hold adds, and the bound on the override's rate that keeps every axis's acceleration
//! within its limit (see the crate's text).

use crate::queue::{LOOKAHEAD, MAX_DEPTH, MIN_DEPTH};
use nc_geom::limits::{AxisLimit, Margins, HOLD_RESERVE};

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

/// The length each chunk must have (`nc_plan::stream::chunk_length`) for a plan no faster
/// than `vmax` whose margins are at most `margins`:
/// what a program streamed before it is planned is cut by (its speed cap and
/// `nc_plan::verify::ceiling`).
pub fn stop_length(vmax: f64, margins: &Margins, hold: &HoldConfig, depth: usize) -> f64 {
    if vmax <= 0.0 || !vmax.is_finite() {
        return 0.0;
    }
    let axes = AxisHold::new(hold, margins);
    let held = depth.clamp(MIN_DEPTH, MAX_DEPTH).min(LOOKAHEAD);
    let spare = held.saturating_sub(2).max(1) as f64;
    1.25 * stop_bound(hold, &axes, vmax) / spare
}

/// Per axis, the rate bound's two factors: `c = HOLD_SHARE * A / w` (infinite for an axis
/// the plan does not move) and `f`, the plan's acceleration fraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AxisHold {
    c: [f64; 5],
    f: [f64; 5],
    /// Least c and greatest f: a lower bound of the rate bound, for the stop distance.
    c_min: f64,
    f_max: f64,
}

impl AxisHold {
    pub(crate) fn new(hold: &HoldConfig, margins: &Margins) -> Self {
        let c: [f64; 5] = core::array::from_fn(|j| {
            let ax = &hold.axes[j];
            let w = margins.velocity[j] * ax.velocity;
            if w > 0.0 && w.is_finite() {
                HOLD_SHARE * ax.acceleration / w
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
        AxisHold {
            c,
            f,
            c_min: c.iter().copied().fold(f64::INFINITY, f64::min),
            f_max: f.iter().copied().fold(0.0, f64::max),
        }
    }

    /// Highest |dk/dt| that keeps every axis's acceleration within its limit at override k
    /// (and at any lower k).
    pub(crate) fn rate(&self, k: f64) -> f64 {
        let k2 = k * k;
        (0..5)
            .map(|j| self.c[j] * (1.0 - self.f[j] * k2).max(0.0))
            .fold(f64::INFINITY, f64::min)
    }

    /// Upper bound of the time to bring the override from `kk` to 0 at a rate of at most
    /// min(r, rate(k)): the integral of dk / min(r, c_min (1 - f_max k^2)).
    pub(crate) fn time_to_zero(&self, kk: f64, r: f64) -> f64 {
        let (c, f) = (self.c_min, self.f_max.min(1.0 - 1e-12));
        if !c.is_finite() || kk <= 0.0 {
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

/// Upper bound of the distance the follower needs to stop from the full plan at speed `v`:
/// [`super::Follower`]'s stop distance at override 1, its rate as high as it may be.
pub(crate) fn stop_bound(hold: &HoldConfig, axes: &AxisHold, v: f64) -> f64 {
    let ts = hold.period;
    let rmax = hold.acc / v;
    let jmax = hold.jerk / v;
    let rise = rmax + jmax * ts;
    let ramps = (2.0 * rmax / jmax).min(2.0 * (1.0 / jmax).sqrt());
    let t = rise / jmax + axes.time_to_zero(1.0, rmax) + ramps + 3.0 * ts;
    v * t
}
