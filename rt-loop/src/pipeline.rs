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
//! end. A drive lost to its supervision does not hold the run up. A condition of the bus
//! itself ([`drives::master::health`]: error frames, a full transmit queue, the interface
//! down) is a warning, a feed hold (the follower paused, as `ctl pause`), a controlled stop
//! (along the path, [`StopReason::Bus`]) or the master's fault (quick stop).
//!
//! Each stage keeps what only it needs in its variant of the run's phase (the approach its
//! move, the interpolating stages their settling count and spindle wait), so a stage cannot
//! read another's leftovers.
//!
//! Files: this one ([`Pipeline`], its state and its period), `stages.rs` (what each stage
//! does in a period), `bus.rs` (the drives of a bus: targets in counts, spindle and coolant,
//! the drives' states), `approach.rs` (the move to the start), `drive_loop.rs` (the
//! real-time loop around [`Pipeline::cycle`], with its lead), `traced.rs` (each period's
//! targets into the trace's queue, `crate::trace`).

mod approach;
mod bus;
mod drive_loop;
mod stages;
mod traced;

pub use crate::control::Progress;
use crate::control::{Command, Consumer};
use approach::Approach;
pub use approach::ApproachLimits;
pub use bus::BusDrives;
pub use drive_loop::{drive_loop, GAP_NS};
use drives::cia402::Goal;
use drives::link::CanLink;
use drives::master::{BusCondition, DriveFault, MAX_NODES};
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

impl Stage {
    /// Its index in [`crate::control::STAGES`].
    pub fn index(self) -> u8 {
        match self {
            Stage::Enabling => 0,
            Stage::Approach => 1,
            Stage::Running => 2,
            Stage::Stopping => 3,
            Stage::Disabling => 4,
            Stage::Finished => 5,
        }
    }
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
    #[error("CAN bus: {0}; stopped along the path, drives disabled")]
    Bus(BusCondition),
}

impl StopReason {
    /// The operator asked for it (not a fault).
    pub fn by_operator(&self) -> bool {
        matches!(self, StopReason::Requested | StopReason::Operator)
    }

    /// The drive that caused it, if one did (not the bus).
    pub fn node(&self) -> Option<u8> {
        match self {
            StopReason::Fault(f) if f.node != DriveFault::BUS => Some(f.node),
            _ => None,
        }
    }
}

/// The run's stage, with what only that stage keeps.
#[derive(Clone, Debug)]
enum Phase {
    /// The drives are brought to Operation enabled; the approach waits to be stepped.
    Enabling(Option<Approach>),
    Approach(Approach),
    Running(Moving),
    Stopping(Moving),
    Disabling,
    Finished,
}

impl Phase {
    fn stage(&self) -> Stage {
        match self {
            Phase::Enabling(_) => Stage::Enabling,
            Phase::Approach(_) => Stage::Approach,
            Phase::Running(_) => Stage::Running,
            Phase::Stopping(_) => Stage::Stopping,
            Phase::Disabling => Stage::Disabling,
            Phase::Finished => Stage::Finished,
        }
    }
}

/// What the interpolating stages keep from period to period.
#[derive(Clone, Copy, Debug, Default)]
struct Moving {
    /// The step computed ahead of the bus work this period ([`Pipeline::prepare`]).
    prepared: Option<Prepared>,
    /// Periods at rest at the end, waiting for the drives (and the spindle) to settle.
    settle: u64,
    /// Periods a move has waited for the spindle.
    spindle_wait: u64,
}

/// What [`Pipeline::new`] refuses.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
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
    #[error("the move to the program's start needs more than {0} S-curve phases")]
    ApproachTooComplex(usize),
}

