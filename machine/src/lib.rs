//! The validated machine description the rest of the program uses: what the `config` crate
//! reads a machine file into (its stage 2), without serde or TOML, so that the real-time
//! crates can take these types and nothing of the file's parsing.
//!
//! A value of these types has passed every check of `config`'s validation: all numbers are finite
//! (except the `±inf` travel of a continuous C table), `min < max`, and every rate limit is
//! `> 0`. Units are the machine's: linear axes in mm, mm/s, mm/s^2, mm/s^3; rotary axes in
//! deg, deg/s, deg/s^2, deg/s^3; the period in seconds.

use std::fmt;
use std::str::FromStr;

pub mod bus;
pub mod io;
pub mod program;
pub mod spindle;

pub use io::BusIo;
pub use program::{IoCounts, Level, McodeAction, ProgramSetup, Tool};
pub use spindle::{BusNode, Coolant, Spindle};

/// A validated machine configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Machine {
    /// `[machine] name`, never empty.
    pub name: String,
    /// Interpolation period in seconds (`[machine] period_ms / 1000`), in `1e-4..=0.1`.
    pub period_s: f64,
    pub kinematics: Kinematics,
    pub axes: Axes,
    pub interpolation: Interpolation,
    /// CAN buses (`[[bus]]`); empty for a machine that is only simulated.
    pub buses: Vec<crate::bus::Bus>,
    /// One drive per axis in joint order (X Y Z tilt C) when `buses` is not empty, else none.
    pub drives: Vec<crate::bus::Drive>,
    pub realtime: Realtime,
    /// A bus over its `max_load` at this period: `file:line:col: ...` of its `max_load`.
    /// The file is valid; [`Machine::check_bus_load`] refuses it where the bus is used.
    pub bus_overload: Option<String>,
    /// `[control] socket`: where `dnurbs run` serves the operator's control socket.
    pub control_socket: Option<std::path::PathBuf>,
    /// `[work_offsets] G54..G59`: program zero in machine coordinates (mm), by offset.
    pub work_offsets: [Option<[f64; 3]>; 6],
    /// `[reference] position`: the G28 position in machine coordinates (mm).
    pub reference: Option<[f64; 3]>,
    /// `[reference] g30`: the G30 position in machine coordinates (mm).
    pub g30: Option<[f64; 3]>,
    /// `[spindle]`: the spindle drive, if the machine has one on its bus.
    pub spindle: Option<crate::spindle::Spindle>,
    /// `[coolant]`: the coolant valves' I/O module, if the machine has one on its bus.
    pub coolant: Option<crate::spindle::Coolant>,
    /// `[io]` on a machine with a bus: the program's digital I/O on its I/O module (the
    /// coolant's, if it has one); the counts are in `program.io`.
    pub bus_io: Option<BusIo>,
    /// `[program]`: start-up modes, tool table, subroutine path, loop limit.
    pub program: ProgramSetup,
}

impl Machine {
    /// The node of the machine's I/O module on bus `bus` (the coolant's, or `[io]`'s: one
    /// module when it has both), if it has one there.
    pub fn io_module(&self, bus: usize) -> Option<u8> {
        let coolant = self.coolant.as_ref().and_then(|c| c.on_bus(bus));
        coolant.or(self.bus_io.filter(|b| b.on_bus(bus)).map(|b| b.at.node))
    }

    /// Every bus within its `max_load` at the machine's period; else the message naming the
    /// bus, its load and by how much it is over.
    pub fn check_bus_load(&self) -> Result<(), &str> {
        match &self.bus_overload {
            Some(m) => Err(m),
            None => Ok(()),
        }
    }

    /// What bus `bus` carries each cycle: the axes' drives, the spindle, the coolant module.
    pub fn bus_nodes(&self, bus: usize) -> crate::bus::Nodes {
        let drives = self.drives.iter().filter(|d| d.bus == bus).count()
            + usize::from(
                self.spindle
                    .as_ref()
                    .is_some_and(|s| s.on_bus(bus).is_some()),
            );
        crate::bus::Nodes {
            drives: drives as u32,
            io: u32::from(
                self.coolant
                    .as_ref()
                    .is_some_and(|c| c.on_bus(bus).is_some()),
            ),
        }
    }

