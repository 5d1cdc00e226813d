//! What the program does not say: the machine's work offsets, reference position and tool
//! table ([`Setup`]), and the modal state the parser keeps between lines ([`Modal`]).

use super::codes::LengthComp;
use crate::vocab::Plane;
use std::collections::BTreeMap;

/// Most errors one parse reports.
pub const MAX_ERRORS: usize = 50;
/// Millimetres per inch (`G20`).
pub const MM_PER_INCH: f64 = 25.4;

/// The shop's side of a program: offsets, reference position, tools and switches. The
/// default has none of them (G54 is then the machine zero; `G28`, `G55`..`G59`, `G43 H` are
/// errors naming what is missing).
#[derive(Clone, Debug, PartialEq)]
pub struct Setup {
    /// `G54`..`G59`: where the program's zero is, in machine coordinates (mm). `None`: not
    /// defined (an undefined `G54` is the machine zero; the others are errors).
    pub work_offsets: [Option<[f64; 3]>; 6],
    /// The `G28` reference position in machine coordinates (mm). A program whose first move
    /// does not give all of X Y Z starts here.
    pub reference: Option<[f64; 3]>,
    /// The `G30` position in machine coordinates (mm; the machine file's `[reference] g30`).
    pub g30: Option<[f64; 3]>,
    /// Tool number -> length (mm, along the spindle).
    pub tools: BTreeMap<u32, f64>,
    /// Tool number -> diameter (mm), for cutter radius compensation (`G41 D`); a tool of
    /// `tools` without one has diameter 0 (compensation then moves nothing, as LinuxCNC).
    pub tool_diameters: BTreeMap<u32, f64>,
    /// Skip lines that start with `/` (block delete). Off: the `/` is ignored.
    pub block_delete: bool,
    /// `M01` stops (optional stop on). Off: `M01` is reported and passed.
    pub optional_stop: bool,
    /// The machine's kinematics, for `G28`/`G53` and tool-length changes with the rotary
    /// axes away from 0 (the tool tip's workpiece coordinates then follow from the machine
    /// coordinates only through it). Without it those are refused.
    pub kinematics: Option<nc_geom::kinematics::MachineKinematics>,
    /// The spindle's highest speed (rpm), where the machine has a spindle drive: an `S`
    /// above it is an error. `None`: any speed up to the language's range is reported only.
    pub max_rpm: Option<f64>,
    /// Where `o<name> call` looks for `name.ngc` when the program does not define `name`,
    /// in order (LinuxCNC's `SUBROUTINE_PATH`).
    pub subroutine_dirs: Vec<std::path::PathBuf>,
    /// Most lines a program may run again, in its loops and subroutines, all together (so
    /// also loops inside loops and calls inside calls), counted line by line: a program that
    /// would run more is refused at the line, instead of holding the planner. Default
    /// [`crate::rules::MAX_LOOP_LINES`].
    pub max_loop_lines: u64,
    /// Modes in effect before the program's first line (the machine file's
    /// `[program] startup`).
    pub startup: crate::startup::Startup,
    /// The machine's highest feed, mm/min: a programmed feed above it is run at it, and an
    /// action says so where the `F` stands. `None`: not checked.
    pub max_feed_mm_min: Option<f64>,
    /// The inputs and outputs `M62`..`M68` may name (the machine file's `[io]`); none by
    /// default.
    pub io: Io,
    /// The M-codes the machine defines and what each does (the machine file's `[mcodes]`).
    pub user_mcodes: BTreeMap<u32, nc_geom::program::UserAction>,
    /// The machine has rotary axes. Off (a 3-axis mill, kinematics `xyz`): the tool stays
    /// vertical, and `A B C` words, tool vectors and `G06.5` blocks are refused.
    pub rotary_axes: bool,
}

/// How many inputs and outputs of each kind the machine has: `M62 P<n>` needs
/// `n < digital_outputs`, and so on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Io {
    pub digital_outputs: u8,
    pub digital_inputs: u8,
    pub analog_outputs: u8,
    pub analog_inputs: u8,
}

impl Default for Setup {
    fn default() -> Self {
        Setup {
            work_offsets: [None; 6],
            reference: None,
            g30: None,
            tools: BTreeMap::new(),
            tool_diameters: BTreeMap::new(),
            block_delete: false,
            optional_stop: false,
            kinematics: None,
            max_rpm: None,
            subroutine_dirs: Vec::new(),
            max_loop_lines: crate::rules::MAX_LOOP_LINES,
            startup: crate::startup::Startup::default(),
            max_feed_mm_min: None,
            io: Io::default(),
            user_mcodes: BTreeMap::new(),
            rotary_axes: true,
        }
    }
}

