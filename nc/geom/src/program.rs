//! The parsed NC program: what the parser (`nc_lang`) produces and the segment
//! builder (`crate::segment`) consumes.
//!
//! Every modal value is resolved by the parser, so each move here is complete: a linear move
//! carries its full end point and tool orientation, a NURBS block its full control net.
//! A block's control net may be large (up to [`MAX_BLOCK_CTRL`]
//! points, as CAD systems write them); the segment builder cuts it into pieces of at most
//! [`MAX_CTRL`] points (`crate::split`), values of known size for the real-time thread.

/// Highest NURBS degree accepted (`G06.5 P5`, `G06.2 P6`).
pub const MAX_DEGREE: usize = 5;
/// Most control points one piece of a NURBS block holds: the fixed capacity the real-time
/// thread evaluates. Larger blocks are cut into pieces (`crate::split`).
pub const MAX_CTRL: usize = 64;
/// Most knots of one piece: control points + degree + 1.
pub const MAX_KNOTS: usize = MAX_CTRL + MAX_DEGREE + 1;
/// Most control points one NURBS block may carry (the parser's limit). The pieces the
/// real-time thread evaluates hold at most [`MAX_CTRL`].
pub const MAX_BLOCK_CTRL: usize = 100_000;

/// Where a token stands in the source: 1-based line and column (in characters).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SrcPos {
    pub line: u32,
    pub col: u32,
}

impl core::fmt::Display for SrcPos {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}:{}", self.line, self.col)
    }
}

/// Tool orientation as programmed on a linear move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Orientation {
    /// `A_ C_` (or `B_ C_` on an xyzbc machine): machine rotary angles in degrees,
    /// interpolated linearly in angle along the move.
    Angles { r1_deg: f64, r2_deg: f64 },
    /// `I_ J_ K_`: tool-axis vector in the workpiece frame, normalised by the parser,
    /// interpolated along the great circle (slerp).
    Vector([f64; 3]),
}

/// `G00` / `G01`: a straight move of the cutter centre with (optionally) changing orientation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearMove {
    /// Position of the `G00`/`G01` word (or of the first word of a modal-motion line).
    pub pos: SrcPos,
    /// `N` number, if the line had one.
    pub n: Option<u32>,
    /// `true` for G00 (moves at the machine's rapid feed).
    pub rapid: bool,
    /// End point of the cutter centre, workpiece frame, mm (modal X/Y/Z resolved).
    pub end: [f64; 3],
    /// Tool orientation at the end point (modal: the previous one if the line gave none).
    pub orientation: Orientation,
    /// Programmed feed, mm/min (ignored for rapid moves; may then be 0).
    pub feed_mm_min: f64,
    /// The feed was programmed in inverse time (`G93`): `feed_mm_min` is the move's length
    /// over the time its `F` gave it.
    pub inverse_time: bool,
    /// Tool length and stops in effect for this move (see [`MoveTooling`]).
    pub tooling: MoveTooling,
}

/// Which NURBS word opened the block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NurbsKind {
    /// `G06.2`: Fanuc 3-axis NURBS. The tool orientation stays as it was before the block.
    G062,
    /// `G06.5`: the paper's double NURBS, with the orientation curve's control points in U V W.
    G065,
}

/// `G06.2` / `G06.5`: one (double) NURBS curve with shared knots and weights.
#[derive(Clone, Debug, PartialEq)]
pub struct NurbsBlock {
    /// Position of the `G06.2`/`G06.5` word.
    pub pos: SrcPos,
    /// `N` number of the opening line, if it had one.
    pub n: Option<u32>,
    pub kind: NurbsKind,
    /// Degree p (for G06.2 the parser converts the rank P to p = P - 1).
    pub degree: u8,
    /// Control points of the cutter-centre curve C(u), X Y Z, mm.
    pub ctrl: Vec<[f64; 3]>,
    /// Control points of the orientation curve CT(u), U V W (G06.5 only; empty for G06.2).
    pub tool_ctrl: Vec<[f64; 3]>,
    /// Source position of each control point's first word, for error messages.
    pub ctrl_pos: Vec<SrcPos>,
    /// Weights R (default 1.0 where a line has none), one per control point.
    pub weights: Vec<f64>,
    /// Knot vector, `ctrl.len() + degree + 1` values, non-decreasing and clamped.
    pub knots: Vec<f64>,
    /// Programmed feed, mm/min (modal F resolved).
    pub feed_mm_min: f64,
    pub tooling: MoveTooling,
    /// Rotary angles (degrees) at the end of an arc that turns the tool (`G02 .. A_ C_`):
    /// they change linearly in path length along the arc, as along a `G01`. `None`: the
    /// tool axis stays as it was (every G06.2, G06.5 and arc without angle words).
    pub turn_to: Option<(f64, f64)>,
}

