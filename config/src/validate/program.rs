//! Validation of `[program]` into [`machine::ProgramSetup`]: the start-up modes as the NC
//! language reads them, the tool table loaded, the subroutine folders present, the loop
//! limit in range. Paths are relative to the machine file's folder.

use crate::check::Check;
use crate::error::ConfigError;
use crate::raw::RawProgram;
use machine::{IoCounts, McodeAction, ProgramSetup};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Largest `max_loop_lines`.
const MAX_LOOP_LINES: i64 = 1_000_000_000_000;

pub(crate) fn program(
    check: &Check<'_, '_>,
    raw: RawProgram,
    work_offsets: &[Option<[f64; 3]>; 6],
    read: &dyn Fn(&Path) -> std::io::Result<String>,
) -> Result<ProgramSetup, ConfigError> {
    let mut program = ProgramSetup::default();
    if let Some(text) = raw.startup {
        let setup = nc_lang::Setup {
            work_offsets: *work_offsets,
            ..nc_lang::Setup::default()
        };
        let startup = nc_lang::Startup::parse(&text, &setup).map_err(|e| {
            let rule = format!(
                "column {} of the modes: {} (start-up modes: {})",
                e.col,
                e.message,
                nc_lang::STARTUP_CODES
            );
            check.invalid(&["program", "startup"], Some(format!("{text:?}")), rule)
        })?;
        program.startup = startup.text().to_owned();
    }
    let folder = check
        .src
        .origin()
        .parent()
        .map(PathBuf::from)
        .unwrap_or_default();
    if let Some(path) = raw.tool_table {
        let resolved = folder.join(&path);
        let text = read(&resolved).map_err(|source| {
            check.invalid(
                &["program", "tool_table"],
                Some(format!("{path:?}")),
                format!(
                    "cannot read {} ({source}); the path is relative to the machine file's folder",
                    resolved.display()
                ),
            )
        })?;
        program.tools = crate::tools::tools_from_str(&text, &resolved)?;
        program.tool_table = Some(resolved);
    }
    for (i, dir) in raw.subroutine_path.unwrap_or_default().iter().enumerate() {
        let resolved = folder.join(dir);
        if !resolved.is_dir() {
            let rule = format!(
                "entry {} ({}) is not a folder; the path is relative to the machine file's folder",
                i + 1,
                resolved.display()
            );
            return Err(check.invalid(&["program", "subroutine_path"], None, rule));
        }
        program.subroutine_dirs.push(resolved);
    }
    if let Some(n) = raw.max_loop_lines {
        if !(1..=MAX_LOOP_LINES).contains(&n) {
            let rule = format!("must be in 1..={MAX_LOOP_LINES} (lines)");
            return Err(check.invalid(&["program", "max_loop_lines"], Some(n.to_string()), rule));
        }
        program.max_loop_lines = n as u64;
    }
    Ok(program)
}

/// `[mcodes]`: `M<n> = "<action>"` for M-codes the language does not define itself.
pub(crate) fn mcodes(
    check: &Check<'_, '_>,
    raw: BTreeMap<String, String>,
    io: IoCounts,
) -> Result<BTreeMap<u32, McodeAction>, ConfigError> {
    let mut out = BTreeMap::new();
    for (key, value) in raw {
        let n = key
            .strip_prefix(['M', 'm'])
            .and_then(|d| d.parse::<u32>().ok())
            .filter(|n| (1..=9999).contains(n));
        let Some(n) = n else {
            return Err(check.invalid(
                &["mcodes", &key],
                Some(key.clone()),
                "keys are M-codes: M followed by 1..=9999 (M428 = \"tcp-on\")".into(),
            ));
        };
        if BUILT_IN.contains(&n) {
            return Err(check.invalid(
                &["mcodes", &key],
                Some(key.clone()),
                format!("M{n} is the language's own ({})", nc_lang::M_LIST),
            ));
        }
        if out.contains_key(&n) {
            return Err(check.invalid(
                &["mcodes", &key],
                Some(key.clone()),
                format!("M{n} is given twice"),
            ));
        }
        let Some(action) = McodeAction::from_name(&value) else {
            return Err(check.invalid(
                &["mcodes", &key],
                Some(format!("{value:?}")),
                format!("must be one of {}", McodeAction::NAMES.join(", ")),
            ));
        };
        let (n_io, count, what) = match action {
            McodeAction::Output { output, .. } => (output, io.digital_outputs, "digital_outputs"),
            McodeAction::Wait { input, .. } => (input, io.digital_inputs, "digital_inputs"),
            _ => (0, 1, ""),
        };
        if n_io >= count {
            return Err(check.invalid(
                &["mcodes", &key],
                Some(format!("{value:?}")),
                format!("names {what} {n_io}, but [io] {what} is {count} (0..{count})"),
            ));
        }
        if let McodeAction::Wait { timeout_s, .. } = action {
            if !(timeout_s > 0.0 && timeout_s <= 3600.0) {
                return Err(check.invalid(
                    &["mcodes", &key],
                    Some(format!("{value:?}")),
                    "waits at most 0 < seconds <= 3600 (as M66 Q)".into(),
                ));
            }
        }
        out.insert(n, action);
    }
    Ok(out)
}

/// The M-codes of the language itself, and those LinuxCNC gives a meaning of its own
/// (overrides M48..M53, M60, M61, the modal state M70..M73), which a machine may not make
/// something else.
const BUILT_IN: [u32; 30] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 30, 48, 49, 50, 51, 52, 53, 60, 61, 62, 63, 64, 65, 66, 67, 68,
    70, 71, 72, 73,
];
