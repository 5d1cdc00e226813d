//! `dnurbs run` and `dnurbs demo`: the whole machine.
//!
//! Three threads:
//! * the **planner** parses and validates the program, builds the segments (arc-length
//!   tables), plans the feed over the whole program, and streams the planned segments into
//!   the preallocated queue (`nc::stream`), freeing the ones the interpolator hands back;
//! * the **real-time thread** (SCHED_FIFO, memory locked, stack prefaulted) runs
//!   [`rt_loop::pipeline::drive_loop`]: interpolation, drive counts, RPDOs + SYNC, histograms;
//! * this thread sets the drives up (SDO), then reports: it writes the interval histograms to
//!   `latency.hlog`, prints progress on stderr when that is a terminal, and at the end prints
//!   and writes the latency report.

use crate::exit::StoppedBeforeMotion;
use crate::feed::{Input, Learned, Ready};
use crate::report::{DriveEnd, Report, StreamNotes, AXES};
use crate::setup::MachineSetup;
use crate::InputError;
use config::Machine;
use drives::link::{CanLink, MemLink, SocketLink};
use drives::master::{
    configure_nodes, Master, NodeSetup, SetupOptions, Supervision, VelocitySetup,
};
use drives::wire::NodeId;
use nc_follow::{Follower, Queues};
use rt_loop::control::{Command, Commands, Producer};
use rt_loop::interval::{Interval, Queues as IntervalQueues, Recorder};
use rt_loop::latency::INTERVAL_NS;
use rt_loop::os;
use rt_loop::pipeline::{drive_loop, ApproachLimits, BusDrives, Pipeline, Progress, StopReason};
use rt_loop::stats::Stats;
use rt_loop::thread::RtMode;
use rt_loop::thread::RtSettings;
use std::io::IsTerminal;
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
    /// ([`drive_loop`]); 0 sleeps to the deadline.
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
    pub underruns: u64,
    pub hard_stops: u64,
    /// Spindle, coolant, tool, stop and dwell words of the program (`crate::words`).
    pub program_words: Vec<String>,
    /// What on-line compression did, when it was on.
    pub compressed: Option<crate::simulate::Compression>,
    /// Why the program was refused ahead of the tool (`file:line:col: reason`), if it was.
    pub refusal: Option<String>,
    /// How the planner streamed the program.
    pub stream: Option<StreamNotes>,
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
            latency: self.stats.summary(),
            program_words: self.program_words.clone(),
            compressed: self.compressed,
            refusal: self.refusal.clone(),
            stream: self.stream,
        }
    }
}

