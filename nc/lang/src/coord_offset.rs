//! `G92`, `G92.1`, `G92.2`, `G92.3`: the offset LinuxCNC adds to every work offset. `G92 X Y
//! Z` shifts the program's zero so that the current point has the coordinates given (in the
//! line's units, never incremental), for the axes given; `G92.1` cancels it and zeroes its
//! parameters (5211..), `G92.2` cancels it keeping them, `G92.3` applies them again. A later
//! `G54`..`G59` keeps it: the program's zero is the work offset plus this one.
//!
//! dnurbs offsets X Y Z only: `G92 A0` is refused with its column (an offset of a rotary axis
//! would turn the part to another angle than the program's), never dropped.

use super::codes::G92;
use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use nc_geom::program::SrcPos;

const AXES: [char; 3] = ['X', 'Y', 'Z'];

impl Parser<'_> {
    /// A `G92`-family line: no motion (the axis words are the offset's).
    pub(super) fn coord_offset(
        &mut self,
        line: &Line<'_>,
        kind: G92,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        if let Some((motion, at)) = line.motion {
            let code = kind.value();
            return Err(ParseErrorKind::AxisWordsTwice { code, motion }.at(at));
        }
        let tenth = match kind {
            G92::Set => 0,
            G92::Reset => 1,
            G92::Suspend => 2,
            G92::Restore => 3,
        };
        if kind == G92::Set {
            if let Some(w) = line.first_of("ABC") {
                return Err(ParseErrorKind::OffsetRotary { axis: w.letter }.at(w.pos));
            }
            line.only("GMFSTXYZ", Context::CoordOffset { tenth })?;
        } else {
            line.only("GMFST", Context::CoordOffset { tenth })?;
        }
        // The work offset alone, under the G92 offset in effect.
        let work: [f64; 3] = std::array::from_fn(|i| self.modal.offset[i] - self.modal.g92[i]);
        let g92 = match kind {
            G92::Set => {
                if line.first_of("XYZ").is_none() {
                    return Err(ParseErrorKind::OffsetWithoutAxes.at(pos));
                }
                let here = self.here_or_reference(line, pos, 'X')?;
                let mut g92 = self.modal.g92;
                for (i, axis) in AXES.into_iter().enumerate() {
                    if let Some(w) = line.get(axis) {
                        g92[i] = here[i] - work[i] - w.value * self.modal.scale();
                    }
                }
                self.modal.g92_saved = g92;
                g92
            }
            G92::Reset => {
                self.modal.g92_saved = [0.0; 3];
                [0.0; 3]
            }
            G92::Suspend => [0.0; 3],
            G92::Restore => self.modal.g92_saved,
        };
        self.modal.g92 = g92;
        self.modal.offset = std::array::from_fn(|i| work[i] + g92[i]);
        Ok(())
    }
}
