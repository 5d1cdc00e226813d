//! One period of the machine: interpolate, convert to drive counts, send the RPDOs and SYNC.
//!
//! [`Pipeline::cycle`] is what the real-time thread calls each period. It allocates nothing,
//! blocks on nothing, and its loops are bounded by the number of drives and the look-ahead.
//! Its stages:
//!
//! 1. **Enabling**: every bus's [`Master`] steps its drives to Operation enabled (targets are
//!    the drives' own positions meanwhile). A drive that is not enabled within
//!    `enable_timeout_cycles` ends the run.
//! 2. **Approach** (only if asked for): a jerk-limited straight move in axis space from where
//!    the drives are to the program's start, every axis within its limits, all arriving
//!    together. Without it, a drive farther than [`AT_START_UNITS`] from the start refuses
//!    the run before anything moves (checked by [`Pipeline::new`]).
//! 3. **Running**: the streamed interpolator's step, the axis positions converted to counts
//!    per drive (rotary radians to degrees first), sent as targets.
//! 4. **Stopping**: after a stop request (SIGINT/SIGTERM) or a target that does not fit the
//!    drive's 32-bit counts, the interpolator decelerates along the path to rest.
//! 5. **Disabling**: the CiA-402 disable sequence; the run ends when every drive has left
//!    Operation enabled.
//!
//! A drive fault is handled by the master itself (quick stop, then disable, targets = actual
//! positions, so nothing jumps); the pipeline stops interpolating and waits for that to end.

pub use crate::control::Progress;
use crate::control::{Command, Consumer};
use crate::os;
use config::bus::Drive;
use drives::cia402::{Goal, State};
use drives::link::CanLink;
use drives::master::{DriveFault, Master, MAX_NODES};
use heapless::Vec as HVec;
use nc::kinematics::Joints;
use nc::scurve::{push_section, Phase};
use nc::stream::Follower;

/// A drive within this distance of the program's start (mm or degrees) is at the start.
pub const AT_START_UNITS: f64 = 0.001;

/// Where the run is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    Enabling,
    Approach,
    Running,
    Stopping,
    Disabling,
    Finished,
}

/// Why a run stopped before the program's end.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum StopReason {
    #[error("stop requested (SIGINT/SIGTERM): stopped along the path, drives disabled")]
    Requested,
    #[error("stopped by the operator (dnurbs ctl stop): stopped along the path, drives disabled")]
    Operator,
    #[error("drive fault: {0}; drives quick-stopped and disabled")]
    Fault(DriveFault),
    #[error("drives not Operation enabled within {0} cycles; disabled")]
    EnableTimeout(u64),
    #[error(
        "axis {axis} target {position:.4} does not fit the drive's 32-bit counts; \
         stopped along the path"
    )]
    CountOverflow { axis: usize, position: f64 },
    #[error(
        "{0} periods in a row overran (more than [realtime] max_consecutive_overruns); \
         stopped along the path, drives disabled"
    )]
    Overruns(u64),
}

impl StopReason {
    /// The operator asked for it (not a fault).
    pub fn by_operator(&self) -> bool {
        matches!(self, StopReason::Requested | StopReason::Operator)
    }

    /// The drive that caused it, if one did.
    pub fn node(&self) -> Option<u8> {
        match self {
            StopReason::Fault(f) => Some(f.node),
            _ => None,
        }
    }
}

/// The drives of one bus and the master driving them.
pub struct BusDrives<L: CanLink> {
    pub master: Master<L>,
    /// In the master's node order.
    pub drives: HVec<Drive, MAX_NODES>,
    targets: [i32; MAX_NODES],
}

impl<L: CanLink> BusDrives<L> {
    /// `drives` in the order of the master's nodes; at most [`MAX_NODES`].
    pub fn new(master: Master<L>, drives: &[Drive]) -> Option<Self> {
        let mut v = HVec::new();
        for d in drives {
            v.push(d.clone()).ok()?;
        }
        let mut targets = [0; MAX_NODES];
        for (t, s) in targets.iter_mut().zip(master.status()) {
            *t = s.actual;
        }
        Some(BusDrives {
            master,
            drives: v,
            targets,
        })
    }
}

