//! The language's numeric rules and what it accepts, in one place: the tolerances and
//! ranges the parser holds programs to, and the codes it knows. The error messages quote
//! them, and the parser's stages check them.

/// An arc's start and end radii (centre format) may differ by up to this much, in the
/// program's units, or by any amount up to 100 times this within 0.1 % of the radius:
/// LinuxCNC's rule (its `CENTER_ARC_RADIUS_TOLERANCE_MM`/`_INCH`, 2 x 0.01 mm x sqrt 2 and
/// 2 x 0.001 in x sqrt 2), so that what LinuxCNC runs, dnurbs runs.
pub const ARC_RADIUS_TOL_MM: f64 = 0.02 * core::f64::consts::SQRT_2;
/// [`ARC_RADIUS_TOL_MM`] in an inch program, inches.
pub const ARC_RADIUS_TOL_IN: f64 = 0.002 * core::f64::consts::SQRT_2;
/// The relative part of the rule (0.1 %).
pub const ARC_RADIUS_REL_TOL: f64 = 0.001;
/// How far `R` may fall short of half the chord and still reach the end point, in the
/// program's units (LinuxCNC's `RADIUS_TOLERANCE_MM`/`_INCH`).
pub const ARC_REACH_TOL_MM: f64 = 0.001_27;
/// [`ARC_REACH_TOL_MM`] in an inch program, inches.
pub const ARC_REACH_TOL_IN: f64 = 0.000_05;

/// Smallest arc radius, mm.
pub const MIN_ARC_RADIUS_MM: f64 = 1e-3;

/// Largest distance of a helix's points from the true helix, mm (along its axis).
pub const HELIX_TOL_MM: f64 = 1e-9;

/// Longest dwell (`G04`), seconds. `P` and `X` are seconds (LinuxCNC's reading); Fanuc
/// posts that write `P` in milliseconds would ask for 1000 times the dwell, and most such
/// values land above this bound and are refused.
pub const MAX_DWELL_S: f64 = 100.0;

/// Slowest programmable feed, mm/min (0.06 mm/min was measured to run a 27 mm move for
/// hours; the planner refuses any plan over 24 h at 1 ms in any case).
pub const MIN_FEED_MM_MIN: f64 = 0.001;

/// Smallest NURBS weight (the largest is the `R` word's bound, 1e6).
pub const MIN_WEIGHT: f64 = 1e-6;

/// Tool-vector length below which `I J K` is rejected (it has no direction).
pub const MIN_VECTOR_LENGTH: f64 = 1e-9;

/// Least distance between a cutter control point and its orientation control point, mm.
pub const MIN_TOOL_OFFSET_MM: f64 = 1e-3;

/// Tolerance of the first control point against the current position, mm per axis.
pub const START_TOLERANCE_MM: f64 = 1e-3;

/// The list the unsupported-code error names.
pub const G_LIST: &str =
    "G00 G01 G02 G03 G04 G05 G05.1 G05.2 G05.3 G06.2 G06.5 G08 G10 G17 G18 G19 G20 G21 G28 G30 G40 G41 G41.1 G42 G42.1 G43 G43.1 G43.2 G43.4 G49 G53 G54-G59 G61 G61.1 G64 G73 G80 G81 G82 G83 G85 G86 G89 G90 G90.1 G91 G91.1 G92 G92.1 G92.2 G92.3 G93 G94 G95 G98 G99";

pub const M_LIST: &str =
    "M00 M01 M02 M03 M04 M05 M06 M07 M08 M09 M30 M62 M63 M64 M65 M66 M67 M68 M70 M71 M72 M73";

/// Highest numbered parameter (`#1`..`#5601`, as LinuxCNC).
pub const MAX_PARAMETER: u32 = 5601;

/// Most subroutine calls nested (LinuxCNC refuses a tenth).
pub const MAX_CALL_DEPTH: usize = 9;

/// Most brackets, functions and signs nested in one expression.
pub const MAX_EXPR_DEPTH: usize = 64;

/// Most lines one program may run again, in its loops (`while`, `do`, `repeat`) and
/// subroutines, all together and counted line by line: a loop that never ends is refused at
/// a line instead of holding the planner (LinuxCNC has no limit). At the interpreter's speed
/// (docs/measurements.md) this is about a minute and a half of interpretation.
pub const MAX_LOOP_LINES: u64 = 100_000_000;

/// How close to a whole number a value must be where one is required (parameter and O-word
/// numbers, loop counts), as LinuxCNC.
pub const WHOLE_TOLERANCE: f64 = 1e-4;
