//! Exit codes, the same for every subcommand, and the errors that choose them.
//!
//! A command returns an [`Outcome`] when it ran (a run that stopped early ran: the drives
//! were brought to rest), or an error: an [`InputError`] is the user's input (exit 2),
//! anything else a failure of the environment or of dnurbs itself (exit 1).

use std::path::Path;

/// The program (or the command) completed cleanly.
pub const COMPLETED: u8 = 0;
/// Failed: a file could not be written, a CAN interface could not be opened, the real-time
/// privileges are missing, an internal error.
pub const FAILED: u8 = 1;
/// Bad input: the NC program, the machine file or a command-line value (nothing moved).
/// clap uses 2 for usage errors too.
pub const BAD_INPUT: u8 = 2;
/// Stopped by a fault: a drive fault or lost drive, a bus fault (bus-off, TX timeout, a full
/// transmit queue, the interface down), drives not enabled in time, a target outside the
/// drive's counts, too many consecutive overruns.
pub const STOPPED_FAULT: u8 = 3;
/// Stopped by the operator: SIGINT/SIGTERM or `dnurbs ctl stop`.
pub const STOPPED_OPERATOR: u8 = 4;
/// Completed, but the real-time thread missed deadlines (overruns; see the report).
pub const COMPLETED_OVERRUNS: u8 = 5;

/// The table printed by `dnurbs --help` and kept in the README.
pub const TABLE: &str = "Exit codes (every subcommand):
  0  completed cleanly
  1  failed (cannot write a file, open a CAN interface, get real-time privileges; internal)
  2  bad input: NC program, machine file or command-line value (nothing moved; or an
     error in the program met ahead of the moving tool, by the planner or, for a program
     too long to check whole before it starts, the pre-pass: stopped along the path,
     drives disabled); `simulate` with a Taylor method whose setpoints go over a limit
  3  stopped by a fault (drive fault or lost drive, bus fault, enable timeout, count
     overflow, too many consecutive overruns); the drives were stopped and disabled
  4  stopped by the operator (SIGINT/SIGTERM, `dnurbs ctl stop`); stopped along the path,
     or before anything moved (a stop while `run` plans or sets up the drives); `fit`
     stopped before it wrote its output
  5  completed, with real-time overruns (missed deadlines: see the report)";

/// How a command that ran ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    Completed,
    CompletedWithOverruns,
    StoppedByFault,
    StoppedByOperator,
    /// An error in the program met ahead of the tool while it moved: stopped along the path.
    StoppedByProgram,
    /// `simulate` with a Taylor method (the machine file's `method`, `--method`) made
    /// setpoints over an axis limit: that method does not hold this program's limits.
    OverLimits,
}

impl Outcome {
    pub fn code(self) -> u8 {
        match self {
            Outcome::Completed => COMPLETED,
            Outcome::CompletedWithOverruns => COMPLETED_OVERRUNS,
            Outcome::StoppedByFault => STOPPED_FAULT,
            Outcome::StoppedByOperator => STOPPED_OPERATOR,
            Outcome::StoppedByProgram | Outcome::OverLimits => BAD_INPUT,
        }
    }

    /// The word in the report's `outcome` field.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Completed => "completed",
            Outcome::CompletedWithOverruns => "completed with overruns",
            Outcome::StoppedByFault => "stopped by a fault",
            Outcome::StoppedByOperator => "stopped by the operator",
            Outcome::StoppedByProgram => "stopped by the program",
            Outcome::OverLimits => "setpoints over a limit",
        }
    }
}

