//! The unit of streaming: a [`Chunk`] of consecutive planned segments with its share of the
//! feed plan, and the program's [`Start`].

use nc_geom::kinematics::Joints;
use nc_geom::limits::{Margins, V_FLOOR};
use nc_geom::scurve::Phase;
use nc_geom::segment::{Pose, Segment};

/// A run of consecutive segments with its share of the feed plan.
#[derive(Debug)]
pub struct Chunk {
    /// 0-based chunk index.
    pub index: usize,
    /// The segments, in path order (at least one).
    pub segments: Vec<Segment>,
    /// Path position where each segment starts.
    pub starts: Vec<f64>,
    /// Path position of the chunk's start and end.
    pub s0: f64,
    pub s1: f64,
    /// The profile's phases that cover the chunk (absolute time and path position).
    pub phases: Vec<Phase>,
    /// Time at which the plan leaves the chunk.
    pub t_end: f64,
    /// Time at which the plan arrives at the chunk's start (at rest there when its first
    /// segment is a stop; before its dwell, if it has one).
    pub t_start: f64,
    /// Highest planned speed over `phases`.
    pub vmax: f64,
    /// Highest planned speed from this chunk to the program's end: what the interpolator's
    /// holds are scaled by. It never rises as chunks arrive, so a hold in progress never
    /// finds its limits tightened under it by a faster chunk coming in.
    pub vmax_ahead: f64,
    /// Time at which the plan arrives at the chunk's end (the next one's `t_start`).
    pub t_arrive: f64,
    /// The plan is at rest where it arrives at the segment's end (an exact stop: at most
    /// the floor speed, [`V_FLOOR`]).
    pub rests_at_end: bool,
    /// The program's last chunk.
    pub last: bool,
    /// How far into the program the chunk starts, 0..=1 (its first segment's source line
    /// over the program's lines, where those are known; else 0).
    pub progress: f64,
}

/// The program's start, known before any chunk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Start {
    pub pose: Pose,
    pub joints: Joints,
    /// The program has no chunk: nothing moves.
    pub empty: bool,
    /// The plan's largest axis velocities and accelerations as fractions of their limits
    /// (its setpoint check, or for a program streamed before it is planned,
    /// [`Margins::ceiling`]): what a hold may add on top of them.
    pub margins: Margins,
}

impl Chunk {
    /// The segment that holds path position `s` (the earlier one where two meet) and the
    /// path position where it starts. By bisection: allocation-free, at most 13 steps.
    ///
    /// Real-time thread.
    pub fn segment_at(&self, s: f64) -> Option<(&Segment, f64)> {
        let i = self.starts.partition_point(|&b| b < s).saturating_sub(1);
        let seg = self.segments.get(i).or_else(|| self.segments.last())?;
        let s0 = self.starts.get(i).or_else(|| self.starts.last())?;
        Some((seg, *s0))
    }

    /// The chunk's first segment: where the path waits for the operator or the spindle,
    /// if it does in this chunk.
    pub fn first(&self) -> Option<&Segment> {
        self.segments.first()
    }
}

/// The highest speed a phase reaches.
pub fn phase_vmax(p: &Phase) -> f64 {
    let mut v = p.v0.max(p.end().v);
    // Constant jerk: v is quadratic in time, with an extremum where a = 0.
    if p.j != 0.0 {
        let tau = -p.a0 / p.j;
        if tau > 0.0 && tau < p.dur {
            v = v.max(p.at(tau).v);
        }
    }
    v.max(0.0)
}

/// Most segments one chunk carries: the real-time side finds the segment at a path position
/// by bisection over them, at most 13 steps.
pub const MAX_CHUNK_SEGMENTS: usize = 4096;

/// A planned speed this low is at rest: the plan's exact stop, which passes a kink at the
/// floor speed (its setpoint check holds there, where the path's direction turns at once).
/// Stopping from it at once is a smaller step than the plan's own at the kink.
pub const REST_V: f64 = V_FLOOR * (1.0 + 1e-9);