/// Axis limits for the approach, in axis units (mm or degrees), joint order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ApproachLimits {
    pub velocity: [f64; 5],
    pub acceleration: [f64; 5],
    pub jerk: [f64; 5],
}

/// The jerk-limited straight move to the start, planned before the loop.
#[derive(Clone, Debug)]
struct Approach {
    from: [f64; 5],
    to: [f64; 5],
    phases: Vec<Phase>,
    duration: f64,
    cursor: usize,
    t: f64,
}

impl Approach {
    fn new(from: [f64; 5], to: [f64; 5], lim: &ApproachLimits) -> Approach {
        // lambda runs 0 -> 1; axis j moves by d_j * lambda.
        let (mut v, mut a, mut j) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for k in 0..5 {
            let d = (to[k] - from[k]).abs();
            if d > 1e-12 {
                v = v.min(lim.velocity[k] / d);
                a = a.min(lim.acceleration[k] / d);
                j = j.min(lim.jerk[k] / d);
            }
        }
        let mut phases = Vec::new();
        if v.is_finite() {
            push_section(&mut phases, 0.0, 0.0, (0.0, 0.0), 1.0, v, (a, j));
        }
        let duration = phases.last().map_or(0.0, |p| p.t0 + p.dur);
        Approach {
            from,
            to,
            phases,
            duration,
            cursor: 0,
            t: 0.0,
        }
    }

    /// The axis positions now, without advancing.
    fn now(&self) -> [f64; 5] {
        if self.t >= self.duration || self.phases.is_empty() {
            return if self.t > 0.0 { self.to } else { self.from };
        }
        let ph = &self.phases[self.cursor.min(self.phases.len() - 1)];
        let l = ph.at((self.t - ph.t0).clamp(0.0, ph.dur)).s.clamp(0.0, 1.0);
        core::array::from_fn(|k| self.from[k] + (self.to[k] - self.from[k]) * l)
    }

    /// Advance one period; the axis positions, and whether the move is over.
    fn step(&mut self, period: f64) -> ([f64; 5], bool) {
        self.t += period;
        if self.t >= self.duration || self.phases.is_empty() {
            return (self.to, true);
        }
        let n = self.phases.len();
        while self.cursor + 1 < n && self.t >= self.phases[self.cursor + 1].t0 {
            self.cursor += 1;
        }
        let ph = &self.phases[self.cursor];
        let l = ph.at((self.t - ph.t0).clamp(0.0, ph.dur)).s.clamp(0.0, 1.0);
        (
            core::array::from_fn(|k| self.from[k] + (self.to[k] - self.from[k]) * l),
            false,
        )
    }
}

/// What [`Pipeline::new`] refuses.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    #[error(
        "axis {axis} is at {actual:.4} but the program starts at {start:.4}: move it there \
         first, or pass --approach to have dnurbs move all axes to the start"
    )]
    NotAtStart {
        axis: &'static str,
        actual: f64,
        start: f64,
    },
}

/// Counts of one cycle, for progress and the report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CycleInfo {
    /// Interpolation compute time: from the parameter update (u at the new arc length) through
    /// the basis functions, both curves and inverse kinematics to the last axis's counts.
    pub compute_ns: u64,
    pub finished: bool,
}

/// The interpolation step of a period, done by [`Pipeline::prepare`] ahead of the bus work.
#[derive(Clone, Copy, Debug)]
struct Prepared {
    compute_ns: u64,
    /// The program's end, or the stop, is reached.
    at_rest: bool,
    overflow: Option<StopReason>,
}

/// Everything the real-time thread works with.
pub struct Pipeline<'q, L: CanLink> {
    pub follower: Follower<'q>,
    pub buses: Vec<BusDrives<L>>,
    stage: Stage,
    reason: Option<StopReason>,
    stop_line: Option<u32>,
    approach: Option<Approach>,
    period: f64,
    enable_timeout_cycles: u64,
    stage_cycles: u64,
    /// Added to the C axis (degrees): the program's C moved to the drive's turn.
    c_shift_deg: f64,
    rotary_deg: [bool; 5],
    cycles: u64,
    settle: u64,
    prepared: Option<Prepared>,
    /// More consecutive overruns than this stop the run along the path.
    max_overruns: u64,
    /// The operator's commands, if a control socket serves them.
    commands: Option<Consumer<'q, Command>>,
}

