//! LinuxCNC's splines in the XY plane, exact as NURBS blocks:
//!
//! - `G5.1 X Y I J`: a quadratic B-spline (a quadratic Bezier) from the current point to
//!   `X Y`, its control point `I J` from the start.
//! - `G5 X Y I J P Q`: a cubic (a cubic Bezier), its first control point `I J` from the start
//!   and its second `P Q` from the end. `I J` may be left out (both): they are then the last
//!   `G5`'s `P Q` negated (the curves join tangent), or 0 before any `G5`, as in LinuxCNC.
//!
//! `X Y` are the end point (incremental under `G91`); `I J P Q` are always offsets. Refused
//! with their column: another plane, a `Z` or angle word (LinuxCNC's splines are planar),
//! inverse time (which LinuxCNC takes), and what LinuxCNC refuses (`G5.1` without both `I`
//! and `J`, `G5` without both `P` and `Q`, or with only one of `I J`).

use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use crate::vocab::{Motion, Plane};
use nc_geom::program::{Block, NurbsBlock, NurbsKind, SrcPos};

impl Parser<'_> {
    /// The modes LinuxCNC's planar curves (`G5`, `G5.1`, `G5.2`) need: `G17`, `G94`, a feed.
    pub(super) fn planar_curve_modes(&self, motion: Motion, pos: SrcPos) -> Result<(), ParseError> {
        if self.modal.plane != Plane::Xy {
            return Err(ParseErrorKind::SplinePlane { motion }.at(pos));
        }
        if self.modal.inverse_time {
            return Err(ParseErrorKind::SplineInverseTime { motion }.at(pos));
        }
        if self.feed.is_none() {
            return Err(self.no_feed(motion).at(pos));
        }
        Ok(())
    }

    /// A `G5` / `G5.1` line (or its modal continuation).
    pub(super) fn spline(
        &mut self,
        line: &Line<'_>,
        motion: Motion,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        let cubic = motion == Motion::G05;
        let letters = if cubic { "GMFSTXYIJPQ" } else { "GMFSTXYIJ" };
        line.only(&self.extra_letters(line, letters), Context::Move(motion))?;
        if line.first_of("XYIJPQ").is_none() {
            return Ok(());
        }
        self.planar_curve_modes(motion, pos)?;
        let scale = self.modal.scale();
        let word = |l: char| line.value(l).map(|v| v * scale);
        let start = self.here_or_reference(line, pos, 'X')?;
        let end = self.end_point(line, pos)?;
        let (x0, y0, z) = (start[0], start[1], start[2]);
        let (x3, y3) = (end[0], end[1]);
        let ctrl = if cubic {
            let missing = |letter| {
                let kind = ParseErrorKind::MissingWord {
                    letter,
                    context: Context::Move(motion),
                };
                Err(kind.at(pos))
            };
            let (p, q) = match (word('P'), word('Q')) {
                (Some(p), Some(q)) => (p, q),
                (None, _) => return missing('P'),
                (_, None) => return missing('Q'),
            };
            let (i, j) = match (word('I'), word('J')) {
                (Some(i), Some(j)) => (i, j),
                (None, None) => {
                    let (pp, pq) = self.last_spline_pq.unwrap_or((0.0, 0.0));
                    (-pp, -pq)
                }
                (None, _) => return Err(ParseErrorKind::SplineWithoutIj.at(pos)),
                (_, None) => return Err(ParseErrorKind::SplineWithoutIj.at(pos)),
            };
            self.last_spline_pq = Some((p, q));
            vec![
                [x0, y0, z],
                [x0 + i, y0 + j, z],
                [x3 + p, y3 + q, z],
                [x3, y3, z],
            ]
        } else {
            let (i, j) = match (word('I'), word('J')) {
                (Some(i), Some(j)) => (i, j),
                (i, _) => {
                    let letter = if i.is_none() { 'I' } else { 'J' };
                    let kind = ParseErrorKind::MissingWord {
                        letter,
                        context: Context::Move(motion),
                    };
                    return Err(kind.at(pos));
                }
            };
            vec![[x0, y0, z], [x0 + i, y0 + j, z], [x3, y3, z]]
        };
        let degree = ctrl.len() - 1;
        let knots: Vec<f64> = (0..2 * ctrl.len())
            .map(|k| if k < ctrl.len() { 0.0 } else { 1.0 })
            .collect();
        // The feed's length: the control polygon bounds the curve; its chord is below. Only
        // inverse time would need it exactly, and that is refused above.
        let length = ctrl
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum::<f64>();
        let feed_mm_min = self.move_feed(line, motion, pos, length)?;
        let tooling = self.tooling();
        self.here = Some([x3, y3, z]);
        let count = ctrl.len();
        self.blocks.push(Block::Nurbs(NurbsBlock {
            pos,
            n: line.n,
            kind: NurbsKind::G062,
            degree: degree as u8,
            ctrl,
            tool_ctrl: Vec::new(),
            ctrl_pos: vec![pos; count],
            weights: vec![1.0; count],
            knots,
            feed_mm_min,
            tooling,
            turn_to: None,
        }));
        Ok(())
    }
}
