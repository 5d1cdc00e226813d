//! Parse errors: one [`ParseErrorKind`] variant per rule of the language, each carrying the
//! offending values, plus the [`SrcPos`] of the token that broke the rule.
//!
//! Everything here is `Copy` and heap-free (numbers are carried as `f64`, words as their
//! letter), so a test can match a variant and its values, and the message is rendered only
//! when displayed. A message names the bad token or value and the rule it breaks.

use core::fmt;

use crate::rules::{
    G_LIST, HELIX_TOL_MM, MAX_DWELL_S, MIN_ARC_RADIUS_MM, MIN_FEED_MM_MIN, MIN_TOOL_OFFSET_MM,
    MIN_VECTOR_LENGTH, MIN_WEIGHT, M_LIST, START_TOLERANCE_MM,
};
use crate::vocab::{Motion, Plane};
use nc_geom::program::SrcPos;
use nc_geom::program::MAX_BLOCK_CTRL;

/// A parse failure: where it happened and which rule was broken.
///
/// Displays as `line:col: message`; the CLI prefixes the file name.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("{pos}: {kind}")]
pub struct ParseError {
    /// Physical line and column of the offending token (continuation lines keep their own
    /// line numbers).
    pub pos: SrcPos,
    pub kind: ParseErrorKind,
}

/// The kind of line a word was found on, for [`ParseErrorKind::WordNotAllowed`] and
/// [`ParseErrorKind::MissingWord`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Context {
    /// A `G00` / `G01` / `G02` / `G03` line, or a line continuing that modal motion.
    Move(Motion),
    /// A line with `G04`.
    Dwell,
    /// A line with `G43` / `G43.4`.
    LengthComp,
    /// A control-point line of a `G06.2` / `G06.5` block (including the opening line).
    ControlPoint(Motion),
    /// A line with no motion at all (only `N`, `F`, `G90`, `G21`, `M02`/`M30`).
    NoMotion,
    /// A `G92` line (`tenth` 0), `G92.1`, `G92.2` or `G92.3`.
    CoordOffset { tenth: u8 },
    /// A `G10 L<l>` line.
    SetTable { l: u8 },
}

impl fmt::Display for Context {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Context::Move(m) => write!(f, "a {m} line"),
            Context::ControlPoint(m) => write!(f, "a {m} control-point line"),
            Context::NoMotion => f.write_str("a line without motion"),
            Context::Dwell => f.write_str("a G04 (dwell) line"),
            Context::LengthComp => f.write_str("a G43/G43.4 (tool length) line"),
            Context::CoordOffset { tenth: 0 } => f.write_str("a G92 line"),
            Context::CoordOffset { tenth } => write!(f, "a G92.{tenth} line"),
            Context::SetTable { l } => write!(f, "a G10 L{l} line"),
        }
    }
}