/// A failure the user can fix in their input (exit code 2). Each names the file and, where
/// known, `line:col`. The library error is part of the message, not a separate `source`
/// (which `{:#}` would print a second time).
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error("{file}: cannot read the program: {error}")]
    ReadProgram { file: String, error: std::io::Error },
    /// Not UTF-8: `line:col: ...` from [`crate::program_text`].
    #[error("{file}:{message}")]
    Encoding { file: String, message: String },
    /// Every error of the program (up to 50), one per line.
    #[error("{}", parse_errors(.file, .errors))]
    Parse {
        file: String,
        errors: nc_lang::ParseErrors,
    },
    /// The program does not fit the machine: geometry or plan (boxed: a plan's refusal
    /// carries the numbers of its message).
    #[error("{file}:{error}")]
    Program {
        file: String,
        error: Box<nc_plan::plan::ProgramError>,
    },
    /// Refused by the pre-pass (`dnurbs check`): geometry or a programmed point outside
    /// the travel.
    #[error("{file}:{error}")]
    Checked {
        file: String,
        error: nc_plan::prepass::Refused,
    },
    #[error(transparent)]
    Machine(#[from] config::ConfigError),
    /// The machine file is valid but cannot serve this command (no drive for an axis,
    /// no bus, a bus over its load at this period).
    #[error("{0}")]
    MachineUse(String),
    /// `--from-line`: the program cannot restart from that line.
    #[error("{file}: --from-line {line}: {error}")]
    Restart {
        file: String,
        line: u32,
        error: nc_lang::restart::RestartError,
    },
    /// A command-line value clap could not check alone.
    #[error("{0}")]
    Usage(String),
    /// The drives are not where the program starts (and no --approach).
    #[error(transparent)]
    Start(#[from] rt_loop::pipeline::PipelineError),
}

/// A stop requested (SIGINT, SIGTERM) before anything moved: while the program was planned
/// or the drives were set up (exit code 4, like a stop along the path).
#[derive(Debug, thiserror::Error)]
#[error("stop requested (SIGINT/SIGTERM) while {stage}: nothing moved, no drive was enabled")]
pub struct StoppedBeforeMotion {
    /// What was under way: "planning the program", "setting up the drives".
    pub stage: &'static str,
}

/// A stop requested (SIGINT, SIGTERM) while a command that moves nothing was under way and
/// before it wrote its result (exit code 4): `fit`'s output is not written.
#[derive(Debug, thiserror::Error)]
#[error("stop requested (SIGINT/SIGTERM) while {doing}")]
pub struct StoppedUnfinished {
    /// What was under way and what it leaves: "fitting prog.nc: nothing written".
    pub doing: String,
}

/// `file:line:col: message` per error, and a last line when the parse stopped early.
fn parse_errors(file: &str, e: &nc_lang::ParseErrors) -> String {
    let mut out: Vec<String> = e.errors.iter().map(|x| format!("{file}:{x}")).collect();
    if e.errors.len() > 1 || e.more {
        out.push(format!(
            "{} errors{}",
            e.errors.len(),
            if e.more {
                format!(
                    " (stopped at {}: fix these and run again)",
                    nc_lang::MAX_ERRORS
                )
            } else {
                String::new()
            }
        ));
    }
    out.join("\n")
}

impl InputError {
    pub fn program(file: &Path, source: impl Into<nc_plan::plan::ProgramError>) -> Self {
        InputError::Program {
            file: file.display().to_string(),
            error: Box::new(source.into()),
        }
    }

    /// A streamed program's refusal: where it was read, built or planned.
    pub fn stream(file: &str, e: nc_plan::stream::StreamError) -> Self {
        use nc_plan::stream::StreamError;
        match e {
            StreamError::Parse(p) => InputError::Parse {
                file: file.to_owned(),
                errors: nc_lang::ParseErrors {
                    errors: vec![p],
                    more: false,
                },
            },
            StreamError::Build(b) => InputError::program(Path::new(file), b),
            StreamError::Plan(p) => InputError::program(Path::new(file), p),
        }
    }
}

/// The exit code for an error: 2 for the user's input, 4 for a stop before motion, 1 for
/// everything else.
pub fn code_of(e: &anyhow::Error) -> u8 {
    if e.downcast_ref::<InputError>().is_some() {
        BAD_INPUT
    } else if e.downcast_ref::<StoppedBeforeMotion>().is_some()
        || e.downcast_ref::<StoppedUnfinished>().is_some()
    {
        STOPPED_OPERATOR
    } else {
        FAILED
    }
}
