//! `[program]`: how programs are read on this machine (LinuxCNC's `[RS274NGC]` and
//! `[EMCIO] TOOL_TABLE`): the start-up modes, the tool table, where called subroutines are
//! found and how long loops may run.

use std::collections::BTreeMap;
use std::path::PathBuf;

/// Most lines a program may run again in its loops and subroutines when the machine file
/// does not say (the NC language's default).
pub const DEFAULT_MAX_LOOP_LINES: u64 = 100_000_000;

/// A validated `[program]` table; the default is an empty table.
#[derive(Clone, Debug, PartialEq)]
pub struct ProgramSetup {
    /// `startup`: modal codes in effect before a program's first line (checked by the NC
    /// language), trimmed; empty for none.
    pub startup: String,
    /// `tool_table`: the table's path (relative to the machine file's folder, resolved).
    pub tool_table: Option<PathBuf>,
    /// The tools of `tool_table`, by number.
    pub tools: BTreeMap<u32, Tool>,
    /// `subroutine_path`: folders searched for `name.ngc` by `o<name> call`, in order,
    /// resolved as `tool_table` is.
    pub subroutine_dirs: Vec<PathBuf>,
    /// `max_loop_lines`: most lines a program may run again in loops and subroutines.
    pub max_loop_lines: u64,
    /// `[io]`: the simulated inputs and outputs `M62`..`M68` may name.
    pub io: IoCounts,
    /// `[mcodes]`: the M-codes this machine defines, by number.
    pub mcodes: BTreeMap<u32, McodeAction>,
}

/// How many inputs and outputs of each kind (`[io]`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IoCounts {
    pub digital_outputs: u8,
    pub digital_inputs: u8,
    pub analog_outputs: u8,
    pub analog_inputs: u8,
}

/// What a machine-defined M-code does (`[mcodes] M428 = "tcp-on"`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum McodeAction {
    /// `"ignore"`: nothing, reported with a note.
    Ignore,
    /// `"tcp-on"`: tool-centre-point control on.
    TcpOn,
    /// `"tcp-off"`: tool-centre-point control off (moves keep the rotary axes at 0).
    TcpOff,
    /// `"stop"`: a program stop, as `M00`.
    Stop,
    /// `"output <n> on"` / `"output <n> off"`: the program's digital output `n` (as `M62` /
    /// `M63 P<n>`).
    Output { output: u8, on: bool },
    /// `"wait <n> high|low|rise|fall <seconds>"`: wait for digital input `n`, at most that
    /// long (as `M66 P<n> L3|L4|L1|L2 Q<seconds>`).
    Wait {
        input: u8,
        level: Level,
        timeout_s: f64,
    },
}

/// What a machine-defined wait waits for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    High,
    Low,
    Rise,
    Fall,
}

impl McodeAction {
    /// The forms a machine file gives, in the order of the variants.
    pub const NAMES: [&'static str; 6] = [
        "ignore",
        "tcp-on",
        "tcp-off",
        "stop",
        "output <n> on|off",
        "wait <n> high|low|rise|fall <seconds>",
    ];

    /// The action a machine file names (the numbers unchecked against `[io]` here).
    pub fn from_name(name: &str) -> Option<McodeAction> {
        let words: Vec<&str> = name.split_whitespace().collect();
        match words[..] {
            ["ignore"] => Some(McodeAction::Ignore),
            ["tcp-on"] => Some(McodeAction::TcpOn),
            ["tcp-off"] => Some(McodeAction::TcpOff),
            ["stop"] => Some(McodeAction::Stop),
            ["output", n, on] => Some(McodeAction::Output {
                output: n.parse().ok()?,
                on: match on {
                    "on" => true,
                    "off" => false,
                    _ => return None,
                },
            }),
            ["wait", n, level, seconds] => Some(McodeAction::Wait {
                input: n.parse().ok()?,
                level: match level {
                    "high" => Level::High,
                    "low" => Level::Low,
                    "rise" => Level::Rise,
                    "fall" => Level::Fall,
                    _ => return None,
                },
                timeout_s: seconds.parse().ok().filter(|t: &f64| t.is_finite())?,
            }),
            _ => None,
        }
    }
}

impl Default for ProgramSetup {
    fn default() -> Self {
        ProgramSetup {
            startup: String::new(),
            tool_table: None,
            tools: BTreeMap::new(),
            subroutine_dirs: Vec::new(),
            max_loop_lines: DEFAULT_MAX_LOOP_LINES,
            io: IoCounts::default(),
            mcodes: BTreeMap::new(),
        }
    }
}

/// One tool of a tool table.
#[derive(Clone, Debug, PartialEq)]
pub struct Tool {
    /// Length along the spindle, mm (`Z`).
    pub length_mm: f64,
    /// Diameter, mm (`D`), if given.
    pub diameter_mm: Option<f64>,
    /// The comment after `;`, trimmed.
    pub comment: String,
}
