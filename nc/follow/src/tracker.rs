//! The override tracker: the factor `k` in [0, 1] by which plan time advances each period,
//! moved toward its target (1, the operator's override, or 0 to hold) with its rate limited
//! to what the path and every axis allow and the rate's own change limited (see the crate's
//! text).

use crate::hold::AxisHold;

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
    /// most `r Ts + jmax Ts^2`, its rate by `jmax Ts`); the stop is bounded from there, so
    /// that a hold that begins next period still fits. At rest the distance is next to
    /// nothing, so a hold creeps on toward the end of the data it has rather than wait for
    /// data that cannot come (the queue full of what it holds).
    pub(crate) fn stop_distance(
        &self,
        v: f64,
        rmax: f64,
        jmax: f64,
        ts: f64,
        axes: &AxisHold,
    ) -> f64 {
        let rise = self.r.max(0.0) + jmax * ts;
        let k_next = (self.k + self.r.max(0.0) * ts + jmax * ts * ts).min(1.0);
        let kpk = (k_next + rise * rise / (2.0 * jmax)).min(1.0);
        // The rate's ramps: up to rmax and back, or a triangle if it never gets there.
        let ramps = (2.0 * rmax / jmax).min(2.0 * (kpk / jmax).sqrt());
        let t = rise / jmax + axes.time_to_zero(kpk, rmax) + ramps + 3.0 * ts;
        v * kpk * t
    }

    /// The rate bound for the coming period toward `target`: the path's `rmax` and the
    /// axes' bound at the highest override this period can reach (the bound falls as k
    /// rises), so that it holds over the whole period. Within the period the rate moves
    /// linearly from r to the new rate, which is at most r toward a lower target, else at
    /// most one jerk step up, the path's bound and the axes' bound at the present k. (A
    /// bound of a whole jerk step, jmax Ts^2, would be most of the range where the plan is
    /// slow and jmax large: the rate would stay at the bound for k = 1 through the whole
    /// stop, far slower than the stop distance assumes.)
    pub(crate) fn rate_bound(
        &self,
        target: f64,
        rmax: f64,
        jmax: f64,
        ts: f64,
        axes: &AxisHold,
    ) -> f64 {
        let up = if target > self.k {
            (self.r + jmax * ts).min(rmax).min(axes.rate(self.k))
        } else {
            0.0
        };
        let k_hi = (self.k + ts * self.r.max(up).max(0.0)).min(1.0);
        rmax.min(axes.rate(k_hi))
    }

    /// Move the override one period `ts` toward `target` with rate <= rmax, rate change <=
    /// jmax. Where rmax has fallen below the present rate (it tightens as k nears 1), the
    /// rate drops to it at once: the axes' acceleration comes before the override's
    /// smoothness.
    pub(crate) fn track(&mut self, target: f64, rmax: f64, jmax: f64, ts: f64) {
        let d = target - self.k;
        let want = d.signum() * rmax.min((2.0 * jmax * d.abs()).sqrt());
        let dr = (want - self.r).clamp(-jmax * ts, jmax * ts);
        let r_new = (self.r + dr).clamp(-rmax, rmax);
        let mut k = self.k + 0.5 * (self.r + r_new) * ts;
        let mut r = r_new;
        if (target - k) * d <= 0.0 || d.abs() < 1e-12 {
            // Reached (or passed) the target this period.
            k = target;
            r = 0.0;
        }
        self.k = k.clamp(0.0, 1.0);
        self.r = r;
    }
}
