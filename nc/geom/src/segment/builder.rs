//! [`Builder`]: blocks in, segments out, one block at a time, holding only the pose and the
//! modal state between them; [`super::build`] runs it over a whole program, a streaming
//! planner over the blocks as they are read.

use super::curve::nurbs;
use super::straight::{linear, linear_tool};
use super::vertical::{c_leaving_vertical, follow, turn_c};
use super::{BuildError, BuildErrorKind, BuildLimits, Pose, Segment};
use crate::kinematics::{Joints, MachineKinematics, Tilt};
use crate::program::{
    Action, ActionKind, Aux, Block, Input, InputWait, LengthMode, SrcPos, Wait, WaitMode,
    MAX_INPUT_WAITS,
};
use nalgebra::Vector3;

/// The segments of a program's blocks, given in order with the actions between them.
pub struct Builder<'k> {
    kin: &'k MachineKinematics,
    limits: &'k BuildLimits,
    /// The start pose, where it was programmed and its joints (C chosen where the path
    /// first leaves a vertical tool); `None` before the first block.
    start: Option<(Pose, SrcPos, Joints)>,
    /// Where the last segment ends, and the joints the interpolator arrives with there.
    pose: Pose,
    joints: Joints,
    /// Whether any segment was built yet (until then the start's C is still free).
    moved: bool,
    /// A wait before a block that moves nothing goes to the next segment.
    wait: Wait,
    /// Spindle and coolant: the words up to each block apply along it; the first feed move
    /// after the spindle is started or changes speed waits for it to be at speed.
    aux: Aux,
    spindle_wait: bool,
    /// `M66` waits before the next block, for its first segment.
    inputs: [Option<InputWait>; MAX_INPUT_WAITS],
    /// An `M66` beyond [`crate::program::MAX_INPUT_WAITS`] before the next move: refused there.
    too_many_waits: Option<SrcPos>,
}

impl<'k> Builder<'k> {
    pub fn new(kin: &'k MachineKinematics, limits: &'k BuildLimits) -> Self {
        Builder {
            kin,
            limits,
            start: None,
            pose: Pose {
                p: Vector3::zeros(),
                tool: super::Tool::Axis(Vector3::z()),
                u: None,
                z: 0.0,
            },
            joints: [0.0; 5],
            moved: false,
            wait: Wait::default(),
            aux: Aux::default(),
            spindle_wait: false,
            inputs: [None; MAX_INPUT_WAITS],
            too_many_waits: None,
        }
    }

    /// The program's angle words must name the machine's tilting axis.
    pub fn tilt_word(&self, word: Option<(char, SrcPos)>) -> Result<(), BuildError> {
        let machine = match self.kin.tilt_kind() {
            Tilt::A => 'A',
            Tilt::B => 'B',
        };
        match word {
            Some((word, pos)) if word != machine => Err(BuildError {
                pos,
                kind: BuildErrorKind::WrongTilt { word, machine },
            }),
            _ => Ok(()),
        }
    }

    /// An action (spindle, coolant, outputs, an input wait) before the next block.
    pub fn action(&mut self, a: &Action) {
        let aux = &mut self.aux;
        self.spindle_wait = aux.apply(&a.kind) || (self.spindle_wait && aux.spindle_rpm != 0.0);
        if let ActionKind::WaitInput {
            input: Input::Digital(input),
            mode,
            timeout_s,
        } = a.kind
        {
            if mode != WaitMode::Immediate {
                let wait = InputWait {
                    input,
                    mode,
                    timeout_s,
                    pos: a.pos,
                };
                match self.inputs.iter_mut().find(|w| w.is_none()) {
                    Some(slot) => *slot = Some(wait),
                    None => {
                        self.too_many_waits.get_or_insert(a.pos);
                    }
                }
            }
        }
    }

    /// The start pose, where it was programmed and its joints: final once a segment is
    /// built or the program ends.
    pub fn start(&self) -> Result<(Pose, SrcPos, Joints), BuildError> {
        self.start.ok_or(BuildError {
            pos: SrcPos::default(),
            kind: BuildErrorKind::NoStart,
        })
    }

    /// The joints where the last block ends (the start pose's before any other block).
    pub fn joints(&self) -> Joints {
        self.joints
    }

