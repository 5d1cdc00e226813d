//! The G and M codes dnurbs knows, decoded into their modal groups.
//!
//! One code per group on a line (`G00 G01` on one line is an error, `G90 G94 G17 G49 G40 G80`
//! is six groups). Codes of real posts that dnurbs cannot honour have their own error, never
//! a silent skip: the canned cycles dnurbs does not run (tapping `G74`/`G84`, back boring
//! `G87`, `G88`).

use crate::comp::Side;
use crate::error::ParseErrorKind;
use crate::vocab::{Cycle, Motion, Plane};
use nc_geom::program::{Coolant, Spindle};

/// Tool-length compensation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LengthComp {
    /// `G43 H`: tool length along machine Z.
    Length,
    /// `G43.4 H`: tool length and tool-centre-point control (RTCP).
    Rtcp,
    /// `G43.1 Z`: the tool length given on the line (LinuxCNC's dynamic offset).
    Dynamic,
    /// `G43.2 H` or `G43.2 Z`: a tool's length or the value added to the one in effect.
    Added,
    /// `G49`.
    Off,
}

/// `G92` and its relatives: the coordinate-system offset that shifts every work offset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum G92 {
    /// `G92 X Y Z`: the current point gets the given coordinates.
    Set,
    /// `G92.1`: the offset is 0, and so are its parameters (5211..).
    Reset,
    /// `G92.2`: the offset is 0, its parameters kept.
    Suspend,
    /// `G92.3`: the offset from its parameters again.
    Restore,
}

impl G92 {
    pub fn value(self) -> f64 {
        match self {
            G92::Set => 92.0,
            G92::Reset => 92.1,
            G92::Suspend => 92.2,
            G92::Restore => 92.3,
        }
    }
}

/// The machine's inputs and outputs (`M62`..`M68`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IoCode {
    /// `M62` (synced) / `M64`: digital output on.
    DigitalOn { synced: bool },
    /// `M63` (synced) / `M65`: digital output off.
    DigitalOff { synced: bool },
    /// `M66`: wait for an input.
    Wait,
    /// `M67` (synced) / `M68`: analog output.
    Analog { synced: bool },
}

impl IoCode {
    pub fn value(self) -> f64 {
        match self {
            IoCode::DigitalOn { synced: true } => 62.0,
            IoCode::DigitalOff { synced: true } => 63.0,
            IoCode::DigitalOn { synced: false } => 64.0,
            IoCode::DigitalOff { synced: false } => 65.0,
            IoCode::Wait => 66.0,
            IoCode::Analog { synced: true } => 67.0,
            IoCode::Analog { synced: false } => 68.0,
        }
    }
}

/// `M70`..`M73`: the modal state saved and restored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContextCode {
    /// `M70`: save.
    Save,
    /// `M71`: forget what `M70` saved.
    Invalidate,
    /// `M72`: restore what `M70` saved.
    Restore,
    /// `M73`: save, and restore when the subroutine returns.
    AutoRestore,
}

/// Program stops and ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopCode {
    /// `M00`.
    Stop,
    /// `M01`.
    Optional,
    /// `M06`.
    ToolChange,
    /// `M02` / `M30`.
    End,
}

/// A decoded code.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Code {
    Motion(Motion),
    /// `G04` dwell (non-modal).
    Dwell,
    /// `G28` return to the reference position (non-modal).
    Home,
    /// `G30` to the second reference position (non-modal).
    Home30,
    /// `G53` move in machine coordinates (non-modal).
    MachineCoords,
    /// `G92`, `G92.1`, `G92.2`, `G92.3` (non-modal).
    CoordOffset(G92),
    /// `G10`: set a work offset or a tool's length and radius (non-modal).
    SetTable,
    Plane(Plane),
    /// `G20` (true) / `G21`.
    Inch(bool),
    /// `G91` (true) / `G90`.
    Incremental(bool),
    /// `G93` (true) / `G94`.
    InverseTime(bool),
    /// `G95`: feed per spindle revolution.
    PerRev,
    /// `G40`.
    CompensationOff,
    /// `G41`/`G42` (`D`: a tool number, or none for the tool in the spindle) and
    /// `G41.1`/`G42.1` (`direct`: `D` is the diameter).
    RadiusComp {
        side: crate::comp::Side,
        direct: bool,
    },
    LengthComp(LengthComp),
    /// `G80`: no canned cycle; without another motion code on its line, no motion mode.
    CannedOff,
    /// `G54`..`G59`: index 0..=5.
    WorkOffset(u8),
    /// `G61` exact stop (false) / `G64` blending (true).
    Blend(bool),
    /// `G90.1` (true: arc centres `I J K` absolute) / `G91.1` (relative to the start).
    ArcCentreAbsolute(bool),
    /// `G99` (true: canned cycles retract to `R`) / `G98` (to the level they started from).
    Retract(bool),
    Stop(StopCode),
    Spindle(Spindle),
    Coolant(Coolant),
    /// `M62`..`M68`.
    Io(IoCode),
    /// A machine-defined M-code (the machine file's `[mcodes]`).
    User(u32),
    /// `M70`..`M73`.
    Context(ContextCode),
    /// `G08`: lathe radius mode, LinuxCNC's default (X words are radii); a mill has nothing
    /// to change. (`G07`, diameter mode, is refused.)
    LatheRadius,
}

