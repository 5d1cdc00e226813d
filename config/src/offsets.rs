//! Work offsets from LinuxCNC's parameter file (`linuxcnc.var`, `--offsets`), so the offsets a
//! shop has touched off on its LinuxCNC machine are reused.
//!
//! One parameter per line: `<number> <value>` (tab or spaces), as LinuxCNC writes the file;
//! blank lines are skipped, and so is anything after `;` or `#` (dnurbs's own comments).
//! The work offsets are parameters 5221 + 20 k .. (k = 0 for `G54` .. 5 for `G59`): X Y Z
//! at 5221..5223, A B C at 5224..5226, U V W at 5227..5229, the rotation about Z at 5230.
//! dnurbs reads X Y Z (mm). An offset of the rotary or U V W axes or a rotation other
//! than 0 is an error: dnurbs offsets only X Y Z, and silently dropping one would put the
//! part elsewhere. Every other parameter (`G28`/`G30` positions, `G92`, `G59.1`..`G59.3`, the
//! numbered variables) is read and ignored. An offset with only some of X Y Z, a parameter
//! twice, a line that is not two numbers, or a coordinate beyond +-1e5 mm is an error with
//! its line and column.

use crate::error::{ConfigError, LineCol, Location};
use std::path::Path;

/// First parameter of `G54` (its X); each further offset starts 20 later.
const G54_X: u32 = 5221;
/// Parameters from one offset's X to the next offset's X.
const STRIDE: u32 = 20;
/// Largest offset coordinate, mm (as the machine file's `[work_offsets]`).
const MAX_MM: f64 = 1e5;
const NAMES: [&str; 6] = ["G54", "G55", "G56", "G57", "G58", "G59"];
/// The axes of an offset after X Y Z, and the rotation, in parameter order.
const OTHERS: [&str; 7] = ["A", "B", "C", "U", "V", "W", "rotation"];

/// `G54` .. `G59` from the file: `Some([x, y, z])` for each offset the file gives.
pub type WorkOffsets = [Option<[f64; 3]>; 6];

/// Reads the parameter file at `path`.
pub fn load_offsets(path: &Path) -> Result<WorkOffsets, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    offsets_from_str(&text, path)
}

