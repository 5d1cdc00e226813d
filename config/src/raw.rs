//! Stage 1: serde types that mirror the TOML file exactly.
//!
//! One struct per table, one field per key, no interpretation: numbers are plain `f64`
//! (TOML integers are accepted, `period_ms = 2` reads as `2.0`), optional keys are `Option`,
//! strings that name a choice (`kind`, `method`) stay strings so that [`crate::validate`]
//! can report a bad choice with the list of allowed names. Every struct has
//! `#[serde(deny_unknown_fields)]`: a misspelt key is an error, never silently ignored.
//!
//! Adding a section (the planned `[[bus]]`, `[drives]`, `[rt]`) is one struct here plus one
//! field in [`RawFile`] (`Option<RawX>` or `#[serde(default)] Vec<RawX>`), then its
//! conversion in `validate.rs`.

use serde::Deserialize;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFile {
    pub machine: RawMachine,
    pub kinematics: RawKinematics,
    pub axes: RawAxes,
    pub interpolation: Option<RawInterpolation>,
    /// `[[bus]]`: CAN buses; absent for a machine that is only simulated.
    #[serde(default)]
    pub bus: Vec<RawBus>,
    pub realtime: Option<RawRealtime>,
    pub control: Option<RawControl>,
    /// `[work_offsets]`: G54..G59.
    pub work_offsets: Option<RawWorkOffsets>,
    /// `[reference]`: the G28 position.
    pub reference: Option<RawReference>,
    /// `[spindle]`: the spindle drive.
    pub spindle: Option<RawSpindle>,
    /// `[coolant]`: the coolant valves' I/O module.
    pub coolant: Option<RawCoolant>,
    /// `[program]`: how programs are read.
    pub program: Option<RawProgram>,
    /// `[io]`: simulated inputs and outputs for M62..M68.
    pub io: Option<RawIo>,
    /// `[mcodes]`: machine-defined M-codes, `M428 = "tcp-on"`.
    pub mcodes: Option<std::collections::BTreeMap<String, String>>,
}

/// `[io]`: how many inputs and outputs of each kind; every key optional (0).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawIo {
    /// On a machine with a bus: the I/O module (the coolant's, if it has one).
    pub bus: Option<String>,
    pub node: Option<i64>,
    /// Module output / input 1..=8 of program output / input 0.
    pub first_output: Option<i64>,
    pub first_input: Option<i64>,
    pub digital_outputs: Option<i64>,
    pub digital_inputs: Option<i64>,
    pub analog_outputs: Option<i64>,
    pub analog_inputs: Option<i64>,
    /// Module input 1..=8 wired to the normally closed e-stop chain.
    pub estop_input: Option<i64>,
}

/// `[program]`: start-up modes, tool table, subroutine path, loop limit; every key optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawProgram {
    pub startup: Option<String>,
    pub tool_table: Option<String>,
    pub subroutine_path: Option<Vec<String>>,
    pub max_loop_lines: Option<i64>,
}

/// `[spindle]`: a CiA-402 drive in profile velocity mode.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSpindle {
    /// Both absent on a simulated machine (no `[[bus]]`).
    pub bus: Option<String>,
    pub node: Option<i64>,
    /// Highest programmable speed, rpm.
    pub max_rpm: f64,
    /// Ramp up and down, rpm/s.
    pub acceleration_rpm_s: f64,
    /// Quick-stop ramp, rpm/s; default twice the acceleration.
    pub quick_stop_rpm_s: Option<f64>,
    /// Drive velocity units per rpm; default 1.
    pub units_per_rpm: Option<f64>,
    /// +1 or -1: the drive's positive direction against M03; default +1.
    pub sign: Option<i64>,
    /// At speed within this many rpm of the command; default 1 % of max_rpm (at least 1).
    pub at_speed_window_rpm: Option<f64>,
    /// Longest wait for the speed before motion, s; default the ramp from 0 to max_rpm + 2 s.
    pub at_speed_timeout_s: Option<f64>,
}

/// `[coolant]`: a CiA-401 digital-output module switching the coolant valves.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCoolant {
    /// Both absent on a simulated machine (no `[[bus]]`).
    pub bus: Option<String>,
    pub node: Option<i64>,
    /// Output (1..=8 of 0x6200:01) switched by M07.
    pub mist_output: Option<i64>,
    /// Output switched by M08.
    pub flood_output: Option<i64>,
}

/// `[work_offsets]`: the program zero of each work offset, machine coordinates X Y Z, mm.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawWorkOffsets {
    #[serde(rename = "G54")]
    pub g54: Option<[f64; 3]>,
    #[serde(rename = "G55")]
    pub g55: Option<[f64; 3]>,
    #[serde(rename = "G56")]
    pub g56: Option<[f64; 3]>,
    #[serde(rename = "G57")]
    pub g57: Option<[f64; 3]>,
    #[serde(rename = "G58")]
    pub g58: Option<[f64; 3]>,
    #[serde(rename = "G59")]
    pub g59: Option<[f64; 3]>,
}

