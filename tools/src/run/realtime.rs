//! A run in real time: the planner thread, the drives set up on their buses, the real-time
//! thread running the loop, and this thread reporting (the `.hlog`, the progress line) while
//! the control socket's thread serves the operator.

use super::trace::TraceWriter;
use super::{buses, check, stage, RunOptions, RunResult};
use crate::exit::StoppedBeforeMotion;
use crate::feed::{Input, Pace};
use config::Machine;
use drives::link::CanLink;
use drives::master::WallClock;
use rt_loop::clock::OsClock;
use rt_loop::control::{Command, Commands, Producer};
use rt_loop::interval::{Interval, Queues as IntervalQueues, Recorder};
use rt_loop::latency::INTERVAL_NS;
use rt_loop::os;
use rt_loop::pipeline::{drive_loop, Pipeline, Progress};
use rt_loop::stats::Stats;
use rt_loop::thread::RtMode;
use rt_loop::trace::{Consumer, TraceRing, TraceRow};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// [`super::run_input`].
pub(super) fn run<L: CanLink + Send>(
    input: Input,
    machine: &Machine,
    open_links: impl FnOnce() -> anyhow::Result<Vec<L>>,
    opts: &RunOptions,
) -> anyhow::Result<RunResult> {
    check(machine)?;
    let period_ns = (machine.period_s * 1e9).round() as u64;
    let mut commands = Commands::new();
    let (command_tx, command_rx) = commands.split();
    let mut writer = match &opts.trace {
        Some(file) => Some(TraceWriter::create(file, machine)?),
        None => None,
    };
    let mut ring = writer.as_ref().map(|_| Box::new(TraceRing::new()));
    let (trace_tx, trace_rx) = match ring.as_mut() {
        Some(r) => {
            let (p, c) = r.split();
            (Some(p), Some(c))
        }
        None => (None, None),
    };
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
    let finished = Arc::new(AtomicBool::new(false));
    // Whatever way the run ends, the planner thread is told.
    struct Finish(Arc<AtomicBool>);
    impl Drop for Finish {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Release);
        }
    }
    let _finish = Finish(Arc::clone(&finished));
    let staged = stage(
        input,
        machine,
        opts,
        Pace::Wall(Arc::clone(&finished)),
        opts.control.is_some(),
        stop,
    )?;
    // Checked before each bus is set up and before the real-time thread starts.
    let stop_before_motion = || -> anyhow::Result<()> {
        if stop.load(Ordering::Relaxed) {
            Err(StoppedBeforeMotion {
                stage: "setting up the drives",
            })?;
        }
        Ok(())
    };
    stop_before_motion()?;
    let mut buses = Vec::new();
    for (bi, link) in open_links()?.into_iter().enumerate() {
        stop_before_motion()?;
        let now = |_: &WallClock| os::now() as f64 * 1e-9;
        buses.push(buses::set_up(
            machine,
            bi,
            link,
            &mut WallClock::default(),
            now,
        )?);
    }
    stop_before_motion()?;
    let (mut pipeline, finish) = staged.pipeline(machine, opts, buses)?;
    pipeline.set_commands(command_rx);
    if let Some(p) = trace_tx {
        pipeline.set_trace(p).map_err(too_many_nodes)?;
    }
    let control = server.as_ref().map(|s| (s, command_tx));
    let trace = writer.as_mut().zip(trace_rx);
    let (stats, realtime) = run_threads(&mut pipeline, period_ns, stop, opts, log, control, trace)?;
    let mut r = finish.result(&pipeline, stats, realtime);
    if let Some(w) = writer {
        r.trace = Some(w.finish(pipeline.trace_dropped())?);
    }
    finished.store(true, Ordering::Release);
    Ok(r)
}

/// `set_trace`'s refusal: more nodes than a trace row holds.
pub(super) fn too_many_nodes(nodes: usize) -> anyhow::Error {
    anyhow::anyhow!(
        "--trace holds at most {} nodes a period; this machine has {nodes}",
        rt_loop::trace::TRACE_NODES
    )
}

/// The real-time thread runs the loop; this one reports until it ends. Returns the totals
/// of every interval and how the thread ran.
fn run_threads<L: CanLink + Send>(
    pipeline: &mut Pipeline<'_, L>,
    period_ns: u64,
    stop: &'static AtomicBool,
    opts: &RunOptions,
    mut log: Option<rt_loop::report::HlogFile>,
    control: Option<(&crate::control::Server, Producer<'_, Command>)>,
    mut trace: Option<(&mut TraceWriter, Consumer<'_, TraceRow>)>,
) -> anyhow::Result<(Stats, RtMode)> {
    let (mut iq, first) = IntervalQueues::new();
    let (full_p, mut full_c) = iq.full.split();
    let (mut free_p, free_c) = iq.free.split();
    let progress = Progress::default();
    let done = AtomicBool::new(false);
    let t0 = os::now();
    let (rt, lead) = (opts.rt, opts.lead_ns);
    let fallback = opts.rt_fallback;
    let _poller = rt.idle_poller()?;
    std::thread::scope(|scope| -> anyhow::Result<(Stats, RtMode)> {
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
                let mut clock = OsClock;
                drive_loop(
                    &mut rec,
                    pl,
                    &mut clock,
                    period_ns,
                    lead,
                    stop,
                    progress,
                    u64::MAX,
                );
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
            if let Some((w, rows)) = trace.as_mut() {
                w.drain(rows)?;
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
        Ok((totals, realtime))
    })
}
