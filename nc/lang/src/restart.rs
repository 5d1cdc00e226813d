//! Run from a line (issue 55): the program as it goes on from line N, with the state the
//! lines before N left and an approach from where the machine stands.
//!
//! The whole program is read as for a run (its parameters, loops, offsets, units and tool
//! lengths are resolved then), so a block after line N is exactly the block a run from the
//! start would have executed. What the lines before N did without moving, the spindle, the
//! coolant, the digital and analog outputs, the path mode and the tool, is folded into a
//! [`Modal`] and restored before the tool comes down; their stops, dwells and input waits
//! are skipped. The tool then approaches the pose where line N's first move starts by a
//! path the operator confirms, as on the big controls:
//!
//! 1. from where it stands, straight back along its own axis by the clearance (rapid);
//! 2. over to the clearance point above the restart pose, turning to its tool axis (rapid);
//!    the restored spindle and coolant come on before this move;
//! 3. down along that axis onto the restart pose, at the feed in effect there (rapid if
//!    line N's move is itself rapid).
//!
//! Refused, with the reason, where a restart is not one point of the program: a line
//! inside a NURBS block's control points (restart from its opening line), a line run in a
//! loop's second pass or inside a subroutine (the line does not say which pass; LinuxCNC
//! too refuses a restart inside a subroutine), a line after the last move. A canned
//! cycle's moves all stand on its line, and are one point.

use nalgebra::Vector3;
use nc_geom::kinematics::{Joints, Kinematics, MachineKinematics};
use nc_geom::program::{
    Action, ActionKind, Aux, Block, Coolant, LinearMove, MoveTooling, Orientation, PathMode,
    Program, Spindle, SrcPos, Wait,
};
use nc_geom::segment::{BuildError, BuildLimits, Builder};
use std::collections::BTreeMap;

/// The longest clearance an approach takes, mm.
pub const MAX_CLEARANCE_MM: f64 = 1000.0;

/// Where the machine stands when the restart is asked: its joints (machine X Y Z in mm,
/// the tilt and C in radians) and the tool length its Z carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Standing {
    pub joints: Joints,
    pub tool_length: f64,
}

impl Standing {
    /// The tool tip where the machine stands, in the workpiece frame (mm), and its rotary
    /// angles as a move gives them.
    pub fn tip(&self, kin: &MachineKinematics) -> ([f64; 3], Orientation) {
        let j = &self.joints;
        let machine = Vector3::new(j[0], j[1], j[2] - self.tool_length);
        (kin.unplace(&machine, j[3], j[4]).into(), angles(j))
    }

    /// A program's start block where the machine stands: a rapid of no length to its tool
    /// tip, at its angles, with its tool length and `tooling`'s mode, waiting for nothing.
    pub fn start(
        &self,
        kin: &MachineKinematics,
        pos: SrcPos,
        n: Option<u32>,
        tooling: MoveTooling,
    ) -> Block {
        let (end, orientation) = self.tip(kin);
        Block::Linear(LinearMove {
            pos,
            n,
            rapid: true,
            end,
            orientation,
            feed_mm_min: 0.0,
            inverse_time: false,
            tooling: MoveTooling {
                tool_length: self.tool_length,
                wait: Wait::default(),
                ..tooling
            },
        })
    }
}

/// What the lines before the restart line left, besides the pose.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Modal {
    /// Spindle, coolant and digital outputs (`M03`..`M09`, `M62`..`M65`).
    pub aux: Aux,
    /// The digital outputs the lines before set at all (on or off).
    pub outputs_set: u64,
    /// The last value of each analog output the lines before set (`M67`/`M68`).
    pub analog: BTreeMap<u8, f64>,
    /// The path mode (`G61`, `G64`), if the lines before set one.
    pub path_mode: Option<PathMode>,
    /// The tool the last `M06` loaded, and the tool `T` last selected.
    pub tool: Option<u32>,
    pub selected: Option<u32>,
}

