//! `[program]`: how programs are read on this machine (LinuxCNC's `[RS274NGC]` and
//! `[EMCIO] TOOL_TABLE`): the start-up modes, the tool table, where called subroutines are
//! found and how long loops may run.

use std::collections::BTreeMap;
use std::path::PathBuf;

/// Most lines a program may run again in its loops and subroutines when the machine file
/// does not say (the NC language's default).
pub const DEFAULT_MAX_LOOP_LINES: u64 = 100_000_000;

/// A validated `[program]` table; the default is an empty table.
#[derive(Clone, Debug, PartialEq)]
pub struct ProgramSetup {
    /// `startup`: modal codes in effect before a program's first line (checked by the NC
    /// language), trimmed; empty for none.
    pub startup: String,
    /// `tool_table`: the table's path (relative to the machine file's folder, resolved).
    pub tool_table: Option<PathBuf>,
    /// The tools of `tool_table`, by number.
    pub tools: BTreeMap<u32, Tool>,
    /// `subroutine_path`: folders searched for `name.ngc` by `o<name> call`, in order,
    /// resolved as `tool_table` is.
    pub subroutine_dirs: Vec<PathBuf>,
    /// `max_loop_lines`: most lines a program may run again in loops and subroutines.
    pub max_loop_lines: u64,
}

impl Default for ProgramSetup {
    fn default() -> Self {
        ProgramSetup {
            startup: String::new(),
            tool_table: None,
            tools: BTreeMap::new(),
            subroutine_dirs: Vec::new(),
            max_loop_lines: DEFAULT_MAX_LOOP_LINES,
        }
    }
}

/// One tool of a tool table.
#[derive(Clone, Debug, PartialEq)]
pub struct Tool {
    /// Length along the spindle, mm (`Z`).
    pub length_mm: f64,
    /// Diameter, mm (`D`), if given.
    pub diameter_mm: Option<f64>,
    /// The comment after `;`, trimmed.
    pub comment: String,
}
