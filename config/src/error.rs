//! [`ConfigError`]: every failure names the file, the position when known, and the key.
//!
//! Display forms, one line each:
//!
//! ```text
//! machines/foo.toml: cannot read: No such file or directory (os error 2)
//! machines/foo.toml:3:11: TOML syntax error: ...
//! machines/foo.toml:14:12: axes.x.velocity: invalid type: string "fast", expected f64
//! machines/foo.toml:14:12: axes.x.velocity = -3: must be in 1e-6..=1e9 (mm/s)
//! ```

use std::fmt;
use std::path::PathBuf;

/// Where in which file an error is. `line_col` is `None` when the position is unknown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    pub file: PathBuf,
    pub line_col: Option<LineCol>,
}

/// A 1-based line and column (column counted in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineCol {
    pub line: usize,
    pub column: usize,
}

impl LineCol {
    /// Position of byte `offset` in `text`. Never panics: an offset past the end, or inside a
    /// multi-byte character, is clamped to the preceding character boundary.
    pub fn of_offset(text: &str, offset: usize) -> LineCol {
        let mut end = offset.min(text.len());
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let before = &text[..end];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        LineCol {
            line: before.matches('\n').count() + 1,
            column: before[line_start..].chars().count() + 1,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(LineCol { line, column }) = self.line_col {
            write!(f, ":{line}:{column}")?;
        }
        Ok(())
    }
}

/// Why a machine configuration could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid TOML.
    #[error("{at}: TOML syntax error: {message}")]
    Syntax { at: Location, message: String },
    /// Valid TOML that does not fit the schema: unknown or missing key, wrong value type.
    /// `key` is the dotted key path, empty for the document itself.
    #[error("{at}: {}{message}", key_prefix(key))]
    Schema {
        at: Location,
        key: String,
        message: String,
    },
    /// A value of the right type outside its allowed range, or a missing/superfluous key that
    /// depends on another key. `value` is the value as written (`None` when the key is
    /// absent); `rule` states what is allowed, with the unit.
    #[error("{at}: {key}{}: {rule}", value_suffix(value))]
    Invalid {
        at: Location,
        key: String,
        value: Option<String>,
        rule: String,
    },
}

fn key_prefix(key: &str) -> String {
    if key.is_empty() {
        String::new()
    } else {
        format!("{key}: ")
    }
}

fn value_suffix(value: &Option<String>) -> String {
    value
        .as_ref()
        .map(|v| format!(" = {v}"))
        .unwrap_or_default()
}

impl ConfigError {
    /// The file and position, if the error is about the file's content.
    pub fn location(&self) -> Option<&Location> {
        match self {
            ConfigError::Read { .. } => None,
            ConfigError::Syntax { at, .. }
            | ConfigError::Schema { at, .. }
            | ConfigError::Invalid { at, .. } => Some(at),
        }
    }

    /// The dotted key path the error is about, if any.
    pub fn key(&self) -> Option<&str> {
        match self {
            ConfigError::Schema { key, .. } | ConfigError::Invalid { key, .. } => Some(key),
            ConfigError::Read { .. } | ConfigError::Syntax { .. } => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_from_one_in_chars() {
        let text = "a = 1\nb = \"é\" x\n";
        assert_eq!(LineCol::of_offset(text, 0), LineCol { line: 1, column: 1 });
        assert_eq!(LineCol::of_offset(text, 6), LineCol { line: 2, column: 1 });
        // `x` follows the two-byte `é`: byte 15, character column 9 (byte column 10).
        assert_eq!(text.find('x'), Some(15));
        assert_eq!(LineCol::of_offset(text, 15), LineCol { line: 2, column: 9 });
    }

    #[test]
    fn line_col_never_panics() {
        let text = "é\n";
        assert_eq!(LineCol::of_offset(text, 1), LineCol { line: 1, column: 1 });
        assert_eq!(LineCol::of_offset(text, 99), LineCol { line: 2, column: 1 });
        assert_eq!(LineCol::of_offset("", 5), LineCol { line: 1, column: 1 });
    }
}