/// A program restarted from a line.
#[derive(Clone, Debug, PartialEq)]
pub struct Restart {
    /// The line asked for, and the line the restart starts on: the first at or after it
    /// with a move.
    pub asked: u32,
    pub line: u32,
    /// Index of the first block kept, in the whole program's blocks.
    pub block: usize,
    pub modal: Modal,
    /// The approach, in the workpiece frame: above where the tool stands, above the
    /// restart pose, and the restart pose itself.
    pub approach: [[f64; 3]; 3],
    /// The program to run: a start where the machine stands, the three approach moves,
    /// then the program from the restart line on.
    pub program: Program,
}

/// Why a program cannot be restarted from a line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RestartError {
    #[error("line {line}: no move at or after it (the last move is on line {last})")]
    PastTheEnd { line: u32, last: u32 },
    #[error("line {line} is a control point of the NURBS block opened on line {opened}: restart from line {opened}")]
    InsideNurbs { line: u32, opened: u32 },
    #[error("line {line} runs in a loop or a subroutine (it does not say which pass): restart from a line outside it")]
    Repeated { line: u32 },
    #[error("clearance = {value} mm: must be more than 0 and at most {MAX_CLEARANCE_MM} mm")]
    Clearance { value: f64 },
    #[error("the program has no moves")]
    NoMoves,
    #[error("the machine's position is not known (joints {joints:?}, tool length {tool_length}): home it first")]
    Standing { joints: Joints, tool_length: f64 },
    /// The program up to the restart line does not build for this machine.
    #[error(transparent)]
    Build(#[from] BuildError),
}

