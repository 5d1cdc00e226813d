//! Jogging one axis: continuous (at a velocity, while the operator holds the key: a
//! dead-man that stops unless renewed) and incremental (to a position, from rest), every
//! start and stop jerk-limited, within the axis's velocity, acceleration and jerk limits and
//! its travel. Sans-I/O and allocation-free, for the real-time thread: [`Jog::step`] gives
//! the next period's position.
//!
//! The motion is a chain of constant-jerk phases ([`nc_geom::scurve::Phase`]) planned from
//! the exact state (position, velocity, acceleration) at the period a command arrives, so
//! position, velocity and acceleration are continuous and the jerk is within its limit
//! everywhere; the setpoints, samples of it at the period, keep every limit by finite
//! differences too. A velocity change from `(v0, a0)` to `(v1, 0)` is time-optimal: the
//! acceleration ramps to its peak at the jerk limit, holds at the acceleration limit if it
//! reaches it, and ramps back to 0. Before each period the jog checks that the tool could
//! still stop within the travel from where the next period leaves it; if not, it stops now
//! (a continuous jog into a travel limit ends short of it, at rest).

use nc_geom::scurve::{change_dist, reachable, Phase};

/// Phases a plan holds: an incremental move has at most seven, a change three, plus rest.
const PHASES: usize = 8;

/// One axis's limits, in its units (mm or degrees) and seconds; `min`/`max` may be
/// infinite (an endless rotary axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JogLimits {
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
    pub min: f64,
    pub max: f64,
}

/// Why a jog command is refused (the jog goes on as before).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum JogRefused {
    #[error("jog speed {speed} is over the axis's velocity limit {limit}, or not more than 0")]
    Speed { speed: f64, limit: f64 },
    #[error("jog target {target} is outside the travel {min}..{max}")]
    OutsideTravel { target: f64, min: f64, max: f64 },
    #[error("an incremental jog starts from rest: the axis is moving")]
    Moving,
}

/// The plan: phases from time 0 (the period it was made), positions `origin + dir * s`.
#[derive(Clone, Copy, Debug)]
struct Plan {
    phases: [Phase; PHASES],
    n: usize,
    origin: f64,
    dir: f64,
    /// Time since the plan was made, s.
    t: f64,
    /// The velocity it ends at (0: at rest once over).
    v_end: f64,
    /// An incremental move's target, where the final rest is, exactly (within the travel:
    /// no travel check needed).
    land: Option<f64>,
}

impl Plan {
    /// No phase yet: from `origin`, positions counted in direction `dir`, ending at `v_end`.
    fn new(origin: f64, dir: f64, v_end: f64) -> Self {
        Plan {
            phases: [Phase::default(); PHASES],
            n: 0,
            origin,
            dir,
            t: 0.0,
            v_end,
            land: None,
        }
    }

    /// Resting at `p`.
    fn rest(p: f64) -> Self {
        let mut plan = Plan::new(p, 1.0, 0.0);
        plan.hold(None);
        plan
    }

    /// Position, velocity and acceleration at time `t` of the plan.
    fn at(&self, t: f64) -> (f64, f64, f64) {
        let mut k = 0;
        while k + 1 < self.n && t >= self.phases[k + 1].t0 {
            k += 1;
        }
        let ph = &self.phases[k];
        if let (Some(p), true) = (self.land, k + 1 == self.n) {
            return (p, 0.0, 0.0);
        }
        let m = ph.at(t - ph.t0);
        (self.origin + self.dir * m.s, self.dir * m.v, self.dir * m.a)
    }

    /// Append a constant-jerk phase of `dur` after the last (skipped when empty).
    fn push(&mut self, j: f64, dur: f64) {
        if dur.is_nan() || dur <= 0.0 || self.n >= PHASES {
            return;
        }
        let (t0, s0, v0, a0) = match self.n {
            0 => (0.0, 0.0, 0.0, 0.0),
            n => {
                let last = self.phases[n - 1];
                let e = last.end();
                (last.t0 + last.dur, e.s, e.v, e.a)
            }
        };
        self.phases[self.n] = Phase {
            t0,
            dur,
            s0,
            v0,
            a0,
            j,
        };
        self.n += 1;
    }

