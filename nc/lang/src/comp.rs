//! Cutter radius compensation (`G41`/`G42`, `G41.1`/`G42.1`, `G40`) as LinuxCNC's interpreter
//! does it, so that a program compensated by the control runs on the path `rs274` prints.
//!
//! The tool centre runs at the tool radius to the left (`G41`) or right (`G42`) of the
//! programmed XY path. The end of a move depends on the move after it (the corner between
//! them), so each compensated move is held in a queue until the next one decides its corner:
//!
//! - **entry** (the first move after `G41`/`G42`): a line from where the tool is to the
//!   programmed end point offset perpendicular to the line by the radius (or an arc whose
//!   end is offset along its radius and whose centre is moved so the arc still fits); the
//!   move must be longer than the radius;
//! - **convex corner** (the tool on the outside): the held move ends as it is, a corner arc
//!   about the programmed corner point (radius = tool radius) joins the next move;
//! - **concave corner** (the tool on the inside): the held moves end where the two offset
//!   paths meet (line/line, line/arc, arc/line, arc/arc); a held line that would have to run
//!   backwards, or a held arc whose sweep would grow, means the tool cannot get into the
//!   corner without gouging, and the program is refused at the move that made the corner;
//! - a move without XY motion keeps the tool's XY and is held too (it moves with the corner);
//! - actions between held moves (feeds, dwells, spindle, coolant) stay between them;
//! - **exit** (`G40`, a stop, the program end): the held moves are released as they are;
//!   after `G40` the next move starts from the programmed point and must be a line.
//!
//! Corners are decided with LinuxCNC's angle tolerance [`CORNER_TOL_RAD`]. The geometry of a
//! corner is in `comp_corner.rs`; this file keeps the state and the queue.

use nc_geom::program::{ActionKind, MoveTooling, Orientation, SrcPos};

/// Corners within this angle (radians) of straight are not corners (LinuxCNC's
/// `TOLERANCE_CONCAVE_CORNER`).
pub const CORNER_TOL_RAD: f64 = 0.05;
/// A held arc's sweep may grow by this much (radians) when a concave corner moves its end,
/// before it counts as a gouge: LinuxCNC's numbers, 0.0254 in a millimetre program and 0.001
/// in an inch program (its tolerance is written in length units but compared with angles).
pub const SWEEP_GROWTH_RAD: [f64; 2] = [0.0254, 0.001];
/// A held arc whose new end is off its circle by more than this (program units) is an
/// internal error (LinuxCNC's check).
const ARC_MOVE_TOL_UNITS: f64 = 0.01;

/// Which side of the programmed path the tool runs on, seen along the path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    /// The other side (a negative diameter swaps them, as in LinuxCNC).
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// Whether the tool is inside an arc turning counter-clockwise (`ccw`) or not.
    pub fn inside(self, ccw: bool) -> bool {
        (self == Side::Left) == ccw
    }
}

/// What a held move carries besides its geometry.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Meta {
    pub pos: SrcPos,
    pub n: Option<u32>,
    pub feed_mm_min: f64,
    pub orientation: Orientation,
    pub tooling: MoveTooling,
}

impl Meta {
    /// The meta of a second block of the same line: the wait stays with the first.
    pub fn without_wait(&self) -> Meta {
        let mut m = self.clone();
        m.tooling.wait = Default::default();
        m
    }
}

/// A held move or action.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Queued {
    Line {
        rapid: bool,
        /// The direction LinuxCNC records for the move, to see whether a moved end runs it
        /// backwards.
        dir: [f64; 2],
        end: [f64; 3],
        meta: Meta,
    },
    Arc {
        /// The programmed arc's sweep (rad, signed); 0 for a corner arc (never checked).
        sweep: f64,
        end: [f64; 3],
        centre: [f64; 2],
        ccw: bool,
        meta: Meta,
    },
    Action(SrcPos, ActionKind),
}

/// A compensation in effect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Active {
    pub side: Side,
    /// Tool radius, mm (>= 0; 0 compensates nothing).
    pub radius: f64,
    /// mm per program unit (units cannot change while compensation is on).
    pub scale: f64,
    /// No move made yet since it was turned on.
    pub first: bool,
    /// The programmed point (mm) the last move ended at.
    pub programmed: [f64; 3],
    /// Where the tool centre is (mm), as far as decided.
    pub current: [f64; 3],
}

/// The compensation state of a program.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Comp {
    pub active: Option<Active>,
    pub(crate) queue: Vec<Queued>,
    /// Where the held moves start (XY), when known (LinuxCNC's `endpoint`).
    pub(crate) endpoint: Option<[f64; 2]>,
    /// Where the last released move ended (mm): the start of the next one.
    pub(crate) released_end: [f64; 3],
    /// The next move must be straight (just after `G40`).
    pub arc_not_allowed: bool,
    /// Released moves and actions, each move with its start, for the parser to emit.
    pub out: Vec<(Queued, [f64; 3])>,
}