/// The program restarted from line `line` on the machine `kin`, its tool approaching from
/// `standing` by `clearance_mm` along the tool axis.
pub fn from_line(
    program: &Program,
    line: u32,
    kin: &MachineKinematics,
    limits: &BuildLimits,
    standing: &Standing,
    clearance_mm: f64,
) -> Result<Restart, RestartError> {
    if !(clearance_mm > 0.0 && clearance_mm <= MAX_CLEARANCE_MM) {
        return Err(RestartError::Clearance {
            value: clearance_mm,
        });
    }
    if !(standing.joints.iter().all(|x| x.is_finite()) && standing.tool_length.is_finite()) {
        return Err(RestartError::Standing {
            joints: standing.joints,
            tool_length: standing.tool_length,
        });
    }
    let blocks = &program.blocks;
    for b in blocks {
        if let Block::Nurbs(n) = b {
            if n.pos.line != line && n.ctrl_pos.iter().any(|p| p.line == line) {
                return Err(RestartError::InsideNurbs {
                    line,
                    opened: n.pos.line,
                });
            }
        }
    }
    let last = blocks
        .iter()
        .map(|b| b.pos().line)
        .max()
        .ok_or(RestartError::NoMoves)?;
    let at = blocks
        .iter()
        .map(|b| b.pos().line)
        .filter(|&l| l >= line)
        .min()
        .ok_or(RestartError::PastTheEnd { line, last })?;
    if program.rerun.iter().any(|&(a, b)| a <= at && at <= b) {
        return Err(RestartError::Repeated { line: at });
    }
    let m = blocks.iter().position(|b| b.pos().line == at).unwrap_or(0);
    // Block 0 is the program's start pose: a restart on it comes down onto that pose.
    let first = m.max(1);
    // The joints where the block before the restart ends, as a run from the start has
    // them (the turns C made included), and the cutter point and tool axis there.
    let to = joints_before(program, first, kin, limits)?;
    let length = tooling_of(&blocks[first - 1]).tool_length;
    let target = kin.unplace(&Vector3::new(to[0], to[1], to[2] - length), to[3], to[4]);
    let target_axis = kin.tool_axis(to[3], to[4]);
    let target_angles = angles(&to);
    let feed = feed_in_effect(blocks, first);

    // The actions: before the restart, folded; from it on, kept.
    let before = |a: &Action| a.before_block < m || (a.before_block == m && a.pos.line < line);
    let folded: Vec<&Action> = program.actions.iter().filter(|a| before(a)).collect();
    let mut modal = Modal::default();
    for a in &folded {
        fold(&mut modal, &a.kind);
    }
    // Each restored word where the program last set it.
    let mut actions: Vec<Action> = restored(&modal)
        .into_iter()
        .map(|kind| Action {
            pos: set_at(&folded, &kind).unwrap_or(blocks[m].pos()),
            before_block: 2,
            kind,
        })
        .collect();
    let kept: Vec<Action> = program
        .actions
        .iter()
        .filter(|a| !before(a))
        .copied()
        .collect();
    // What waits before the first kept block now waits before the move over (step 2).
    let wait = waits(kept.iter().filter(|a| a.before_block <= first));
    for a in kept {
        let before_block = if a.before_block <= first {
            2
        } else {
            a.before_block - first + 4
        };
        actions.push(Action { before_block, ..a });
    }

    // The approach.
    let j = &standing.joints;
    let (here, here_angles) = standing.tip(kin);
    let here = Vector3::from(here);
    let up = here + kin.tool_axis(j[3], j[4]) * clearance_mm;
    let above = target + target_axis * clearance_mm;
    let pos = blocks[m].pos();
    let n = match &blocks[m] {
        Block::Linear(l) => l.n,
        Block::Nurbs(b) => b.n,
    };
    // The tool length and mode of the block before: the first kept block changes them
    // as it does in a whole run.
    let tooling = MoveTooling {
        wait: Wait::default(),
        ..tooling_of(&blocks[first - 1])
    };
    let step = |end: Vector3<f64>, orientation, rapid, wait| {
        Block::Linear(LinearMove {
            pos,
            n,
            rapid,
            end: end.into(),
            orientation,
            feed_mm_min: if rapid { 0.0 } else { feed.unwrap_or(0.0) },
            inverse_time: false,
            tooling: MoveTooling { wait, ..tooling },
        })
    };
    let start = standing.start(kin, pos, n, tooling);
    let plunge_rapid =
        feed.is_none() || matches!(blocks.get(first), Some(Block::Linear(l)) if l.rapid);
    let mut out = vec![
        start,
        step(up, here_angles, true, Wait::default()),
        step(above, target_angles, true, wait),
        step(target, target_angles, plunge_rapid, Wait::default()),
    ];
    out.extend(
        blocks[first..]
            .iter()
            .cloned()
            .enumerate()
            .map(|(i, mut b)| {
                if i == 0 {
                    set_wait(&mut b, Wait::default());
                }
                b
            }),
    );
    Ok(Restart {
        asked: line,
        line: at,
        block: m,
        modal,
        approach: [up.into(), above.into(), target.into()],
        program: Program {
            blocks: out,
            end: program.end,
            actions,
            tilt_word: program.tilt_word,
            rerun: Vec::new(),
        },
    })
}

/// The joints at the end of block `first - 1`: the program built up to there.
fn joints_before(
    program: &Program,
    first: usize,
    kin: &MachineKinematics,
    limits: &BuildLimits,
) -> Result<Joints, BuildError> {
    let mut builder = Builder::new(kin, limits);
    builder.tilt_word(program.tilt_word)?;
    let mut actions = program.actions.iter().peekable();
    let mut segments = Vec::new();
    for (i, block) in program.blocks[..first].iter().enumerate() {
        while let Some(a) = actions.next_if(|a| a.before_block <= i) {
            builder.action(a);
        }
        builder.block(i, block, &mut segments)?;
        segments.clear();
    }
    Ok(builder.joints())
}

/// The machine's own rotary angles of `j`, as a move gives them (`A_ C_`, degrees).
fn angles(j: &Joints) -> Orientation {
    Orientation::Angles {
        r1_deg: j[3].to_degrees(),
        r2_deg: j[4].to_degrees(),
    }
}

/// The feed of the last feed move before block `i` or of block `i` itself (mm/min).
fn feed_in_effect(blocks: &[Block], i: usize) -> Option<f64> {
    blocks[..=i.min(blocks.len() - 1)]
        .iter()
        .rev()
        .find_map(|b| match b {
            Block::Linear(l) if !l.rapid => Some(l.feed_mm_min),
            Block::Linear(_) => None,
            Block::Nurbs(n) => Some(n.feed_mm_min),
        })
}