    /// End at the velocity `v_end` and zero acceleration, forever (exactly: the phases
    /// before it reach them to rounding). `s_end` replaces the end position if given.
    fn hold(&mut self, s_end: Option<f64>) {
        let (t0, s0) = match self.n {
            0 => (0.0, 0.0),
            n => {
                let last = self.phases[n - 1];
                (last.t0 + last.dur, last.end().s)
            }
        };
        if self.n < PHASES {
            self.phases[self.n] = Phase {
                t0,
                dur: f64::INFINITY,
                s0: s_end.unwrap_or(s0),
                v0: self.v_end * self.dir,
                a0: 0.0,
                j: 0.0,
            };
            self.n += 1;
        }
    }

    /// The lowest and highest positions from time 0 to the start of the final hold: at
    /// the phases' ends and where their velocity crosses zero.
    fn extremes(&self) -> (f64, f64) {
        let (mut lo, mut hi) = (self.origin, self.origin);
        let mut see = |s: f64| {
            let p = self.origin + self.dir * s;
            lo = lo.min(p);
            hi = hi.max(p);
        };
        for ph in &self.phases[..self.n.saturating_sub(1)] {
            see(ph.end().s);
            // v0 + a0 t + j t^2 / 2 = 0 within the phase.
            let (a, b, c) = (ph.j / 2.0, ph.a0, ph.v0);
            let roots = if a == 0.0 {
                [if b != 0.0 { -c / b } else { -1.0 }, -1.0]
            } else {
                let disc = b * b - 4.0 * a * c;
                if disc < 0.0 {
                    [-1.0, -1.0]
                } else {
                    let r = disc.sqrt();
                    [(-b - r) / (2.0 * a), (-b + r) / (2.0 * a)]
                }
            };
            for t in roots {
                if t > 0.0 && t < ph.dur {
                    see(ph.at(t).s);
                }
            }
        }
        (lo, hi)
    }
}

/// A plan from `(p, v, a)` to the velocity `v1` at zero acceleration, then on at `v1`.
fn change_plan(p: f64, v: f64, a: f64, v1: f64, lim: &JogLimits) -> Plan {
    let mut plan = Plan::new(p, 1.0, v1);
    // A phase of no length carries the starting velocity and acceleration.
    plan.phases[0] = Phase {
        v0: v,
        a0: a,
        ..Phase::default()
    };
    plan.n = 1;
    for (j, dur) in change(v, a, v1, lim.acceleration, lim.jerk) {
        plan.push(j, dur);
    }
    plan.hold(None);
    plan
}

/// The time-optimal change from `(v0, a0)` to `(v1, 0)` with |a| <= `amax`, |j| <= `jmax`:
/// three (jerk, duration) phases, some of them empty.
fn change(v0: f64, a0: f64, v1: f64, amax: f64, jmax: f64) -> [(f64, f64); 3] {
    // The velocity reached by ramping the acceleration to 0 at once.
    let v_ramp = v0 + a0 * a0.abs() / (2.0 * jmax);
    let s = if v1 > v_ramp {
        1.0
    } else if v1 < v_ramp {
        -1.0
    } else {
        return [
            (-a0.signum() * jmax, a0.abs() / jmax),
            (0.0, 0.0),
            (0.0, 0.0),
        ];
    };
    // Mirrored so that the velocity rises: a0s the acceleration, dv > 0 the change.
    let (a0s, dv) = (s * a0, s * (v1 - v0));
    let mut peak = ((2.0 * jmax * dv + a0s * a0s) / 2.0).max(0.0).sqrt();
    let mut hold = 0.0;
    if peak > amax {
        peak = amax;
        hold = ((dv - (amax * amax - a0s * a0s) / (2.0 * jmax) - amax * amax / (2.0 * jmax))
            / amax)
            .max(0.0);
    }
    let peak = peak.max(a0s);
    [
        (s * jmax, (peak - a0s) / jmax),
        (0.0, hold),
        (-s * jmax, peak / jmax),
    ]
}

/// The lowest and highest positions of a stop by [`change`] from `(p, v, a)`.
fn stop_extremes(p: f64, v: f64, a: f64, lim: &JogLimits) -> (f64, f64) {
    change_plan(p, v, a, 0.0, lim).extremes()
}

/// One axis's jog.
#[derive(Clone, Copy, Debug)]
pub struct Jog {
    lim: JogLimits,
    period: f64,
    plan: Plan,
    /// Periods left before a continuous jog stops unless renewed; `None` when not jogging
    /// continuously.
    deadman: Option<u32>,
    /// Periods a renewal keeps a continuous jog going.
    deadman_periods: u32,
    /// The last jog stopped short of the travel.
    limited: bool,
}

