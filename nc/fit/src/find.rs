//! Runs of `G01` moves a fit may replace, found in a parsed program: the rules both the
//! text rewrite (`dnurbs fit`, [`super::runs`]) and the on-line compressor
//! ([`super::compress`]) share.
//!
//! Blocks b..=e form a run when each is a feed move (`G01`, not rapid) that follows a
//! linear move, moves the cutter, turns the tool by at most [`MAX_TURN_DEG`] (and is not
//! a move in machine angles from a tilted pose given as a vector, [`may_follow`]), has the
//! run's feed (within [`INVERSE_FEED_SPREAD`] under `G93`) and tool length and no wait
//! before it (but the first), keeps the tool vertical if the first does and only then
//! ([`keeps_vertical`]), and no two of them meet at a corner sharper than the corner angle;
//! the caller adds its own conditions for a run's first move and for each move that joins
//! it.

use super::{fit, Fitted, Point, Tolerance};
use crate::options::Options;
use nalgebra::Vector3;
use nc_geom::kinematics::{is_vertical, Kinematics, MachineKinematics};
use nc_geom::program::{Block, LinearMove, Orientation, Program};
use nc_lang::MIN_FEED_MM_MIN;

/// Largest tool turn (degrees) of one move in a run: the fit follows the tool axis at the
/// points, so a move's own turn between them must be small (and a `C` turn of a whole
/// revolution, which leaves the axis where it was, is never fitted away).
pub const MAX_TURN_DEG: f64 = 10.0;

/// How far the feeds (mm/min) of a run's moves under `G93` may spread, relative to its
/// first's: a post writes each move's 1/minutes for its own rounded length, so a constant
/// speed of the tool comes out a little different on every move.
pub const INVERSE_FEED_SPREAD: f64 = 0.01;

/// The largest feed a program can give (the domain of an `F` word), mm/min.
const MAX_FEED_MM_MIN: f64 = 1e6;

/// A run and its fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    /// Its first and last block (indices into [`Program::blocks`]).
    pub blocks: (usize, usize),
    /// The last block it could have taken, before it was cut back to one it may end at.
    pub reach: usize,
    /// The programmed points: where the run starts, then each move's end.
    pub points: Vec<Point>,
    /// Programmed feed, mm/min: for a run under `G93`, its length over its time.
    pub feed_mm_min: f64,
    /// The run was programmed in inverse time (`G93`); its time, minutes, is the sum of
    /// its moves'.
    pub inverse_minutes: Option<f64>,
    /// The fitted curve, or `None` when no curve meets the tolerances.
    pub fitted: Option<Fitted>,
}

/// The cutter point and unit tool axis at a linear move's end.
pub fn point(m: &LinearMove, kin: &MachineKinematics) -> Point {
    let axis = match m.orientation {
        Orientation::Vector(v) => Vector3::from(v).normalize(),
        Orientation::Angles { r1_deg, r2_deg } => {
            kin.tool_axis(r1_deg.to_radians(), r2_deg.to_radians())
        }
    };
    Point {
        p: Vector3::from(m.end),
        axis,
    }
}

fn angles(m: &LinearMove) -> Option<(f64, f64)> {
    match m.orientation {
        Orientation::Angles { r1_deg, r2_deg } => Some((r1_deg, r2_deg)),
        Orientation::Vector(_) => None,
    }
}

/// Feed moves of a program (block 0 is the start pose, not a move).
pub fn moves_in(program: &Program) -> usize {
    program
        .blocks
        .iter()
        .skip(1)
        .filter(|b| matches!(b, Block::Linear(m) if !m.rapid))
        .count()
}