    /// `[machine] period_ms` when omitted.
    pub const DEFAULT_PERIOD_MS: f64 = 2.0;
    /// Smallest allowed `period_ms`.
    pub const MIN_PERIOD_MS: f64 = 0.1;
    /// Largest allowed `period_ms`.
    pub const MAX_PERIOD_MS: f64 = 100.0;
}

/// Which kinematic transformation maps workpiece coordinates and tool axis to machine axes.
#[derive(Clone, Debug, PartialEq)]
pub enum Kinematics {
    /// Paper: machine XYZ = workpiece XYZ (no tool-centre-point compensation), rotary A about X
    /// and C about Z.
    Paper,
    /// A tilting table (about machine X) carrying a C rotary table (about the table normal,
    /// machine Z at A=0). Points in mm, machine frame.
    XyzacTrt {
        /// A point on the A axis.
        a_axis_point: [f64; 3],
        /// A point on the C axis at A = 0.
        c_axis_point: [f64; 3],
    },
    /// B tilting table (about machine Y) carrying a C rotary table. Points in mm, machine frame.
    XyzbcTrt {
        /// A point on the B axis.
        b_axis_point: [f64; 3],
        /// A point on the C axis at B = 0.
        c_axis_point: [f64; 3],
    },
    /// A 3-axis mill: machine XYZ = workpiece XYZ, the tool always vertical. Its rotary axes
    /// are locked at 0 ([`Axes::locked`]); a program that turns the tool is refused.
    Xyz,
}

impl Kinematics {
    /// The `kind` names accepted in `[kinematics]`, in the order of the variants.
    pub const KINDS: [&'static str; 4] = ["paper", "xyzac-trt", "xyzbc-trt", "xyz"];

    /// The `kind` name as written in the TOML file.
    pub fn kind(&self) -> &'static str {
        match self {
            Kinematics::Paper => Self::KINDS[0],
            Kinematics::XyzacTrt { .. } => Self::KINDS[1],
            Kinematics::XyzbcTrt { .. } => Self::KINDS[2],
            Kinematics::Xyz => Self::KINDS[3],
        }
    }

    /// Whether the machine has rotary axes (all kinds but `xyz`).
    pub fn has_rotary_axes(&self) -> bool {
        *self != Kinematics::Xyz
    }

    /// The tilting rotary axis this kinematics has (A or B).
    pub fn tilt_name(&self) -> RotaryName {
        match self {
            Kinematics::Paper | Kinematics::XyzacTrt { .. } | Kinematics::Xyz => RotaryName::A,
            Kinematics::XyzbcTrt { .. } => RotaryName::B,
        }
    }
}

/// Name of the tilting rotary axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RotaryName {
    /// Tilts about machine X.
    A,
    /// Tilts about machine Y.
    B,
}

impl RotaryName {
    /// Upper-case axis letter, as in NC programs: `"A"` or `"B"`.
    pub fn letter(self) -> &'static str {
        match self {
            RotaryName::A => "A",
            RotaryName::B => "B",
        }
    }

    /// The table key under `[axes]`: `"a"` or `"b"`.
    pub fn key(self) -> &'static str {
        match self {
            RotaryName::A => "a",
            RotaryName::B => "b",
        }
    }
}

impl fmt::Display for RotaryName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.letter())
    }
}

/// Travel and rate limits of one axis (mm or deg, per s, s^2, s^3).
#[derive(Clone, Debug, PartialEq)]
pub struct AxisLimits {
    /// Lower travel limit; `-inf` only for a continuous C table.
    pub min: f64,
    /// Upper travel limit, `> min`; `+inf` only for a continuous C table.
    pub max: f64,
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
}

impl AxisLimits {
    /// True when the axis has no travel limits (a continuous rotary table).
    pub fn is_unlimited(&self) -> bool {
        self.min == f64::NEG_INFINITY && self.max == f64::INFINITY
    }
}

