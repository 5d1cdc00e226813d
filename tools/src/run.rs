//! `dnurbs run` and `dnurbs demo`: the whole machine.
//!
//! Three threads:
//! * the **planner** parses and validates the program, builds the segments (arc-length
//!   tables), plans the feed over the whole program, and streams the planned segments into
//!   the preallocated queue (`nc_follow`), freeing the ones the interpolator hands back
//!   ([`crate::feed`]);
//! * the **real-time thread** (SCHED_FIFO, memory locked, stack prefaulted) runs
//!   [`rt_loop::pipeline::drive_loop`]: interpolation, drive counts, RPDOs + SYNC, histograms;
//! * this thread sets the drives up (SDO), then reports: it writes the interval histograms to
//!   `latency.hlog`, prints progress on stderr when that is a terminal, and at the end prints
//!   and writes the latency report ([`realtime`]).
//!
//! [`simulated`] runs the same stages against simulated drives on a virtual clock: the loop,
//! the planner's rounds and the drives' answers take turns, a period at a time, so a whole
//! run takes the time its computation takes and does not depend on the machine's load.
//!
//! Files: this one (options, result, what both share), `buses.rs` (each bus's drives set up
//! and handed to a master), `realtime.rs` (the threads of a real run), `simulated.rs`.

pub(crate) mod buses;
mod realtime;
pub mod simulated;
pub mod trace;

pub use buses::home_request;

use crate::feed::{Input, Learned, Pace, Ready};
use crate::report::{BusNotes, DriveEnd, Report, StreamNotes, AXES};
use crate::setup::MachineSetup;
use crate::InputError;
use config::Machine;
use drives::link::CanLink;
use drives::master::{NodeSetup, VelocitySetup};
use drives::wire::NodeId;
use nc_follow::{Feeder, Follower, Queues, Start};
use rt_loop::pipeline::{ApproachLimits, BusDrives, Pipeline, StopReason};
use rt_loop::stats::Stats;
use rt_loop::thread::{RtMode, RtSettings};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// How to run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Program name for messages (the file path).
    pub name: String,
    /// Move the axes to the program's start before it (otherwise they must be there).
    pub approach: bool,
    /// Real-time settings; `priority: None` is --no-rt.
    pub rt: RtSettings,
    /// Wake this long before each deadline to rehearse the step and wait on the clock
    /// ([`rt_loop::pipeline::drive_loop`]); 0 sleeps to the deadline.
    pub lead_ns: u64,
    /// If the real-time privileges are missing, run without them (demo) instead of failing.
    pub rt_fallback: bool,
    pub report: Option<PathBuf>,
    /// Print progress on stderr (when it is a terminal).
    pub progress: bool,
    /// Serve the operator's control socket here ([`crate::control`]).
    pub control: Option<PathBuf>,
    /// Tool table and switches for the parser.
    pub shop: crate::shop::ShopOptions,
    /// Write every target as sent to the drives into this file (`--trace`).
    pub trace: Option<PathBuf>,
}

/// What a run did.
#[derive(Debug)]
pub struct RunResult {
    pub stats: Stats,
    /// Why it stopped early; `None` when the program ran to its end.
    pub reason: Option<StopReason>,
    /// The program line being machined when the stop began.
    pub stop_line: Option<u32>,
    /// How the real-time thread ran.
    pub realtime: RtMode,
    /// When the run started (UTC, RFC 3339).
    pub started: String,
    /// Per drive: axis, node, last target, last actual position (counts).
    pub drives: Vec<(usize, u8, i32, i32)>,
    /// Per drive: the program's end point in counts (same order as `drives`).
    pub end_counts: Vec<Option<i32>>,
    /// Per bus: error frames, dropped frames and the reactions they called for.
    pub buses: Vec<BusNotes>,
    pub underruns: u64,
    pub hard_stops: u64,
    /// `M66` waits that ended at their timeout, and the line of the last.
    pub input_timeouts: (u64, Option<u32>),
    /// Spindle, coolant, tool, stop and dwell words of the program (`crate::words`).
    pub program_words: Vec<String>,
    /// What on-line compression did, when it was on.
    pub compressed: Option<crate::simulate::Compression>,
    /// Why the program was refused ahead of the tool (`file:line:col: reason`), if it was.
    pub refusal: Option<String>,
    /// How the planner streamed the program.
    pub stream: Option<StreamNotes>,
    /// What `--trace` wrote.
    pub trace: Option<crate::report::TraceNotes>,
}

