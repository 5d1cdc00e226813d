//! `G64 P Q`: the path tolerances as LinuxCNC reads them, in mm. What they permit is
//! [`PathMode::merge`]: the on-line compressor follows it.

use super::error::{ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use nc_geom::program::PathMode;

impl Parser<'_> {
    /// The line's `G64` with its `P` (blending) and `Q` (naive-CAM) tolerances, in mm.
    pub(super) fn blend_words(&self, line: &Line<'_>) -> Result<PathMode, ParseError> {
        let scale = self.modal.scale();
        let word = |letter: char| -> Result<Option<f64>, ParseError> {
            match line.get(letter) {
                None => Ok(None),
                // LinuxCNC takes a negative tolerance for one not given; dnurbs refuses it
                // rather than guess.
                Some(w) if w.value < 0.0 => {
                    let (letter, value) = (letter, w.value);
                    Err(ParseErrorKind::NegativePathTolerance { letter, value }.at(w.pos))
                }
                Some(w) => Ok(Some(w.value * scale)),
            }
        };
        Ok(PathMode::Blend {
            p_mm: word('P')?,
            q_mm: word('Q')?,
        })
    }
}
