//! LinuxCNC's polar coordinates: `@` the radius and `^` the angle (degrees) of X Y about the
//! program's zero (`G90`), or added to the current point's radius and angle about it
//! (`G91`); a word left out keeps the current point's. X or Y on the same line is an error,
//! and so is what LinuxCNC finds indeterminate at the program's zero.

use super::error::{ParseError, ParseErrorKind};
use super::line::Line;
use super::moves::check_domain;
use super::parser::Parser;
use nc_geom::program::SrcPos;

impl Parser<'_> {
    /// `end` (workpiece frame, mm; X Y the current point's) with X Y from the line's `@ ^`.
    pub(super) fn polar(
        &self,
        line: &Line<'_>,
        pos: SrcPos,
        end: &mut [f64; 3],
    ) -> Result<(), ParseError> {
        if let Some(w) = line.first_of("XY") {
            return Err(ParseErrorKind::PolarWithXy { letter: w.letter }.at(w.pos));
        }
        let (scale, off) = (self.modal.scale(), self.modal.offset);
        // The current point in program coordinates.
        let (mut x, mut y) = ((end[0] - off[0]) / scale, (end[1] - off[1]) / scale);
        let (r, theta) = (line.value('@'), line.value('^'));
        let indeterminate = |incremental| ParseErrorKind::PolarAtOrigin { incremental }.at(pos);
        if self.modal.incremental {
            if let Some(dr) = r {
                if x == 0.0 && y == 0.0 {
                    return Err(indeterminate(true));
                }
                let (t, rad) = (y.atan2(x), y.hypot(x) + dr);
                (x, y) = (rad * t.cos(), rad * t.sin());
            }
            if let Some(dt) = theta {
                if x == 0.0 && y == 0.0 {
                    return Err(indeterminate(true));
                }
                let (t, rad) = (y.atan2(x) + dt.to_radians(), y.hypot(x));
                (x, y) = (rad * t.cos(), rad * t.sin());
            }
        } else {
            let (rad, t) = match (r, theta) {
                (Some(r), Some(t)) => (r, t.to_radians()),
                (Some(_), None) if x == 0.0 && y == 0.0 => return Err(indeterminate(false)),
                (Some(r), None) => (r, y.atan2(x)),
                (None, Some(t)) => (y.hypot(x), t.to_radians()),
                (None, None) => return Ok(()),
            };
            (x, y) = (rad * t.cos(), rad * t.sin());
        }
        end[0] = check_domain('X', x * scale + off[0], pos)?;
        end[1] = check_domain('Y', y * scale + off[1], pos)?;
        Ok(())
    }
}
