//! A run on simulated time: the stages of a real run ([`super::realtime`]) against simulated
//! drives on a virtual clock. The loop is the real-time thread's, on a [`VirtualClock`];
//! while it "sleeps" to its next deadline, the rest of the machine takes its turn: each
//! bus's drives answer the period's frames ([`Lockstep`]), the planner thread takes one
//! round ([`Pace::Lockstep`]), the operator's hand acts on what the loop published, the
//! intervals go to the report. Then the clock jumps to the deadline.
//!
//! The run is deterministic (the same program and machine give the same targets, period
//! for period) and takes as long as its computation: what the tests of whole runs use,
//! whatever the machine's load.

use super::trace::TraceWriter;
use super::{buses, check, stage, RunOptions, RunResult};
use crate::feed::{Input, Pace};
use config::Machine;
use drives::link::CanLink;
use drives::master::Clock;
use drives::sim::{Lockstep, Record};
use rt_loop::clock::VirtualClock;
use rt_loop::control::{Command, Commands, Producer};
use rt_loop::interval::{Queues as IntervalQueues, Recorder};
use rt_loop::latency::INTERVAL_NS;
use rt_loop::pipeline::{drive_loop, Progress};
use rt_loop::stats::Stats;
use rt_loop::thread::RtMode;
use rt_loop::trace::TraceRing;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// Run `input` on `machine` whose buses are simulated: per `[[bus]]`, in the machine file's
/// order, the master's end of a link and the drives on the other. `operator` is called
/// once a period with what the loop published and may send commands, as `dnurbs ctl` would
/// (the control socket is not served). Returns the result and every target the drives
/// took, bus by bus.
pub fn run_simulated<L: CanLink + Send>(
    input: Input,
    machine: &Machine,
    sims: Vec<(L, Lockstep<L>)>,
    opts: &RunOptions,
    mut operator: impl FnMut(&Progress, &mut Producer<'_, Command>),
) -> anyhow::Result<(RunResult, Vec<Record>)> {
    check(machine)?;
    anyhow::ensure!(
        sims.len() == machine.buses.len(),
        "{} simulated buses for the machine's {}",
        sims.len(),
        machine.buses.len()
    );
    let period_ns = (machine.period_s * 1e9).round() as u64;
    let stop = AtomicBool::new(false);
    let mut writer = match &opts.trace {
        Some(file) => Some(TraceWriter::create(file, machine)?),
        None => None,
    };
    let mut ring = writer.as_ref().map(|_| Box::new(TraceRing::new()));
    let (go_tx, go) = std::sync::mpsc::sync_channel(1);
    let (done, done_rx) = std::sync::mpsc::sync_channel(1);
    let staged = stage(
        input,
        machine,
        opts,
        Pace::Lockstep { go, done },
        true,
        &stop,
    )?;
    let mut buses = Vec::new();
    let mut drives = Vec::new();
    for (bi, (link, mut sim)) in sims.into_iter().enumerate() {
        let now = |c: &Lockstep<L>| Clock::now(c).as_secs_f64();
        buses.push(buses::set_up(machine, bi, link, &mut sim, now)?);
        drives.push(sim);
    }
    // Every bus's clock where the slowest set-up left its own.
    let t0 = drives
        .iter()
        .map(|d| d.now())
        .max()
        .unwrap_or(Duration::ZERO);
    for d in drives.iter_mut() {
        d.advance_to(t0);
    }
    let t0 = t0.as_nanos() as u64;
    let (mut pipeline, finish) = staged.pipeline(machine, opts, buses)?;
    let mut commands = Commands::new();
    let (mut command_tx, command_rx) = commands.split();
    pipeline.set_commands(command_rx);
    let mut trace_rx = None;
    if let Some(r) = ring.as_mut() {
        let (p, c) = r.split();
        pipeline
            .set_trace(p)
            .map_err(super::realtime::too_many_nodes)?;
        trace_rx = Some(c);
    }
    let mut trace_error = None;
    let (mut iq, first) = IntervalQueues::new();
    let (full_p, mut full_c) = iq.full.split();
    let (mut free_p, free_c) = iq.free.split();
    let progress = Progress::default();
    let mut totals = Stats::new();
    let last = {
        let world = |t: u64| {
            for d in drives.iter_mut() {
                d.advance_to(Duration::from_nanos(t));
            }
            // One round of the planner; it hangs up only once its thread has ended.
            if go_tx.send(()).is_ok() {
                let _ = done_rx.recv();
            }
            operator(&progress, &mut command_tx);
            while let Some(mut iv) = full_c.dequeue() {
                totals.add(&iv.stats);
                iv.stats.clear();
                let _ = free_p.enqueue(iv);
            }
            if let (Some(w), Some(rows)) = (writer.as_mut(), trace_rx.as_mut()) {
                if let Err(e) = w.drain(rows) {
                    trace_error.get_or_insert(e);
                }
            }
        };
        let mut clock = VirtualClock::new(t0, world);
        let mut rec = Recorder::new(first, full_p, free_c, INTERVAL_NS, t0);
        drive_loop(
            &mut rec,
            &mut pipeline,
            &mut clock,
            period_ns,
            0,
            &stop,
            &progress,
            u64::MAX,
        );
        let end = rt_loop::clock::LoopClock::now(&mut clock);
        rec.finish(end)
    };
    // The planner's pace hangs up: its thread ends.
    drop(go_tx);
    totals.add(&last.stats);
    let realtime = RtMode {
        without_because: Some("simulated time: the loop ran on a virtual clock".into()),
        ..RtMode::default()
    };
    let mut result = finish.result(&pipeline, totals, realtime);
    if let Some(e) = trace_error {
        return Err(e);
    }
    if let (Some(mut w), Some(rows)) = (writer, trace_rx.as_mut()) {
        w.drain(rows)?;
        result.trace = Some(w.finish(pipeline.trace_dropped())?);
    }
    let records = drives.iter_mut().flat_map(|d| d.take_records()).collect();
    Ok((result, records))
}