/// `[reference]`: the machine's reference (G28) position.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawReference {
    /// Machine coordinates X Y Z, mm.
    pub position: [f64; 3],
    /// The `G30` position, machine coordinates X Y Z, mm.
    pub g30: Option<[f64; 3]>,
}

/// `[control]`: the operator's control socket of `dnurbs run`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawControl {
    /// Path of the Unix socket.
    pub socket: Option<String>,
}

/// `[realtime]`: the real-time thread and drive supervision; every key optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawRealtime {
    /// SCHED_FIFO priority 1..=99.
    pub priority: Option<i64>,
    /// CPU to pin the real-time thread to.
    pub cpu: Option<i64>,
    /// Keep that CPU busy between periods with a SCHED_IDLE poller.
    pub idle_poll: Option<bool>,
    /// µs before each deadline to wake, warm up and compute (0: sleep to the deadline).
    pub lead_us: Option<f64>,
    /// Segments the planner may have queued ahead of the interpolator.
    pub queue_depth: Option<i64>,
    /// Consecutive overrun periods that stop the run along the path.
    pub max_consecutive_overruns: Option<i64>,
    /// ms without a heartbeat before a drive counts as lost.
    pub heartbeat_timeout_ms: Option<f64>,
    /// ms without position feedback (TPDO) before a drive counts as lost.
    pub feedback_timeout_ms: Option<f64>,
    /// ms to wait for every drive's boot-up after the NMT reset.
    pub boot_timeout_ms: Option<f64>,
    /// ms to wait for one SDO answer during set-up.
    pub sdo_timeout_ms: Option<f64>,
}

/// `[[bus]]`: one CAN bus.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawBus {
    /// Name the axes' `drive.bus` refers to.
    pub name: String,
    /// SocketCAN interface, e.g. "can0" or "vcan0".
    pub interface: String,
    /// bit/s; default 1 000 000.
    pub bitrate: Option<i64>,
    /// Highest allowed worst-case bus load, fraction of the bitrate; default 0.70.
    pub max_load: Option<f64>,
}

/// `[axes.*.drive]`: the CiA-402 drive behind one axis.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDrive {
    pub bus: String,
    pub node: i64,
    /// Drive counts per mm (linear) or per degree (rotary).
    pub counts_per_unit: f64,
    /// +1 or -1; default +1.
    pub sign: Option<i64>,
    /// Counts at axis position 0; default 0.
    pub offset: Option<i64>,
    /// The drive's own guard: following error (mm or deg) and its time (ms), option codes.
    pub following_error: Option<f64>,
    pub following_error_timeout_ms: Option<i64>,
    pub quick_stop_option: Option<i64>,
    pub fault_reaction_option: Option<i64>,
}

/// `[machine]`
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMachine {
    pub name: String,
    /// Interpolation period in milliseconds.
    pub period_ms: Option<f64>,
}

/// `[kinematics]`: `kind` selects which of the point keys are required.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawKinematics {
    pub kind: String,
    /// mm, machine frame; xyzac-trt only.
    pub a_axis_point: Option<[f64; 3]>,
    /// mm, machine frame; xyzbc-trt only.
    pub b_axis_point: Option<[f64; 3]>,
    /// mm, machine frame at tilt = 0; the trt kinds only.
    pub c_axis_point: Option<[f64; 3]>,
}

/// `[axes.*]`: exactly one of `a` / `b` must be present, as the kinematics requires.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawAxes {
    pub x: RawAxis,
    pub y: RawAxis,
    pub z: RawAxis,
    pub a: Option<RawAxis>,
    pub b: Option<RawAxis>,
    /// Required unless the kinematics is `xyz`.
    pub c: Option<RawAxis>,
}

/// One axis. Linear: mm, mm/s, mm/s^2, mm/s^3. Rotary: deg, deg/s, deg/s^2, deg/s^3.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawAxis {
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
    pub drive: Option<RawDrive>,
    pub home: Option<RawHome>,
}

/// `[axes.*.home]`: how the axis is homed.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawHome {
    /// "switch", "switch-index", "current" or "absolute".
    pub method: String,
    /// "positive" or "negative": the side of its edge the home switch is active on.
    pub direction: Option<String>,
    /// Axis position of the home point; default 0.
    pub position: Option<f64>,
    /// Axis units/s; defaults a tenth of the velocity limit, a tenth of the search.
    pub search_velocity: Option<f64>,
    pub latch_velocity: Option<f64>,
    /// Axis units/s^2; default half the acceleration limit.
    pub acceleration: Option<f64>,
    /// 0..=9; default 0.
    pub sequence: Option<i64>,
}

/// `[interpolation]`: every key optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawInterpolation {
    pub method: Option<String>,
    pub chord_tolerance_mm: Option<f64>,
    /// mm/s^2
    pub path_acceleration: Option<f64>,
    /// mm/s^3
    pub path_jerk: Option<f64>,
    pub max_feed_mm_min: Option<f64>,
    pub rapid_feed_mm_min: Option<f64>,
    pub compress: Option<bool>,
    pub compress_tol_mm: Option<f64>,
    pub compress_tol_deg: Option<f64>,
    pub compress_corner_deg: Option<f64>,
}