/// Move `m` may follow `prev` in a run: a feed move that moves the cutter and turns the
/// tool by at most [`MAX_TURN_DEG`], and not a move in machine angles from a tilted pose
/// given as a vector.
///
/// A move in angles turns the joints linearly from where the pose before left them, and
/// after a tilted vector those are the inverse kinematics' choice of two solutions, which
/// the fit does not know: a move from a tool tilted 8.2 degrees, given as `I J K`, to one
/// at `A0.4543 C45.7471` turns C by 132 degrees, spread over the move joint by joint (A
/// stays above 0.45 degrees), while a fitted axis took the short way, nearer the vertical,
/// where C turns faster per millimetre: refused compressed, C's velocity over its limit at
/// the slowest feed, where the move as posted ran (`nc/tests/compressed_posts.rs`). Such a
/// move stays a `G01`. From a vertical vector the fit may take it: there the move as
/// posted turns C from wherever it was kept while the tool leaves the vertical, and
/// programs that start so were refused as posted and ran fitted.
pub fn may_follow(prev: &LinearMove, m: &LinearMove, kin: &MachineKinematics) -> bool {
    let (pa, pb) = (point(prev, kin), point(m, kin));
    let rot = match (angles(prev), angles(m)) {
        (Some((a1, c1)), Some((a2, c2))) => (a2 - a1).abs().max((c2 - c1).abs()),
        (None, Some(_)) if !is_vertical(&pa.axis) => return false,
        _ => pa.axis.angle(&pb.axis).to_degrees(),
    };
    !m.rapid && (pb.p - pa.p).norm() > 1e-6 && rot <= MAX_TURN_DEG
}

/// The move to `m` from `prev`'s end keeps the tool vertical (within
/// [`VERTICAL_RHO`](nc_geom::kinematics::VERTICAL_RHO) at both ends), where a table's C is
/// undefined and the interpolator keeps it. A run holds such moves only, or none of them: a
/// fitted orientation curve is exactly vertical only where all its data are, and a tool a
/// hair off the vertical has C follow its azimuth, anywhere round the table (a pass that
/// tilts to the vertical and stays there, fitted whole, was refused by the planner where
/// the moves as posted ran: `nc/tests/compressed_posts.rs`).
pub fn keeps_vertical(prev: &LinearMove, m: &LinearMove, kin: &MachineKinematics) -> bool {
    is_vertical(&point(prev, kin).axis) && is_vertical(&point(m, kin).axis)
}

/// Move `m` has the feed, tool length and mode of the run `first` begins: the same feed
/// per minute, or both in inverse time (`G93`) at speeds within [`INVERSE_FEED_SPREAD`].
pub fn same_run(first: &LinearMove, m: &LinearMove) -> bool {
    let feeds = match (first.inverse_time, m.inverse_time) {
        (true, true) => {
            (m.feed_mm_min - first.feed_mm_min).abs() <= INVERSE_FEED_SPREAD * first.feed_mm_min
        }
        (false, false) => m.feed_mm_min == first.feed_mm_min,
        _ => false,
    };
    feeds
        && m.tooling.tool_length == first.tooling.tool_length
        && m.tooling.mode == first.tooling.mode
}

/// The feed (mm/min) a fitted block of `moves` is given, and under `G93` the run's time
/// (minutes, the sum of its moves': each took its length over its feed, the parser's own
/// measure); `points`: the run's start, then each move's end. None for a run in inverse
/// time at a speed no feed per minute can give, which stays as it is.
pub fn run_feed<'m>(
    mut moves: impl Iterator<Item = &'m LinearMove>,
    points: &[Point],
) -> Option<(f64, Option<f64>)> {
    let first = moves.next()?;
    if !first.inverse_time {
        return Some((first.feed_mm_min, None));
    }
    let (length, minutes) = core::iter::once(first)
        .chain(moves)
        .zip(points.windows(2))
        .fold((0.0, 0.0), |(length, minutes), (m, w)| {
            let chord = (w[1].p - w[0].p).norm();
            (length + chord, minutes + chord / m.feed_mm_min)
        });
    let feed = length / minutes;
    (MIN_FEED_MM_MIN..=MAX_FEED_MM_MIN)
        .contains(&feed)
        .then_some((feed, Some(minutes)))
}