/// The modal state of the language besides motion and feed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Modal {
    pub plane: Plane,
    pub inch: bool,
    pub incremental: bool,
    pub inverse_time: bool,
    /// `G95`: F is mm (inch) per spindle revolution.
    pub per_rev: bool,
    /// Active work offset (0 = G54), and where the program's zero is (mm, workpiece frame):
    /// the work offset plus `g92`.
    pub work: u8,
    pub offset: [f64; 3],
    /// The `G92` offset in effect (mm), and the one its parameters 5211..5213 hold (`G92.3`
    /// restores it).
    pub g92: [f64; 3],
    pub g92_saved: [f64; 3],
    /// The `G92` offset of the rotary axes (degrees): the tilting axis (A or B) and C, added
    /// to the angles a program writes; and the one `G92.3` restores.
    pub g92_rot: [f64; 2],
    pub g92_rot_saved: [f64; 2],
    pub comp: LengthComp,
    /// Tool length in effect (mm).
    pub tool_length: f64,
    /// `G61`/`G61.1` or `G64 P Q`: what the on-line compressor may merge (the action
    /// [`ActionKind::PathMode`](nc_geom::program::ActionKind::PathMode) tells it).
    pub path: nc_geom::program::PathMode,
    /// Mist and flood coolant on (`M07`, `M08` until `M09`).
    pub mist: bool,
    pub flood: bool,
    /// Tool-centre-point control switched off by a machine-defined M-code (`tcp-off`): the
    /// code, while moves must keep the rotary axes at 0.
    pub tcp_off: Option<u32>,
    /// Tool-centre-point control switched on by a machine-defined M-code (`tcp-on`, LinuxCNC's
    /// `M428`): `G43` then places the tool tip as `G43.4` does, as LinuxCNC's kinematics
    /// switched to TCP do.
    pub tcp_on: bool,
    /// `G90.1`: arc centres `I J K` are absolute coordinates (else offsets from the start).
    pub arc_absolute: bool,
    /// The canned cycles' sticky words and `G98`/`G99`.
    pub cycle: CycleState,
    /// The spindle as last commanded.
    pub spindle: nc_geom::program::Spindle,
    /// Selected tool (`T`) and loaded tool (after `M06`).
    pub selected: Option<u32>,
    pub loaded: Option<u32>,
    /// Spindle speed in effect, rpm.
    pub rpm: f64,
}

impl Default for Modal {
    fn default() -> Self {
        Modal {
            plane: Plane::Xy,
            inch: false,
            incremental: false,
            inverse_time: false,
            per_rev: false,
            work: 0,
            offset: [0.0; 3],
            g92: [0.0; 3],
            g92_saved: [0.0; 3],
            g92_rot: [0.0; 2],
            g92_rot_saved: [0.0; 2],
            comp: LengthComp::Off,
            tool_length: 0.0,
            path: nc_geom::program::PathMode::default(),
            arc_absolute: false,
            mist: false,
            flood: false,
            tcp_off: None,
            tcp_on: false,
            // LinuxCNC's rs274 starts in G99.
            cycle: CycleState {
                retract_to_r: true,
                ..CycleState::default()
            },
            spindle: nc_geom::program::Spindle::Off,
            selected: None,
            loaded: None,
            rpm: 0.0,
        }
    }
}

impl Modal {
    /// Millimetres per program unit of length.
    pub fn scale(&self) -> f64 {
        if self.inch {
            MM_PER_INCH
        } else {
            1.0
        }
    }
}

/// What a cycle keeps between its lines (LinuxCNC's `cycle_*` settings).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct CycleState {
    /// The level the cycle started from (workpiece mm along the cycle axis), while cycles
    /// follow each other.
    pub initial: Option<f64>,
    /// `R`, the depth, `P` and `Q` as last written (program units).
    pub r: f64,
    pub depth: f64,
    pub p: f64,
    pub q: f64,
    /// `G99` (retract to `R`) rather than `G98`.
    pub retract_to_r: bool,
    /// The cycle the last motion ran, if it was one: a line of another one needs its words.
    pub active: Option<crate::vocab::Cycle>,
}
