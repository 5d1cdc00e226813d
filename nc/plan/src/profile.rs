//! The planned feed: the jerk-limited phases s(t) along the whole path, read by the offline
//! interpolator, the setpoint check and the cutter.

use nc_geom::limits::Margins;
use nc_geom::scurve::{Motion, Phase};

/// The planned feed along the whole path.
#[derive(Clone, Debug, PartialEq)]
pub struct FeedProfile {
    pub phases: Vec<Phase>,
    /// Path position where each segment starts (segment k spans seg_start[k]..seg_start[k+1]).
    pub seg_start: Vec<f64>,
    /// Where the plan ends: the path's length (while the planner checks a window, the
    /// window's end, where it stops).
    pub length: f64,
    pub duration: f64,
    /// The largest axis velocity, acceleration, jerk and chord error the setpoints reach,
    /// as fractions of their limits (all <= 1 for a plan that [`plan`] returned).
    pub margins: Margins,
}

impl FeedProfile {
    /// Path state at time t. `cursor` remembers the phase between calls (monotonic time);
    /// each call advances it at most over the phases that ended. Allocation-free.
    pub fn at(&self, t: f64, cursor: &mut usize) -> Motion {
        if t >= self.duration || self.phases.is_empty() {
            return Motion {
                s: self.length,
                v: 0.0,
                a: 0.0,
            };
        }
        let n = self.phases.len();
        while *cursor + 1 < n && t >= self.phases[*cursor + 1].t0 {
            *cursor += 1;
        }
        let ph = &self.phases[(*cursor).min(n - 1)];
        let mut m = ph.at((t - ph.t0).clamp(0.0, ph.dur));
        m.s = m.s.clamp(0.0, self.length);
        m.v = m.v.max(0.0);
        m
    }

    /// Path state at time t, by a binary search over the phases (for random access;
    /// [`Self::at`] walks forward).
    pub fn motion_at(&self, t: f64) -> Motion {
        let mut i = self.phases.partition_point(|p| p.t0 <= t).saturating_sub(1);
        self.at(t, &mut i)
    }

    /// The phases over times `lo..=hi`, for many random accesses there: each searches
    /// those phases alone, not the whole plan's (a search over millions of phases per
    /// access missed the cache at every step and made the check n log n).
    pub fn near(&self, lo: f64, hi: f64) -> Near<'_> {
        let i0 = self
            .phases
            .partition_point(|p| p.t0 <= lo)
            .saturating_sub(1);
        let i1 = self.phases.partition_point(|p| p.t0 <= hi);
        Near {
            profile: self,
            i0,
            i1: i1.max(i0),
            lo,
            hi,
        }
    }
}

/// [`FeedProfile::near`].
pub struct Near<'a> {
    profile: &'a FeedProfile,
    i0: usize,
    i1: usize,
    lo: f64,
    hi: f64,
}

impl Near<'_> {
    /// [`FeedProfile::motion_at`], the same to the bit: no phase before `i0` starts after
    /// `lo`, none from `i1` on starts before `hi`.
    pub fn motion_at(&self, t: f64) -> Motion {
        if !(t >= self.lo && t <= self.hi) {
            return self.profile.motion_at(t);
        }
        let local = self.profile.phases[self.i0..self.i1].partition_point(|p| p.t0 <= t);
        let mut i = (self.i0 + local).saturating_sub(1);
        self.profile.at(t, &mut i)
    }
}
