//! The limits every plan and every setpoint is held to, and what a plan reports of them:
//! one axis's velocity, acceleration and jerk ([`AxisLimit`]), the share of them a plan may
//! use so that a hold or an override can still slow it down ([`reserve`]), and the margins
//! a plan's setpoint check measured ([`Margins`]). Shared by the planner, which holds a plan
//! to them, and the real-time follower, whose feed hold adds no more than they leave.

/// Limits of one machine axis, in mm or radians and seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisLimit {
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
}

/// The most acceleration a plan's jerk builds up on an axis in one period, as a share of the
/// axis's acceleration: see [`AxisLimit::planned_jerk`].
pub const JERK_RISE: f64 = 0.098;

/// Share of every axis's jerk a plan leaves unused, for a feed hold, a stop or an override
/// change. Slowing down along the path adds `3 k k' q'' + k'' q'` to an axis's jerk (k the
/// override, primes in time and plan time), so a plan at its jerk limit could not change
/// k at all while any axis accelerates. `nc_follow` spends what is left, and no more. It
/// costs machining time only where the plan is jerk-limited: docs/measurements.md says
/// how much on the README's programs.
pub const JERK_RESERVE: f64 = 0.15;

impl AxisLimit {
    /// The jerk a plan keeps to on this axis, and its setpoint check holds it to: the
    /// limit, or [`JERK_RISE`] times the acceleration per `period` where that is less. The
    /// check measures the acceleration at one phase of the period; a hold or an override
    /// shifts the phase, and between phases the acceleration differs by up to `J Ts / 2`,
    /// which the check keeps in reserve ([`reserve`]). A jerk that builds
    /// much of the acceleration within a period (a linear motor, or a jerk set huge to mean
    /// none, as LinuxCNC has none) left the ramps planned at 90 % of an acceleration the
    /// check allowed half of, and a plain raster was refused on its first ramp (the
    /// xyzac-trt-mill with every jerk 1e9: `the X axis acceleration would reach 2.6949e3
    /// mm/s^2 ... 1.797x its limit of 1.5000e3`). At this jerk the reserve leaves about
    /// 96 %: a ramp reaches the acceleration in ten periods or more. Of that, a plan uses all but
    /// [`JERK_RESERVE`].
    pub fn planned_jerk(&self, period: f64) -> f64 {
        self.jerk.min(JERK_RISE * self.acceleration / period) * (1.0 - JERK_RESERVE)
    }
}

/// Slowest speed the planner schedules where a ceiling would be lower (path units/s), so
/// that every section ends in finite time: the plan's "exact stop" at a kink passes the
/// kink at this speed, and its setpoint check holds there; but a joint where an axis's
/// rate jumps by more than this speed allows is passed slower (`nc_plan::plan::V_JOINT_FLOOR`).
pub const V_FLOOR: f64 = 1e-3;

/// The largest value of each quantity as a fraction of its limit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Margins {
    pub velocity: [f64; 5],
    pub acceleration: [f64; 5],
    pub jerk: [f64; 5],
    pub chord: f64,
    /// Setpoints checked (cycles of the plan).
    pub cycles: u64,
}

/// Share of every axis's velocity and acceleration a plan leaves unused. A feed hold, a
/// stop or an override change adds acceleration along the path in proportion to
/// `1 - k^2 f` (k the override, f the plan's largest fraction, see `nc_follow`), so a
/// plan at exactly its limit could not begin to slow down; and after a hold the setpoints
/// fall at other phases of the plan than the ones measured here, which sees the velocity
/// and the acceleration averaged over the period. Between phases the velocity differs by at
/// most `J Ts^2 / 8` and the acceleration by `J Ts / 2` (J the axis's planned jerk, kept inside
/// blocks; corners are measured at their worst phase, `nc_plan::verify`): [`reserve`] adds that.
pub const HOLD_RESERVE: f64 = 1e-3;

/// The fraction of an axis's velocity and acceleration limits the plan's setpoints may use.
pub fn reserve(ax: &AxisLimit, ts: f64) -> (f64, f64) {
    let jerk = ax.planned_jerk(ts);
    let v = 1.0 - HOLD_RESERVE - jerk * ts * ts / (8.0 * ax.velocity);
    let a = 1.0 - HOLD_RESERVE - jerk * ts / (2.0 * ax.acceleration);
    (v.max(0.5), a.max(0.5))
}