/// [`Pipeline::from_here`] refused: why, and what it was given, unchanged.
pub struct NotHere<'q, L: CanLink> {
    pub error: PipelineError,
    pub follower: Follower<'q>,
    pub buses: Vec<BusDrives<L>>,
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
    phase: Phase,
    /// Periods in the present stage.
    stage_cycles: u64,
    reason: Option<StopReason>,
    stop_line: Option<u32>,
    period: f64,
    enable_timeout_cycles: u64,
    /// Added to the C axis (degrees): the program's C moved to the drive's turn.
    c_shift_deg: f64,
    rotary_deg: [bool; 5],
    cycles: u64,
    /// More consecutive overruns than this stop the run along the path.
    max_overruns: u64,
    /// The operator's commands, if a control socket serves them.
    commands: Option<Consumer<'q, Command>>,
    /// Spindle and coolant sent this period.
    aux: Aux,
    /// Most periods at rest at the end for the drives (and the spindle) to settle.
    settle_limit: u64,
    /// Where each period's targets go, if they are traced; rows the queue had no room for.
    trace: Option<crate::trace::Producer<'q, crate::trace::TraceRow>>,
    trace_dropped: u64,
    /// At the program's end, or after a stop that is not a fault, the drives stay enabled
    /// holding where the path ended ([`Pipeline::keep_enabled`]).
    keep_enabled: bool,
}

/// Most periods to wait at the end for the drives to reach their last target.
pub const SETTLE_CYCLES: u64 = 500;

