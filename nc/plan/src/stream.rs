//! From a plan to the chunks the real-time follower takes (`nc_follow`): the [`Cutter`] cuts
//! committed phases and segments into chunks as the plan is made, [`cut`] and [`chunks`]
//! run it over a whole plan, and [`Source`] chains the streaming stages, program lines in,
//! chunks out.

use crate::plan::Sink;
use crate::profile::FeedProfile;
use nc_follow::{phase_vmax, stop_length, Chunk, HoldConfig, Start};
use nc_geom::segment::Path;

mod cutter;
mod source;
#[cfg(test)]
mod tests;

pub use cutter::Cutter;
pub use source::{Machine, ProgramEntries, ProgramSource, Source, Stages, StreamError};

/// Look-ahead in distance: how long each chunk must be (mm, or degrees along a rotary-only
/// path), merging consecutive segments until it is. The interpolator holds when the path
/// that has arrived ends within the distance it needs to stop (`nc_follow::Follower`); with the
/// chunks it can hold (`depth`, at most [`nc_follow::LOOKAHEAD`]) each at least this long, what has
/// arrived always covers a stop from the plan's highest speed, with a quarter to spare and
/// two chunks in transit (the one being left and the one the planner is about to push), so a
/// planner that keeps up never makes the tool hold, however short the program's moves.
pub fn chunk_length(profile: &FeedProfile, hold: &HoldConfig, depth: usize) -> f64 {
    let vmax = profile.phases.iter().map(phase_vmax).fold(0.0, f64::max);
    stop_length(vmax, &profile.margins, hold, depth)
}

/// Cut a planned path into chunks (outside the real-time thread) for an interpolator that
/// holds `depth` of them: runs of consecutive segments at least [`chunk_length`] long (fewer
/// if [`nc_follow::MAX_CHUNK_SEGMENTS`] come first). A segment where the path waits for the operator or
/// the spindle starts a chunk. Boxed, because the boxes travel through the queues as
/// pointers.
#[allow(clippy::vec_box)]
pub fn chunks(
    path: Path,
    profile: &FeedProfile,
    hold: &HoldConfig,
    depth: usize,
) -> (Start, Vec<Box<Chunk>>) {
    cut(path, profile, chunk_length(profile, hold, depth))
}

/// Cut a planned path into chunks at least `min_len` long (0: one segment a chunk, as a
/// planner that pushes each segment as soon as it is planned). [`chunks`] with the length
/// its depth needs. The [`Cutter`] a streamed plan goes through, fed the whole plan; each
/// chunk's `vmax_ahead` is the plan's own highest speed from there to its end.
#[allow(clippy::vec_box)]
pub fn cut(path: Path, profile: &FeedProfile, min_len: f64) -> (Start, Vec<Box<Chunk>>) {
    let mut cutter = Cutter::new(min_len, 0.0);
    let (start, joints) = (path.start, path.start_joints);
    cutter.phases(&profile.phases);
    for seg in path.segments {
        cutter.segment(seg);
    }
    cutter.finish(profile.duration);
    let mut out: Vec<Box<Chunk>> = core::iter::from_fn(|| cutter.next_chunk()).collect();
    let n = out.len();
    for (i, c) in out.iter_mut().enumerate() {
        c.progress = i as f64 / n as f64;
    }
    for i in (1..n).rev() {
        out[i - 1].vmax_ahead = out[i - 1].vmax.max(out[i].vmax_ahead);
    }
    let start = Start {
        pose: start,
        joints,
        empty: out.is_empty(),
        margins: profile.margins,
    };
    (start, out)
}
