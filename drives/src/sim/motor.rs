//! The simulated drive's motor, advanced once per SYNC period: a first-order lag toward a
//! position (CSP) or a velocity ramp (profile velocity). Pure arithmetic on `f64`; no input
//! makes it panic or leaves it non-finite.

/// 2^32 counts: one wrap of the 32-bit position.
const WRAP: f64 = 4_294_967_296.0;
/// 2^31 counts.
const HALF_WRAP: f64 = 2_147_483_648.0;

/// A velocity ramp: toward `target` (units/s), with |v| growing by at most `accel` and
/// shrinking by at most `decel` units/s per second; a rate of 0 does not limit (the velocity
/// steps).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ramp {
    pub target: f64,
    pub accel: f64,
    pub decel: f64,
}

/// What the motor does during the coming SYNC period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Demand {
    /// Follow this position (counts) with the first-order lag; the motor's own position
    /// means standing still.
    Position(f64),
    /// Ramp the velocity, the position integrating it.
    Velocity(Ramp),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motor {
    /// Counts, with the exact fraction. Within the `i32` range but for a velocity demand,
    /// which wraps it into [-2^31, 2^31).
    position: f64,
    /// Units (counts) per second.
    velocity: f64,
    demand: Demand,
}

impl Motor {
    /// At rest at `position`.
    pub fn new(position: f64) -> Self {
        Self {
            position,
            velocity: 0.0,
            demand: Demand::Position(position),
        }
    }

    /// Stops the motor where it stands.
    pub fn stop(&mut self) {
        self.velocity = 0.0;
        self.demand = Demand::Position(self.position);
    }

    pub fn position(&self) -> f64 {
        self.position
    }

    /// The position in counts, rounded, wrapping like an `i32` counter.
    pub fn position_counts(&self) -> i32 {
        self.position.round() as i64 as i32 // |position| < 2^32: the i64 is exact
    }

    /// The velocity in units/s, rounded (saturating).
    pub fn velocity_units(&self) -> i32 {
        self.velocity.round() as i32
    }

    /// Re-reference the position by `delta` counts (homing), the motor unmoved: the demand
    /// moves with it.
    pub fn rebase(&mut self, delta: f64) {
        if !delta.is_finite() {
            return;
        }
        self.position = wrap(self.position + delta);
        if let Demand::Position(d) = self.demand {
            self.demand = Demand::Position(wrap(d + delta));
        }
    }

    pub fn set_demand(&mut self, demand: Demand) {
        self.demand = demand;
    }

    /// One SYNC period of `period_s` toward the demand. A position demand moves the motor by
    /// the lag with time constant `lag_s` (0 = at once) and sets the velocity to the distance
    /// over the period; a velocity demand ramps.
    pub fn advance(&mut self, period_s: f64, lag_s: f64) {
        match self.demand {
            Demand::Position(demand) => {
                let before = self.position;
                self.position += (demand - self.position) * lag_factor(period_s, lag_s);
                let velocity = (self.position - before) / period_s;
                self.velocity = if velocity.is_finite() { velocity } else { 0.0 };
            }
            Demand::Velocity(ramp) => {
                let (velocity, distance) = ramp_step(self.velocity, ramp, period_s);
                let position = self.position + distance;
                if velocity.is_finite() && position.is_finite() {
                    self.velocity = velocity;
                    self.position = wrap(position);
                }
            }
        }
    }
}

/// The fraction of the remaining distance a first-order lag covers in one period, in 0..=1.
fn lag_factor(period_s: f64, lag_s: f64) -> f64 {
    let alpha = if lag_s > 0.0 {
        1.0 - (-period_s / lag_s).exp()
    } else {
        1.0
    };
    if alpha.is_finite() {
        alpha.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// `dt` seconds of `ramp` from velocity `v`: the velocity at the end and the distance
/// covered, both exact for the continuous profile (linear ramps, constant velocity once at
/// the target). Reversing decelerates to 0 first, then accelerates. A `dt` that is not a
/// positive finite time changes nothing.
fn ramp_step(v: f64, ramp: Ramp, dt: f64) -> (f64, f64) {
    if !(dt.is_finite() && dt > 0.0) {
        return (v, 0.0);
    }
    let (mut v, mut left, mut distance) = (v, dt, 0.0);
    // At most two phases: down to 0 when reversing, then toward the target.
    for _ in 0..2 {
        if v == ramp.target {
            break;
        }
        let reversing = v != 0.0 && (ramp.target == 0.0 || (ramp.target > 0.0) != (v > 0.0));
        let (goal, rate) = if reversing {
            (0.0, ramp.decel)
        } else if ramp.target.abs() > v.abs() {
            (ramp.target, ramp.accel)
        } else {
            (ramp.target, ramp.decel)
        };
        let gap = goal - v;
        let (time, end) = if rate <= 0.0 {
            (0.0, goal)
        } else if gap.abs() / rate <= left {
            (gap.abs() / rate, goal)
        } else {
            (left, v + gap.signum() * rate * left)
        };
        distance += (v + end) / 2.0 * time;
        left -= time;
        v = end;
    }
    (v, distance + v * left)
}

/// `position` (finite) into [-2^31, 2^31), exactly.
fn wrap(position: f64) -> f64 {
    let p = if position.abs() >= WRAP {
        position % WRAP
    } else {
        position
    };
    if p >= HALF_WRAP {
        p - WRAP
    } else if p < -HALF_WRAP {
        p + WRAP
    } else {
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(target: f64, accel: f64, decel: f64) -> Ramp {
        Ramp {
            target,
            accel,
            decel,
        }
    }

    #[test]
    fn a_ramp_reaching_its_target_mid_period_covers_the_exact_distance() {
        // 0 -> 10 at 100/s takes 0.1 s: 0.5 * 10 * 0.1 = 0.5, then 10 * 0.1 = 1.
        assert_eq!(ramp_step(0.0, ramp(10.0, 100.0, 1.0), 0.2), (10.0, 1.5));
        // Unlimited: a step at the start of the period.
        assert_eq!(ramp_step(-3.0, ramp(10.0, 0.0, 0.0), 0.5), (10.0, 5.0));
    }

    #[test]
    fn reversing_decelerates_to_zero_then_accelerates() {
        // 10 -> 0 at 100/s in 0.1 s (distance 0.5), then 0.1 s at 50/s to -5 (distance -0.25).
        let (v, d) = ramp_step(10.0, ramp(-20.0, 50.0, 100.0), 0.2);
        assert_eq!(v, -5.0);
        assert!((d - 0.25).abs() < 1e-12, "{d}");
    }

    #[test]
    fn odd_periods_change_nothing() {
        for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(ramp_step(7.0, ramp(10.0, 1.0, 1.0), dt), (7.0, 0.0));
        }
    }

    #[test]
    fn the_position_wraps_like_an_i32_counter() {
        let mut m = Motor::new(f64::from(i32::MAX) - 0.25);
        m.set_demand(Demand::Velocity(ramp(1000.0, 0.0, 0.0)));
        m.advance(0.001, 0.0); // one count further
        assert_eq!(m.position_counts(), i32::MIN);
        assert_eq!(m.velocity_units(), 1000);
        assert_eq!(wrap(3.0 * WRAP + 1.5), 1.5);
        assert_eq!(wrap(-HALF_WRAP - 1.0), HALF_WRAP - 1.0);
    }
}