/// Most periods to wait at the end for the drives to reach their last target.
pub const SETTLE_CYCLES: u64 = 500;

/// Axis names in joint order (for messages).
const AXES: [&str; 5] = ["X", "Y", "Z", "tilt (A/B)", "C"];

impl<'q, L: CanLink> Pipeline<'q, L> {
    /// `start_joints`: the program's start (mm, radians). `approach`: limits for the move to
    /// the start, or `None` to require the drives to be there already. `c_continuous`: the C
    /// axis has no travel limits, so the program may be shifted by whole turns to where the
    /// drive is.
    pub fn new(
        follower: Follower<'q>,
        buses: Vec<BusDrives<L>>,
        start_joints: Joints,
        period: f64,
        approach: Option<ApproachLimits>,
        c_continuous: bool,
        enable_timeout_cycles: u64,
    ) -> Result<Self, PipelineError> {
        let rotary_deg = [false, false, false, true, true];
        let start: [f64; 5] = core::array::from_fn(|j| {
            if rotary_deg[j] {
                start_joints[j].to_degrees()
            } else {
                start_joints[j]
            }
        });
        let mut actual = start;
        for b in &buses {
            for (d, s) in b.drives.iter().zip(b.master.status()) {
                if d.axis < 5 {
                    actual[d.axis] = d.position(s.actual);
                }
            }
        }
        let c_shift_deg = if c_continuous {
            ((actual[4] - start[4]) / 360.0).round() * 360.0
        } else {
            0.0
        };
        let mut target = start;
        target[4] += c_shift_deg;
        let approach = match approach {
            Some(lim) => Some(Approach::new(actual, target, &lim)),
            None => {
                for j in 0..5 {
                    if (actual[j] - target[j]).abs() > AT_START_UNITS {
                        return Err(PipelineError::NotAtStart {
                            axis: AXES[j],
                            actual: actual[j],
                            start: target[j],
                        });
                    }
                }
                None
            }
        };
        Ok(Pipeline {
            follower,
            buses,
            stage: Stage::Enabling,
            reason: None,
            stop_line: None,
            approach,
            period,
            enable_timeout_cycles,
            stage_cycles: 0,
            c_shift_deg,
            rotary_deg,
            cycles: 0,
            settle: 0,
            prepared: None,
            max_overruns: u64::MAX,
            commands: None,
        })
    }

    /// Take the operator's commands from this queue, at the start of every period.
    pub fn set_commands(&mut self, commands: Consumer<'q, Command>) {
        self.commands = Some(commands);
    }

    /// Apply the commands that arrived (at most the queue's capacity: bounded).
    fn take_commands(&mut self) {
        for _ in 0..crate::control::QUEUE {
            let Some(c) = self.commands.as_mut().and_then(|q| q.dequeue()) else {
                return;
            };
            match c {
                Command::Pause => self.follower.pause(),
                Command::Resume => self.follower.resume(),
                Command::Override(p) => self.follower.set_override(f64::from(p.min(100)) / 100.0),
                Command::Stop => {
                    if self.stage != Stage::Finished {
                        self.stop(StopReason::Operator);
                    }
                }
            }
        }
    }

    /// Publish where the run is (every period, allocation-free).
    pub fn publish(&self, progress: &Progress) {
        let stage = match self.stage {
            Stage::Enabling => 0,
            Stage::Approach => 1,
            Stage::Running => 2,
            Stage::Stopping => 3,
            Stage::Disabling => 4,
            Stage::Finished => 5,
        };
        let sp = self.follower.last();
        let axes = match (&self.approach, self.stage) {
            (Some(ap), Stage::Enabling | Stage::Approach) => ap.now(),
            _ => self.joints_to_axes(&sp.joints),
        };
        progress.publish(
            stage,
            self.follower.is_paused(),
            self.follower.line(),
            sp.block,
            &axes,
            sp.feed * 60.0,
            (self.follower.feed_override() * 100.0).round() as u8,
        );
    }

