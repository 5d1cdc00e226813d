//! Machine configuration: a TOML file read once at start-up into validated types.
//!
//! # Two stages
//!
//! 1. **Raw** (`raw.rs`): serde structs that mirror the TOML exactly, one struct per table,
//!    with `#[serde(deny_unknown_fields)]` everywhere, so a misspelt key is an error instead of
//!    a silently used default. Syntax, unknown/missing keys and wrong value types fail here.
//! 2. **Validated** ([`Machine`] and the types of the `machine` crate): built once from the raw
//!    structs by `validate.rs`, which checks every range. The rest of the program (and all
//!    real-time code) sees only these types, whose invariants it may rely on: every number
//!    finite (except `±inf` travel of a continuous C table), `min < max`, rates `> 0`.
//!
//! The text is parsed once into toml's span-carrying tree (`source.rs`), which is kept so
//! that every error can say where it is: [`ConfigError`]'s `Display` names the file, the
//! line:col, the dotted key path, the value as written and the allowed range with its unit:
//!
//! ```text
//! machines/foo.toml:14:12: axes.x.velocity = -3: must be in 1e-6..=1e9 (mm/s)
//! ```
//!
//! # Units
//!
//! | keys | unit |
//! |---|---|
//! | `[machine] period_ms` | ms (stored as [`Machine::period_s`] in s) |
//! | `[kinematics] *_axis_point` | mm, machine frame |
//! | `[axes.x/y/z]` `min`, `max`, `velocity`, `acceleration`, `jerk` | mm, mm/s, mm/s^2, mm/s^3 |
//! | `[axes.a/b/c]` same keys | deg, deg/s, deg/s^2, deg/s^3 |
//! | `[interpolation] chord_tolerance_mm` | mm |
//! | `[interpolation] path_acceleration`, `path_jerk` | mm/s^2, mm/s^3 |
//! | `[interpolation] max_feed_mm_min`, `rapid_feed_mm_min` | mm/min |
//! | `[realtime] *_ms` | ms (stored in s) |
//! | `[spindle] max_rpm`, `at_speed_window_rpm` | rpm |
//! | `[spindle] acceleration_rpm_s`, `quick_stop_rpm_s` | rpm/s |
//!
//! # File layout
//!
//! ```toml
//! [machine]
//! name = "paper-ac-table"   # required, non-empty
//! period_ms = 2.0           # optional, default 2.0, allowed 0.1..=100
//!
//! [kinematics]
//! kind = "paper"            # "paper" | "xyzac-trt" | "xyzbc-trt" | "xyz" (3 axes, no [axes.a], [axes.c])
//! # xyzac-trt: a_axis_point = [x, y, z], c_axis_point = [x, y, z]
//! # xyzbc-trt: b_axis_point = [x, y, z], c_axis_point = [x, y, z]
//!
//! [interpolation]           # optional, as is every key in it
//! method = "arclength"      # "arclength" | "taylor1" | "taylor2"
//! chord_tolerance_mm = 0.001
//! path_acceleration = 1000.0
//! path_jerk = 20000.0
//! max_feed_mm_min = 10000.0
//! rapid_feed_mm_min = 10000.0   # default: max_feed_mm_min
//! compress = false          # fit runs of G01 moves into G06.5 blocks before planning
//! compress_tol_mm = 0.001   # 1e-5..=1: programmed points off the fitted curve
//! compress_tol_deg = 0.01   # 1e-4..=5: programmed tool axes off the fitted axis
//! compress_corner_deg = 10  # 0..=180: a sharper turn between moves ends a block
//!
//! [axes.x]                  # also [axes.y], [axes.z]
//! min = -300.0
//! max = 300.0
//! velocity = 250.0
//! acceleration = 2500.0
//! jerk = 50000.0
//! # [axes.a] (paper, xyzac-trt) or [axes.b] (xyzbc-trt): same keys, required.
//! # [axes.c]: same keys; min and max may both be omitted for a continuous table.
//!
//! [realtime]                # optional, as is every key in it
//! priority = 80             # SCHED_FIFO priority of the real-time thread, 1..=99
//! # cpu = 1                 # pin the real-time thread to this CPU (default: not pinned)
//! # idle_poll = true        # keep that CPU from halting between periods (needs cpu)
//! # lead_us = 60            # wake 60 µs early: warm up, compute, send at the deadline
//! queue_depth = 64          # planned segments queued ahead of the interpolator, 2..=1024
//! max_consecutive_overruns = 10 # more periods in a row past their deadline stop the run
//! heartbeat_timeout_ms = 300    # a drive without heartbeat this long is lost
//! feedback_timeout_ms = 20      # ... without TPDO feedback (default max(20, 5 periods))
//! boot_timeout_ms = 3000        # wait for the boot-ups after the NMT reset
//! sdo_timeout_ms = 200          # wait for one SDO answer during set-up
//!
//! [control]                 # optional
//! # socket = "/run/dnurbs/control.sock"   # `dnurbs ctl` talks to the run here (mode 0660)
//!
//! [spindle]                 # optional: a CiA-402 drive in profile velocity mode
//! bus = "can1"              # a [[bus]] name; node unique on that bus
//! node = 6
//! max_rpm = 24000           # an S above it is refused with its line
//! acceleration_rpm_s = 8000 # ramp up and down (0x6083, 0x6084)
//! # quick_stop_rpm_s = 16000     # default twice the acceleration (0x6085)
//! # units_per_rpm = 1.0          # drive velocity units per rpm (0x60FF, 0x606C)
//! # sign = 1                     # drive direction against M03
//! # at_speed_window_rpm = 240    # default 1 % of max_rpm (0x606D)
//! # at_speed_timeout_s = 5       # default max_rpm / acceleration + 2 s
//!
//! [coolant]                 # optional: a CiA-401 digital-output module
//! bus = "can1"
//! node = 7
//! mist_output = 1           # M07 (output 1..=8 of 0x6200:01)
//! flood_output = 2          # M08; M09 switches both off
//!
//! [program]                 # optional, as is every key in it
//! startup = "G17 G21 G40 G49 G54 G64 G80 G90 G94"  # modes before the first line
//! tool_table = "mill.tbl"   # LinuxCNC tool.tbl, relative to this file
//! subroutine_path = ["subs"]    # where `o<name> call` finds name.ngc, relative to this file
//! max_loop_lines = 100000000    # most lines run again in loops and subroutines
//!
//! [io]                      # optional, simulated machines only (no [[bus]])
//! digital_outputs = 4       # M62..M65 P0..P3
//! digital_inputs = 4        # M66 P0..P3
//! analog_outputs = 2        # M67/M68 E0..E1
//! analog_inputs = 2         # M66 E0..E1
//!
//! [mcodes]                  # optional: M-codes the machine defines
//! M428 = "tcp-on"           # "ignore" | "tcp-on" | "tcp-off" | "stop"
//! ```
//!
//! Example files: `config/machines/*.toml`.

