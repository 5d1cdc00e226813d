//! `G10`: LinuxCNC's tables set from the program. `G10 L2 P<n> X Y Z` sets work offset `n`
//! (1..6: G54..G59; 0: the one in effect) to the coordinates given (machine frame, the line's
//! units, always absolute); `G10 L20` sets it so that the current point gets the coordinates
//! given; `G10 L1 P<tool> Z R` sets a tool's length and radius. Axes left out keep their
//! value; the offset in effect moves at once, and its parameters (#5221..) follow.
//!
//! dnurbs's offsets move X Y Z only: a rotary word or a rotation (`R`) other than 0 is
//! refused with its column, as `G92 A` is.

use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use nc_geom::program::SrcPos;

const AXES: [char; 3] = ['X', 'Y', 'Z'];

impl Parser<'_> {
    /// A `G10` line (no motion: its axis words are the table's).
    pub(super) fn set_table(&mut self, line: &Line<'_>, pos: SrcPos) -> Result<(), ParseError> {
        if let Some((motion, at)) = line.motion {
            return Err(ParseErrorKind::AxisWordsTwice { code: 10.0, motion }.at(at));
        }
        let l = match line.get('L').and_then(|w| w.uint) {
            Some(l @ (1 | 2 | 20)) => l as u8,
            _ => return Err(ParseErrorKind::G10Kind.at(line.get('L').map_or(pos, |w| w.pos))),
        };
        let p = line.get('P');
        let index = |max: u32| {
            let bad = ParseErrorKind::G10Index {
                l,
                value: p.map_or(f64::NAN, |w| w.value),
            };
            match p.and_then(|w| w.uint) {
                Some(n) if n <= max => Ok(n),
                _ => Err(bad.at(p.map_or(pos, |w| w.pos))),
            }
        };
        if l == 1 {
            line.only("GMFSTLPZR", Context::SetTable { l })?;
            let tool = index(99_999)?;
            if tool == 0 {
                let kind = ParseErrorKind::G10Index { l, value: 0.0 };
                return Err(kind.at(p.map_or(pos, |w| w.pos)));
            }
            let scale = self.modal.scale();
            if let Some(z) = line.get('Z') {
                self.tools.insert(tool, z.value * scale);
            } else {
                self.tools.entry(tool).or_insert(0.0);
            }
            if let Some(r) = line.get('R') {
                self.diameters.insert(tool, 2.0 * r.value * scale);
            }
            return Ok(());
        }
        line.only("GMFSTLPXYZABCR", Context::SetTable { l })?;
        let r = line.get('R');
        let rotary = ['A', 'B', 'C']
            .into_iter()
            .filter_map(|l| line.get(l))
            .chain(r.filter(|_| l == 20));
        for w in rotary {
            let letter = w.letter;
            if w.value != 0.0 {
                let kind = ParseErrorKind::G10Rotary {
                    letter,
                    value: w.value,
                };
                return Err(kind.at(w.pos));
            }
        }
        let n = index(6)?;
        let k = match n {
            0 => usize::from(self.modal.work),
            n => n as usize - 1,
        };
        if k == usize::from(self.modal.work) {
            self.comp_forbids("changing the work offset in effect", pos)?;
        }
        let mut work = self
            .work_offsets
            .get(k)
            .copied()
            .flatten()
            .unwrap_or([0.0; 3]);
        let here = if l == 20 {
            self.rotation_forbids("G10 L20", pos)?;
            Some(self.here_or_reference(line, pos, 'X')?)
        } else {
            None
        };
        for (i, axis) in AXES.into_iter().enumerate() {
            if let Some(w) = line.get(axis) {
                let v = w.value * self.modal.scale();
                work[i] = match here {
                    // The current point gets `v` in that system (the G92 offset kept).
                    Some(h) => h[i] - self.modal.g92[i] - v,
                    None => v,
                };
            }
        }
        if let Some(slot) = self.work_offsets.get_mut(k) {
            *slot = Some(work);
        }
        if let (Some(r), Some(slot)) = (r, self.rotations.get_mut(k)) {
            *slot = r.value;
        }
        if k == usize::from(self.modal.work) {
            self.modal.offset = std::array::from_fn(|i| work[i] + self.modal.g92[i]);
        }
        Ok(())
    }
}