    /// Stop the run along the path once more than `n` consecutive periods overrun.
    pub fn set_max_consecutive_overruns(&mut self, n: u64) {
        self.max_overruns = n;
    }

    /// The loop's count of consecutive overruns up to the period just done.
    pub fn overruns_in_a_row(&mut self, n: u64) {
        if n > self.max_overruns && self.reason.is_none() && self.stage != Stage::Finished {
            self.stop(StopReason::Overruns(n));
        }
    }

    pub fn stage(&self) -> Stage {
        self.stage
    }

    /// Why the run stopped early, if it did.
    pub fn reason(&self) -> Option<StopReason> {
        self.reason
    }

    /// The program line being machined when the stop began (0 before the program).
    pub fn stop_line(&self) -> Option<u32> {
        self.stop_line
    }

    /// The first reason is kept, with the program line where it came.
    fn set_reason(&mut self, reason: StopReason) {
        if self.reason.is_none() {
            self.reason = Some(reason);
            self.stop_line = Some(self.follower.line());
        }
    }

    fn enter(&mut self, stage: Stage) {
        self.stage = stage;
        self.stage_cycles = 0;
    }

    fn stop(&mut self, reason: StopReason) {
        self.set_reason(reason);
        self.follower.request_stop();
    }

    /// Axis positions (mm, degrees) to targets; `false` if one did not fit.
    fn set_targets(&mut self, axes: &[f64; 5]) -> Result<(), StopReason> {
        for b in self.buses.iter_mut() {
            for (d, t) in b.drives.iter().zip(b.targets.iter_mut()) {
                let Some(&p) = axes.get(d.axis) else { continue };
                match d.counts(p) {
                    Some(c) => *t = c,
                    None => {
                        return Err(StopReason::CountOverflow {
                            axis: d.axis,
                            position: p,
                        })
                    }
                }
            }
        }
        Ok(())
    }

    fn joints_to_axes(&self, j: &Joints) -> [f64; 5] {
        core::array::from_fn(|k| {
            if self.rotary_deg[k] {
                j[k].to_degrees() + if k == 4 { self.c_shift_deg } else { 0.0 }
            } else {
                j[k]
            }
        })
    }

    /// The cache warm-up before the step: the interpolation and the count conversion run once
    /// where the next period will likely be ([`Follower::rehearse`]) and the result is
    /// dropped, so the timed step finds its code and data in the caches. Changes no state and
    /// sends nothing; does nothing outside the program.
    pub fn rehearse(&self) {
        if !matches!(self.stage, Stage::Running | Stage::Stopping) {
            return;
        }
        let axes = self.joints_to_axes(&self.follower.rehearse());
        for b in &self.buses {
            for d in &b.drives {
                if let Some(&p) = axes.get(d.axis) {
                    core::hint::black_box(d.counts(p));
                }
            }
        }
    }

    /// Every drive within one count of its target.
    fn settled(&self) -> bool {
        self.buses.iter().all(|b| {
            b.master
                .status()
                .iter()
                .zip(&b.targets)
                .all(|(s, t)| (s.actual.wrapping_sub(*t)).abs() <= 1)
        })
    }

    fn all_in(&self, f: impl Fn(State) -> bool) -> bool {
        self.buses
            .iter()
            .all(|b| b.master.status().iter().all(|s| s.state.is_some_and(&f)))
    }

    /// The interpolation step of the coming period, while the program runs: feed, override
    /// and chunk hand-off, then the timed span, the paper's: parameter update (u at the new
    /// s), basis functions, both curves, tool axis, inverse kinematics, to the final axis
    /// positions in counts. [`Pipeline::cycle`] sends what it computed; it calls this itself
    /// unless the loop did so before the deadline. Once per period: a second call does
    /// nothing.
    pub fn prepare(&mut self) {
        if self.prepared.is_some() || !matches!(self.stage, Stage::Running | Stage::Stopping) {
            return;
        }
        self.follower.advance();
        let t0 = os::now();
        let sp = self.follower.evaluate();
        let axes = self.joints_to_axes(&sp.joints);
        let overflow = self.set_targets(&axes).err();
        self.prepared = Some(Prepared {
            compute_ns: os::now().saturating_sub(t0),
            at_rest: sp.done || self.follower.is_stopped(),
            overflow,
        });
    }

