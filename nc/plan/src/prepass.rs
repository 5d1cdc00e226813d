//! The pre-pass: a program checked from its first line to its last before anything moves,
//! in the memory of one line and one block, at the speed of the parser.
//!
//! It checks every rule of the language (the parser's, with every error up to
//! [`nc_lang::MAX_ERRORS`]), the geometry the builder checks (NURBS tool vectors,
//! rotary steps, angle words for the machine), and that the machine's axes at every
//! programmed point (the start pose and the end of every block, through the kinematics,
//! on the rotary branch the interpolator follows) lie within the travel. It does not plan:
//! the speeds, and the path between programmed points (a curve's bulge, an arc), are the
//! planner's to check, window by window, before the interpolator gets there.

use nc_geom::kinematics::{Joints, MachineKinematics, Tilt};
use nc_geom::program::SrcPos;
use nc_geom::segment::{BuildError, BuildLimits, Builder};
use nc_lang::{Entries, Entry, LineSource, ParseError, ParseErrors, Setup, MAX_ERRORS};

/// What a program that passed holds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Passed {
    /// Physical lines read.
    pub lines: u32,
    /// Motion blocks (the start pose among them) and the segments they build.
    pub blocks: usize,
    pub segments: usize,
    /// Sum of the segments' lengths (mm; degrees for moves that only turn the tool).
    pub length: f64,
    /// The joints at the program's end, on the rotary branch the interpolator follows.
    pub end_joints: Joints,
    /// The first move that waits for the operator (`M00`, `M01` taken, `M06`), if any.
    pub operator_stop: Option<SrcPos>,
}

/// Why a program fails the pre-pass.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Refused {
    /// Every parse error (up to `MAX_ERRORS`); the pass stops at the end of the file.
    #[error("{}", .0.errors.iter().map(ToString::to_string).collect::<Vec<_>>().join("\n"))]
    Parse(ParseErrors),
    #[error(transparent)]
    Build(BuildError),
    #[error("{pos}: the programmed point puts the {axis} axis at {value:.4} {unit}, outside its travel {min} .. {max} {unit}")]
    Travel {
        pos: SrcPos,
        axis: char,
        unit: &'static str,
        value: f64,
        min: f64,
        max: f64,
    },
}

impl Refused {
    /// Where the (first) reason stands.
    pub fn pos(&self) -> SrcPos {
        match self {
            Refused::Parse(e) => e.first().map_or(SrcPos::default(), |e| e.pos),
            Refused::Build(e) => e.pos,
            Refused::Travel { pos, .. } => *pos,
        }
    }
}

/// Relative slack on the travel, as the setpoint check allows (`crate::verify`).
const SLACK: f64 = 1e-9;

/// The first axis of `q` outside `travel` (mm, radians), as a refusal at `pos`.
fn outside(
    q: &Joints,
    travel: &[(f64, f64); 5],
    kin: &MachineKinematics,
    pos: SrcPos,
) -> Option<Refused> {
    (0..5).find_map(|j| {
        let (lo, hi) = travel[j];
        let inside =
            q[j] >= lo - SLACK * lo.abs().max(1.0) && q[j] <= hi + SLACK * hi.abs().max(1.0);
        if inside {
            return None;
        }
        let (axis, unit, k) = match (j, kin.tilt_kind()) {
            (0..=2, _) => (['X', 'Y', 'Z'][j], "mm", 1.0),
            (3, Tilt::A) => ('A', "deg", 1f64.to_degrees()),
            (3, Tilt::B) => ('B', "deg", 1f64.to_degrees()),
            _ => ('C', "deg", 1f64.to_degrees()),
        };
        Some(Refused::Travel {
            pos,
            axis,
            unit,
            value: q[j] * k,
            min: lo * k,
            max: hi * k,
        })
    })
}

/// Checks the program from `lines` (see the module's text).
pub fn check<S: LineSource>(
    lines: S,
    setup: &Setup,
    kin: &MachineKinematics,
    limits: &BuildLimits,
    travel: &[(f64, f64); 5],
) -> Result<Passed, Refused> {
    let mut entries = Entries::new(lines, setup);
    let mut builder = Builder::new(kin, limits);
    let mut errors: Vec<ParseError> = Vec::new();
    // The first build or travel refusal; parse errors found later still come first.
    let mut refused: Option<Refused> = None;
    let mut passed = Passed::default();
    let mut segments = Vec::new();
    let mut tilt_checked = false;
    while let Some(entry) = entries.next() {
        let entry = match entry {
            Ok(entry) => entry,
            Err(e) => {
                errors.push(e);
                if errors.len() >= MAX_ERRORS {
                    let more = !entries.is_finished();
                    return Err(Refused::Parse(ParseErrors { errors, more }));
                }
                continue;
            }
        };
        if refused.is_some() || !errors.is_empty() {
            // Past the first error only the syntax is checked.
            continue;
        }
        if !tilt_checked {
            if let Some(word) = entries.tilt_word() {
                tilt_checked = true;
                if let Err(e) = builder.tilt_word(Some(word)) {
                    refused = Some(Refused::Build(e));
                    continue;
                }
            }
        }
        match entry {
            Entry::Action(a) => builder.action(&a),
            Entry::Block(i, block) => {
                segments.clear();
                if let Err(e) = builder.block(i, &block, &mut segments) {
                    refused = Some(Refused::Build(e));
                    continue;
                }
                passed.blocks += 1;
                passed.segments += segments.len();
                passed.length += segments.iter().map(|s| s.length).sum::<f64>();
                if passed.operator_stop.is_none() {
                    passed.operator_stop = segments.iter().find_map(|s| s.wait.operator);
                }
                refused = outside(&builder.joints(), travel, kin, block.pos());
            }
        }
    }
    if !errors.is_empty() {
        return Err(Refused::Parse(ParseErrors {
            errors,
            more: false,
        }));
    }
    if let Some(r) = refused {
        return Err(r);
    }
    let (_, start_src, start_joints) = builder.start().map_err(Refused::Build)?;
    if let Some(r) = outside(&start_joints, travel, kin, start_src) {
        return Err(r);
    }
    passed.lines = entries.eof().line;
    passed.end_joints = builder.joints();
    Ok(passed)
}
