//! An open `G06.2` / `G06.5` block: collects control points and knots line by line and
//! checks every NURBS rule as soon as the offending token is seen.
//!
//! Shape of a block: the opening line carries the first control point, each following
//! control-point line one more, each with its knot; then lines of `K` words only bring the
//! remaining degree + 1 knots. The first `K`-only line fixes the control-point count and so the
//! knot count; the block is complete when that many knots have arrived.

use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::word::Word;
use crate::rules::{MIN_TOOL_OFFSET_MM, START_TOLERANCE_MM};
use crate::vocab::Motion;
use nc_geom::program::MAX_BLOCK_CTRL;
use nc_geom::program::{MoveTooling, NurbsBlock, NurbsKind, SrcPos, MAX_DEGREE};

/// Program coordinates to the workpiece frame: `mm = value * scale + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Frame {
    pub scale: f64,
    pub offset: [f64; 3],
}

impl Frame {
    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        [
            p[0] * self.scale + self.offset[0],
            p[1] * self.scale + self.offset[1],
            p[2] * self.scale + self.offset[2],
        ]
    }
}

pub(super) struct OpenNurbs {
    block: NurbsBlock,
    frame: Frame,
    motion: Motion,
    /// Position of each knot's `K` word, for errors found when the block completes.
    knot_pos: Vec<SrcPos>,
    /// Knot count, fixed by the first `K`-only line.
    need: Option<usize>,
}

impl OpenNurbs {
    /// Opens a block on its `G06.2` / `G06.5` line and takes that line's control point.
    /// `here` is the current position, `feed` the modal feed (this line's `F` included).
    pub fn open(
        line: &Line<'_>,
        (motion, pos): (Motion, SrcPos),
        here: [f64; 3],
        feed: Option<f64>,
        frame: Frame,
        tooling: MoveTooling,
    ) -> Result<Self, ParseError> {
        let kind = if motion == Motion::G065 {
            NurbsKind::G065
        } else {
            NurbsKind::G062
        };
        let letters = if kind == NurbsKind::G065 {
            "GFPXYZUVWRK"
        } else {
            "GFPXYZRK"
        };
        line.only(letters, Context::ControlPoint(motion))?;
        let feed_mm_min = feed.ok_or(ParseErrorKind::NoFeed { motion }.at(pos))?;
        let degree = match (kind, line.get('P')) {
            (NurbsKind::G065, None) => return Err(ParseErrorKind::MissingDegree.at(pos)),
            (NurbsKind::G062, None) => 3, // rank 4
            (_, Some(p)) => {
                let rank_offset = if kind == NurbsKind::G062 { 1.0 } else { 0.0 };
                let degree = p.value - rank_offset;
                if degree.fract() != 0.0 || !(1.0..=MAX_DEGREE as f64).contains(&degree) {
                    let bad = ParseErrorKind::BadDegree {
                        motion,
                        value: p.value,
                    };
                    return Err(bad.at(p.pos));
                }
                degree as u8 // exact: an integer in 1..=MAX_DEGREE
            }
        };
        let block = NurbsBlock {
            pos,
            n: line.n,
            kind,
            degree,
            ctrl: Vec::new(),
            tool_ctrl: Vec::new(),
            ctrl_pos: Vec::new(),
            weights: Vec::new(),
            knots: Vec::new(),
            feed_mm_min,
            tooling,
            turn_to: None,
        };
        let mut open = OpenNurbs {
            block,
            frame,
            motion,
            knot_pos: Vec::new(),
            need: None,
        };
        open.add_point(line, Some(here))?;
        Ok(open)
    }

    /// Takes a line that follows the opening line. Returns `true` when the block is complete.
    ///
    /// A line of `K` words only brings knots. A line without G/M codes that has a word only a
    /// control point has (`K`, `R`, and for `G06.5` `U V W`) is a control-point line and is
    /// checked as one. Any other line (a code, bare coordinates) means the block was cut short.
    pub fn take_line(&mut self, line: &Line<'_>) -> Result<bool, ParseError> {
        if line.knots_only {
            return self.add_knots(line.body);
        }
        if line.body.is_empty() {
            return Ok(false); // a line with only `N`
        }
        let g065 = self.block.kind == NurbsKind::G065;
        let point_line =
            !line.has_codes && line.first_of(if g065 { "KRUVW" } else { "KR" }).is_some();
        // Once knots have started, the control points are over.
        if !point_line || self.need.is_some() {
            let at = line.first_of("GM").map_or(line.first, |w| w.pos);
            return Err(self.incomplete(at));
        }
        line.only(self.point_letters(), Context::ControlPoint(self.motion))?;
        self.add_point(line, None)?;
        Ok(false)
    }

