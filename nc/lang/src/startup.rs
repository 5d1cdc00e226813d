//! The machine's start-up modes ([`Startup`], LinuxCNC's `RS274NGC_STARTUP_CODE`): modal
//! codes in effect before a program's first line, so that a program written for an inch
//! machine without a `G20` runs in inches there, as it does on that machine's LinuxCNC.
//!
//! Only codes that set a mode may be given, each at most once per modal group: the plane
//! (`G17` `G18` `G19`), units (`G20` `G21`), `G40`, `G49`, a work offset (`G54`..`G59`),
//! path control (`G61`, `G64` with its `P` `Q`), `G80`, distance modes (`G90` `G91`
//! `G90.1` `G91.1`), feed modes (`G93` `G94`) and the canned-cycle return (`G98` `G99`).
//! A motion, a move, a tool, a spindle or coolant word is refused: start-up is a state, not
//! an action.

use crate::word::Word;

/// The G codes start-up modes may hold.
pub const STARTUP_CODES: &str =
    "G08 G17 G18 G19 G20 G21 G40 G49 G54-G59 G61 G61.1 G64 (P Q) G80 G90 G91 G90.1 G91.1 G93 G94 G98 G99";

/// Start-up modes, parsed and checked ([`Startup::parse`], in `startup_parse`); the default sets none.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Startup {
    pub(crate) text: String,
    pub(crate) words: Vec<Word>,
}

/// Why start-up modes are refused: the column (from 1) in the text and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("column {col}: {message}")]
pub struct StartupError {
    pub col: u32,
    pub message: String,
}

impl Startup {
    /// The modes as written (trimmed).
    pub fn text(&self) -> &str {
        &self.text
    }

    pub(crate) fn words(&self) -> &[Word] {
        &self.words
    }
}