impl RunResult {
    /// The report of this run of `program` on `machine`.
    pub fn report(&self, program: &str, machine: &str) -> Report {
        let outcome = crate::report::outcome(self.reason.as_ref(), self.stats.overruns);
        Report {
            dnurbs_version: env!("CARGO_PKG_VERSION"),
            started: self.started.clone(),
            program: program.to_owned(),
            machine: machine.to_owned(),
            outcome: outcome.name(),
            exit_code: outcome.code(),
            stop_reason: self.reason.map(|r| r.to_string()),
            stop_node: self.reason.and_then(|r| r.node()),
            stop_line: self.stop_line.filter(|&l| l > 0).map(|l| l as usize),
            realtime: self.realtime.clone(),
            overruns: self.stats.overruns,
            max_consecutive_overruns: self.stats.max_consecutive_overruns,
            feed_holds: self.underruns,
            hard_stops: self.hard_stops,
            input_timeouts: (self.input_timeouts.0 > 0).then_some(crate::report::InputTimeouts {
                count: self.input_timeouts.0,
                last_line: self.input_timeouts.1,
            }),
            drives: self
                .drives
                .iter()
                .zip(&self.end_counts)
                .map(|(&(axis, node, target, actual), &end)| DriveEnd {
                    axis: AXES.get(axis).copied().unwrap_or("?"),
                    node,
                    target_counts: target,
                    actual_counts: actual,
                    program_end_counts: end,
                })
                .collect(),
            buses: self.buses.clone(),
            latency: self.stats.summary(),
            program_words: self.program_words.clone(),
            compressed: self.compressed,
            refusal: self.refusal.clone(),
            stream: self.stream,
            trace: self.trace.clone(),
        }
    }
}

/// Every axis must have a drive for `run`.
fn check_drives(m: &Machine) -> Result<(), InputError> {
    for (j, (name, _)) in m.axes.all().iter().enumerate() {
        if !m.drives.iter().any(|d| d.axis == j) {
            return Err(InputError::MachineUse(format!(
                "machine {:?}: axis {name} has no drive: add [axes.{}.drive] with bus, node and \
                 counts_per_unit",
                m.name,
                name.to_lowercase()
            )));
        }
    }
    if m.buses.is_empty() {
        return Err(InputError::MachineUse(format!(
            "machine {:?} has no [[bus]]: dnurbs run needs the CAN bus of the drives",
            m.name
        )));
    }
    Ok(())
}

/// How long the spindle's velocity must stay in its window before the drive reports the
/// speed reached (0x606E), ms.
pub const AT_SPEED_WINDOW_MS: u16 = 100;

/// The nodes of bus `bus` in the master's order: the axes' drives (X Y Z tilt C), then the
/// spindle drive, then the I/O module (the coolant valves', the program's `[io]`).
pub fn node_setups(machine: &Machine, bus: usize) -> Vec<NodeSetup> {
    let mut v: Vec<NodeSetup> = machine
        .drives
        .iter()
        .filter(|d| d.bus == bus)
        .filter_map(|d| {
            let limits = machine.axes.all().get(d.axis).map(|(_, l)| (*l).clone());
            Some(NodeSetup::Position(
                NodeId::new(d.node)?,
                buses::protections(d, limits),
            ))
        })
        .collect();
    if let Some(s) = machine.spindle.as_ref() {
        if let Some(n) = s.on_bus(bus).and_then(NodeId::new) {
            let setup = VelocitySetup {
                ramp: s.ramp_units(s.acceleration_rpm_s),
                quick_stop: s.ramp_units(s.quick_stop_rpm_s),
                window: s.window_units(),
                window_ms: AT_SPEED_WINDOW_MS,
            };
            v.push(NodeSetup::Velocity(n, setup));
        }
    }
    if let Some(node) = machine.io_module(bus) {
        v.extend(NodeId::new(node).map(NodeSetup::Io));
    }
    v
}