/// One motion block of the program.
#[derive(Clone, Debug, PartialEq)]
pub enum Block {
    Linear(LinearMove),
    Nurbs(NurbsBlock),
}

impl Block {
    pub fn pos(&self) -> SrcPos {
        match self {
            Block::Linear(m) => m.pos,
            Block::Nurbs(b) => b.pos,
        }
    }
}

/// A whole parsed program. The first block must be a linear move with a full X Y Z (and
/// orientation, else the tool is vertical): it defines the start pose, and the interpolator
/// starts there (no motion is generated towards it).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Program {
    pub blocks: Vec<Block>,
    /// Where `M02`/`M30` stood, if the program had one.
    pub end: Option<SrcPos>,
    /// Program words that drive no axis (spindle, coolant, tool selection, stops and dwells),
    /// in program order: what a run reports and, where the machine has the hardware, does.
    pub actions: Vec<Action>,
    /// The tilting-axis letter the program's angle words use (`'A'` or `'B'`) and where it
    /// first stood; `None` if the program gives no angles. The machine must match it.
    pub tilt_word: Option<(char, SrcPos)>,
    /// Source lines run more than once or inside a subroutine (in a loop's second pass
    /// and after, or called), as sorted, disjoint, inclusive ranges: a restart from one
    /// of them would not say which pass (`nc_lang::restart`).
    pub rerun: Vec<(u32, u32)>,
}

/// What the tool does along a move besides its geometry: the tool-length offset at the
/// move's end and what must happen, at rest, before the move starts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MoveTooling {
    /// Tool length (mm along the spindle axis, machine +Z) in effect at the end of the
    /// move: `G43 H` / `G43.4 H` from the tool table, 0 after `G49` or without either. The
    /// machine's Z axis carries it: machine Z = the kinematics' Z + length. It changes only
    /// along a `G00`/`G01` (the change is spread over the move).
    pub tool_length: f64,
    /// Which tool-length mode is in effect. dnurbs always places the programmed X Y Z in the
    /// workpiece frame (tool-centre-point control) on the `*-trt` machines; see
    /// [`LengthMode`] for what each mode allows.
    pub mode: LengthMode,
    /// The path stops before this move and waits there (`G04`, `M00`, `M01`, `M06`).
    pub wait: Wait,
}

/// The tool-length mode of a move.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LengthMode {
    /// Neither `G43` nor `G43.4` (or `G49`): dnurbs's own reading, positions in the workpiece
    /// frame on every machine, tool length 0.
    #[default]
    None,
    /// `G43 H`: a post for a control without tool-centre-point control wrote X Y Z for the
    /// rotary axes at 0; a move that tilts or turns a rotary table under it is refused
    /// (`segment::build`), since its positions would be read differently.
    Length,
    /// `G43.4 H`: tool-centre-point control (RTCP); needs a machine with RTCP kinematics.
    Rtcp,
}

/// A stop before a move: a dwell, the operator's resume, or both.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wait {
    /// Seconds to stay at rest (sum of the `G04` dwells before the move).
    pub dwell_s: f64,
    /// The operator must resume (`M00`, `M01` when optional stops are on, `M06`): where the
    /// first such word stood.
    pub operator: Option<SrcPos>,
    /// The spindle must be at its commanded speed: the first feed move after `M03`/`M04`
    /// or a new `S` while turning (set by the segment builder, not the parser).
    pub spindle: bool,
}

/// Most `M66` waits between two moves (`Segment::inputs`).
pub const MAX_INPUT_WAITS: usize = 4;

