//! `G92`, `G92.1`, `G92.2`, `G92.3`: the offset LinuxCNC adds to every work offset. `G92 X Y
//! Z` shifts the program's zero so that the current point has the coordinates given (in the
//! line's units, never incremental), for the axes given; `G92.1` cancels it and zeroes its
//! parameters (5211..), `G92.2` cancels it keeping them, `G92.3` applies them again. A later
//! `G54`..`G59` keeps it: the program's zero is the work offset plus this one.
//!
//! On the rotary axes (`G92 A`, `B`, `C`) the offset is in degrees and makes the angle in
//! effect read as the one given (a 3D printer's post resets its extruder axis so); the angles
//! a program writes are then that much off the machine's. It needs the angles in effect:
//! after a tool axis given as a vector it is refused.

use super::codes::G92;
use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use nc_geom::program::{Orientation, SrcPos};

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
            line.only("GMFSTXYZABC", Context::CoordOffset { tenth })?;
            self.rotary_offset(line)?;
        } else {
            line.only("GMFST", Context::CoordOffset { tenth })?;
        }
        // The work offset alone, under the G92 offset in effect.
        let work: [f64; 3] = std::array::from_fn(|i| self.modal.offset[i] - self.modal.g92[i]);
        let g92 = match kind {
            G92::Set => {
                if line.first_of("XYZABC").is_none() {
                    return Err(ParseErrorKind::OffsetWithoutAxes.at(pos));
                }
                if line.first_of("XYZ").is_none() {
                    return Ok(());
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
                self.modal.g92_rot_saved = [0.0; 2];
                self.modal.g92_rot = [0.0; 2];
                [0.0; 3]
            }
            G92::Suspend => {
                self.modal.g92_rot = [0.0; 2];
                [0.0; 3]
            }
            G92::Restore => {
                self.modal.g92_rot = self.modal.g92_rot_saved;
                self.modal.g92_saved
            }
        };
        self.modal.g92 = g92;
        self.modal.offset = std::array::from_fn(|i| work[i] + g92[i]);
        Ok(())
    }

    /// `G92 A B C`: the rotary offsets that make the angles in effect read as those given.
    fn rotary_offset(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let Some(first) = line.first_of("ABC") else {
            return Ok(());
        };
        let current = match self.orientation {
            Orientation::Angles { r1_deg, r2_deg } => [r1_deg, r2_deg],
            Orientation::Vector(_) if !self.orientation_given => [0.0, 0.0],
            Orientation::Vector(_) => {
                let kind = ParseErrorKind::OffsetRotary { axis: first.letter };
                return Err(kind.at(first.pos));
            }
        };
        let (tilt, c) = (line.first_of("AB"), line.get('C'));
        if let Some(w) = tilt {
            self.rotary_letter(w)?;
        }
        let mut rot = self.modal.g92_rot;
        for (k, w) in [(0, tilt), (1, c)] {
            if let (Some(w), Some(slot), Some(cur)) = (w, rot.get_mut(k), current.get(k)) {
                *slot = cur - w.value;
            }
        }
        self.modal.g92_rot = rot;
        self.modal.g92_rot_saved = rot;
        Ok(())
    }
}