impl Jog {
    /// At rest at `position`. A continuous jog goes on for `deadman_periods` periods after
    /// its last renewal.
    pub fn new(position: f64, lim: JogLimits, period: f64, deadman_periods: u32) -> Self {
        Jog {
            lim,
            period,
            plan: Plan::rest(position),
            deadman: None,
            deadman_periods,
            limited: false,
        }
    }

    /// Position, velocity and acceleration now.
    pub fn state(&self) -> (f64, f64, f64) {
        self.plan.at(self.plan.t)
    }

    /// At rest with nothing planned.
    pub fn at_rest(&self) -> bool {
        let (_, v, a) = self.state();
        v == 0.0 && a == 0.0 && self.plan.v_end == 0.0
    }

    /// The last jog was stopped short of the travel.
    pub fn limited(&self) -> bool {
        self.limited
    }

    /// Continuous jog at `velocity` (signed), until [`Jog::stop`] or the dead-man runs out.
    pub fn velocity(&mut self, velocity: f64) -> Result<(), JogRefused> {
        let limit = self.lim.velocity;
        if velocity.is_nan() || velocity.abs() > limit || velocity == 0.0 {
            return Err(JogRefused::Speed {
                speed: velocity.abs(),
                limit,
            });
        }
        self.replan(velocity);
        self.deadman = Some(self.deadman_periods);
        self.limited = false;
        Ok(())
    }

    /// The operator still holds the key: the continuous jog goes on.
    pub fn renew(&mut self) {
        if self.deadman.is_some() {
            self.deadman = Some(self.deadman_periods);
        }
    }

    /// Stop, jerk-limited, from wherever the jog is.
    pub fn stop(&mut self) {
        self.deadman = None;
        if !self.at_rest() {
            self.replan(0.0);
        }
    }

    /// Incremental jog to `target` at up to `speed`, from rest.
    pub fn to(&mut self, target: f64, speed: f64) -> Result<(), JogRefused> {
        let lim = self.lim;
        if !(speed > 0.0 && speed <= lim.velocity) {
            return Err(JogRefused::Speed {
                speed,
                limit: lim.velocity,
            });
        }
        if !(target >= lim.min && target <= lim.max) {
            return Err(JogRefused::OutsideTravel {
                target,
                min: lim.min,
                max: lim.max,
            });
        }
        if !self.at_rest() {
            return Err(JogRefused::Moving);
        }
        let (p, _, _) = self.state();
        let d = target - p;
        let len = d.abs();
        let mut plan = Plan::new(p, d.signum(), 0.0);
        let (a, j) = (lim.acceleration, lim.jerk);
        let vc = speed.min(reachable(0.0, len / 2.0, a, j));
        if len > 0.0 && vc > 0.0 {
            for (jk, dur) in change(0.0, 0.0, vc, a, j) {
                plan.push(jk, dur);
            }
            let cruise = len - 2.0 * change_dist(0.0, vc, a, j);
            plan.push(0.0, (cruise / vc).max(0.0));
            for (jk, dur) in change(vc, 0.0, 0.0, a, j) {
                plan.push(jk, dur);
            }
        }
        // Lands on the target exactly.
        plan.hold(Some(len));
        plan.land = Some(target);
        self.plan = plan;
        self.deadman = None;
        self.limited = false;
        Ok(())
    }

    /// The next period's position.
    pub fn step(&mut self) -> f64 {
        if let Some(n) = self.deadman {
            if n == 0 {
                self.stop();
            } else {
                self.deadman = Some(n - 1);
            }
        }
        let next = self.plan.t + self.period;
        if self.plan.land.is_none() && self.would_leave_travel(next) {
            self.deadman = None;
            self.limited = true;
            self.replan(0.0);
        }
        self.plan.t += self.period;
        self.state().0
    }

    /// From the state at plan time `t`, a stop would pass outside the travel.
    fn would_leave_travel(&self, t: f64) -> bool {
        let (p, v, a) = self.plan.at(t);
        let (lo, hi) = stop_extremes(p, v, a, &self.lim);
        hi > self.lim.max || lo < self.lim.min
    }

    /// A new plan from the state now to velocity `v1`.
    fn replan(&mut self, v1: f64) {
        let (p, v, a) = self.state();
        self.plan = change_plan(p, v, a, v1, &self.lim);
    }
}
