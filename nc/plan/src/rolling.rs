//! [`Rolling`]: the [`Interpolator`] over a plan that arrives a piece at a time, holding only
//! the stretch it stands on. It is a [`Sink`] for the streaming [`crate::plan::Planner`]:
//! the planner's final phases and segments collect in a window, [`Rolling::run`] steps the
//! interpolator as far as they reach, and the window then lets go of what lies behind it.
//! The setpoints are those of the interpolator over the whole path and plan, to the bit
//! (the same code, resumed at its own [`Mark`] over a window whose indices moved with the
//! dropped front), so `simulate` needs no memory for the program however long it is.
//!
//! How far the data reach: a step needs the phase that holds its time (and the next one's
//! start), and the path a period's travel past the end of the segment the interpolator
//! stands on (a Taylor method drifts from the plan's s(t), so its own segment is the
//! measure, not the plan's). Until the plan is finished, the interpolator stops short of
//! either end and waits for more; a step that runs off the path held all the same (a
//! Taylor step on a curve whose parameter speed jumps) is taken back, never given.

use crate::interp::{Interpolator, Mark, Method};
use crate::plan::{Finished, ProgramError, Sink};
use crate::profile::FeedProfile;
use crate::stream::{ProgramSource, Stages, StreamError};
use crate::verify::MAX_CYCLES;
use nc_geom::kinematics::{MachineKinematics, RotaryLimits};
use nc_geom::limits::Margins;
use nc_geom::scurve::Phase;
use nc_geom::segment::{Path, Pose, Segment, Tool};
use nc_geom::setpoint::Setpoint;

/// Dropped entries are let go of in batches at least this long (and at least half of what
/// is held), so that moving the rest down costs O(1) an entry.
const TRIM_AT: usize = 1024;

/// What a setpoint's consumer may read of the path: the segments held, from the one the
/// setpoint lies on (or an earlier one) to the newest arrived.
#[derive(Clone, Copy, Debug)]
pub struct Window<'w> {
    pub segments: &'w [Segment],
    /// Index in the whole path of `segments[0]`.
    pub first: usize,
}

/// The interpolator's machine and method.
#[derive(Clone, Copy, Debug)]
pub struct Stepping {
    pub kin: MachineKinematics,
    pub lim: RotaryLimits,
    pub method: Method,
    pub period: f64,
    /// See [`Interpolator::new`].
    pub creep: f64,
    /// No planned speed is above it (path units/s; `nc_geom::segment::BuildLimits::speed_cap`).
    pub speed_cap: f64,
}

/// See the module's text.
pub struct Rolling {
    step: Stepping,
    /// The segments held (from `first` on) and the phases held; `seg_start` is absolute.
    path: Path,
    profile: FeedProfile,
    first: usize,
    mark: Option<Mark>,
    /// The plan is whole: every segment and phase has arrived.
    finished: bool,
    done: bool,
    most_held: usize,
}

impl Rolling {
    pub fn new(step: Stepping) -> Self {
        Rolling {
            step,
            path: Path {
                // Until [`Rolling::start_at`] says where the program starts.
                start: Pose {
                    p: nalgebra::Vector3::zeros(),
                    tool: Tool::Axis(nalgebra::Vector3::z()),
                    u: None,
                    z: 0.0,
                },
                start_src: Default::default(),
                start_joints: [0.0; 5],
                segments: Vec::new(),
            },
            profile: FeedProfile {
                phases: Vec::new(),
                seg_start: vec![0.0],
                // Unknown until the plan is finished: nothing clamps the plan's s(t) or
                // ends it before then.
                length: f64::INFINITY,
                duration: f64::INFINITY,
                margins: Margins::default(),
            },
            first: 0,
            mark: None,
            finished: false,
            done: false,
            most_held: 0,
        }
    }

    /// Where the program starts (before the first [`Rolling::run`]).
    pub fn start_at(&mut self, pose: Pose, joints: nc_geom::kinematics::Joints) {
        self.path.start = pose;
        self.path.start_joints = joints;
    }

    /// Every segment and phase has arrived; the plan came to `end`.
    pub fn finish(&mut self, end: &Finished) {
        self.finished = true;
        self.profile.length = end.length;
        self.profile.duration = end.duration;
        self.profile.margins = end.margins;
    }

    /// The last setpoint has been given.
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// The most segments held at once so far.
    pub fn most_held(&self) -> usize {
        self.most_held
    }

    /// The program's last segment, once the plan is finished (what the end is measured by).
    pub fn last_segment(&self) -> Option<&Segment> {
        self.path.segments.last().filter(|_| self.finished)
    }