    /// One period at monotonic time `now_ns`. `stop` is the stop request (signal flag).
    pub fn cycle(&mut self, now_ns: u64, stop: bool) -> CycleInfo {
        let now = now_ns as f64 * 1e-9;
        self.cycles += 1;
        self.stage_cycles += 1;
        if stop && self.reason.is_none() && self.stage != Stage::Finished {
            self.stop(StopReason::Requested);
        }
        self.take_commands();
        let mut compute_ns = 0;
        match self.stage {
            Stage::Enabling => {
                if self.reason.is_some() {
                    self.enter(Stage::Disabling);
                } else if self.all_in(|s| s == State::OperationEnabled) {
                    let next = if self.approach.is_some() {
                        Stage::Approach
                    } else {
                        Stage::Running
                    };
                    self.enter(next);
                } else if self.stage_cycles > self.enable_timeout_cycles {
                    self.set_reason(StopReason::EnableTimeout(self.enable_timeout_cycles));
                    self.enter(Stage::Disabling);
                }
            }
            Stage::Approach => {
                if self.reason.is_some() {
                    // A straight axis move, not a path: the drives stop by their own
                    // quick-stop ramp (CiA-402), then are disabled.
                    for b in self.buses.iter_mut() {
                        b.master.set_goal(Goal::QuickStop);
                    }
                    self.enter(Stage::Disabling);
                } else if let Some(ap) = self.approach.as_mut() {
                    let (axes, done) = ap.step(self.period);
                    if let Err(r) = self.set_targets(&axes) {
                        self.set_reason(r);
                    }
                    if done {
                        self.enter(Stage::Running);
                    }
                }
            }
            Stage::Running | Stage::Stopping => {
                self.prepare();
                if let Some(p) = self.prepared.take() {
                    compute_ns = p.compute_ns;
                    if let Some(r) = p.overflow {
                        self.stop(r);
                    }
                    if self.reason.is_some() && self.stage == Stage::Running {
                        self.enter(Stage::Stopping);
                    }
                    // At rest: let the drives reach the last target (their own lag) before
                    // disabling, so they stop where the path ends; bounded by SETTLE_CYCLES.
                    if p.at_rest {
                        self.settle += 1;
                        if self.settled() || self.settle > SETTLE_CYCLES {
                            self.enter(Stage::Disabling);
                        }
                    }
                }
            }
            Stage::Disabling => {
                let goal_quick = self
                    .buses
                    .iter()
                    .any(|b| b.master.goal() == Goal::QuickStop);
                for b in self.buses.iter_mut() {
                    if !goal_quick || b.master.fault().is_some() {
                        b.master.set_goal(Goal::Disabled);
                    }
                }
                let stopped = |s: State| {
                    matches!(
                        s,
                        State::SwitchOnDisabled
                            | State::ReadyToSwitchOn
                            | State::Fault
                            | State::NotReadyToSwitchOn
                    )
                };
                // A lost drive (silent past its supervision) cannot report a state: it
                // does not hold the run up until the timeout.
                let all_stopped = self.buses.iter().all(|b| {
                    b.master
                        .status()
                        .iter()
                        .all(|s| s.state.is_some_and(stopped) || b.master.lost(s))
                });
                if all_stopped || self.stage_cycles > self.enable_timeout_cycles {
                    self.enter(Stage::Finished);
                } else if goal_quick && self.all_in(|s| s != State::OperationEnabled) {
                    for b in self.buses.iter_mut() {
                        b.master.set_goal(Goal::Disabled);
                    }
                }
            }
            Stage::Finished => {}
        }
        if self.stage == Stage::Enabling && self.cycles == 1 {
            for b in self.buses.iter_mut() {
                b.master.set_goal(Goal::Enabled);
            }
        }
        let mut fault = None;
        for b in self.buses.iter_mut() {
            let n = b.master.status().len().min(MAX_NODES);
            if let Some(f) = b.master.cycle(&b.targets[..n], now) {
                fault = fault.or(Some(f));
            }
        }
        if let Some(f) = fault {
            if self.reason.is_none() {
                self.set_reason(StopReason::Fault(f));
                self.follower.request_stop();
                if matches!(
                    self.stage,
                    Stage::Running | Stage::Approach | Stage::Enabling
                ) {
                    self.stage = Stage::Disabling;
                    self.stage_cycles = 0;
                }
            }
        }
        CycleInfo {
            compute_ns,
            finished: self.stage == Stage::Finished,
        }
    }