/// Starts the planner thread ([`crate::feed`]) at `pace` and waits for its first window
/// while this one watches `stop`: a stop requested meanwhile ends the run at once, before
/// any drive is touched (the planner thread is left to end alone; the process's exit ends
/// it, or its pace once the run is over).
fn start_planner(
    job: crate::feed::Job,
    feeder: Feeder<'static>,
    pace: Pace,
    learned: Arc<Learned>,
    stop: &AtomicBool,
) -> anyhow::Result<Ready> {
    let (tx, rx) = std::sync::mpsc::sync_channel(1);
    std::thread::Builder::new()
        .name("dnurbs-planner".into())
        .spawn(move || crate::feed::plan_and_feed(&job, feeder, pace, tx, &learned))?;
    loop {
        match rx.recv_timeout(Duration::from_millis(20)) {
            Ok(ready) => return Ok(ready?),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                if stop.load(Ordering::Relaxed) {
                    Err(crate::exit::StoppedBeforeMotion {
                        stage: "planning the program",
                    })?;
                }
            }
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                anyhow::bail!("the planner thread ended without a result")
            }
        }
    }
}

/// What a run has ready before its drives are touched: the machine as the planner sees it,
/// the queues (their planner's end given to the planner thread), the program's start.
struct Staged {
    started: String,
    setup: MachineSetup,
    inlet: nc_follow::Inlet<'static>,
    ready: Ready,
    learned: Arc<Learned>,
}

/// What both runners check first: every axis has a drive, every bus carries its load.
fn check(machine: &Machine) -> anyhow::Result<()> {
    check_drives(machine)?;
    crate::check_bus_load(machine)?;
    Ok(())
}

/// Plans the program's first window in the planner thread (at `pace`)
/// and returns once it is ready. `stop` ends it before then. `operator`: someone can resume
/// the program's operator stops (a control socket, or a simulated operator).
fn stage(
    input: Input,
    machine: &Machine,
    opts: &RunOptions,
    pace: Pace,
    operator: bool,
    stop: &AtomicBool,
) -> anyhow::Result<Staged> {
    let started = crate::report::now_utc();
    let setup = MachineSetup::new(machine).with_compress(opts.shop.compress);
    let shop = crate::shop::parse_setup(machine, &opts.shop)?;
    // The queues live as long as the process: the planner thread may outlive a run that a
    // stop ended while it planned.
    let queues: &'static mut Queues = Box::leak(Queues::new());
    let (feeder, inlet) = queues.split(machine.realtime.queue_depth);
    let learned = Arc::new(Learned::default());
    let job = crate::feed::Job {
        input,
        name: opts.name.clone(),
        setup: setup.clone(),
        shop,
        depth: machine.realtime.queue_depth,
        control: operator,
    };
    let ready = start_planner(job, feeder, pace, Arc::clone(&learned), stop)?;
    Ok(Staged {
        started,
        setup,
        inlet,
        ready,
        learned,
    })
}

impl Staged {
    fn start(&self) -> Start {
        self.ready.start
    }

