//! The `dnurbs` command-line tool as a library, so the integration tests and benchmarks can
//! use the same code paths as the binary. `main.rs` only parses arguments and maps errors to
//! exit codes.

pub mod run;
pub mod setup;
pub mod simdrives;
pub mod simulate;

use std::path::Path;

/// A failure the user can fix in their input (exit code 2), already formatted as
/// `file:line:col: message` where a position is known.
#[derive(Debug)]
pub struct InputError(pub String);

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for InputError {}

/// Read and parse an NC program; errors name the file, line and column.
pub fn load_program(path: &Path) -> Result<nc::program::Program, InputError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError(format!("{}: cannot read the program: {e}", path.display())))?;
    nc::parse::parse(&text).map_err(|e| InputError(format!("{}:{e}", path.display())))
}

/// Read and validate a machine file.
pub fn load_machine(path: &Path) -> Result<config::Machine, InputError> {
    config::load(path).map_err(|e| InputError(e.to_string()))
}