/// The rotary axes (tilt and C), sent in degrees.
const ROTARY_DEG: [bool; 5] = [false, false, false, true, true];

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
        let (c_shift_deg, approach) =
            Self::from_where_they_stand(&buses, start_joints, approach, c_continuous)?;
        Ok(Self::build(
            follower,
            buses,
            period,
            c_shift_deg,
            approach,
            enable_timeout_cycles,
        ))
    }

    /// A program that starts where the drives stand (within [`AT_START_UNITS`]), on drives
    /// already enabled: what the long-lived controller runs each program and MDI line with.
    /// Refused, with the interpolator and the buses given back unchanged, when a drive is
    /// elsewhere.
    ///
    /// Real-time thread: allocates nothing (hence the large refusal, not boxed).
    #[allow(clippy::result_large_err)]
    pub fn from_here(
        follower: Follower<'q>,
        buses: Vec<BusDrives<L>>,
        start_joints: Joints,
        period: f64,
        c_continuous: bool,
        enable_timeout_cycles: u64,
    ) -> Result<Self, NotHere<'q, L>> {
        match Self::from_where_they_stand(&buses, start_joints, None, c_continuous) {
            Ok((c_shift_deg, _)) => {
                let mut p = Self::build(
                    follower,
                    buses,
                    period,
                    c_shift_deg,
                    None,
                    enable_timeout_cycles,
                );
                p.keep_enabled();
                Ok(p)
            }
            Err(error) => Err(NotHere {
                error,
                follower,
                buses,
            }),
        }
    }

    /// The C shift (degrees) and the approach from where the drives stand to the start.
    fn from_where_they_stand(
        buses: &[BusDrives<L>],
        start_joints: Joints,
        approach: Option<ApproachLimits>,
        c_continuous: bool,
    ) -> Result<(f64, Option<Approach>), PipelineError> {
        let rotary_deg = ROTARY_DEG;
        let start: [f64; 5] = core::array::from_fn(|j| {
            if rotary_deg[j] {
                start_joints[j].to_degrees()
            } else {
                start_joints[j]
            }
        });
        let mut actual = start;
        for b in buses {
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
            Some(lim) => Some(
                Approach::new(actual, target, &lim)
                    .ok_or(PipelineError::ApproachTooComplex(approach::APPROACH_PHASES))?,
            ),
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
        Ok((c_shift_deg, approach))
    }

    fn build(
        follower: Follower<'q>,
        buses: Vec<BusDrives<L>>,
        period: f64,
        c_shift_deg: f64,
        approach: Option<Approach>,
        enable_timeout_cycles: u64,
    ) -> Self {
        let rotary_deg = ROTARY_DEG;
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
        Pipeline {
            aux: Aux::default(),
            settle_limit,
            follower,
            buses,
            phase: Phase::Enabling(approach),
            stage_cycles: 0,
            reason: None,
            stop_line: None,
            period,
            enable_timeout_cycles,
            c_shift_deg,
            rotary_deg,
            cycles: 0,
            max_overruns: u64::MAX,
            commands: None,
            trace: None,
            trace_dropped: 0,
            keep_enabled: false,
        }
    }

    /// The drives stay enabled at the end: once the path is at rest (its end, or a stop
    /// that is not a fault) and the drives have settled, the run is finished with them
    /// holding there. A fault still quick-stops and disables them. What the long-lived
    /// controller runs each program and MDI line with ([`crate::life`]).
    pub fn keep_enabled(&mut self) {
        self.keep_enabled = true;
    }

    /// The interpolator and the buses back, once the run is over (or never started).
    pub fn into_parts(self) -> (Follower<'q>, Vec<BusDrives<L>>) {
        (self.follower, self.buses)
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
            self.command(c);
        }
    }

    /// Apply an operator's command now.
    ///
    /// Real-time thread.
    pub fn command(&mut self, c: Command) {
        match c {
            Command::Pause => self.follower.pause(),
            Command::Resume => self.follower.resume(),
            Command::Override(p) => self.follower.set_override(f64::from(p.min(100)) / 100.0),
            Command::Stop => {
                if self.stage() != Stage::Finished {
                    self.stop(StopReason::Operator);
                }
            }
        }
    }

    /// Publish where the run is (every period, allocation-free).
    ///
    /// Real-time thread.
    pub fn publish(&self, progress: &Progress) {
        let stage = usize::from(self.stage().index());
        let sp = self.follower.last();
        let axes = match &self.phase {
            Phase::Enabling(Some(ap)) | Phase::Approach(ap) => ap.now(),
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
        if n > self.max_overruns && self.reason.is_none() && self.stage() != Stage::Finished {
            self.stop(StopReason::Overruns(n));
        }
    }

    pub fn stage(&self) -> Stage {
        self.phase.stage()
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

    pub(super) fn stop(&mut self, reason: StopReason) {
        self.set_reason(reason);
        self.follower.request_stop();
    }

    /// One period at monotonic time `now_ns`. `stop` is the stop request (signal flag).
    ///
    /// Real-time thread.
    pub fn cycle(&mut self, now_ns: u64, stop: bool) -> CycleInfo {
        let now = now_ns as f64 * 1e-9;
        self.cycles += 1;
        self.stage_cycles += 1;
        let finished = self.stage() == Stage::Finished;
        if stop && self.reason.is_none() && !finished {
            self.stop(StopReason::Requested);
        }
        if let Some(line) = self.follower.refused() {
            if self.reason.is_none() && !finished {
                self.stop(StopReason::ProgramRefused { line });
            }
        }
        self.take_commands();
        let mut compute_ns = 0;
        let before = self.stage();
        // The stage's own step; the phase is held out of `self` meanwhile.
        let next = match core::mem::replace(&mut self.phase, Phase::Finished) {
            Phase::Enabling(ap) => self.enabling(ap),
            Phase::Approach(ap) => self.approaching(ap),
            Phase::Running(m) => self.moving(m, false, &mut compute_ns),
            Phase::Stopping(m) => self.moving(m, true, &mut compute_ns),
            Phase::Disabling => self.disabling(),
            Phase::Finished => Phase::Finished,
        };
        self.phase = next;
        if self.stage() != before {
            self.stage_cycles = 0;
        }
        if !matches!(self.stage(), Stage::Running | Stage::Stopping) {
            self.command_aux(Aux::default());
        }
        if self.stage() == Stage::Enabling && self.cycles == 1 {
            for b in self.buses.iter_mut() {
                b.master.set_goal(Goal::Enabled);
            }
        }
        let mut fault: Option<DriveFault> = None;
        for b in self.buses.iter_mut() {
            let n = b.master.status().len().min(MAX_NODES);
            if let Some(f) = b.master.cycle(&b.targets[..n], now) {
                fault = fault.or(Some(f));
            }
        }
        self.trace_period();
        self.bus_reaction();
        if let Some(f) = fault {
            if self.reason.is_none() {
                self.set_reason(StopReason::Fault(f));
                self.follower.request_stop();
                if matches!(
                    self.stage(),
                    Stage::Running | Stage::Approach | Stage::Enabling
                ) {
                    self.phase = Phase::Disabling;
                    self.stage_cycles = 0;
                }
            }
        }
        CycleInfo {
            compute_ns,
            finished: self.stage() == Stage::Finished,
        }
    }
}