/// Starts the planner thread ([`crate::feed`]) and waits for its first window while this
/// one watches for SIGINT and SIGTERM: a stop requested meanwhile ends `run` at once, before
/// any drive is touched (the planner thread is left to end alone; the process's exit ends
/// it, or the `finished` flag once it reads it).
fn start_planner(
    job: crate::feed::Job,
    feeder: nc_follow::Feeder<'static>,
    finished: Arc<AtomicBool>,
    learned: Arc<Learned>,
) -> anyhow::Result<Ready> {
    let (tx, rx) = std::sync::mpsc::sync_channel(1);
    std::thread::Builder::new()
        .name("dnurbs-planner".into())
        .spawn(move || crate::feed::plan_and_feed(&job, feeder, &finished, tx, &learned))?;
    let stop = os::stop_requested();
    loop {
        match rx.recv_timeout(Duration::from_millis(20)) {
            Ok(ready) => return Ok(ready?),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                if stop.load(Ordering::Relaxed) {
                    Err(StoppedBeforeMotion {
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
/// spindle drive, then the coolant I/O module.
pub fn node_setups(machine: &Machine, bus: usize) -> Vec<NodeSetup> {
    let mut v: Vec<NodeSetup> = machine
        .drives
        .iter()
        .filter(|d| d.bus == bus)
        .filter_map(|d| NodeId::new(d.node).map(NodeSetup::Position))
        .collect();
    if let Some(s) = machine.spindle.as_ref().filter(|s| s.bus == bus) {
        if let Some(n) = NodeId::new(s.node) {
            let setup = VelocitySetup {
                ramp: s.ramp_units(s.acceleration_rpm_s),
                quick_stop: s.ramp_units(s.quick_stop_rpm_s),
                window: s.window_units(),
                window_ms: AT_SPEED_WINDOW_MS,
            };
            v.push(NodeSetup::Velocity(n, setup));
        }
    }
    if let Some(c) = machine.coolant.as_ref().filter(|c| c.bus == bus) {
        v.extend(NodeId::new(c.node).map(NodeSetup::Io));
    }
    v
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

/// [`run`] of a program from `input` (a file is read a line at a time as it runs).
pub fn run_input<L: CanLink + Send>(
    input: Input,
    machine: &Machine,
    open_links: impl FnOnce() -> anyhow::Result<Vec<L>>,
    opts: &RunOptions,
) -> anyhow::Result<RunResult> {
    check_drives(machine)?;
    crate::check_bus_load(machine)?;
    let started = crate::report::now_utc();
    let setup = MachineSetup::new(machine).with_compress(opts.shop.compress);
    let shop = crate::shop::parse_setup(machine, &opts.shop);
    let rtc = &machine.realtime;
    let period = machine.period_s;
    let period_ns = (period * 1e9).round() as u64;
    // The queues live as long as the process: the planner thread may outlive a run that a
    // stop ended while it planned.
    let queues: &'static mut Queues = Box::leak(Queues::new());
    let (feeder, inlet) = queues.split(rtc.queue_depth);
    let mut commands = Commands::new();
    let (command_tx, command_rx) = commands.split();
    let server = match &opts.control {
        Some(path) => {
            let tilt = if machine.axes.tilt_name == config::RotaryName::B {
                "B"
            } else {
                "A"
            };
            Some(crate::control::Server::bind(
                path,
                ["X", "Y", "Z", tilt, "C"],
            )?)
        }
        None => None,
    };
    let finished = Arc::new(AtomicBool::new(false));
    let log = match &opts.report {
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
            let p = dir.join("latency.hlog");
            Some(
                rt_loop::report::HlogFile::create(&p)
                    .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", p.display()))?,
            )
        }
        None => None,
    };
    os::install_stop_handler()?;
    let stop = os::stop_requested();
    let learned = Arc::new(Learned::default());
    let job = crate::feed::Job {
        input,
        name: opts.name.clone(),
        setup: setup.clone(),
        shop,
        depth: rtc.queue_depth,
        control: opts.control.is_some(),
    };
    // Whatever way the run ends, the planner thread is told.
    struct Finish(Arc<AtomicBool>);
    impl Drop for Finish {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Release);
        }
    }
    let _finish = Finish(Arc::clone(&finished));
    let ready = start_planner(job, feeder, Arc::clone(&finished), Arc::clone(&learned))?;
    let start = ready.start;
    // Checked before each bus is set up and before the real-time thread starts.
    let stop_before_motion = || -> anyhow::Result<()> {
        if stop.load(Ordering::Relaxed) {
            Err(StoppedBeforeMotion {
                stage: "setting up the drives",
            })?;
        }
        Ok(())
    };

    {
        let result = (|| -> anyhow::Result<RunResult> {
            // Drive set-up on every bus (SDO, PDO mapping, NMT start).
            let mut sopts = SetupOptions::new(period);
            sopts.boot_timeout = Duration::from_secs_f64(rtc.boot_timeout_s);
            sopts.sdo_timeout = Duration::from_secs_f64(rtc.sdo_timeout_s);
            let sup = Supervision {
                heartbeat_timeout_s: rtc.heartbeat_timeout_s,
                feedback_timeout_cycles: (rtc.feedback_timeout_s / period).ceil() as u32,
            };
            let mut buses = Vec::new();
            stop_before_motion()?;
            for (bi, mut link) in open_links()?.into_iter().enumerate() {
                stop_before_motion()?;
                let drives: Vec<config::bus::Drive> = machine
                    .drives
                    .iter()
                    .filter(|d| d.bus == bi)
                    .cloned()
                    .collect();
                let setups = node_setups(machine, bi);
                let bus_name = &machine.buses[bi].interface;
                let initial = configure_nodes(&mut link, &setups, &sopts, &mut |_| {})
                    .map_err(|e| anyhow::anyhow!("drive set-up on {bus_name}: {e}"))?;
                let kinds: Vec<_> = setups.iter().map(|s| (s.node(), s.kind())).collect();
                let now = os::now() as f64 * 1e-9;
                let master = Master::with_kinds(link, &kinds, &initial, sup, now)
                    .ok_or_else(|| anyhow::anyhow!("{bus_name}: too many drives on one bus"))?;
                let mut bus = BusDrives::new(master, &drives)
                    .ok_or_else(|| anyhow::anyhow!("{bus_name}: too many drives"))?;
                if let Some(s) = machine.spindle.as_ref().filter(|s| s.bus == bi) {
                    bus = bus.with_spindle(s.clone());
                }
                if let Some(c) = machine.coolant.as_ref().filter(|c| c.bus == bi) {
                    bus = bus.with_coolant(c.clone());
                }
                buses.push(bus);
            }
            stop_before_motion()?;
            let drive_axes: Vec<_> = buses
                .iter()
                .flat_map(|b| b.drives.iter())
                .map(|d| (d.axis, d.clone()))
                .collect();
            let lim = |f: fn(&config::AxisLimits) -> f64| -> [f64; 5] {
                core::array::from_fn(|j| f(&setup.limits[j]))
            };
            let approach = opts.approach.then(|| ApproachLimits {
                velocity: lim(|l| l.velocity),
                acceleration: lim(|l| l.acceleration),
                jerk: lim(|l| l.jerk),
            });
            let follower = Follower::new(
                inlet,
                start,
                setup.kin,
                setup.plan.rotary,
                setup.plan.hold(),
            );
            let enable_cycles = (rtc.boot_timeout_s / period).ceil() as u64;
            let mut pipeline = Pipeline::new(
                follower,
                buses,
                start.joints,
                period,
                approach,
                machine.axes.c.is_unlimited(),
                enable_cycles,
            )
            .map_err(InputError::from)?;
            pipeline.set_max_consecutive_overruns(rtc.max_consecutive_overruns);
            pipeline.set_commands(command_rx);
            let control = server.as_ref().map(|s| (s, command_tx));
            let r = run_threads(&mut pipeline, period_ns, stop, opts, log, control)?;
            // The program's end, for the closing check of the drive positions: known once
            // the pre-pass or the planner has read the whole program.
            let end = learned.end_joints.get().copied();
            let end_counts = drive_axes
                .iter()
                .map(|(axis, d)| {
                    let v = end?[*axis];
                    d.counts(if *axis >= 3 { v.to_degrees() } else { v })
                })
                .collect();
            Ok(RunResult {
                started,
                program_words: learned.words(),
                compressed: learned.compressed(),
                end_counts,
                refusal: learned.refusal().map(|r| r.1),
                stream: Some(StreamNotes {
                    first_window_s: ready.first_window_s,
                    checked_whole: ready.checked_whole,
                    lines: learned.lines.get().copied(),
                }),
                ..r
            })
        })();
        finished.store(true, Ordering::Release);
        result
    }
}

fn run_threads<L: CanLink + Send>(
    pipeline: &mut Pipeline<'_, L>,
    period_ns: u64,
    stop: &'static AtomicBool,
    opts: &RunOptions,
    mut log: Option<rt_loop::report::HlogFile>,
    control: Option<(&crate::control::Server, Producer<'_, Command>)>,
) -> anyhow::Result<RunResult> {
    let (mut iq, first) = IntervalQueues::new();
    let (full_p, mut full_c) = iq.full.split();
    let (mut free_p, free_c) = iq.free.split();
    let progress = Progress::default();
    let done = AtomicBool::new(false);
    let t0 = os::now();
    let (rt, lead) = (opts.rt, opts.lead_ns);
    let fallback = opts.rt_fallback;
    let _poller = rt.idle_poller()?;
    std::thread::scope(|scope| -> anyhow::Result<RunResult> {
        let (progress, done) = (&progress, &done);
        if let Some((server, mut tx)) = control {
            std::thread::Builder::new()
                .name("dnurbs-control".into())
                .spawn_scoped(scope, move || server.serve(&mut tx, progress, done))?;
        }
        let pl = &mut *pipeline;
        let rt_thread = rt_loop::thread::spawn_rt(
            scope,
            rt,
            fallback,
            move |realtime| {
                let mut rec = Recorder::new(first, full_p, free_c, INTERVAL_NS, os::now());
                let faults = os::minor_faults();
                drive_loop(&mut rec, pl, period_ns, lead, stop, progress, u64::MAX);
                let faults = os::minor_faults() - faults;
                (rec.finish(os::now()), faults, realtime)
            },
            move || done.store(true, Ordering::Release),
        )?;
        let mut totals = Stats::new();
        let mut report = |iv: &Interval, totals: &mut Stats| -> anyhow::Result<()> {
            totals.add(&iv.stats);
            if let Some(l) = log.as_mut() {
                l.append(iv, t0)?;
            }
            Ok(())
        };
        let tty = opts.progress && std::io::stderr().is_terminal();
        let mut last_print = std::time::Instant::now();
        loop {
            let finished = done.load(Ordering::Acquire);
            while let Some(mut iv) = full_c.dequeue() {
                report(&iv, &mut totals)?;
                iv.stats.clear();
                let _ = free_p.enqueue(iv);
            }
            if finished {
                break;
            }
            if tty && last_print.elapsed() >= Duration::from_millis(250) {
                last_print = std::time::Instant::now();
                eprint!(
                    "\r{}: {:5.1} %   cycle {}   overruns {}   feed holds {}   ",
                    opts.name,
                    progress.ppm.load(Ordering::Relaxed) as f64 / 1e4,
                    progress.cycles.load(Ordering::Relaxed),
                    progress.overruns.load(Ordering::Relaxed),
                    progress.underruns.load(Ordering::Relaxed),
                );
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        if tty {
            eprintln!();
        }
        let joined = rt_thread
            .join()
            .map_err(|_| anyhow::anyhow!("the real-time thread panicked"))?;
        let (last, faults, realtime) = joined.map_err(|e| anyhow::anyhow!("{e}"))?;
        report(&last, &mut totals)?;
        totals.minor_faults = faults;
        Ok(RunResult {
            stats: totals,
            reason: None,
            stop_line: None,
            started: String::new(),
            realtime,
            drives: Vec::new(),
            end_counts: Vec::new(),
            underruns: 0,
            hard_stops: 0,
            program_words: Vec::new(),
            compressed: None,
            refusal: None,
            stream: None,
        })
    })
    .map(|mut r| {
        r.reason = pipeline.reason();
        r.stop_line = pipeline.stop_line();
        r.drives = pipeline.drive_positions().collect();
        let c = pipeline.follower.counters();
        r.underruns = c.underruns;
        r.hard_stops = c.hard_stops;
        r
    })
}

/// The demo's machine: the paper's machine (its drives on an in-process bus).
pub const DEMO_MACHINE: &str = include_str!("../../config/machines/paper-ac-table.toml");
/// The demo's program: the paper's example.
pub const DEMO_PROGRAM: &str = include_str!("../../tests/data/paper-example.nc");

/// The in-process bus of `dnurbs demo` (`--link`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DemoLink {
    /// Lock-free queues in memory (`MemLink`): the cycle makes no system call for the bus.
    Memory,
    /// A kernel socketpair (`SocketLink::pair`) carrying `can_frame` structs through the
    /// same system calls as a CAN interface (`sendmmsg`/`recvmmsg` per cycle).
    Socketpair,
}

/// Frames each direction of the demo's memory bus holds (a few hundred periods' worth).
pub const DEMO_QUEUE_FRAMES: usize = 1024;

/// `dnurbs demo`: the paper's example on the paper's machine, its five drives simulated in a
/// thread on the other end of an in-process link.
pub fn demo(
    opts: &RunOptions,
    link: DemoLink,
    input: Input,
) -> anyhow::Result<(RunResult, Vec<drives::sim::Record>)> {
    let machine = config::from_str(
        DEMO_MACHINE,
        std::path::Path::new("config/machines/paper-ac-table.toml"),
    )?;
    match link {
        DemoLink::Memory => demo_on(&machine, opts, input, || {
            Ok(MemLink::pair(DEMO_QUEUE_FRAMES))
        }),
        DemoLink::Socketpair => demo_on(&machine, opts, input, SocketLink::pair),
    }
}

fn demo_on<L: CanLink + Send + 'static>(
    machine: &Machine,
    opts: &RunOptions,
    input: Input,
    pair: impl Fn() -> std::io::Result<(L, L)>,
) -> anyhow::Result<(RunResult, Vec<drives::sim::Record>)> {
    let mut links = Vec::new();
    let mut sims = Vec::new();
    for bi in 0..machine.buses.len() {
        let (master_end, drive_end) = pair()?;
        let nodes = crate::simdrives::sim_nodes(machine, bi, 0.0, &Default::default());
        // The drives answer within their cycle: with real-time privileges their thread runs
        // SCHED_FIFO one priority below the controller's, so a loaded host cannot starve it.
        let below = opts.rt.priority.map(|p| (p - 1).max(1));
        sims.push(drives::sim::SimThread::start_with(
            drive_end,
            nodes,
            machine.period_s,
            Duration::from_micros(200),
            move || {
                if let Some(p) = below {
                    let _ = os::set_fifo(p);
                }
            },
        )?);
        links.push(master_end);
    }
    let result = run_input(input, machine, move || Ok(links), opts);
    let records = sims.into_iter().flat_map(|s| s.finish()).collect();
    Ok((result?, records))
}
