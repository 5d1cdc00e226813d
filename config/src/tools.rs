//! The tool table, in LinuxCNC's `tool.tbl` format, so a shop's existing table is reused.
//!
//! One tool per line: `T<number> P<pocket> [X.. Y.. Z.. A.. B.. C.. U.. V.. W..] [D<diameter>]
//! [I.. J.. Q..] [;comment]`, words in any order, case-insensitive. dnurbs reads `T` (the
//! number `G43 H` and `M06` refer to), `Z` (the tool length, mm) and `D` (the diameter, for
//! the report); `P` and the other offsets are accepted and ignored (dnurbs changes tools by
//! hand and offsets only along Z). Blank lines and lines of only a comment are skipped. A
//! tool without `Z` has length 0. A tool number twice, a word that is not a letter and a
//! number, or a length outside +-10 000 mm is an error with its line and column.

use crate::error::{ConfigError, LineCol, Location};
use std::collections::BTreeMap;
use std::path::Path;

pub use machine::Tool;

/// Largest tool length, mm.
pub const MAX_TOOL_LENGTH_MM: f64 = 1e4;

/// Reads the tool table at `path`.
pub fn load_tools(path: &Path) -> Result<BTreeMap<u32, Tool>, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    tools_from_str(&text, path)
}

/// Parses a tool table held in `text`; `origin` names it in errors.
pub fn tools_from_str(text: &str, origin: &Path) -> Result<BTreeMap<u32, Tool>, ConfigError> {
    let mut tools = BTreeMap::new();
    for (index, raw) in text.lines().enumerate() {
        let (body, comment) = raw.split_once(';').unwrap_or((raw, ""));
        if body.trim().is_empty() {
            continue;
        }
        let at = |col: usize| Location {
            file: origin.to_path_buf(),
            line_col: Some(LineCol {
                line: index + 1,
                column: col,
            }),
        };
        let invalid = |col: usize, value: &str, rule: &str| ConfigError::Invalid {
            at: at(col),
            key: "tool table".into(),
            value: Some(value.to_owned()),
            rule: rule.to_owned(),
        };
        let mut number = None;
        let mut tool = Tool {
            length_mm: 0.0,
            diameter_mm: None,
            comment: comment.trim().to_owned(),
        };
        for (start, word) in words(body) {
            let col = body.get(..start).map_or(0, |s| s.chars().count()) + 1;
            let mut chars = word.chars();
            let letter = chars.next().map(|c| c.to_ascii_uppercase());
            let value: Option<f64> = chars.as_str().parse().ok().filter(|v: &f64| v.is_finite());
            match (letter, value) {
                (Some('T'), Some(v)) if v >= 0.0 && v.fract() == 0.0 && v <= 99_999.0 => {
                    number = Some(v as u32); // exact: a whole number in range
                }
                (Some('T'), _) => {
                    return Err(invalid(col, word, "T must be a whole tool number from 0 to 99999"))
                }
                (Some('Z'), Some(v)) if v.abs() <= MAX_TOOL_LENGTH_MM => tool.length_mm = v,
                (Some('Z'), _) => {
                    return Err(invalid(col, word, "Z (tool length) must be a number within +-10000 mm"))
                }
                (Some('D'), Some(v)) if (0.0..=MAX_TOOL_LENGTH_MM).contains(&v) => {
                    tool.diameter_mm = Some(v)
                }
                (Some('D'), _) => {
                    return Err(invalid(col, word, "D (diameter) must be a number from 0 to 10000 mm"))
                }
                (Some('P' | 'X' | 'Y' | 'A' | 'B' | 'C' | 'U' | 'V' | 'W' | 'I' | 'J' | 'Q'), Some(_)) => {}
                _ => {
                    return Err(invalid(
                        col,
                        word,
                        "not a tool-table word: T P X Y Z A B C U V W D I J Q, each followed by a number",
                    ))
                }
            }
        }
        let Some(number) = number else {
            return Err(invalid(1, raw.trim(), "a tool line needs T<number>"));
        };
        if tools.insert(number, tool).is_some() {
            return Err(invalid(
                1,
                raw.trim(),
                "this tool number is already in the table",
            ));
        }
    }
    Ok(tools)
}

/// The whitespace-separated words of `s` with their byte offsets.
fn words(s: &str) -> impl Iterator<Item = (usize, &str)> {
    s.split_whitespace()
        .map(move |w| (w.as_ptr() as usize - s.as_ptr() as usize, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_linuxcnc_lines() {
        let t = tools_from_str(
            "T1 P1 Z+75.000 D6.000 ;6mm flat\n\n; only a comment\nt2 p2 x0 z-1.5 d10 i0 j0 q1\n",
            Path::new("tool.tbl"),
        )
        .unwrap();
        assert_eq!(t[&1].length_mm, 75.0);
        assert_eq!(t[&1].diameter_mm, Some(6.0));
        assert_eq!(t[&1].comment, "6mm flat");
        assert_eq!(t[&2].length_mm, -1.5);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = tools_from_str("T1 P1 Z75\nT2 P2 Zabc\n", Path::new("tool.tbl")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "tool.tbl:2:7: tool table = Zabc: Z (tool length) must be a number within +-10000 mm"
        );
        let e = tools_from_str("T1 Z1\nT1 Z2\n", Path::new("t")).unwrap_err();
        assert!(e.to_string().contains("already in the table"), "{e}");
        let e = tools_from_str("P1 Z1\n", Path::new("t")).unwrap_err();
        assert!(e.to_string().contains("needs T<number>"), "{e}");
    }
}