    /// Block `i` of the program (from 0): its segments are appended to `out` (none for the
    /// start pose, block 0, and for a move that moves nothing).
    pub fn block(
        &mut self,
        i: usize,
        block: &Block,
        out: &mut Vec<Segment>,
    ) -> Result<(), BuildError> {
        let err = |pos, kind| BuildError { pos, kind };
        if let Some(pos) = self.too_many_waits.take() {
            return Err(err(pos, BuildErrorKind::TooManyInputWaits));
        }
        let (kin, limits) = (self.kin, self.limits);
        let lim = &limits.rotary;
        if self.start.is_none() {
            let first = match block {
                Block::Nurbs(b) => return Err(err(b.pos, BuildErrorKind::NurbsFirst)),
                Block::Linear(m) => m,
            };
            self.pose = Pose {
                p: Vector3::from(first.end),
                tool: linear_tool(first),
                u: None,
                z: first.tooling.tool_length,
            };
            self.joints = self.pose.joints(kin, &[0.0; 5], lim);
            self.start = Some((self.pose, first.pos, self.joints));
            return Ok(());
        }
        let index = u32::try_from(i + 1).unwrap_or(u32::MAX);
        let (tooling, pos) = match block {
            Block::Linear(m) => (m.tooling, m.pos),
            Block::Nurbs(b) => (b.tooling, b.pos),
        };
        if tooling.mode == LengthMode::Rtcp && *kin == MachineKinematics::Paper {
            return Err(err(pos, BuildErrorKind::RtcpUnsupported));
        }
        self.wait = merge(self.wait, tooling.wait);
        let segs: Vec<Segment> = match block {
            Block::Linear(m) => linear(index, m, &self.pose, &self.joints, kin, limits)?
                .into_iter()
                .collect(),
            Block::Nurbs(b) => {
                if b.tooling.tool_length != self.pose.z {
                    let kind = BuildErrorKind::LengthChangeOnCurve {
                        from: self.pose.z,
                        to: b.tooling.tool_length,
                    };
                    return Err(err(b.pos, kind));
                }
                nurbs(index, b, &self.pose, &self.joints, kin, limits)?
            }
        };
        let mut first = true;
        for mut seg in segs {
            if core::mem::take(&mut first) {
                seg.wait = core::mem::take(&mut self.wait);
                seg.inputs = core::mem::take(&mut self.inputs);
                seg.stop |= seg.waits();
            }
            seg.aux = self.aux;
            if self.spindle_wait && !seg.rapid {
                seg.wait.spindle = true;
                seg.stop = true;
                self.spindle_wait = false;
            }
            // With a vertical tool C is free: choose it where the path leaves the vertical.
            if let Some(c) = c_leaving_vertical(&seg, kin, &self.joints, lim) {
                if !self.moved {
                    if let Some(start) = &mut self.start {
                        start.2[4] = c;
                    }
                    self.joints[4] = c;
                } else if (c - self.joints[4]).abs() > 1e-9 {
                    out.push(turn_c(&seg, &self.joints, c, self.limits));
                    self.joints[4] = c;
                    // The turn waits where the segment would have: not a second time.
                    seg.wait = Wait::default();
                    seg.inputs = [None; MAX_INPUT_WAITS];
                }
            }
            // The joints at the end are those the interpolator arrives with: follow the
            // segment, so the next block starts from the rotary branch the path really took.
            let at_start = self.joints;
            self.joints = follow(&seg, kin, &self.joints, lim);
            if tooling.mode == LengthMode::Length && matches!(kin, MachineKinematics::Trt { .. }) {
                let turned = |j: &Joints| j[3].abs() > 1e-9 || j[4].abs() > 1e-9;
                let bad = [at_start, self.joints].into_iter().find(turned);
                if let Some(j) = bad {
                    let kind = BuildErrorKind::RotaryWithoutRtcp {
                        tilt_deg: j[3].to_degrees(),
                        c_deg: j[4].to_degrees(),
                    };
                    return Err(err(seg.src, kind));
                }
            }
            self.pose = seg.pose(seg.length);
            self.moved = true;
            out.push(seg);
        }
        Ok(())
    }
}

/// Two waits in a row: the dwells add up, the first operator stop counts.
fn merge(a: Wait, b: Wait) -> Wait {
    Wait {
        dwell_s: a.dwell_s + b.dwell_s,
        operator: a.operator.or(b.operator),
        spindle: a.spindle || b.spindle,
    }
}
