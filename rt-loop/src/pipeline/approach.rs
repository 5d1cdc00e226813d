//! The approach: one jerk-limited straight move in axis space from where the drives are to
//! the program's start, every axis within its limits, all arriving together; planned before
//! the loop, stepped in it. Its phases are held in place (a rest-to-rest S-curve has at most
//! seven), so the move can pass from stage to stage in the loop without the heap.

use nc_geom::scurve::{push_section, Phase, Ramps};

/// Most phases the approach holds.
pub(super) const APPROACH_PHASES: usize = 8;

/// Axis limits for the approach, in axis units (mm or degrees), joint order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ApproachLimits {
    pub velocity: [f64; 5],
    pub acceleration: [f64; 5],
    pub jerk: [f64; 5],
}

/// The jerk-limited straight move to the start, planned before the loop.
#[derive(Clone, Debug)]
pub(super) struct Approach {
    from: [f64; 5],
    to: [f64; 5],
    phases: heapless::Vec<Phase, APPROACH_PHASES>,
    duration: f64,
    cursor: usize,
    t: f64,
}

impl Approach {
    /// `None` if the S-curve has more phases than [`APPROACH_PHASES`] (a rest-to-rest
    /// section has at most seven).
    pub(super) fn new(from: [f64; 5], to: [f64; 5], lim: &ApproachLimits) -> Option<Approach> {
        // lambda runs 0 -> 1; axis j moves by d_j * lambda.
        let (mut v, mut a, mut j) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for k in 0..5 {
            let d = (to[k] - from[k]).abs();
            if d > 1e-12 {
                v = v.min(lim.velocity[k] / d);
                a = a.min(lim.acceleration[k] / d);
                j = j.min(lim.jerk[k] / d);
            }
        }
        let mut phases = Vec::new();
        if v.is_finite() {
            push_section(
                &mut phases,
                0.0,
                0.0,
                (0.0, 0.0),
                1.0,
                v,
                Ramps::both((a, j)),
            );
        }
        let duration = phases.last().map_or(0.0, |p| p.t0 + p.dur);
        Some(Approach {
            from,
            to,
            phases: heapless::Vec::from_slice(&phases).ok()?,
            duration,
            cursor: 0,
            t: 0.0,
        })
    }

    /// The axis positions now, without advancing.
    pub(super) fn now(&self) -> [f64; 5] {
        if self.t >= self.duration || self.phases.is_empty() {
            return if self.t > 0.0 { self.to } else { self.from };
        }
        let ph = &self.phases[self.cursor.min(self.phases.len() - 1)];
        let l = ph.at((self.t - ph.t0).clamp(0.0, ph.dur)).s.clamp(0.0, 1.0);
        core::array::from_fn(|k| self.from[k] + (self.to[k] - self.from[k]) * l)
    }

    /// Advance one period; the axis positions, and whether the move is over.
    pub(super) fn step(&mut self, period: f64) -> ([f64; 5], bool) {
        self.t += period;
        if self.t >= self.duration || self.phases.is_empty() {
            return (self.to, true);
        }
        let n = self.phases.len();
        while self.cursor + 1 < n && self.t >= self.phases[self.cursor + 1].t0 {
            self.cursor += 1;
        }
        let ph = &self.phases[self.cursor];
        let l = ph.at((self.t - ph.t0).clamp(0.0, ph.dur)).s.clamp(0.0, 1.0);
        (
            core::array::from_fn(|k| self.from[k] + (self.to[k] - self.from[k]) * l),
            false,
        )
    }
}
