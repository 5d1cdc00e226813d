//! Helpers shared by the integration tests: a valid base file and a tiny line editor for it.

#![allow(dead_code)] // each test binary uses a different subset

use std::path::Path;

use config::{ConfigError, LineCol, Machine};

/// File name used as `origin` in tests; every error message must contain it.
pub const ORIGIN: &str = "machines/under-test.toml";

pub const PAPER: &str = include_str!("../../machines/paper-ac-table.toml");
pub const XYZAC: &str = include_str!("../../machines/xyzac-trt-mill.toml");

/// The smallest valid file: paper kinematics, every optional key omitted.
pub const MINIMAL: &str = r#"[machine]
name = "minimal"

[kinematics]
kind = "paper"

[axes.x]
min = -100.0
max = 100.0
velocity = 100.0
acceleration = 1000.0
jerk = 10000.0

[axes.y]
min = -100.0
max = 100.0
velocity = 100.0
acceleration = 1000.0
jerk = 10000.0

[axes.z]
min = -100.0
max = 100.0
velocity = 100.0
acceleration = 1000.0
jerk = 10000.0

[axes.a]
min = -90.0
max = 90.0
velocity = 90.0
acceleration = 900.0
jerk = 9000.0

[axes.c]
velocity = 180.0
acceleration = 1800.0
jerk = 18000.0
"#;

pub fn parse(text: &str) -> Result<Machine, ConfigError> {
    config::from_str(text, Path::new(ORIGIN))
}

/// Parses `text`, which must fail; returns the error and its `Display`.
pub fn fail(text: &str) -> (ConfigError, String) {
    match parse(text) {
        Ok(m) => panic!("expected an error, got {m:?}\n--- input:\n{text}"),
        Err(e) => {
            let shown = e.to_string();
            (e, shown)
        }
    }
}

/// Asserts that `shown` contains every one of `parts`.
#[track_caller]
pub fn assert_mentions(shown: &str, parts: &[&str]) {
    for p in parts {
        assert!(shown.contains(p), "{shown:?} does not mention {p:?}");
    }
}

/// 1-based line and column where `needle` first occurs in `text`.
#[track_caller]
pub fn pos_of(text: &str, needle: &str) -> LineCol {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle:?} not in text"));
    let before = &text[..at];
    LineCol {
        line: before.matches('\n').count() + 1,
        column: at - before.rfind('\n').map_or(0, |i| i + 1) + 1,
    }
}

/// Asserts that the error starts with `ORIGIN:line:col: ` for `pos`.
#[track_caller]
pub fn assert_at(shown: &str, pos: LineCol) {
    let prefix = format!("{ORIGIN}:{}:{}: ", pos.line, pos.column);
    assert!(
        shown.starts_with(&prefix),
        "{shown:?} does not start with {prefix:?}"
    );
}

fn header(line: &str) -> Option<&str> {
    let line = line.split('#').next().unwrap_or("").trim();
    line.strip_prefix('[')?.strip_suffix(']')
}

fn is_key(line: &str, key: &str) -> bool {
    line.trim_start()
        .strip_prefix(key)
        .is_some_and(|rest| rest.trim_start().starts_with('='))
}

/// Sets `key = value` in `[table]` (replacing the line, or adding it after the header).
#[track_caller]
pub fn set(text: &str, table: &str, key: &str, value: &str) -> String {
    edit(text, table, key, Some(&format!("{key} = {value}")))
}

/// Removes `key` from `[table]`.
#[track_caller]
pub fn remove(text: &str, table: &str, key: &str) -> String {
    edit(text, table, key, None)
}

#[track_caller]
fn edit(text: &str, table: &str, key: &str, new: Option<&str>) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let start = lines
        .iter()
        .position(|l| header(l) == Some(table))
        .unwrap_or_else(|| panic!("no [{table}]"));
    let end = (start + 1..lines.len())
        .find(|&i| header(&lines[i]).is_some())
        .unwrap_or(lines.len());
    match ((start + 1..end).find(|&i| is_key(&lines[i], key)), new) {
        (Some(i), Some(new)) => lines[i] = new.to_owned(),
        (Some(i), None) => {
            lines.remove(i);
        }
        (None, Some(new)) => lines.insert(start + 1, new.to_owned()),
        (None, None) => panic!("no {key} in [{table}]"),
    }
    lines.join("\n") + "\n"
}

/// Renames the table header `[from]` to `[to]`.
#[track_caller]
pub fn rename_table(text: &str, from: &str, to: &str) -> String {
    let old = format!("[{from}]");
    assert!(text.contains(&old), "no {old}");
    text.replacen(&old, &format!("[{to}]"), 1)
}
