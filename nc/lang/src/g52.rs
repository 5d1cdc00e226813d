//! LinuxCNC's NURBS in the XY plane, `G5.2` .. `G5.3`, exact as a NURBS block:
//!
//! ```text
//! G5.2 [P<first weight>] [X Y P] [L<order>]
//! X Y P          (a control point and its weight, P > 0)
//! ...
//! G5.3
//! ```
//!
//! As LinuxCNC builds it: the current point is the first control point (its weight the `P`
//! of a `G5.2` line without `X Y`, else 1); the order is 3 unless an `L` above 3 gives it;
//! the knots are the clamped uniform integers `0 .. n - k + 2` of its `NURBS_FEED`; `X Y` are
//! resolved as a move's (units, `G91` from the point before the block, offsets) and `Z`
//! stays. Refused with their column: another plane, `Z` or angle words, `X` without `Y`, a
//! weight that is not positive, fewer points than the order, an order above 6 (degree 5,
//! dnurbs's highest), `G93`, a block that another motion interrupts or the program ends in.

use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use crate::open_g52::OpenG52;
use crate::vocab::Motion;
use nc_geom::program::{Block, NurbsBlock, NurbsKind, SrcPos};

/// Highest order (degree + 1) dnurbs evaluates.
const MAX_ORDER: usize = 6;

impl Parser<'_> {
    /// A line of a `G5.2` block: the opening line, or a control point.
    pub(super) fn g52_point(&mut self, line: &Line<'_>, pos: SrcPos) -> Result<(), ParseError> {
        let motion = Motion::G052;
        line.only(
            &self.extra_letters(line, "GMFSTXYPL"),
            Context::Move(motion),
        )?;
        self.planar_curve_modes(motion, pos)?;
        let (x, y) = (line.get('X'), line.get('Y'));
        if let (Some(w), None) | (None, Some(w)) = (x, y) {
            return Err(ParseErrorKind::NurbsPointXy { letter: w.letter }.at(w.pos));
        }
        let weight = line.get('P');
        if self.g52.is_none() {
            let start = self.here_or_reference(line, pos, 'X')?;
            let first = match (x, weight) {
                (None, Some(p)) if p.value > 0.0 => p.value,
                _ => 1.0,
            };
            self.g52 = Some(OpenG52 {
                pos,
                n: line.n,
                ctrl: vec![start],
                ctrl_pos: vec![pos],
                weights: vec![first],
                order: 3,
            });
        } else if let (None, Some(p)) = (x, weight) {
            return Err(ParseErrorKind::NurbsFirstWeight.at(p.pos));
        }
        if let Some(l) = line.get('L') {
            let order = l.uint.map_or(0, |o| o as usize);
            if order > MAX_ORDER || l.uint.is_none() {
                return Err(ParseErrorKind::NurbsOrder { value: l.value }.at(l.pos));
            }
            if order > 3 {
                if let Some(open) = &mut self.g52 {
                    open.order = order;
                }
            }
        }
        if x.is_some() {
            let w = match weight {
                Some(p) if p.value > 0.0 => p.value,
                Some(p) => return Err(ParseErrorKind::NurbsWeight { value: p.value }.at(p.pos)),
                None => {
                    let kind = ParseErrorKind::MissingWord {
                        letter: 'P',
                        context: Context::Move(motion),
                    };
                    return Err(kind.at(pos));
                }
            };
            // X Y as a move's, from the point before the block (LinuxCNC keeps its current
            // point there until G5.3).
            let end = self.end_point(line, pos)?;
            if let Some(open) = &mut self.g52 {
                let z = open.ctrl[0][2];
                open.ctrl.push([end[0], end[1], z]);
                open.ctrl_pos.push(pos);
                open.weights.push(w);
            }
        }
        Ok(())
    }

    /// `G5.3`: the block's curve, from the point before it to its last control point.
    pub(super) fn g52_close(&mut self, line: &Line<'_>, pos: SrcPos) -> Result<(), ParseError> {
        line.only(
            &self.extra_letters(line, "GMFST"),
            Context::Move(Motion::G053),
        )?;
        self.mode = None;
        let Some(open) = self.g52.take() else {
            return Err(ParseErrorKind::NurbsCloseWithoutOpen.at(pos));
        };
        let count = open.ctrl.len();
        if count < open.order {
            let kind = ParseErrorKind::NurbsTooFewPoints {
                count,
                order: open.order,
            };
            return Err(kind.at(pos));
        }
        let (n, k) = (count - 1, open.order);
        let knots: Vec<f64> = (0..=n + k)
            .map(|i| match i {
                i if i < k => 0.0,
                i if i <= n => (i + 1 - k) as f64,
                _ => (n + 2 - k) as f64,
            })
            .collect();
        let length = open
            .ctrl
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum::<f64>();
        let feed_mm_min = self.move_feed(line, Motion::G052, open.pos, length)?;
        let tooling = self.tooling();
        self.here = open.ctrl.last().copied();
        self.blocks.push(Block::Nurbs(NurbsBlock {
            pos: open.pos,
            n: open.n,
            kind: NurbsKind::G062,
            degree: (k - 1) as u8,
            ctrl: open.ctrl,
            tool_ctrl: Vec::new(),
            ctrl_pos: open.ctrl_pos,
            weights: open.weights,
            knots,
            feed_mm_min,
            tooling,
            turn_to: None,
        }));
        Ok(())
    }

    /// A `G5.2` block still open where another motion or the program's end comes.
    pub(super) fn g52_unclosed(&self, at: SrcPos) -> Result<(), ParseError> {
        match &self.g52 {
            Some(open) => Err(ParseErrorKind::NurbsNotClosed { opened: open.pos }.at(at)),
            None => Ok(()),
        }
    }
}
