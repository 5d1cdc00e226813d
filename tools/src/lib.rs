//! The `dnurbs` command-line tool as a library, so the integration tests and benchmarks can
//! use the same code paths as the binary. `main.rs` only parses the arguments ([`cli`]),
//! calls the command ([`commands`]) and maps its outcome or error to an exit code ([`exit`]).

pub mod cli;
pub mod commands;
pub mod control;
pub mod demo;
pub mod exit;
pub mod feed;
pub mod report;
mod rt_serde;
pub mod run;
pub mod serve;
pub mod setup;
pub mod shop;
pub mod simdrives;
pub mod simulate;
pub mod words;

pub use exit::InputError;
use std::path::Path;

/// Read and parse an NC program; errors name the file, line and column.
pub fn load_program(
    path: &Path,
    setup: &nc_lang::Setup,
) -> Result<nc_geom::program::Program, InputError> {
    let text = read_program(path)?;
    parse_text(&text, &path.display().to_string(), setup)
}

/// Read an NC program's text (see [`program_text`]); errors name the file.
pub fn read_program(path: &Path) -> Result<String, InputError> {
    let file = path.display().to_string();
    let mut bytes = std::fs::read(path).map_err(|error| InputError::ReadProgram {
        file: file.clone(),
        error,
    })?;
    let encoding = |message| InputError::Encoding {
        file: file.clone(),
        message,
    };
    let bom = program_text(&bytes).map_err(encoding)?.len() < bytes.len();
    if bom {
        bytes.drain(..3);
    }
    String::from_utf8(bytes).map_err(|e| encoding(e.to_string()))
}

/// Parse an NC program held in memory; `file` names it in errors.
pub fn parse_program(
    bytes: &[u8],
    file: &str,
    setup: &nc_lang::Setup,
) -> Result<nc_geom::program::Program, InputError> {
    let text = program_text(bytes).map_err(|message| InputError::Encoding {
        file: file.to_owned(),
        message,
    })?;
    parse_text(text, file, setup)
}

/// Parse an NC program's text; `file` names it in errors.
pub fn parse_text(
    text: &str,
    file: &str,
    setup: &nc_lang::Setup,
) -> Result<nc_geom::program::Program, InputError> {
    nc_lang::parse_with(text, setup).map_err(|errors| InputError::Parse {
        file: file.to_owned(),
        errors,
    })
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
    let m = config::load(path)?;
    if let Some(note) = jerk_note(&m) {
        eprintln!("dnurbs: note: {}: {note}", path.display());
    }
    Ok(m)
}

/// The axes whose jerk the planner keeps below the machine file's
/// ([`nc_geom::limits::AxisLimit::planned_jerk`]), said rather than done silently.
pub fn jerk_note(m: &config::Machine) -> Option<String> {
    let lowered: Vec<String> = m
        .axes
        .all()
        .iter()
        .enumerate()
        .filter_map(|(j, (name, l))| {
            let planned = nc_geom::limits::AxisLimit {
                velocity: l.velocity,
                acceleration: l.acceleration,
                jerk: l.jerk,
            }
            .planned_jerk(m.period_s);
            let unit = if j >= 3 { "deg" } else { "mm" };
            let said = format!("{name} {:.4e} -> {planned:.4e} {unit}/s^3", l.jerk);
            let kept = l.jerk * (1.0 - nc_geom::limits::JERK_RESERVE);
            (planned < kept * (1.0 - 1e-12)).then_some(said)
        })
        .collect();
    (!lowered.is_empty()).then(|| {
        format!(
            "planned at a jerk of {} of the axis's acceleration a period ({} ms), less the \
             {} % every plan keeps for a hold, where the file's is higher: {}; the setpoint \
             check keeps in reserve the acceleration a jerk adds within a period, and a \
             higher jerk would leave the ramps too little",
            nc_geom::limits::JERK_RISE,
            m.period_s * 1e3,
            nc_geom::limits::JERK_RESERVE * 100.0,
            lowered.join(", ")
        )
    })
}

/// Refuse a machine whose bus is over its load at its period (for the commands that use
/// the bus).
pub fn check_bus_load(m: &config::Machine) -> Result<(), InputError> {
    m.check_bus_load()
        .map_err(|e| InputError::MachineUse(e.to_owned()))
}
