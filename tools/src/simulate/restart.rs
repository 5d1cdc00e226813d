//! `simulate --from-line N`: the program restarted from a line ([`nc_lang::restart`]), with
//! the machine standing where the program starts, and what the restart restored and how
//! the tool approaches, for the summary.

use crate::exit::InputError;
use crate::setup::MachineSetup;
use nc_geom::program::Program;
use nc_geom::segment::build;
use nc_lang::restart::{from_line, Standing};
use serde::Serialize;
use std::path::Path;

/// What a restart restored and the approach it takes ([`crate::simulate::Summary::restart`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RestartNote {
    /// The line asked for, and the line with the first move at or after it.
    pub asked: u32,
    pub line: u32,
    pub clearance_mm: f64,
    /// The approach in the workpiece frame, mm: back along the tool axis from where the
    /// machine stands, over above the restart pose, down onto it.
    pub approach: [[f64; 3]; 3],
    /// Restored from the lines before: the spindle (rpm, negative counter-clockwise), the
    /// coolant, the tool the last `M06` loaded (it must be in the spindle).
    pub spindle_rpm: f64,
    pub mist: bool,
    pub flood: bool,
    pub tool: Option<u32>,
}

impl RestartNote {
    /// The summary's lines.
    pub fn text(&self) -> String {
        let p = |x: &[f64; 3]| format!("X{:.4} Y{:.4} Z{:.4}", x[0], x[1], x[2]);
        let coolant = match (self.mist, self.flood) {
            (true, true) => "mist and flood",
            (true, false) => "mist",
            (false, true) => "flood",
            (false, false) => "off",
        };
        let tool = self.tool.map_or_else(
            || "none loaded".to_owned(),
            |t| format!("T{t} (must be in the spindle)"),
        );
        let from = if self.asked == self.line {
            format!("line {}", self.line)
        } else {
            format!(
                "line {} (the first move at or after line {})",
                self.line, self.asked
            )
        };
        format!(
            "restart            from {from}: spindle {} rpm, coolant {coolant}, tool {tool}\n\
             approach           up {} mm along the tool to {}, over to {}, down to {}\n",
            self.spindle_rpm,
            self.clearance_mm,
            p(&self.approach[0]),
            p(&self.approach[1]),
            p(&self.approach[2]),
        )
    }
}

/// `program` restarted from `line`, the machine standing at the program's start pose.
pub fn restart(
    program: &Program,
    file: &Path,
    line: u32,
    clearance_mm: f64,
    setup: &MachineSetup,
) -> Result<(Program, RestartNote), InputError> {
    // Where the program starts: its first block, built alone.
    let first = Program {
        blocks: program.blocks.iter().take(1).cloned().collect(),
        actions: Vec::new(),
        end: None,
        tilt_word: program.tilt_word,
        rerun: Vec::new(),
    };
    let start =
        build(&first, &setup.kin, &setup.build).map_err(|e| InputError::program(file, e))?;
    let standing = Standing {
        joints: start.start_joints,
        tool_length: start.start.z,
    };
    let r = from_line(
        program,
        line,
        &setup.kin,
        &setup.build,
        &standing,
        clearance_mm,
    )
    .map_err(|error| InputError::Restart {
        file: file.display().to_string(),
        line,
        error,
    })?;
    let note = RestartNote {
        asked: r.asked,
        line: r.line,
        clearance_mm,
        approach: r.approach,
        spindle_rpm: r.modal.aux.spindle_rpm,
        mist: r.modal.aux.mist,
        flood: r.modal.aux.flood,
        tool: r.modal.tool,
    };
    Ok((r.program, note))
}
