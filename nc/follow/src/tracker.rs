//! The override tracker: the factor `k` in [0, 1] by which plan time advances each period,
//! moved toward its target (1, the operator's override, or 0 to hold) with its rate limited
//! to what the path and every axis allow and the rate's own change limited (see the crate's
//! text).

use crate::hold::AxisHold;

#[cfg(test)]
mod tests;

/// The override and its rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Tracker {
    pub(crate) k: f64,
    pub(crate) r: f64,
}

impl Tracker {
    /// Following the plan at full speed.
    pub(crate) fn new() -> Self {
        Tracker { k: 1.0, r: 0.0 }
    }

    /// Held at once: nothing moves.
    pub(crate) fn rest(&mut self) {
        self.k = 0.0;
        self.r = 0.0;
    }

    pub(crate) fn at_rest(&self) -> bool {
        self.k == 0.0 && self.r == 0.0
    }

    /// Distance needed to bring the override to 0 from its current state, travelling at
    /// most `v` (a bound, not the exact figure), at period `ts`.
    ///
    /// The check runs before this period's step, which may still raise the override (by at
    /// most `r Ts + j Ts^2`, its rate by `j Ts`); the stop is bounded from there, so that a
    /// hold that begins next period still fits. At rest the distance is next to nothing, so
    /// a hold creeps on toward the end of the data it has rather than wait for data that
    /// cannot come (the queue full of what it holds).
    pub(crate) fn stop_distance(
        &self,
        v: f64,
        rmax: f64,
        jerk: Jerk,
        ts: f64,
        axes: &AxisHold,
    ) -> f64 {
        let step = jerk.at(axes, self.k);
        // Braking a rising rate, k rises: the least the axes allow, at k = 1.
        let low = jerk.at(axes, 1.0);
        let rise = self.r.max(0.0) + step * ts;
        let k_next = (self.k + self.r.max(0.0) * ts + step * ts * ts).min(1.0);
        let kpk = (k_next + rise * rise / (2.0 * low)).min(1.0);
        // The rate's ramps down to -rmax and back to 0, or a triangle if it never gets
        // there, at what the axes allow at kpk (the least over the stop).
        let j = jerk.at(axes, kpk);
        let ramps = 2.0 * (rmax / j).min((kpk / j).sqrt());
        let t = rise / low + axes.time_to_zero(kpk, rmax) + ramps + 3.0 * ts;
        v * kpk * t
    }

    /// The bounds of the rate for the coming period, from the path's `rmax` and the
    /// axes' ([`AxisHold::rate`], which falls as k rises): for a falling k, the axes' bound
    /// at the period's highest k; for a rising one, the bound where k would come to rest
    /// if the rate were braked at what the axes allow at k = 1.
    pub(crate) fn rate_bound(&self, rmax: f64, jerk: Jerk, ts: f64, axes: &AxisHold) -> Rates {
        // A falling k: the axes' bound at the highest k of the period (it grows as k falls).
        let down = rmax.min(axes.rate((self.k + ts * self.r.max(0.0)).min(1.0)));
        // A rising k: the highest rate `rc` below the bound where k would come to rest if
        // the rate were braked from `rc` at what the axes allow at k = 1 (`low`), after this
        // period: `k + (r + rc) Ts / 2 + rc^2 / 2 low`. Braking at `low` keeps that point
        // where it is, so the bound there never falls under the rate, and one step of
        // braking always meets it. The bound falls as `rc` rises: the set is an interval
        // from 0, found by bisection (bounded: 24 steps, to 6e-8 of the top).
        let low = jerk.at(axes, 1.0);
        let braked = |rc: f64| {
            let point = self.k + 0.5 * (self.r + rc) * ts + rc * rc / (2.0 * low);
            axes.rate(point.clamp(0.0, 1.0))
        };
        let top = rmax.min(axes.rate(self.k));
        if !top.is_finite() || top <= braked(top) {
            return Rates { down, up: top };
        }
        let (mut lo, mut hi) = (0.0, top);
        for _ in 0..24 {
            let mid = 0.5 * (lo + hi);
            if mid <= braked(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Rates { down, up: lo }
    }

    /// Move the override one period `ts` toward `target` with its rate within `rates` and
    /// its change within what the path and the axes allow at the period's highest k
    /// ([`Jerk::at`]), braking toward the target at what they allow at the target or here,
    /// whichever is less (the axes allow more as k falls). Where a bound has fallen below
    /// the present rate, the rate drops to it at once: the axes' acceleration comes before
    /// the override's smoothness. Returns the plan time the period covers, the integral of
    /// k over it (k quadratic within the period).
    pub(crate) fn track(
        &mut self,
        target: f64,
        rates: Rates,
        jerk: Jerk,
        ts: f64,
        axes: &AxisHold,
    ) -> f64 {
        let (k0, r0) = (self.k, self.r);
        let d = target - k0;
        let k_hi = (k0 + ts * r0.max(0.0) + jerk.path * ts * ts).min(1.0);
        let step = jerk.at(axes, k_hi);
        let brake_j = step.min(jerk.at(axes, target));
        // The rate from which braking at brake_j, a step a period, still stops at the
        // target: r^2 / 2j + r Ts within what is left after this period at the present rate.
        let left = (d.abs() - 0.5 * (r0 * d.signum()).max(0.0) * ts).max(0.0);
        let brake = brake_j * ((ts * ts + 2.0 * left / brake_j).sqrt() - ts);
        let toward = if d > 0.0 { rates.up } else { rates.down };
        let want = d.signum() * toward.min(brake.max(0.0));
        // (max and min, not clamp: no panic whatever the limits.)
        let dr = (want - r0).max(-step * ts).min(step * ts);
        let r_new = (r0 + dr).max(-rates.down).min(rates.up);
        let mut k = k0 + 0.5 * (r0 + r_new) * ts;
        let mut r = r_new;
        let mut covered = k0 * ts + r0 * ts * ts / 2.0 + (r_new - r0) * ts * ts / 6.0;
        // Reached (or passed) the target this period at a rate a step of brake_j ends. A
        // target that moved closer than the rate can brake for (a lower override while k
        // rises) is passed and come back to, not met with a step in the rate.
        let slow = r_new.abs() <= brake_j * ts;
        if ((target - k) * d <= 0.0 || d.abs() < 1e-12) && slow {
            k = target;
            r = 0.0;
            covered = 0.5 * (k0 + target) * ts;
        }
        // Never past 0 or 1: the plan is not run backwards nor above its speed.
        if !(0.0..=1.0).contains(&k) {
            k = if k > 1.0 { 1.0 } else { 0.0 };
            r = 0.0;
            covered = 0.5 * (k0 + k) * ts;
        }
        self.k = k;
        self.r = r;
        covered.max(0.0)
    }
}

/// The bounds of the override's rate for a period: of a falling k (`down`, as a magnitude)
/// and of a rising one (`up`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rates {
    pub(crate) down: f64,
    pub(crate) up: f64,
}

/// The change of the override's rate a period may make: the path's `path` (its jerk over
/// the hold's speed scale), and what the axes allow at k ([`AxisHold::jerk`]) times `cap`
/// (below 1 where a hold creeps on with a gentler jerk).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Jerk {
    pub(crate) path: f64,
    pub(crate) cap: f64,
}

impl Jerk {
    pub(crate) fn at(&self, axes: &AxisHold, k: f64) -> f64 {
        self.path.min(self.cap * axes.jerk(k))
    }
}