/// The path turns at the end of `m` (from `a`'s end, to `c`'s) by more than `corner_deg`.
pub fn is_corner(a: &LinearMove, m: &LinearMove, c: &LinearMove, corner_deg: f64) -> bool {
    let (d1, d2) = (
        Vector3::from(m.end) - Vector3::from(a.end),
        Vector3::from(c.end) - Vector3::from(m.end),
    );
    d1.angle(&d2).to_degrees() > corner_deg
}

/// The runs of at least `opts.min_moves` moves, fitted. `start(b)`: the tolerance a run
/// beginning at block b is fitted within, or None where none may begin; `may_join(k)`: block k may follow block k - 1 in one; `may_end(k, e)`: a fitted
/// block may end at block k of a run that could go on to block e (the run is cut back to
/// the last such block, and the moves after it stay as they are).
pub fn find_runs(
    program: &Program,
    kin: &MachineKinematics,
    opts: &Options,
    start: impl Fn(usize) -> Option<Tolerance>,
    may_join: impl Fn(usize) -> bool,
    may_end: impl Fn(usize, usize) -> bool,
) -> Vec<Found> {
    find_open_runs(program, kin, opts, start, may_join, may_end).0
}

/// [`find_runs`], and the first block of the run that reaches the program's last block,
/// if one does (fitted or not, whatever its length): where a program read a piece at a
/// time may have a run that goes on.
pub fn find_open_runs(
    program: &Program,
    kin: &MachineKinematics,
    opts: &Options,
    start: impl Fn(usize) -> Option<Tolerance>,
    may_join: impl Fn(usize) -> bool,
    may_end: impl Fn(usize, usize) -> bool,
) -> (Vec<Found>, Option<usize>) {
    let linear = |b: usize| match program.blocks.get(b) {
        Some(Block::Linear(m)) => Some(m),
        _ => None,
    };
    let eligible = |b: usize| -> bool {
        let (Some(m), Some(prev)) = (linear(b), b.checked_sub(1).and_then(linear)) else {
            return false;
        };
        may_follow(prev, m, kin)
    };
    let vertical = |b: usize| -> bool {
        let (Some(prev), Some(m)) = (b.checked_sub(1).and_then(linear), linear(b)) else {
            return false;
        };
        keeps_vertical(prev, m, kin)
    };
    let corner = |b: usize| -> bool {
        let (Some(a), Some(m), Some(c)) = (linear(b - 1), linear(b), linear(b + 1)) else {
            return true;
        };
        is_corner(a, m, c, opts.corner_deg)
    };
    let mut runs = Vec::new();
    let mut open = None;
    let mut b = 1;
    while b < program.blocks.len() {
        let begun = linear(b).filter(|_| eligible(b));
        let Some((first, tol)) = begun.and_then(|m| Some((m, start(b)?))) else {
            b += 1;
            continue;
        };
        let mut e = b;
        let upright = vertical(b);
        while e + 1 < program.blocks.len()
            && eligible(e + 1)
            && vertical(e + 1) == upright
            && may_join(e + 1)
            && linear(e + 1).is_some_and(|m| same_run(first, m) && !m.tooling.wait.is_some())
            && !corner(e)
        {
            e += 1;
        }
        if e + 1 == program.blocks.len() {
            open = Some(b);
        }
        let mut end = e;
        while end >= b && !may_end(end, e) {
            end -= 1;
        }
        if end + 1 - b >= opts.min_moves {
            let points: Vec<Point> = (b - 1..=end)
                .filter_map(|k| linear(k).map(|m| point(m, kin)))
                .collect();
            if let Some((feed_mm_min, inverse_minutes)) =
                run_feed((b..=end).filter_map(linear), &points)
            {
                runs.push(Found {
                    blocks: (b, end),
                    reach: e,
                    fitted: fit(&points, tol, opts.degree),
                    points,
                    feed_mm_min,
                    inverse_minutes,
                });
            }
        }
        b = e + 1;
    }
    (runs, open)
}