    /// Takes the control point of `line`. `start` is the current position when this is the
    /// block's first point, which must coincide with it.
    fn add_point(&mut self, line: &Line<'_>, start: Option<[f64; 3]>) -> Result<(), ParseError> {
        let context = Context::ControlPoint(self.motion);
        let g065 = self.block.kind == NurbsKind::G065;
        let pos = line
            .first_of(self.point_letters())
            .map_or(line.first, |w| w.pos);
        let need = |letter| line.require(letter, context, pos);
        let xyz = self
            .frame
            .apply([need('X')?.value, need('Y')?.value, need('Z')?.value]);
        let tool = if g065 {
            Some([need('U')?, need('V')?, need('W')?])
        } else {
            None
        };
        let knot = need('K')?;
        let weight = match line.get('R') {
            Some(r) if r.value < crate::rules::MIN_WEIGHT => {
                return Err(ParseErrorKind::BadWeight { value: r.value }.at(r.pos));
            }
            Some(r) => r.value,
            None => 1.0,
        };
        let uvw = tool.map(|w| self.frame.apply(w.map(|w| w.value)));
        if let (Some(uvw), Some([u, ..])) = (uvw, tool) {
            let dist = distance(xyz, uvw);
            if dist < MIN_TOOL_OFFSET_MM {
                return Err(ParseErrorKind::ToolPointTooClose { xyz, uvw, dist }.at(u.pos));
            }
        }
        if let Some(current) = start {
            if xyz
                .iter()
                .zip(current)
                .any(|(a, b)| (a - b).abs() > START_TOLERANCE_MM)
            {
                return Err(ParseErrorKind::StartMismatch { ctrl: xyz, current }.at(pos));
            }
        }
        if self.block.ctrl.len() >= MAX_BLOCK_CTRL {
            return Err(ParseErrorKind::TooManyControlPoints.at(pos));
        }
        self.block.ctrl.push(xyz);
        self.block.ctrl_pos.push(pos);
        self.block.weights.push(weight);
        if let Some(uvw) = uvw {
            self.block.tool_ctrl.push(uvw);
        }
        self.push_knot(knot)
    }

    /// The words of a control-point line.
    fn point_letters(&self) -> &'static str {
        match self.block.kind {
            NurbsKind::G062 => "XYZRK",
            NurbsKind::G065 => "XYZUVWRK",
        }
    }

    /// Takes a line of `K` words. Returns `true` when the block has all its knots.
    fn add_knots(&mut self, words: &[Word]) -> Result<bool, ParseError> {
        let p = usize::from(self.block.degree);
        let count = self.block.ctrl.len();
        let need = match self.need {
            Some(need) => need,
            None if count < p + 1 => {
                let kind = ParseErrorKind::TooFewControlPoints { count, min: p + 1 };
                return Err(kind.at(self.block.pos));
            }
            None => *self.need.insert(count + p + 1),
        };
        for w in words {
            if self.block.knots.len() >= need {
                let kind = ParseErrorKind::TooManyKnots {
                    value: w.value,
                    opened: self.block.pos,
                    need,
                };
                return Err(kind.at(w.pos));
            }
            self.push_knot(*w)?;
        }
        Ok(self.block.knots.len() >= need)
    }

    fn push_knot(&mut self, k: Word) -> Result<(), ParseError> {
        let at = |kind: ParseErrorKind| kind.at(k.pos);
        let knots = &mut self.block.knots;
        if let Some(&prev) = knots.last() {
            if k.value < prev {
                return Err(at(ParseErrorKind::DecreasingKnot {
                    value: k.value,
                    prev,
                }));
            }
        }
        let count = usize::from(self.block.degree) + 1;
        if let Some(&first) = knots.first() {
            if knots.len() < count && k.value > first {
                return Err(at(ParseErrorKind::UnclampedStart {
                    value: k.value,
                    expected: first,
                    count,
                }));
            }
        }
        if knots.len() > MAX_BLOCK_CTRL + MAX_DEGREE {
            return Err(at(ParseErrorKind::TooManyKnots {
                value: k.value,
                opened: self.block.pos,
                need: self.block.ctrl.len() + count,
            }));
        }
        knots.push(k.value);
        self.knot_pos.push(k.pos);
        Ok(())
    }

    /// The error for a block cut short at `pos` (by another kind of line or the end of file).
    pub fn incomplete(&self, pos: SrcPos) -> ParseError {
        let need = self.block.ctrl.len() + usize::from(self.block.degree) + 1;
        let kind = ParseErrorKind::IncompleteKnots {
            opened: self.block.pos,
            have: self.block.knots.len(),
            need,
        };
        kind.at(pos)
    }

    /// Checks the rules that need the whole knot vector and hands out the block.
    pub fn finish(self) -> Result<NurbsBlock, ParseError> {
        let knots = &self.block.knots;
        let count = usize::from(self.block.degree) + 1;
        let (Some(&first), Some(&last)) = (knots.first(), knots.last()) else {
            return Err(self.incomplete(self.block.pos));
        };
        let tail = knots.len().saturating_sub(count);
        let at = |i: usize, kind: ParseErrorKind| {
            kind.at(self.knot_pos.get(i).copied().unwrap_or(self.block.pos))
        };
        if let Some((i, &value)) = knots
            .iter()
            .enumerate()
            .skip(tail)
            .find(|&(_, &k)| k < last)
        {
            return Err(at(
                i,
                ParseErrorKind::UnclampedEnd {
                    value,
                    expected: last,
                    count,
                },
            ));
        }
        if last <= first {
            return Err(at(
                knots.len().saturating_sub(1),
                ParseErrorKind::EmptyKnotRange { first, last },
            ));
        }
        Ok(self.block)
    }
}

/// Euclidean distance of two points, mm.
pub(super) fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    let [dx, dy, dz] = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    dx.hypot(dy).hypot(dz)
}