/// The five axes. The tilting axis is A or B as [`Axes::tilt_name`] says.
#[derive(Clone, Debug, PartialEq)]
pub struct Axes {
    pub x: AxisLimits,
    pub y: AxisLimits,
    pub z: AxisLimits,
    pub tilt_name: RotaryName,
    pub tilt: AxisLimits,
    pub c: AxisLimits,
}

impl Axes {
    /// The limits of a rotary axis a 3-axis machine does not have: locked at 0 (it never
    /// moves; rates of 1 deg/s.. are never reached).
    pub fn locked() -> AxisLimits {
        AxisLimits {
            min: 0.0,
            max: 0.0,
            velocity: 1.0,
            acceleration: 1.0,
            jerk: 1.0,
        }
    }

    /// All axes with their NC letters, in the order X, Y, Z, A/B, C.
    pub fn all(&self) -> [(&'static str, &AxisLimits); 5] {
        [
            ("X", &self.x),
            ("Y", &self.y),
            ("Z", &self.z),
            (self.tilt_name.letter(), &self.tilt),
            ("C", &self.c),
        ]
    }
}

/// Parameter-update method of the interpolator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Arc-length parametrisation (lowest feed fluctuation).
    #[default]
    Arclength,
    /// First-order Taylor update (paper eq. 9).
    Taylor1,
    /// Second-order Taylor update (paper eq. 10).
    Taylor2,
}

impl Method {
    /// Every method, in declaration order.
    pub const ALL: [Method; 3] = [Method::Arclength, Method::Taylor1, Method::Taylor2];

    /// The name used in the TOML file and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Arclength => "arclength",
            Method::Taylor1 => "taylor1",
            Method::Taylor2 => "taylor2",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A string that names no [`Method`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown interpolation method {0:?}: expected one of \"arclength\", \"taylor1\", \"taylor2\""
)]
pub struct UnknownMethod(pub String);

impl FromStr for Method {
    type Err = UnknownMethod;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownMethod(s.to_owned()))
    }
}

/// `[realtime]`: the real-time thread and drive supervision.
#[derive(Clone, Debug, PartialEq)]
pub struct Realtime {
    /// SCHED_FIFO priority, 1..=99.
    pub priority: i32,
    /// CPU the real-time thread is pinned to, if any.
    pub cpu: Option<usize>,
    /// Keep `cpu` from halting between periods with a `SCHED_IDLE` polling thread.
    pub idle_poll: bool,
    /// Wake this long before each deadline, warm the caches, compute the step and send at
    /// the deadline, s; 0 sleeps to the deadline.
    pub lead_s: f64,
    /// Segments the planner may keep queued ahead of the interpolator, 2..=1024.
    pub queue_depth: usize,
    /// More periods in a row than this overrunning their deadline stop the run along the
    /// path (exit 3), 1..=100000.
    pub max_consecutive_overruns: u64,
    /// A drive whose heartbeat is older than this is lost, s.
    pub heartbeat_timeout_s: f64,
    /// A drive without position feedback for this long is lost, s.
    pub feedback_timeout_s: f64,
    /// Wait for the drives' boot-up messages, s.
    pub boot_timeout_s: f64,
    /// Wait for one SDO answer during set-up, s.
    pub sdo_timeout_s: f64,
}

impl Realtime {
    /// Deepest allowed `queue_depth` (the preallocated queue's capacity).
    pub const MAX_QUEUE_DEPTH: usize = 1024;
}

impl Default for Realtime {
    /// The values used when `[realtime]` or one of its keys is omitted.
    fn default() -> Self {
        Realtime {
            priority: 80,
            cpu: None,
            idle_poll: false,
            lead_s: 0.0,
            queue_depth: 64,
            max_consecutive_overruns: 10,
            heartbeat_timeout_s: 0.3,
            feedback_timeout_s: 0.02,
            boot_timeout_s: 3.0,
            sdo_timeout_s: 0.2,
        }
    }
}