    /// Step the interpolator as far as the data reach (to the end once the plan is
    /// finished), each setpoint to `take` with the path around it. A run longer than
    /// [`MAX_CYCLES`] is an error, not a truncated result.
    pub fn run(&mut self, mut take: impl FnMut(&Setpoint, Window)) -> Result<(), ProgramError> {
        if self.done {
            return Ok(());
        }
        let s = self.step;
        let mut ip = Interpolator::new(
            &self.path,
            &self.profile,
            s.kin,
            s.lim,
            s.method,
            s.period,
            s.creep,
        );
        if let Some(m) = &self.mark {
            ip.resume(m);
        }
        let window = Window {
            segments: &self.path.segments,
            first: self.first,
        };
        let mut stepped = self.mark.is_some();
        while self.finished || ready(&self.profile, &self.path, &ip.mark(), &s) {
            let before = ip.mark();
            let sp = ip.step();
            if sp.done && !self.finished {
                // A Taylor step carried past the last segment held (on a curve a step's
                // overshoot scales with the parameter speed): that is not the program's
                // end. Take the step back and wait for more of the path.
                ip.resume(&before);
                break;
            }
            stepped = true;
            take(&sp, window);
            if sp.done || self.path.segments.is_empty() {
                self.done = true;
                break;
            }
            if sp.cycle >= MAX_CYCLES {
                return Err(ProgramError::Unfinished(MAX_CYCLES));
            }
        }
        // A fresh interpolator over no segments yet says it is done: no mark until a step.
        if stepped {
            self.mark = Some(ip.mark());
            self.trim();
        }
        Ok(())
    }

    /// Let go of the segments and phases before the ones the interpolator stands on.
    fn trim(&mut self) {
        let Some(mark) = &mut self.mark else {
            return;
        };
        let (seg, ph) = (mark.segment(), mark.phase());
        let segs = seg >= TRIM_AT && 2 * seg >= self.path.segments.len();
        let phases = ph >= TRIM_AT && 2 * ph >= self.profile.phases.len();
        if !segs && !phases {
            return;
        }
        let (seg, ph) = (if segs { seg } else { 0 }, if phases { ph } else { 0 });
        self.path.segments.drain(..seg);
        self.profile.seg_start.drain(..seg);
        self.profile.phases.drain(..ph);
        self.first += seg;
        mark.rebase(seg, ph);
    }
}

/// Whether the next step's data have all arrived: the phase that holds its time, and the
/// one after it (the whole plan's walk moves on to a phase once its start is reached), and
/// the path a period's travel (twice over) past the end of the segment the interpolator
/// stands on. A step that still runs off the path held is taken back ([`Rolling::run`]).
fn ready(profile: &FeedProfile, path: &Path, mark: &Mark, s: &Stepping) -> bool {
    let t = mark.next_cycle() as f64 * s.period;
    let in_time = profile.phases.last().is_some_and(|p| t < p.t0);
    let seg = mark.segment();
    let (Some(&end), Some(&seg_end)) = (profile.seg_start.last(), profile.seg_start.get(seg + 1))
    else {
        return false;
    };
    let reach = 2.0 * s.speed_cap * (1.0 + 1e-6) * s.period + 1e-9 * end.abs().max(1.0);
    in_time && seg_end + reach < end && seg + 1 < path.segments.len()
}

impl Sink for Rolling {
    fn segment(&mut self, seg: Segment) {
        let s0 = self.profile.seg_start.last().copied().unwrap_or(0.0);
        self.profile.seg_start.push(s0 + seg.length);
        self.path.segments.push(seg);
        self.most_held = self.most_held.max(self.path.segments.len());
    }

    fn phases(&mut self, phases: &[Phase]) {
        self.profile.phases.extend_from_slice(phases);
    }
}

/// Why a streamed interpolation stopped short of the program's end.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Unrolled {
    /// The program was refused where it was read, built or planned.
    #[error(transparent)]
    Stream(#[from] StreamError),
    /// See [`ProgramError::Unfinished`].
    #[error("the interpolation did not reach the program's end within {0} periods")]
    Unfinished(u64),
}

impl From<ProgramError> for Unrolled {
    fn from(e: ProgramError) -> Self {
        match e {
            ProgramError::Build(b) => Unrolled::Stream(b.into()),
            ProgramError::Plan(p) => Unrolled::Stream(p.into()),
            ProgramError::Unfinished(n) => Unrolled::Unfinished(n),
        }
    }
}

/// Read `stages` to the program's end, stepping a [`Rolling`] interpolator after every
/// entry as far as the plan reaches, each setpoint to `take`. Returns the interpolator, its
/// last setpoint given (it holds the program's last segment), and what the plan came to.
pub fn interpolate<E: ProgramSource>(
    stages: &mut Stages<'_, E>,
    step: Stepping,
    mut take: impl FnMut(&Setpoint, Window),
) -> Result<(Rolling, Finished), Unrolled> {
    let mut rolling = Rolling::new(step);
    let mut started = false;
    loop {
        let more = stages.read(&mut rolling)?;
        if let (false, Some(start)) = (started, stages.start()) {
            rolling.start_at(start.pose, start.joints);
            started = true;
        }
        let end = stages.end().filter(|_| !more).map(|e| e.1);
        if let Some(end) = &end {
            rolling.finish(end);
        }
        if started {
            rolling.run(&mut take)?;
        }
        if let Some(end) = end {
            return Ok((rolling, end));
        }
    }
}