/// Modal groups, as indices of [`super::line::Line`]'s code table.
pub const GROUPS: usize = 20;

impl Code {
    pub fn group(self) -> usize {
        match self {
            Code::Motion(_) => 0,
            Code::Dwell
            | Code::Home
            | Code::Home30
            | Code::MachineCoords
            | Code::CoordOffset(_)
            | Code::SetTable => 1,
            Code::Plane(_) => 2,
            Code::Inch(_) => 3,
            Code::Incremental(_) => 4,
            Code::InverseTime(_) | Code::PerRev => 5,
            Code::CompensationOff | Code::RadiusComp { .. } => 6,
            Code::LengthComp(_) => 7,
            Code::CannedOff => 8,
            Code::WorkOffset(_) => 9,
            Code::Blend(_) => 10,
            Code::Stop(_) => 11,
            Code::Spindle(_) => 12,
            Code::Coolant(_) => 13,
            Code::ArcCentreAbsolute(_) => 14,
            Code::Retract(_) => 15,
            Code::Io(_) => 16,
            Code::User(_) => 17,
            Code::Context(_) => 18,
            Code::LatheRadius => 19,
        }
    }
}

/// The G codes, by value. Exact comparisons are sound: `06.5` and `6.5` parse to the same
/// correctly-rounded f64.
const G_CODES: [(f64, Code); 60] = [
    (0.0, Code::Motion(Motion::G00)),
    (1.0, Code::Motion(Motion::G01)),
    (2.0, Code::Motion(Motion::G02)),
    (3.0, Code::Motion(Motion::G03)),
    (4.0, Code::Dwell),
    (5.0, Code::Motion(Motion::G05)),
    (8.0, Code::LatheRadius),
    (10.0, Code::SetTable),
    (5.1, Code::Motion(Motion::G051)),
    (5.2, Code::Motion(Motion::G052)),
    (5.3, Code::Motion(Motion::G053)),
    (6.2, Code::Motion(Motion::G062)),
    (6.5, Code::Motion(Motion::G065)),
    (17.0, Code::Plane(Plane::Xy)),
    (18.0, Code::Plane(Plane::Zx)),
    (19.0, Code::Plane(Plane::Yz)),
    (20.0, Code::Inch(true)),
    (21.0, Code::Inch(false)),
    (28.0, Code::Home),
    (30.0, Code::Home30),
    (40.0, Code::CompensationOff),
    (
        41.0,
        Code::RadiusComp {
            side: Side::Left,
            direct: false,
        },
    ),
    (
        41.1,
        Code::RadiusComp {
            side: Side::Left,
            direct: true,
        },
    ),
    (
        42.0,
        Code::RadiusComp {
            side: Side::Right,
            direct: false,
        },
    ),
    (
        42.1,
        Code::RadiusComp {
            side: Side::Right,
            direct: true,
        },
    ),
    (43.0, Code::LengthComp(LengthComp::Length)),
    (43.1, Code::LengthComp(LengthComp::Dynamic)),
    (43.2, Code::LengthComp(LengthComp::Added)),
    (43.4, Code::LengthComp(LengthComp::Rtcp)),
    (49.0, Code::LengthComp(LengthComp::Off)),
    (53.0, Code::MachineCoords),
    (54.0, Code::WorkOffset(0)),
    (55.0, Code::WorkOffset(1)),
    (56.0, Code::WorkOffset(2)),
    (57.0, Code::WorkOffset(3)),
    (58.0, Code::WorkOffset(4)),
    (59.0, Code::WorkOffset(5)),
    (61.0, Code::Blend(false)),
    (61.1, Code::Blend(false)),
    (64.0, Code::Blend(true)),
    (73.0, Code::Motion(Motion::Cycle(Cycle::G73))),
    (80.0, Code::CannedOff),
    (81.0, Code::Motion(Motion::Cycle(Cycle::G81))),
    (82.0, Code::Motion(Motion::Cycle(Cycle::G82))),
    (83.0, Code::Motion(Motion::Cycle(Cycle::G83))),
    (85.0, Code::Motion(Motion::Cycle(Cycle::G85))),
    (86.0, Code::Motion(Motion::Cycle(Cycle::G86))),
    (89.0, Code::Motion(Motion::Cycle(Cycle::G89))),
    (98.0, Code::Retract(false)),
    (99.0, Code::Retract(true)),
    (92.0, Code::CoordOffset(G92::Set)),
    (92.1, Code::CoordOffset(G92::Reset)),
    (92.2, Code::CoordOffset(G92::Suspend)),
    (92.3, Code::CoordOffset(G92::Restore)),
    (90.0, Code::Incremental(false)),
    (90.1, Code::ArcCentreAbsolute(true)),
    (91.0, Code::Incremental(true)),
    (91.1, Code::ArcCentreAbsolute(false)),
    (93.0, Code::InverseTime(true)),
    (95.0, Code::PerRev),
];