/// Path-level interpolation settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Interpolation {
    pub method: Method,
    /// Maximum chord error, mm, in `(0, 1]`.
    pub chord_tolerance_mm: f64,
    /// Tangential acceleration limit, mm/s^2.
    pub path_acceleration: f64,
    /// Tangential jerk limit, mm/s^3.
    pub path_jerk: f64,
    /// Highest programmable feed, mm/min.
    pub max_feed_mm_min: f64,
    /// Feed for rapid moves, mm/min.
    pub rapid_feed_mm_min: f64,
    /// On-line compression: runs of G01 moves fitted into G06.5 blocks before planning.
    pub compress: bool,
    /// Its tolerances (kept when it is off: `--compress` turns it on with them).
    pub compression: Compress,
}

/// `[interpolation] compress = true` and its tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compress {
    /// Largest distance of a programmed point from the fitted cutter curve, mm.
    pub tol_mm: f64,
    /// Largest angle between a programmed tool axis and the fitted one, degrees.
    pub tol_deg: f64,
    /// A turn of the path between two moves above this is a corner (degrees).
    pub corner_deg: f64,
}

impl Compress {
    /// Defaults: 1 um, 0.01 degree, corners above 10 degrees.
    pub const DEFAULT: Compress = Compress {
        tol_mm: 0.001,
        tol_deg: 0.01,
        corner_deg: 10.0,
    };
    /// Allowed ranges of the three.
    pub const TOL_MM: (f64, f64) = (1e-5, 1.0);
    pub const TOL_DEG: (f64, f64) = (1e-4, 5.0);
    pub const CORNER_DEG: (f64, f64) = (0.0, 180.0);
}

impl Interpolation {
    /// Largest allowed `chord_tolerance_mm` (the lower bound, 0, is exclusive).
    pub const MAX_CHORD_TOLERANCE_MM: f64 = 1.0;
    /// Default `chord_tolerance_mm` (1 um, the design target).
    pub const DEFAULT_CHORD_TOLERANCE_MM: f64 = 0.001;
    /// Default `path_acceleration`, mm/s^2.
    pub const DEFAULT_PATH_ACCELERATION: f64 = 1000.0;
    /// Default `path_jerk`, mm/s^3.
    pub const DEFAULT_PATH_JERK: f64 = 20000.0;
    /// Default `max_feed_mm_min`; `rapid_feed_mm_min` defaults to `max_feed_mm_min`.
    pub const DEFAULT_MAX_FEED_MM_MIN: f64 = 10000.0;
}

impl Default for Interpolation {
    /// The values used when `[interpolation]` or one of its keys is omitted.
    fn default() -> Self {
        Interpolation {
            method: Method::default(),
            chord_tolerance_mm: Self::DEFAULT_CHORD_TOLERANCE_MM,
            path_acceleration: Self::DEFAULT_PATH_ACCELERATION,
            path_jerk: Self::DEFAULT_PATH_JERK,
            max_feed_mm_min: Self::DEFAULT_MAX_FEED_MM_MIN,
            rapid_feed_mm_min: Self::DEFAULT_MAX_FEED_MM_MIN,
            compress: false,
            compression: Compress::DEFAULT,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.to_string().parse::<Method>(), Ok(m));
        }
        let err = "taylor3".parse::<Method>().unwrap_err().to_string();
        assert!(
            err.contains("\"taylor3\"") && err.contains("taylor2"),
            "{err}"
        );
    }

    #[test]
    fn all_names_the_tilt_axis() {
        let l = AxisLimits {
            min: -1.0,
            max: 1.0,
            velocity: 1.0,
            acceleration: 1.0,
            jerk: 1.0,
        };
        let axes = Axes {
            x: l.clone(),
            y: l.clone(),
            z: l.clone(),
            tilt_name: RotaryName::B,
            tilt: l.clone(),
            c: l,
        };
        let names = axes.all().map(|(n, _)| n);
        assert_eq!(names, ["X", "Y", "Z", "B", "C"]);
    }
}
