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
    let bytes = std::fs::read(path)
        .map_err(|e| InputError(format!("{}: cannot read the program: {e}", path.display())))?;
    let text = program_text(&bytes).map_err(|e| InputError(format!("{}:{e}", path.display())))?;
    nc::parse::parse(text).map_err(|e| InputError(format!("{}:{e}", path.display())))
}

/// The program's text: UTF-8, with a leading byte-order mark dropped. Invalid UTF-8 is an
/// error at its line and column (columns in characters, as the parser counts them).
pub fn program_text(bytes: &[u8]) -> Result<&str, String> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    std::str::from_utf8(bytes).map_err(|e| {
        let good = &bytes[..e.valid_up_to()];
        let line = good.iter().filter(|&&b| b == b'\n').count() + 1;
        let start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        // The prefix is valid UTF-8 by construction.
        let col = std::str::from_utf8(&good[start..]).map_or(0, |s| s.chars().count()) + 1;
        format!(
            "{line}:{col}: byte 0x{:02x} is not UTF-8: save the program as UTF-8 (or ASCII)",
            bytes[e.valid_up_to()]
        )
    })
}

/// Read and validate a machine file.
pub fn load_machine(path: &Path) -> Result<config::Machine, InputError> {
    config::load(path).map_err(|e| InputError(e.to_string()))
}