    /// Each drive's node, last target and actual position (counts), bus by bus.
    pub fn drive_positions(&self) -> impl Iterator<Item = (usize, u8, i32, i32)> + '_ {
        self.buses.iter().flat_map(|b| {
            b.drives
                .iter()
                .zip(b.master.status())
                .map(|(d, s)| (d.axis, d.node, s.target, s.actual))
        })
    }
}

/// With a lead: a pause between two clock reads longer than this, ns, means something else
/// ran on the CPU (an interrupt, the hypervisor) and may have evicted the caches.
pub const GAP_NS: u64 = 2_000;
/// With a lead: a disturbance this close to a compute slot, ns, makes the slot unquiet.
const NEAR_NS: u64 = 15_000;
/// With a lead: a slot is quiet again this long after its last disturbance, ns.
const FORGET_NS: u64 = 1_000_000_000;

/// Where in the lead the step is computed. Periodic interruptions (a hypervisor's timer
/// tick, an SMI) come at a phase that drifts slowly against the loop's deadlines; the loop
/// sees them while it waits on the clock, and computes in whichever of two slots, a quarter
/// and three quarters of the lead before the deadline, has been quiet the longer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Slots {
    /// Offset of each slot before the deadline, ns.
    before: [u64; 2],
    /// When a disturbance was last seen near each slot (monotonic ns; 0: never).
    seen: [u64; 2],
}

impl Slots {
    fn new(lead_ns: u64) -> Slots {
        Slots {
            before: [lead_ns / 4, lead_ns * 3 / 4],
            seen: [0; 2],
        }
    }

    /// The slot to compute in at time `now`: the one nearer the deadline unless it was
    /// disturbed in the last [`FORGET_NS`] and the other was disturbed less recently.
    fn choose(&self, now: u64) -> usize {
        let recent = |k: usize| self.seen[k] != 0 && now.saturating_sub(self.seen[k]) < FORGET_NS;
        usize::from(recent(0) && self.seen[1] < self.seen[0])
    }

    /// Something ran on the CPU at `at` in the period due at `deadline`.
    fn disturbed(&mut self, at: u64, deadline: u64) {
        let before = deadline as i64 - at as i64;
        for k in 0..2 {
            if before.abs_diff(self.before[k] as i64) <= NEAR_NS {
                self.seen[k] = at;
            }
        }
    }
}