pub fn g_code(value: f64) -> Result<Code, ParseErrorKind> {
    if value == 94.0 {
        return Ok(Code::InverseTime(false));
    }
    if let Some((_, code)) = G_CODES.iter().find(|(v, _)| *v == value) {
        return Ok(*code);
    }
    Err(if value == 7.0 {
        ParseErrorKind::LatheDiameterMode
    } else if [38.2, 38.3, 38.4, 38.5].contains(&value) {
        ParseErrorKind::Probing { code: value }
    } else if [33.0, 33.1, 76.0].contains(&value) {
        ParseErrorKind::SpindleSynchronised { code: value }
    } else if (73.0..=89.0).contains(&value) && value.fract() == 0.0 {
        ParseErrorKind::CannedCycle { code: value }
    } else {
        ParseErrorKind::UnsupportedGCode { code: value }
    })
}

pub fn m_code(value: f64) -> Result<Code, ParseErrorKind> {
    const M_CODES: [(f64, Code); 22] = [
        (0.0, Code::Stop(StopCode::Stop)),
        (1.0, Code::Stop(StopCode::Optional)),
        (2.0, Code::Stop(StopCode::End)),
        (3.0, Code::Spindle(Spindle::Cw)),
        (4.0, Code::Spindle(Spindle::Ccw)),
        (5.0, Code::Spindle(Spindle::Off)),
        (6.0, Code::Stop(StopCode::ToolChange)),
        (7.0, Code::Coolant(Coolant::Mist)),
        (8.0, Code::Coolant(Coolant::Flood)),
        (9.0, Code::Coolant(Coolant::Off)),
        (30.0, Code::Stop(StopCode::End)),
        (62.0, Code::Io(IoCode::DigitalOn { synced: true })),
        (63.0, Code::Io(IoCode::DigitalOff { synced: true })),
        (64.0, Code::Io(IoCode::DigitalOn { synced: false })),
        (65.0, Code::Io(IoCode::DigitalOff { synced: false })),
        (66.0, Code::Io(IoCode::Wait)),
        (67.0, Code::Io(IoCode::Analog { synced: true })),
        (68.0, Code::Io(IoCode::Analog { synced: false })),
        (70.0, Code::Context(ContextCode::Save)),
        (71.0, Code::Context(ContextCode::Invalidate)),
        (72.0, Code::Context(ContextCode::Restore)),
        (73.0, Code::Context(ContextCode::AutoRestore)),
    ];
    M_CODES
        .iter()
        .find(|(v, _)| *v == value)
        .map(|(_, c)| *c)
        .ok_or(ParseErrorKind::UnsupportedMCode { code: value })
}