/// One `M66 P<n> L1..L4 Q<s>`: the path waits at rest until digital input `input` rises,
/// falls, is high or is low, at most `timeout_s`; then it goes on (LinuxCNC's `#5399`
/// would say -1 after a timeout; dnurbs refuses a program that reads it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputWait {
    pub input: u8,
    pub mode: WaitMode,
    pub timeout_s: f64,
    /// Where the `M66` stands.
    pub pos: SrcPos,
}

impl InputWait {
    /// Whether the wait is over with the input `high` now, `seen` telling whether the
    /// level before the edge has been seen since the wait began (updated here).
    pub fn met(&self, high: bool, seen: &mut bool) -> bool {
        match self.mode {
            WaitMode::Immediate => true,
            WaitMode::High => high,
            WaitMode::Low => !high,
            WaitMode::Rise => {
                let met = *seen && high;
                *seen |= !high;
                met
            }
            WaitMode::Fall => {
                let met = *seen && !high;
                *seen |= high;
                met
            }
        }
    }
}

impl Wait {
    pub fn is_some(&self) -> bool {
        self.dwell_s > 0.0 || self.operator.is_some() || self.spindle
    }
}

/// The spindle, coolant and digital outputs commanded while a segment runs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Aux {
    /// rpm, signed: positive after `M03` (clockwise), negative after `M04`, 0 stopped.
    pub spindle_rpm: f64,
    /// `M07` until `M09`.
    pub mist: bool,
    /// `M08` until `M09`.
    pub flood: bool,
    /// The program's digital outputs (`M62`..`M65 P<n>`: bit n), on from the move after
    /// the word.
    pub outputs: u64,
}

impl Aux {
    /// The state after `action`; `true` if the spindle must now reach a new, non-zero
    /// speed (a start, a reversal, a new `S` while turning).
    pub fn apply(&mut self, action: &ActionKind) -> bool {
        let before = self.spindle_rpm;
        match *action {
            ActionKind::Spindle { dir, rpm } => {
                self.spindle_rpm = match dir {
                    Spindle::Cw => rpm,
                    Spindle::Ccw => -rpm,
                    Spindle::Off => 0.0,
                }
            }
            ActionKind::Speed { rpm } if self.spindle_rpm != 0.0 => {
                self.spindle_rpm = rpm.copysign(self.spindle_rpm);
            }
            ActionKind::Coolant(Coolant::Mist) => self.mist = true,
            ActionKind::Coolant(Coolant::Flood) => self.flood = true,
            ActionKind::Coolant(Coolant::Off) => {
                self.mist = false;
                self.flood = false;
            }
            ActionKind::DigitalOutput { index, on, .. } => {
                let bit = 1u64.checked_shl(u32::from(index)).unwrap_or(0);
                if on {
                    self.outputs |= bit;
                } else {
                    self.outputs &= !bit;
                }
            }
            _ => {}
        }
        self.spindle_rpm != before && self.spindle_rpm != 0.0
    }
}

/// A program word that drives no axis, and where it stood.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Action {
    pub pos: SrcPos,
    /// Index in [`Program::blocks`] of the first motion block after the word
    /// (`blocks.len()` when no motion follows).
    pub before_block: usize,
    pub kind: ActionKind,
}

/// Spindle direction (`M03` clockwise, `M04` counter-clockwise, `M05` stopped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spindle {
    Cw,
    Ccw,
    Off,
}

/// Coolant outputs (`M07` mist, `M08` flood, `M09` both off).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coolant {
    Mist,
    Flood,
    Off,
}

/// What `M66` waits for (its `L` word).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WaitMode {
    /// `L0`: no wait, the input is read at once.
    Immediate,
    /// `L1`: a rising edge.
    Rise,
    /// `L2`: a falling edge.
    Fall,
    /// `L3`: the input high.
    High,
    /// `L4`: the input low.
    Low,
}

/// An input `M66` reads: digital `P<n>` or analog `E<n>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    Digital(u8),
    Analog(u8),
}