/// The interpolating loop: sleep to the absolute deadline, run one [`Pipeline::cycle`],
/// record wake-up latency, compute time and whole-cycle time, publish progress. Ends when
/// the pipeline has finished, or after `max_cycles` (a bound for tests and a last resort).
/// Allocation-free; overruns are counted and the missed deadlines skipped, never caught up.
///
/// With a `lead_ns` above zero (at most half the period: more is cut to that; the machine
/// file and the command line refuse it) the thread wakes that much before each deadline,
/// rehearses the step ([`Pipeline::rehearse`]) to warm the caches, waits on the clock for
/// the quieter of two compute slots (a quarter and three quarters of the lead before the
/// deadline: the one longer free of pauses seen while waiting; it rehearses again after a
/// pause), rehearses once more and computes the period's targets there
/// ([`Pipeline::prepare`]), then waits on the clock for the deadline and sends them. The
/// frames leave on time even when the wake-up is late by less than the lead. The wake-up
/// latency is measured against the early wake-up time, the whole cycle from the deadline (or
/// the wake-up, if that was later) to the last frame written: the step is done by then. The
/// lead costs its length in CPU time per period.
pub fn drive_loop<L: CanLink>(
    rec: &mut crate::interval::Recorder<'_>,
    pipeline: &mut Pipeline<'_, L>,
    period_ns: u64,
    lead_ns: u64,
    stop: &std::sync::atomic::AtomicBool,
    progress: &Progress,
    max_cycles: u64,
) {
    use std::sync::atomic::Ordering::Relaxed;
    let period = period_ns.max(1);
    let lead = lead_ns.min(period / 2);
    let mut slots = Slots::new(lead);
    let mut next = os::now().saturating_add(period);
    let (mut underruns, mut total_overruns) = (0, 0);
    let mut run = crate::stats::OverrunRun::default();
    for _ in 0..max_cycles {
        let wake_at = next.saturating_sub(lead);
        os::sleep_until(wake_at);
        let woke = os::now();
        let start = if lead > 0 {
            // Rehearsing only right before the step gave a compute p99.9 of 0.69-0.73 us in
            // pinned demo runs here; also at the wake-up and after each pause, 0.47-0.63 us.
            pipeline.rehearse();
            let slot = next.saturating_sub(slots.before[slots.choose(woke)]);
            os::spin_until(slot, lead, GAP_NS, |at| {
                slots.disturbed(at, next);
                pipeline.rehearse();
            });
            pipeline.rehearse();
            let t0 = os::now();
            pipeline.prepare();
            if os::now().saturating_sub(t0) > GAP_NS {
                slots.disturbed(t0, next);
            }
            os::spin_until(next, lead, GAP_NS, |at| slots.disturbed(at, next)).max(woke)
        } else {
            woke
        };
        let info = pipeline.cycle(start, stop.load(Relaxed));
        let done = os::now();
        let stats = rec.stats();
        let (late, busy) = (woke.saturating_sub(wake_at), done.saturating_sub(start));
        if info.compute_ns > 0 {
            stats.record(late, info.compute_ns, busy);
        } else {
            stats.record_idle(late, busy);
        }
        next += period;
        let overrun = done > next;
        let in_a_row = run.period(overrun, stats);
        if overrun {
            total_overruns += 1;
            next += (done - next) / period * period + period;
        }
        pipeline.overruns_in_a_row(in_a_row);
        let c = pipeline.follower.counters();
        stats.underruns += c.underruns - underruns;
        underruns = c.underruns;
        pipeline.publish(progress);
        progress.cycles.fetch_add(1, Relaxed);
        progress.overruns.store(total_overruns, Relaxed);
        progress.underruns.store(c.underruns, Relaxed);
        progress
            .ppm
            .store((pipeline.follower.progress() * 1e6) as u64, Relaxed);
        rec.maybe_rotate(done);
        if info.finished {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    #[test]
    fn the_step_moves_to_the_quieter_slot_and_back_when_the_disturbance_passes() {
        let mut s = Slots::new(60_000);
        assert_eq!(s.before, [15_000, 45_000]);
        let deadline = 10_000 * MS;
        // Nothing seen: the slot nearer the deadline.
        assert_eq!(s.choose(deadline), 0);
        // Far from both slots (50 µs after the deadline... 31 µs before it): no effect.
        s.disturbed(deadline + 50_000, deadline);
        s.disturbed(deadline - 31_000, deadline);
        assert_eq!(s.choose(deadline), 0);
        // Near the first slot: compute in the second.
        s.disturbed(deadline - 2_000, deadline);
        assert_eq!(s.seen[0], deadline - 2_000);
        assert_eq!(s.choose(deadline), 1);
        // Two periods later near the second slot too, the first one older: back to it.
        let d2 = deadline + 4 * MS;
        s.disturbed(d2 - 50_000, d2);
        assert_eq!(s.choose(d2), 0);
        // Both seen, the second longer ago: the second.
        let d3 = d2 + 2 * MS;
        s.disturbed(d3 - 12_000, d3);
        assert_eq!(s.choose(d3), 1);
        // A second after the last disturbance near the first slot it is quiet again.
        assert_eq!(s.choose(d3 - 12_000 + FORGET_NS), 0);
    }
}