fn tooling_of(b: &Block) -> MoveTooling {
    match b {
        Block::Linear(l) => l.tooling,
        Block::Nurbs(n) => n.tooling,
    }
}

fn set_wait(b: &mut Block, wait: Wait) {
    match b {
        Block::Linear(l) => l.tooling.wait = wait,
        Block::Nurbs(n) => n.tooling.wait = wait,
    }
}

fn fold(m: &mut Modal, kind: &ActionKind) {
    m.aux.apply(kind);
    match *kind {
        ActionKind::DigitalOutput { index, .. } => {
            m.outputs_set |= 1u64.checked_shl(u32::from(index)).unwrap_or(0);
        }
        ActionKind::AnalogOutput { index, value, .. } => {
            m.analog.insert(index, value);
        }
        ActionKind::PathMode(mode) => m.path_mode = Some(mode),
        ActionKind::SelectTool { tool } => m.selected = Some(tool),
        ActionKind::ChangeTool { tool } => m.tool = tool.or(m.selected),
        _ => {}
    }
}

/// The actions that restore `m`: the spindle, the coolant, every output the lines before
/// set, and the path mode.
fn restored(m: &Modal) -> Vec<ActionKind> {
    let mut out = Vec::new();
    if let Some(mode) = m.path_mode {
        out.push(ActionKind::PathMode(mode));
    }
    for index in 0..64u8 {
        if m.outputs_set & (1u64 << index) != 0 {
            out.push(ActionKind::DigitalOutput {
                index,
                on: m.aux.outputs & (1u64 << index) != 0,
                synced: false,
            });
        }
    }
    for (&index, &value) in &m.analog {
        out.push(ActionKind::AnalogOutput {
            index,
            value,
            synced: false,
        });
    }
    if m.aux.spindle_rpm != 0.0 {
        let dir = if m.aux.spindle_rpm > 0.0 {
            Spindle::Cw
        } else {
            Spindle::Ccw
        };
        out.push(ActionKind::Spindle {
            dir,
            rpm: m.aux.spindle_rpm.abs(),
        });
    }
    if m.aux.mist {
        out.push(ActionKind::Coolant(Coolant::Mist));
    }
    if m.aux.flood {
        out.push(ActionKind::Coolant(Coolant::Flood));
    }
    out
}

/// Where the last of `folded` that set what `kind` restores stands.
fn set_at(folded: &[&Action], kind: &ActionKind) -> Option<SrcPos> {
    use ActionKind as K;
    let sets = |a: &ActionKind| match (kind, a) {
        (K::PathMode(_), K::PathMode(_)) => true,
        (K::DigitalOutput { index: i, .. }, K::DigitalOutput { index: j, .. }) => i == j,
        (K::AnalogOutput { index: i, .. }, K::AnalogOutput { index: j, .. }) => i == j,
        (K::Spindle { .. }, K::Spindle { .. } | K::Speed { .. }) => true,
        (K::Coolant(c), K::Coolant(d)) => c == d,
        _ => false,
    };
    folded.iter().rev().find(|a| sets(&a.kind)).map(|a| a.pos)
}

/// The wait the kept actions ask before a move, as the parser sets it: their dwells
/// summed, the first word that waits for the operator.
fn waits<'a>(actions: impl Iterator<Item = &'a Action>) -> Wait {
    let mut wait = Wait::default();
    for a in actions {
        match a.kind {
            ActionKind::Dwell { seconds } => wait.dwell_s += seconds,
            ActionKind::Stop
            | ActionKind::OptionalStop { taken: true }
            | ActionKind::ChangeTool { .. }
            | ActionKind::UserM {
                action: nc_geom::program::UserAction::Stop,
                ..
            } => {
                wait.operator.get_or_insert(a.pos);
            }
            _ => {}
        }
    }
    wait
}

#[cfg(test)]
mod tests;