mod check;
mod error;
pub mod offsets;
mod raw;
mod source;

pub mod tools;
mod validate;

use std::path::Path;

pub use error::{ConfigError, LineCol, Location};
// The types a machine file is read into, defined below the file's parsing (crate `machine`).
pub use machine::{
    bus, Axes, AxisLimits, BusNode, Compress, Coolant, Interpolation, IoCounts, Kinematics, Level,
    Machine, McodeAction, Method, Realtime, RotaryName, Spindle, Tool, UnknownMethod,
};

/// Reads and validates the machine configuration file at `path`.
pub fn load(path: &Path) -> Result<Machine, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    from_str(&text, path)
}

/// Parses and validates a machine configuration held in `text`; `origin` names it in errors,
/// and the files it names (`[program] tool_table`) are read relative to its folder.
pub fn from_str(text: &str, origin: &Path) -> Result<Machine, ConfigError> {
    from_str_with_files(text, origin, &|path| std::fs::read_to_string(path))
}

/// [`from_str`] with the files the machine file names read by `read` (given the path
/// resolved against `origin`'s folder): a machine file built into the program (`dnurbs
/// demo`) has its tool table built in beside it.
pub fn from_str_with_files(
    text: &str,
    origin: &Path,
    read: &dyn Fn(&Path) -> std::io::Result<String>,
) -> Result<Machine, ConfigError> {
    let src = source::Source::parse(text, origin)?;
    let raw = src.raw()?;
    validate::machine(raw, &src, read)
}