/// Parses a parameter file held in `text`; `origin` names it in errors.
pub fn offsets_from_str(text: &str, origin: &Path) -> Result<WorkOffsets, ConfigError> {
    // Per offset: X Y Z as read, with the line of the first one seen.
    let mut xyz = [[None::<f64>; 3]; 6];
    let mut first_line = [0usize; 6];
    let mut seen = std::collections::BTreeSet::new();
    let invalid = |line: usize, column: usize, value: &str, rule: String| ConfigError::Invalid {
        at: Location {
            file: origin.to_path_buf(),
            line_col: Some(LineCol { line, column }),
        },
        key: "parameter".into(),
        value: Some(value.to_owned()),
        rule,
    };
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let body = raw.split([';', '#']).next().unwrap_or("");
        let words: Vec<&str> = body.split_whitespace().collect();
        if words.is_empty() {
            continue;
        }
        let column = raw.len() - raw.trim_start().len() + 1;
        let (Some(number), Some(value), 2) = (
            words.first().and_then(|w| w.parse::<u32>().ok()),
            words
                .get(1)
                .and_then(|w| w.parse::<f64>().ok())
                .filter(|v| v.is_finite()),
            words.len(),
        ) else {
            return Err(invalid(
                line,
                column,
                raw.trim(),
                "a parameter line is its number and a finite value (e.g. `5221\t10.000000`)".into(),
            ));
        };
        if !seen.insert(number) {
            return Err(invalid(
                line,
                column,
                raw.trim(),
                format!("parameter {number} is already in the file"),
            ));
        }
        let Some(rel) = number.checked_sub(G54_X) else {
            continue;
        };
        let (k, i) = ((rel / STRIDE) as usize, (rel % STRIDE) as usize);
        let Some(name) = NAMES.get(k) else {
            continue; // G59.1 .. G59.3 and beyond: not offsets dnurbs has
        };
        match i {
            0..=2 => {
                if value.abs() > MAX_MM {
                    return Err(invalid(
                        line,
                        column,
                        raw.trim(),
                        format!(
                            "{name} {} must be within +-{MAX_MM:e} mm",
                            ["X", "Y", "Z"][i]
                        ),
                    ));
                }
                if xyz[k].iter().all(Option::is_none) {
                    first_line[k] = line;
                }
                xyz[k][i] = Some(value);
            }
            3..=9 if value != 0.0 => {
                return Err(invalid(
                    line,
                    column,
                    raw.trim(),
                    format!(
                        "{name} {} is {value}: dnurbs applies work offsets in X Y Z only, so it must be 0",
                        OTHERS[i - 3]
                    ),
                ));
            }
            _ => {}
        }
    }
    let mut out = [None; 6];
    for (k, v) in xyz.iter().enumerate() {
        match v {
            [Some(x), Some(y), Some(z)] => out[k] = Some([*x, *y, *z]),
            [None, None, None] => {}
            _ => {
                let missing: Vec<String> = v
                    .iter()
                    .zip(["X", "Y", "Z"].iter().zip(0u32..))
                    .filter(|(c, _)| c.is_none())
                    .map(|(_, (axis, i))| format!("{axis} ({})", G54_X + STRIDE * k as u32 + i))
                    .collect();
                return Err(invalid(
                    first_line[k],
                    1,
                    NAMES[k],
                    format!(
                        "{} has no {}: give all of X Y Z",
                        NAMES[k],
                        missing.join(", ")
                    ),
                ));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The head of a parameter file as LinuxCNC 2.9 writes it (tabs, six decimals).
    const VAR: &str = "5161\t0.000000\n5162\t0.000000\n5163\t-10.000000\n5211\t0.000000\n\
        5220\t1.000000\n5221\t120.500000\n5222\t-35.250000\n5223\t-210.000000\n5224\t0.000000\n\
        5225\t0.000000\n5226\t0.000000\n5227\t0.000000\n5228\t0.000000\n5229\t0.000000\n\
        5230\t0.000000\n5241\t0.000000\n5242\t0.000000\n5243\t0.000000\n5301\t1.000000\n\
        5302\t2.000000\n5303\t3.000000\n5341\t9.000000\n5342\t9.000000\n5343\t9.000000\n";

    #[test]
    fn reads_the_offsets_linuxcnc_wrote() {
        let o = offsets_from_str(VAR, Path::new("linuxcnc.var")).unwrap();
        assert_eq!(o[0], Some([120.5, -35.25, -210.0]));
        assert_eq!(o[1], Some([0.0; 3]));
        assert_eq!((o[2], o[3], o[5]), (None, None, None));
        assert_eq!(o[4], Some([1.0, 2.0, 3.0]), "G58");
    }

    #[test]
    fn what_dnurbs_cannot_apply_is_an_error_with_its_place() {
        let err = |text: &str| {
            offsets_from_str(text, Path::new("p.var"))
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            err("5221 1\n5222 2\n5223 3\n5226 90\n"),
            "p.var:4:1: parameter = 5226 90: G54 C is 90: dnurbs applies work offsets in X Y Z only, so it must be 0"
        );
        assert_eq!(
            err("5261 1\n5263 3\n"),
            "p.var:1:1: parameter = G56: G56 has no Y (5262): give all of X Y Z"
        );
        assert_eq!(
            err("5221 1\n  5221 2\n"),
            "p.var:2:3: parameter = 5221 2: parameter 5221 is already in the file"
        );
        assert!(err("5221 abc\n").contains("p.var:1:1: parameter = 5221 abc: a parameter line"));
        assert!(err("5221 1 2\n").contains("a parameter line"));
        assert!(err("5221 2e5\n").contains("G54 X must be within +-1e5 mm"));
        assert!(err("5230 15\n").contains("G54 rotation is 15"));
    }

    #[test]
    fn comments_and_blank_lines_are_skipped() {
        let o = offsets_from_str(
            "; shop offsets\n\n5281 1 # G57\n5282 2\n5283 3\n",
            Path::new("v"),
        )
        .unwrap();
        assert_eq!(o[3], Some([1.0, 2.0, 3.0]));
    }
}