/// What the machine file maps a machine-defined M-code to (`[mcodes]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UserAction {
    /// Nothing moves or switches: reported with a note.
    Ignore,
    /// Tool-centre-point control on (LinuxCNC's `M428` in its trunnion demos): what dnurbs
    /// does on its `*-trt` machines anyway.
    TcpOn,
    /// Tool-centre-point control off (LinuxCNC's `M429`, its trivial kinematics): the
    /// machine's axes are then the program's, which they are only with the rotary axes at 0,
    /// so moves are refused unless they are there.
    TcpOff,
    /// A program stop: the path stops for the operator, as at `M00`.
    Stop,
    /// The program's digital output `index` on or off, as `M62`/`M63` (an action of its own
    /// follows the code's).
    Output { index: u8, on: bool },
    /// A wait for digital input `input`, as `M66 P L1..L4 Q` (an action of its own follows).
    Wait {
        input: u8,
        mode: WaitMode,
        timeout_s: f64,
    },
}

/// A path-control mode: LinuxCNC's permissions to leave the programmed path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathMode {
    /// `G61` exact path, `G61.1` exact stop: no permission.
    Exact,
    /// `G64`: blend corners within `p_mm`, merge runs of nearly collinear moves within
    /// `q_mm` (LinuxCNC's naive-CAM tolerance; mm; None where the word is not given).
    Blend {
        p_mm: Option<f64>,
        q_mm: Option<f64>,
    },
}

impl Default for PathMode {
    /// `G64` without `P` or `Q`: LinuxCNC's start-up mode.
    fn default() -> Self {
        PathMode::Blend {
            p_mm: None,
            q_mm: None,
        }
    }
}

/// How far runs of moves may be merged under a [`PathMode`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Merge {
    /// Not at all: the moves run as programmed.
    Off,
    /// As the machine sets it (its default naive-CAM tolerance).
    Machine,
    /// Within this distance of the programmed points (mm).
    Within(f64),
}

impl PathMode {
    /// LinuxCNC's rule for the naive-CAM tolerance: `G64 Q`, else `G64 P`, else the
    /// machine's default; none in `G61` and `G61.1`. A tolerance of 0 merges nothing.
    pub fn merge(self) -> Merge {
        match self {
            PathMode::Exact => Merge::Off,
            PathMode::Blend { p_mm, q_mm } => match q_mm.or(p_mm) {
                None => Merge::Machine,
                Some(t) if t > 0.0 => Merge::Within(t),
                Some(_) => Merge::Off,
            },
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ActionKind {
    /// `M03`/`M04`/`M05` with the speed in effect (rpm, `S`).
    Spindle {
        dir: Spindle,
        rpm: f64,
    },
    /// `S` alone: the speed for the next `M03`/`M04` (or, while turning, a new speed).
    Speed {
        rpm: f64,
    },
    Coolant(Coolant),
    /// `T`: the tool the next `M06` loads.
    SelectTool {
        tool: u32,
    },
    /// `M06`: the selected tool is loaded (the path stops for the operator).
    ChangeTool {
        tool: Option<u32>,
    },
    /// `G04`.
    Dwell {
        seconds: f64,
    },
    /// `M00`.
    Stop,
    /// `M01`: `taken` when optional stops are on.
    OptionalStop {
        taken: bool,
    },
    /// `M62`/`M63` (`synced`: as the next move starts) and `M64`/`M65` (at once): digital
    /// output `index` on or off.
    DigitalOutput {
        index: u8,
        on: bool,
        synced: bool,
    },
    /// `M67` (`synced`) and `M68`: analog output `index` set to `value`.
    AnalogOutput {
        index: u8,
        value: f64,
        synced: bool,
    },
    /// `M66`: wait for `input` as `mode` says, at most `timeout_s`.
    WaitInput {
        input: Input,
        mode: WaitMode,
        timeout_s: f64,
    },
    /// A programmed feed above the machine's highest: feed moves run at `used_mm_min` until
    /// the next `F`.
    FeedClamped {
        programmed_mm_min: f64,
        used_mm_min: f64,
    },
    /// `G61`, `G61.1` or `G64 P Q` (or an `M72` that restores one): the path-control mode
    /// from here on. The on-line compressor follows it ([`PathMode::merge`]).
    PathMode(PathMode),
    /// A machine-defined M-code and what the machine file maps it to.
    UserM {
        code: u32,
        action: UserAction,
    },
}