/// Which rule was broken, with the offending values.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum ParseErrorKind {
    // ---- reading the source -------------------------------------------------------------
    #[error("byte 0x{byte:02x} is not UTF-8: save the program as UTF-8 (or ASCII)")]
    NotUtf8 { byte: u8 },
    #[error("the line is longer than {max} bytes: no NC line is, so this is not an NC program")]
    LineTooLong { max: usize },
    #[error("the program could not be read on from here: {kind}")]
    Unreadable { kind: std::io::ErrorKind },

    // ---- lexical rules -----------------------------------------------------------------
    #[error("unexpected character {ch:?}: expected a word (a letter and a number), a comment, or `\\` at the end of the line")]
    UnexpectedChar { ch: char },
    #[error("word letter {letter} is not followed by a number (like {letter}1.5, {letter}-2 or {letter}.5)")]
    MissingNumber { letter: char },
    #[error("the number after {letter} ({len} characters) is too large for a finite value")]
    NumberOutOfRange { letter: char, len: usize },
    #[error("{letter}{value:e} is outside the range dnurbs accepts for {letter}: at most {max:e} in magnitude (README, NC language)")]
    OutsideDomain { letter: char, value: f64, max: f64 },
    #[error("comment `(` is not closed: a comment must end with `)` on the same line")]
    UnterminatedComment,
    #[error("`\\` continues a line only as its last character (spaces may follow, nothing else)")]
    MisplacedBackslash,
    #[error("`\\` continues the line but the file ends here")]
    ContinuationAtEof,
    #[error("`%` (tape marker) stands alone on the program's first line and on the line that ends the program; here it is neither")]
    MisplacedTapeMark,
    /// Parameters, expressions, O-word flow control, active comments.
    #[error("{0}")]
    Interp(crate::interp_error::InterpError),
    #[error("word {letter}{value} is not supported: dnurbs accepts the words A B C F G H I J K L M N O P Q R S T U V W X Y Z")]
    UnsupportedWord { letter: char, value: f64 },

    // ---- line structure ----------------------------------------------------------------
    #[error("sequence number N{value} must be an integer from 0 to {}", u32::MAX)]
    BadSequenceNumber { value: f64 },
    #[error("sequence number N{value} must be the first word of its line")]
    MisplacedSequenceNumber { value: f64 },
    #[error(
        "word {letter} appears twice on one line (first at {first}): each word may appear once"
    )]
    RepeatedWord { letter: char, first: SrcPos },
    #[error("{} and {} on one line: they belong to the same modal group", Code(*.letter, *.first), Code(*.letter, *.second))]
    ConflictingCodes {
        letter: char,
        first: f64,
        second: f64,
    },
    #[error("canned cycle {cycle} with inverse-time feed (G93): cycles need a feed in mm/min (G94), as in LinuxCNC")]
    CycleInverseTime { cycle: crate::vocab::Cycle },
    #[error("canned cycle {cycle} needs the spindle turning (M03 or M04) before it")]
    CycleSpindleOff { cycle: crate::vocab::Cycle },
    #[error("canned cycle: R at {r} mm is below the hole's bottom at {depth} mm")]
    CycleRBelowDepth { r: f64, depth: f64 },
    #[error("L{value}: a canned cycle's repeats are a whole number from 1")]
    BadRepeat { value: f64 },
    #[error("the canned cycle on this line makes more than {max} moves (its L repeats times its pecks): write it over several lines")]
    CycleTooLong { max: usize },
    #[error("Q{value}: the peck of G73/G83 must be above 0")]
    BadPeck { value: f64 },
    #[error("{letter}{value} is not a code: {letter} numbers are whole (M) or have one decimal (G), within 0.001")]
    NotACode { letter: char, value: f64 },
    #[error("{letter} is an axis this machine does not have: dnurbs's machines have X Y Z and two rotary axes (U V W are the orientation curve of a G06.5 block only)")]
    NoSuchAxis { letter: char },
    #[error("unsupported G-code {}: dnurbs accepts {G_LIST}", Code('G', *.code))]
    UnsupportedGCode { code: f64 },
    #[error("unsupported M-code {}: dnurbs accepts {M_LIST}, and the M-codes the machine file's [mcodes] maps (M100..M199 and others: \"ignore\", \"tcp-on\", \"tcp-off\", \"stop\")", Code('M', *.code))]
    UnsupportedMCode { code: f64 },
    #[error("{what} is not allowed while cutter radius compensation is on: turn it off with G40 first (LinuxCNC's rule)")]
    CompensationForbids { what: &'static str },
    #[error("{what} while cutter radius compensation is on is not supported by dnurbs: turn it off with G40 first")]
    CompensationUnsupported { what: &'static str },
    #[error("{} while cutter radius compensation is already on: turn it off with G40 first", Code('G', *.code))]
    CompensationTwice { code: f64 },
    #[error("cutter radius compensation {} works in the XY plane (G17) only; this line is in {}", Code('G', *.code), .plane.name())]
    CompensationPlane { code: f64, plane: Plane },
    #[error("{} needs D, the tool diameter", Code('G', *.code))]
    CompensationWithoutD { code: f64 },
    #[error("D is the tool (G41/G42) or the diameter (G41.1/G42.1) of cutter radius compensation: it belongs on a G41, G42, G41.1 or G42.1 line")]
    DWithoutCompensation,
    #[error("the move after cutter radius compensation is turned on must be longer in XY ({length:.6} mm) than the tool radius ({radius:.6} mm)")]
    CompensationEntryTooShort { length: f64, radius: f64 },
    #[error("with the tool inside the arc, the tool radius ({radius:.6} mm) must be smaller than the arc's radius ({arc_radius:.6} mm)")]
    CompensationToolTooBig { arc_radius: f64, radius: f64 },
    #[error("cutter radius compensation would gouge: {what}")]
    CompensationGouge { what: &'static str },
    #[error("cutter radius compensation failed: {what} (please report this program)")]
    CompensationInternal { what: &'static str },
    #[error("{what} needs rotary axes: this machine (kinematics \"xyz\") is a 3-axis mill and keeps the tool vertical")]
    NoRotaryAxes { what: &'static str },
    #[error("the move just after G40 must be straight, not {motion} (the tool is still off the programmed path; LinuxCNC's rule)")]
    ArcAfterCompensation { motion: Motion },
    #[error("canned cycle {} is not supported: post the cycle expanded into G00/G01 moves", Code('G', *.code))]
    CannedCycle { code: f64 },
    #[error("P{value} on an arc is the number of turns: a whole number from 1 to 10000")]
    ArcTurns { value: f64 },
    #[error("G07 (lathe diameter mode: X words are diameters) is not supported: dnurbs's machines are mills")]
    LatheDiameterMode,
    #[error("probing {} is not supported: dnurbs plans the whole program before the machine moves, and a probe's result (#5061..#5070) is only known when it touches", Code('G', *.code))]
    Probing { code: f64 },
    #[error("spindle-synchronised motion {} (threading, rigid tapping) is not supported: dnurbs's spindle is not an axis the path follows", Code('G', *.code))]
    SpindleSynchronised { code: f64 },
    #[error("program number O{value} must stand alone on its line (after an optional N)")]
    MisplacedProgramNumber { value: f64 },
    #[error("word {letter} after the program end at {end}: only blank lines, comments and `%` may follow M02/M30")]
    AfterProgramEnd { letter: char, end: SrcPos },
    #[error("word {letter} is not allowed on {context}")]
    WordNotAllowed { letter: char, context: Context },
    #[error("{context} needs the word {letter}")]
    MissingWord { letter: char, context: Context },

    // ---- modal state -------------------------------------------------------------------
    #[error("feed F{value} must be at least {MIN_FEED_MM_MIN} mm/min")]
    BadFeed { value: f64 },
    #[error("G64 {letter}{value}: a path tolerance is a distance, 0 or more")]
    NegativePathTolerance { letter: char, value: f64 },
    #[error(
        "{motion} needs a feed but none is in effect: program F<mm/min> on this or an earlier line"
    )]
    NoFeed { motion: Motion },
    #[error("{motion} under G95 (feed per revolution) needs a spindle speed: S is 0")]
    PerRevWithoutSpeed { motion: Motion },
    #[error(
        "word {letter} moves the machine but no motion mode is in effect: start with G00 or G01"
    )]
    NoMotionMode { letter: char },
    #[error("the first move defines the start pose and must give X, Y and Z ({axis} is missing), unless the machine file has a [reference] position to start from")]
    MissingStartAxis { axis: char },
    #[error("{motion} block before the start pose: the program must first move with a G00/G01 giving X, Y and Z")]
    NurbsBeforeStart { motion: Motion },

    #[error("{letter}{value} must be a whole number from 0 to 99999")]
    BadNumber { letter: char, value: f64 },
    #[error("spindle speed S{value} must be from 0 to 1000000 rpm")]
    BadSpeed { value: f64 },
    #[error(
        "spindle speed S{value} is above the spindle's maximum of {max} rpm ([spindle] max_rpm)"
    )]
    SpeedAboveMax { value: f64, max: f64 },
    #[error("G04 needs the dwell time: P<seconds> or X<seconds>")]
    DwellWithoutTime,
    #[error("dwell of {value} s must be from 0 to {MAX_DWELL_S} s (P and X are seconds here; a post that writes P in milliseconds must be set to seconds)")]
    BadDwell { value: f64 },
    #[error(
        "G93 (inverse-time feed) needs F on every {motion} line: F is 1/minutes for that move"
    )]
    InverseTimeWithoutFeed { motion: Motion },
    #[error("{motion} in G91 (incremental) mode: a NURBS block takes absolute coordinates, program G90 first")]
    NurbsIncremental { motion: Motion },
    #[error("work offset {} is not defined: define it under [work_offsets] in the machine file or in an --offsets file", Code('G', *.code))]
    UnknownWorkOffset { code: f64 },
    #[error("{} and {motion} on one line both take the axis words: put them on lines of their own", Code('G', *.code))]
    AxisWordsTwice { code: f64, motion: Motion },
    #[error("{} and {} on one line both take the {letter} word: put them on lines of their own", Code(*.first_letter, *.first), Code(*.second_letter, *.second))]
    WordShared {
        letter: char,
        first_letter: char,
        first: f64,
        second_letter: char,
        second: f64,
    },
    #[error("{} {letter}{value}: the machine has {count} {what} ({what} of the machine file's [io])", Code('M', *.code))]
    NoSuchIo {
        code: f64,
        letter: char,
        value: f64,
        count: u8,
        what: &'static str,
    },
    #[error("{} needs {letter}", Code('M', *.code))]
    IoWordMissing { code: f64, letter: char },
    #[error("M72: no modal state is saved (M70 saves it; M71 or a restore forgets it)")]
    NothingSaved,
    #[error(
        "M66 L{value}: the wait mode is 0 (read at once), 1 (rise), 2 (fall), 3 (high) or 4 (low)"
    )]
    BadWaitMode { value: f64 },
    #[error("M66 Q{value}: the timeout is 0..=3600 s")]
    BadWaitTimeout { value: f64 },
    #[error("M66 L{mode} waits at most Q seconds: give Q more than 0 (LinuxCNC refuses a zero timeout with a wait mode other than L0)")]
    ZeroWaitTimeout { mode: u8 },
    #[error("M66 L{mode} with E (an analog input) waits for a digital input's edge or level: give P, or L0")]
    AnalogWait { mode: u8 },
    #[error("M{code} switched tool-centre-point control off ([mcodes] of the machine file): the machine's axes are then the program's, which they are only with the rotary axes at 0 (here {r1}, {r2} deg)")]
    TcpOffTurned { code: u32, r1: f64, r2: f64 },
    #[error("{motion}: LinuxCNC's splines are in the XY plane (G17)")]
    SplinePlane { motion: Motion },
    #[error("{motion} under G93 (inverse time): give the feed in G94")]
    SplineInverseTime { motion: Motion },
    #[error("{letter}: a G05.2 control point needs both X and Y")]
    NurbsPointXy { letter: char },
    #[error("P without X Y sets the weight of the first control point only (on the G05.2 line)")]
    NurbsFirstWeight,
    #[error("G05.2 L{value}: the order is a whole number, at most 6 (degree 5)")]
    NurbsOrder { value: f64 },
    #[error("G05.2 P{value}: a control point's weight must be above 0")]
    NurbsWeight { value: f64 },
    #[error("G05.3 without a G05.2 block open")]
    NurbsCloseWithoutOpen,
    #[error("G05.3: {count} control points, fewer than the order {order}")]
    NurbsTooFewPoints { count: usize, order: usize },
    #[error("the G05.2 block of {opened} is not closed by G05.3 here")]
    NurbsNotClosed { opened: SrcPos },
    #[error("G05 needs both I and J, or neither (then the last G05's P Q, negated)")]
    SplineWithoutIj,
    #[error("{letter} with polar coordinates (@ ^) on one line: give X Y or @ ^")]
    PolarWithXy { letter: char },
    #[error("{letter}: polar coordinates are for the XY plane (G17), as in LinuxCNC")]
    PolarPlane { letter: char },
    #[error("{}", if *.incremental { "G91 motion with polar coordinates is indeterminate at the program's zero: give the angle and radius in G90" } else { "@ without ^ at the program's zero: give the angle" })]
    PolarAtOrigin { incremental: bool },
    #[error("G92 {axis}: an offset of a rotary axis makes the angle in effect read as the one given, but the tool axis in effect was given as a vector (I J K), not as angles")]
    OffsetRotary { axis: char },
    #[error("G92 needs at least one of X Y Z: the coordinates the current point is to have")]
    OffsetWithoutAxes,
    #[error("G10 needs L: L1 (a tool's length and radius), L2 (a work offset), L20 (a work offset from the current point); dnurbs does not take L10/L11 (tool tables from the current point)")]
    G10Kind,
    #[error("G10 L{l} P{value}: P is {}", if *.l == 1 { "a tool number in the tool table" } else { "a work offset: 0 the one in effect, 1..6 for G54..G59 (dnurbs has no G59.1..G59.3)" })]
    G10Index { l: u8, value: f64 },
    #[error("G10 {letter}{value}: dnurbs's work offsets move X Y Z (an offset of a rotary axis is not supported)")]
    G10Rotary { letter: char, value: f64 },
    #[error("{what} in a rotated coordinate system (G10 L2 R{deg}) is not supported by dnurbs: select a work offset without rotation first")]
    NotRotated { what: &'static str, deg: f64 },
    #[error("{} needs the machine's {}: define it under [reference] in the machine file", Code('G', *.code), if *.code == 30.0 { "second reference position (g30)" } else { "reference position" })]
    NoReference { code: f64 },
    #[error("{} moves {axis} in machine coordinates, which are the workpiece's only with the rotary axes at 0: the tool is tilted or the table turned here", Code('G', *.code))]
    MachineMoveRotated { code: f64, axis: char },
    #[error("{} needs G00 or G01 in effect (it is a straight move in machine coordinates)", Code('G', *.code))]
    MachineMoveNotLinear { code: f64 },
    #[error("tool {tool} is not in the tool table: add a line T{tool} ... Z<length> to the machine file's [program] tool_table, or give --tools FILE (LinuxCNC tool.tbl)")]
    UnknownTool { tool: u32 },
    #[error("the tool length changes ({from} -> {to} mm) on a {motion} block: change it on a G00/G01 (posts write G43 Z.. H..)")]
    LengthChangeOnCurve { motion: Motion, from: f64, to: f64 },
    #[error("the tool length changes with the tool axis given as angles other than 0: program the change on a line with X Y Z")]
    LengthChangeTilted,

    // ---- arcs --------------------------------------------------------------------------
    #[error("{motion} needs its centre: {} offsets, or R", .plane.offset_letters())]
    ArcWithoutCentre { motion: Motion, plane: Plane },
    #[error("{motion} with both R and the centre offset {letter}: give one of them")]
    ArcCentreAndRadius { motion: Motion, letter: char },
    #[error("centre offset {letter} is not in the {} plane: its offsets are {}", .plane.name(), .plane.offset_letters())]
    ArcOffsetOutOfPlane { letter: char, plane: Plane },
    #[error("the arc's radius is {start} mm at its start and {end} mm at its end: they differ by more than {tol} mm and 0.1 % of the radius, or by more than 100 x {tol} mm (LinuxCNC's rule; check the end point and the centre)")]
    ArcRadiusMismatch { start: f64, end: f64, tol: f64 },
    #[error("arc radius R{value} is less than half the distance to the end point ({half} mm): no arc fits")]
    ArcRadiusTooSmall { value: f64, half: f64 },
    #[error("an arc given by R cannot end where it starts: program a full circle with its centre offsets")]
    ArcFullCircleRadius,
    #[error("arc radius {radius} mm is below {MIN_ARC_RADIUS_MM} mm")]
    ArcTooSmall { radius: f64 },
    #[error("a helix rising {rise} mm over {sweep_deg:.3} deg needs {pieces} pieces to stay within {HELIX_TOL_MM} mm of the true helix, more than one block holds: program it as several arcs")]
    HelixTooSteep {
        rise: f64,
        sweep_deg: f64,
        pieces: f64,
    },

    // ---- tool orientation on G00/G01 ---------------------------------------------------
    #[error("angle {angle} and vector word {vector} on one line: give the orientation either as angles or as I J K")]
    MixedOrientation { angle: char, vector: char },
    #[error("tool vector word {given} without {missing}: I, J and K must be given together")]
    IncompleteVector { given: char, missing: char },
    #[error("tool vector I{} J{} K{} has (near) zero length: its length must exceed {MIN_VECTOR_LENGTH:e}", .ijk[0], .ijk[1], .ijk[2])]
    ZeroVector { ijk: [f64; 3] },
    #[error("rotary axis {letter} in a program that uses {first} (first at {first_pos}): a program drives either A C or B C")]
    MixedRotaryAxes {
        letter: char,
        first: char,
        first_pos: SrcPos,
    },
    #[error("only one rotary angle ({given}) after an I J K orientation: give both angles, the other one cannot be inherited from a vector")]
    PartialAngles { given: char },

    // ---- NURBS blocks ------------------------------------------------------------------
    #[error("G06.5 needs P<degree> (1 to 5)")]
    MissingDegree,
    #[error("{motion} P{value}: {}", if *.motion == Motion::G062 { "the rank (degree + 1) must be an integer from 2 to 6" } else { "the degree must be an integer from 1 to 5" })]
    BadDegree { motion: Motion, value: f64 },
    #[error("weight R{value} must be from {MIN_WEIGHT:e} to 1e6")]
    BadWeight { value: f64 },
    #[error("too few control points ({count}): a degree-{} block needs at least {min} (degree + 1)", .min - 1)]
    TooFewControlPoints { count: usize, min: usize },
    #[error("control point {} exceeds the capacity of a block: at most MAX_BLOCK_CTRL = {} control points", MAX_BLOCK_CTRL + 1, MAX_BLOCK_CTRL)]
    TooManyControlPoints,
    #[error(
        "block opened at {opened} has {have} knots, needs {need} (control points + degree + 1)"
    )]
    IncompleteKnots {
        opened: SrcPos,
        have: usize,
        need: usize,
    },
    #[error("knot K{value} is one too many: the block opened at {opened} needs {need} knots (control points + degree + 1)")]
    TooManyKnots {
        value: f64,
        opened: SrcPos,
        need: usize,
    },
    #[error(
        "knot K{value} is smaller than the previous knot {prev}: knots must be non-decreasing"
    )]
    DecreasingKnot { value: f64, prev: f64 },
    #[error("knot K{value} breaks the clamped start: the first {count} knots (degree + 1) must all equal {expected}")]
    UnclampedStart {
        value: f64,
        expected: f64,
        count: usize,
    },
    #[error("knot K{value} breaks the clamped end: the last {count} knots (degree + 1) must all equal {expected}")]
    UnclampedEnd {
        value: f64,
        expected: f64,
        count: usize,
    },
    #[error("knot K{last} equals the first knot {first}: the knot range must not be empty")]
    EmptyKnotRange { first: f64, last: f64 },
    #[error("first control point {} is not the current position {}: they must agree within {START_TOLERANCE_MM} mm per axis", Pt(.ctrl), Pt(.current))]
    StartMismatch { ctrl: [f64; 3], current: [f64; 3] },
    #[error("orientation point U V W {} is {dist} mm from cutter point X Y Z {}: they must be at least {MIN_TOOL_OFFSET_MM} mm apart", Pt(.uvw), Pt(.xyz))]
    ToolPointTooClose {
        xyz: [f64; 3],
        uvw: [f64; 3],
        dist: f64,
    },
}

/// A G or M code as usually written: `G01`, `G06.5`, `M30`.
struct Code(char, f64);

impl fmt::Display for Code {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pad = if (0.0..10.0).contains(&self.1) {
            "0"
        } else {
            ""
        };
        write!(f, "{}{pad}{}", self.0, self.1)
    }
}

/// A point as `(x, y, z)`.
struct Pt<'a>(&'a [f64; 3]);

impl fmt::Display for Pt<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.0;
        write!(f, "({x}, {y}, {z})")
    }
}

impl ParseErrorKind {
    /// This rule broken at `pos`.
    pub(super) fn at(self, pos: SrcPos) -> ParseError {
        ParseError { pos, kind: self }
    }
}
