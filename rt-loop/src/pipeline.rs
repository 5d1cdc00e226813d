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
//! **Spindle and coolant**: where a bus carries them ([`BusDrives::with_spindle`],
//! [`BusDrives::with_coolant`]) the spindle drive is sent the speed and the I/O module the
//! coolant outputs the interpolator commands ([`nc_geom::setpoint::Setpoint::aux`]); both are off
//! outside the program and once it is at rest (end or stop), and the drives are disabled
//! only after the spindle has stopped. A move that needs the spindle at speed waits for the
//! drive to report it (target reached, bit 10, and its velocity within the window) and the
//! run stops there if it does not within `[spindle] at_speed_timeout_s`.
//!
//! A drive fault is handled by the master itself (quick stop, then disable, every target
//! held at the last one commanded); the pipeline stops interpolating and waits for that to
//! end. A drive lost to its supervision does not hold the run up.
//!
//! Files: this one ([`Pipeline`] and its stages), `approach.rs` (the move to the start),
//! `drive_loop.rs` (the real-time loop around [`Pipeline::cycle`], with its lead).

mod approach;
mod drive_loop;

pub use crate::control::Progress;
use crate::control::{Command, Consumer};
use crate::os;
use approach::Approach;
pub use approach::ApproachLimits;
pub use drive_loop::{drive_loop, GAP_NS};
use drives::cia402::{Goal, State, Statusword};
use drives::link::CanLink;
use drives::master::{DriveFault, Master, NodeKind, NodeStatus, MAX_NODES};
use heapless::Vec as HVec;
use machine::bus::Drive;
use nc_follow::Follower;
use nc_geom::kinematics::Joints;
use nc_geom::program::Aux;

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
    #[error(
        "line {line}: the spindle did not reach {rpm:.0} rpm within {timeout_s} s ([spindle] \
         at_speed_timeout_s; it turns at {actual_rpm:.0} rpm); stopped before the move, \
         drives disabled"
    )]
    SpindleNotAtSpeed {
        line: u32,
        rpm: f64,
        actual_rpm: f64,
        timeout_s: f64,
    },
    #[error(
        "the program is refused at line {line}, ahead of the tool (the refusal says why); \
         stopped along the path, drives disabled"
    )]
    ProgramRefused { line: u32 },
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
    /// The axes' drives, first in the master's node order.
    pub drives: HVec<Drive, MAX_NODES>,
    /// The spindle drive and its index in the master's node order (after the axes).
    pub spindle: Option<(usize, machine::Spindle)>,
    /// The coolant I/O module and its index in the master's node order (last).
    pub coolant: Option<(usize, machine::Coolant)>,
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
            spindle: None,
            coolant: None,
            targets,
        })
    }

    /// The spindle drive is the master's node after the axes' drives.
    pub fn with_spindle(mut self, spindle: machine::Spindle) -> Self {
        self.spindle = Some((self.drives.len(), spindle));
        self
    }

    /// The coolant I/O module is the master's node after the drives (and the spindle).
    pub fn with_coolant(mut self, coolant: machine::Coolant) -> Self {
        let i = self.drives.len() + usize::from(self.spindle.is_some());
        self.coolant = Some((i, coolant));
        self
    }

    /// Spindle speed and coolant outputs as targets.
    fn set_aux(&mut self, aux: &Aux) {
        if let Some((i, s)) = &self.spindle {
            if let Some(t) = self.targets.get_mut(*i) {
                *t = s.velocity(aux.spindle_rpm);
            }
        }
        if let Some((i, c)) = &self.coolant {
            if let Some(t) = self.targets.get_mut(*i) {
                *t = i32::from(c.outputs(aux.mist, aux.flood));
            }
        }
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
    /// Spindle and coolant sent this period.
    aux: Aux,
    /// Periods a move has waited for the spindle.
    spindle_wait: u64,
    /// Most periods at rest at the end for the drives (and the spindle) to settle.
    settle_limit: u64,
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
        let spindle = buses
            .iter()
            .find_map(|b| b.spindle.as_ref().map(|s| s.1.clone()));
        let mut follower = follower;
        follower.wait_for_spindle(spindle.is_some());
        // Stopping the spindle from full speed bounds the wait at the end.
        let settle_limit = spindle.map_or(SETTLE_CYCLES, |s| {
            let stop_s = s.max_rpm / s.acceleration_rpm_s + 1.0;
            SETTLE_CYCLES.max((stop_s / period).ceil() as u64)
        });
        Ok(Pipeline {
            aux: Aux::default(),
            spindle_wait: 0,
            settle_limit,
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
    ///
    /// Real-time thread.
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
            self.follower.awaiting(),
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
    ///
    /// Real-time thread.
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

    /// Every axis within one count of its target, the spindle at its speed.
    fn settled(&self) -> bool {
        self.buses.iter().all(|b| {
            b.master
                .status()
                .iter()
                .zip(&b.targets)
                .all(|(s, t)| match (s.kind, &b.spindle) {
                    (NodeKind::Position, _) => (s.actual.wrapping_sub(*t)).abs() <= 1,
                    (NodeKind::Velocity, Some((_, sp))) => {
                        i64::from(s.actual).abs_diff(i64::from(*t)) <= u64::from(sp.window_units())
                    }
                    _ => true,
                })
        })
    }

    /// Every CiA-402 drive's state satisfies `f` (I/O modules have none).
    fn all_in(&self, f: impl Fn(State) -> bool) -> bool {
        self.buses.iter().all(|b| {
            b.master
                .status()
                .iter()
                .all(|s| s.kind == NodeKind::Io || s.state.is_some_and(&f))
        })
    }

    /// The spindle drive's status and configuration, if the machine has one.
    fn spindle(&self) -> Option<(&NodeStatus, &machine::Spindle)> {
        self.buses.iter().find_map(|b| {
            let (i, s) = b.spindle.as_ref()?;
            Some((b.master.status().get(*i)?, s))
        })
    }

    /// The speed the spindle has reached, if it is the one sent: Operation enabled, target
    /// reached (bit 10) and the velocity actual within the window of it.
    fn spindle_at_speed(&self) -> Option<f64> {
        let (st, sp) = self.spindle()?;
        let want = sp.velocity(self.aux.spindle_rpm);
        let within = i64::from(st.actual).abs_diff(i64::from(want)) <= u64::from(sp.window_units());
        (st.state == Some(State::OperationEnabled)
            && st.target == want
            && Statusword(st.statusword).target_reached()
            && within)
            .then_some(self.aux.spindle_rpm)
    }

    /// Send `aux` from this period on.
    fn command_aux(&mut self, aux: Aux) {
        self.aux = aux;
        for b in self.buses.iter_mut() {
            b.set_aux(&aux);
        }
    }

    /// The interpolation step of the coming period, while the program runs: feed, override
    /// and chunk hand-off, then the timed span, the paper's: parameter update (u at the new
    /// s), basis functions, both curves, tool axis, inverse kinematics, to the final axis
    /// positions in counts. [`Pipeline::cycle`] sends what it computed; it calls this itself
    /// unless the loop did so before the deadline. Once per period: a second call does
    /// nothing.
    ///
    /// Real-time thread.
    pub fn prepare(&mut self) {
        if self.prepared.is_some() || !matches!(self.stage, Stage::Running | Stage::Stopping) {
            return;
        }
        let at_speed = self.spindle_at_speed();
        self.follower.spindle_at_speed(at_speed);
        self.follower.advance();
        let t0 = os::now();
        let sp = self.follower.evaluate();
        let axes = self.joints_to_axes(&sp.joints);
        let overflow = self.set_targets(&axes).err();
        let compute_ns = os::now().saturating_sub(t0);
        let at_rest = sp.done || self.follower.is_stopped();
        // At the end, or stopped: spindle and coolant off.
        self.command_aux(if at_rest { Aux::default() } else { sp.aux });
        self.prepared = Some(Prepared {
            compute_ns,
            at_rest,
            overflow,
        });
    }

    /// One period at monotonic time `now_ns`. `stop` is the stop request (signal flag).
    ///
    /// Real-time thread.
    pub fn cycle(&mut self, now_ns: u64, stop: bool) -> CycleInfo {
        let now = now_ns as f64 * 1e-9;
        self.cycles += 1;
        self.stage_cycles += 1;
        if stop && self.reason.is_none() && self.stage != Stage::Finished {
            self.stop(StopReason::Requested);
        }
        if let Some(line) = self.follower.refused() {
            if self.reason.is_none() && self.stage != Stage::Finished {
                self.stop(StopReason::ProgramRefused { line });
            }
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
                    self.spindle_timeout();
                    if self.reason.is_some() && self.stage == Stage::Running {
                        self.enter(Stage::Stopping);
                    }
                    // At rest: let the drives reach the last target (their own lag) and the
                    // spindle stop before disabling, so they stop where the path ends;
                    // bounded by SETTLE_CYCLES (longer with a spindle: its ramp down).
                    if p.at_rest {
                        self.settle += 1;
                        if self.settled() || self.settle > self.settle_limit {
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
        if !matches!(self.stage, Stage::Running | Stage::Stopping) {
            self.command_aux(Aux::default());
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

    /// A move waiting for the spindle longer than `[spindle] at_speed_timeout_s` stops the
    /// run (the path is at rest there).
    fn spindle_timeout(&mut self) {
        let Some(line) = self.follower.awaiting_spindle() else {
            self.spindle_wait = 0;
            return;
        };
        self.spindle_wait += 1;
        let Some((st, sp)) = self.spindle() else {
            return;
        };
        let timeout_s = sp.at_speed_timeout_s;
        if self.spindle_wait as f64 * self.period > timeout_s && self.reason.is_none() {
            let reason = StopReason::SpindleNotAtSpeed {
                line,
                rpm: self.aux.spindle_rpm,
                actual_rpm: sp.rpm(st.actual),
                timeout_s,
            };
            self.stop(reason);
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