    /// The pipeline over the set-up buses, the follower reading the staged queue.
    fn pipeline<L: CanLink>(
        self,
        machine: &Machine,
        opts: &RunOptions,
        buses: Vec<BusDrives<L>>,
    ) -> Result<(Pipeline<'static, L>, Finished), InputError> {
        let start = self.start();
        let setup = &self.setup;
        let lim = |f: fn(&config::AxisLimits) -> f64| -> [f64; 5] {
            core::array::from_fn(|j| f(&setup.limits[j]))
        };
        let approach = opts.approach.then(|| ApproachLimits {
            velocity: lim(|l| l.velocity),
            acceleration: lim(|l| l.acceleration),
            jerk: lim(|l| l.jerk),
        });
        let drive_axes: Vec<_> = buses
            .iter()
            .flat_map(|b| b.drives.iter())
            .map(|d| (d.axis, d.clone()))
            .collect();
        let follower = Follower::new(
            self.inlet,
            start,
            setup.kin,
            setup.plan.rotary,
            setup.plan.hold(),
        );
        let rtc = &machine.realtime;
        let enable_cycles = (rtc.boot_timeout_s / machine.period_s).ceil() as u64;
        let mut pipeline = Pipeline::new(
            follower,
            buses,
            start.joints,
            machine.period_s,
            approach,
            machine.axes.c.is_unlimited(),
            enable_cycles,
        )?;
        pipeline.set_max_consecutive_overruns(rtc.max_consecutive_overruns);
        let finished = Finished {
            started: self.started,
            ready: self.ready,
            learned: self.learned,
            drive_axes,
            bus_names: machine.buses.iter().map(|b| b.interface.clone()).collect(),
        };
        Ok((pipeline, finished))
    }
}

/// What the result needs once the loop is over.
struct Finished {
    started: String,
    ready: Ready,
    learned: Arc<Learned>,
    drive_axes: Vec<(usize, config::bus::Drive)>,
    /// Each bus's interface, in the machine file's order.
    bus_names: Vec<String>,
}

impl Finished {
    /// The run's result, from what the loop measured and what the pipeline ended with.
    fn result<L: CanLink>(
        self,
        pipeline: &Pipeline<'_, L>,
        stats: Stats,
        realtime: RtMode,
    ) -> RunResult {
        // The program's end, for the closing check of the drive positions: known once the
        // pre-pass or the planner has read the whole program.
        let end = self.learned.end_joints.get().copied();
        let end_counts = self
            .drive_axes
            .iter()
            .map(|(axis, d)| {
                let v = end?[*axis];
                d.counts(if *axis >= 3 { v.to_degrees() } else { v })
            })
            .collect();
        let c = pipeline.follower.counters();
        RunResult {
            stats,
            reason: pipeline.reason(),
            stop_line: pipeline.stop_line(),
            realtime,
            started: self.started,
            drives: pipeline.drive_positions().collect(),
            buses: pipeline
                .bus_health()
                .zip(&self.bus_names)
                .map(|((h, dropped), name)| BusNotes::new(name, h, dropped))
                .collect(),
            end_counts,
            underruns: c.underruns,
            hard_stops: c.hard_stops,
            input_timeouts: pipeline.follower.input_timeouts(),
            program_words: self.learned.words(),
            compressed: self.learned.compressed(),
            refusal: self.learned.refusal().map(|r| r.1),
            stream: Some(StreamNotes {
                first_window_s: self.ready.first_window_s,
                checked_whole: self.ready.checked_whole,
                lines: self.learned.lines.get().copied(),
            }),
            trace: None,
        }
    }
}

/// Run `src` on `machine`. `open_links` gives one link per `[[bus]]` (in the machine file's
/// order); it is called once the program has been parsed, built and planned, so a bad
/// program is reported before anything touches the bus.
pub fn run<L: CanLink + Send>(
    src: &[u8],
    machine: &Machine,
    open_links: impl FnOnce() -> anyhow::Result<Vec<L>>,
    opts: &RunOptions,
) -> anyhow::Result<RunResult> {
    run_input(Input::Text(src.into()), machine, open_links, opts)
}

/// [`run`] of a program from `input` (a file is read a line at a time as it runs), in real
/// time ([`realtime`]).
pub fn run_input<L: CanLink + Send>(
    input: Input,
    machine: &Machine,
    open_links: impl FnOnce() -> anyhow::Result<Vec<L>>,
    opts: &RunOptions,
) -> anyhow::Result<RunResult> {
    realtime::run(input, machine, open_links, opts)
}