/// Why a compensated move is refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum CompError {
    EntryTooShort { length: f64, radius: f64 },
    ToolTooBig { arc_radius: f64, radius: f64 },
    Gouge(&'static str),
    Internal(&'static str),
}

impl Comp {
    /// Whether compensation moves the tool (on, with a radius above 0).
    pub fn compensating(&self) -> Option<Active> {
        self.active.filter(|a| a.radius > 0.0)
    }

    /// The point a move's missing and incremental coordinates are taken from: the
    /// programmed point once the entry move is made.
    pub fn base(&self) -> Option<[f64; 3]> {
        self.compensating()
            .filter(|a| !a.first)
            .map(|a| a.programmed)
    }

    /// How many moves are held.
    pub fn held_moves(&self) -> usize {
        self.queue
            .iter()
            .filter(|q| !matches!(q, Queued::Action(..)))
            .count()
    }

    /// Whether actions must be held (a move is held before them).
    pub fn holding(&self) -> bool {
        !self.queue.is_empty()
    }

    /// Moves everything held to `out`, in order.
    pub(crate) fn release(&mut self) {
        self.endpoint = None;
        for q in self.queue.drain(..) {
            let start = self.released_end;
            match &q {
                Queued::Line { end, .. } | Queued::Arc { end, .. } => self.released_end = *end,
                Queued::Action(..) => {}
            }
            self.out.push((q, start));
        }
    }

    /// Ends every held move at `xy` and releases them: LinuxCNC's `move_endpoint_and_flush`,
    /// with its checks that the tool does not have to run a line backwards or an arc further
    /// round than programmed to get there.
    pub(crate) fn move_ends_and_release(&mut self, xy: [f64; 2]) -> Result<(), CompError> {
        if self.queue.is_empty() {
            return Ok(());
        }
        let scale = self.active.map_or(1.0, |a| a.scale);
        let ep = self.endpoint;
        let ep_xy = ep.unwrap_or([0.0; 2]);
        for q in &mut self.queue {
            match q {
                Queued::Arc {
                    sweep,
                    end,
                    centre,
                    ccw,
                    ..
                } => {
                    let r1 = (end[0] - centre[0]).hypot(end[1] - centre[1]);
                    let r2 = (xy[0] - centre[0]).hypot(xy[1] - centre[1]);
                    if (r1 - r2).abs() > ARC_MOVE_TOL_UNITS * scale {
                        return Err(CompError::Internal("a held arc's end is off its circle"));
                    }
                    let new_sweep = find_turn(ep_xy, *centre, *ccw, xy);
                    let growth = SWEEP_GROWTH_RAD[usize::from(scale != 1.0)];
                    if *sweep != 0.0 && ep.is_some() && new_sweep.abs() > sweep.abs() + growth {
                        return Err(CompError::Gouge(
                            "an arc in a concave corner cannot be reached by the tool",
                        ));
                    }
                    end[0] = xy[0];
                    end[1] = xy[1];
                }
                Queued::Line {
                    rapid, dir, end, ..
                } => {
                    let dot = dir[0] * (xy[0] - ep_xy[0]) + dir[1] * (xy[1] - ep_xy[1]);
                    if ep.is_some() && dot < 0.0 {
                        return Err(CompError::Gouge(if *rapid {
                            "a rapid in a concave corner cannot be reached by the tool"
                        } else {
                            "a line in a concave corner cannot be reached by the tool"
                        }));
                    }
                    end[0] = xy[0];
                    end[1] = xy[1];
                }
                Queued::Action(..) => {}
            }
        }
        self.release();
        self.endpoint = Some(xy);
        Ok(())
    }

    /// Releases the held moves where they are (a stop, `G40`, the program end).
    pub(crate) fn flush_here(&mut self) -> Result<(), CompError> {
        if let Some(a) = self.compensating() {
            self.move_ends_and_release([a.current[0], a.current[1]])?;
        }
        self.release();
        Ok(())
    }

    /// `G40`: releases the held moves; the tool continues from the programmed point.
    /// Returns the programmed point when compensation had moved the tool.
    pub(crate) fn off(&mut self) -> Result<Option<[f64; 3]>, CompError> {
        let moved = self.compensating().filter(|a| !a.first);
        if moved.is_some() {
            self.flush_here()?;
            self.arc_not_allowed = true;
        }
        self.active = None;
        Ok(moved.map(|a| a.programmed))
    }
}

/// The signed angle (rad, counter-clockwise positive) an arc about `centre` turns from `a`
/// to `b`, one turn at most (LinuxCNC's `find_turn` for one turn).
pub(crate) fn find_turn(a: [f64; 2], centre: [f64; 2], ccw: bool, b: [f64; 2]) -> f64 {
    use core::f64::consts::TAU;
    let alpha = (a[1] - centre[1]).atan2(a[0] - centre[0]);
    let beta = (b[1] - centre[1]).atan2(b[0] - centre[0]);
    if ccw {
        let beta = if beta <= alpha { beta + TAU } else { beta };
        beta - alpha
    } else {
        let alpha = if alpha <= beta { alpha + TAU } else { alpha };
        beta - alpha
    }
}
