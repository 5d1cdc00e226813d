//! `latency`: the real-time loop with nothing to do, and its report.

use super::{cpu_text, keep_off_rt_cpu, report_dir};
use crate::cli::show;
use crate::exit::{InputError, Outcome};
use crate::report::{Report, RtMode};
use std::path::PathBuf;

pub fn latency(
    period: u64,
    duration: u64,
    rt: rt_loop::thread::RtSettings,
    report: Option<PathBuf>,
) -> anyhow::Result<Outcome> {
    if period > duration {
        return Err(InputError::Usage(format!(
            "--period {} is longer than --duration {}",
            show(period),
            show(duration)
        ))
        .into());
    }
    keep_off_rt_cpu(rt)?;
    eprintln!(
        "dnurbs latency: {} periods of {} us{}{}",
        duration / period,
        period as f64 / 1000.0,
        if rt.priority.is_some() {
            ", SCHED_FIFO"
        } else {
            ", without real-time privileges (--no-rt)"
        },
        cpu_text(rt)
    );
    report_dir(&report)?;
    let started = crate::report::now_utc();
    let hlog = report.as_ref().map(|d| d.join("latency.hlog"));
    let stats = rt_loop::latency::run(period, duration, rt, hlog.as_deref())?;
    // The loop refuses to run without the privileges it was asked for.
    let realtime = RtMode {
        sched_fifo: rt.priority.is_some(),
        priority: rt.priority,
        memory_locked: rt.priority.is_some(),
        cpu: rt.cpu,
        without_because: rt.priority.is_none().then(|| "--no-rt".to_owned()),
    };
    let outcome = crate::report::outcome(None, stats.overruns);
    let rep = Report {
        dnurbs_version: env!("CARGO_PKG_VERSION"),
        started,
        program: format!("latency, {} periods of {}", duration / period, show(period)),
        machine: String::new(),
        program_words: Vec::new(),
        compressed: None,
        refusal: None,
        stream: None,
        outcome: outcome.name(),
        exit_code: outcome.code(),
        stop_reason: None,
        stop_node: None,
        stop_line: None,
        realtime,
        overruns: stats.overruns,
        max_consecutive_overruns: stats.max_consecutive_overruns,
        feed_holds: 0,
        hard_stops: 0,
        input_timeouts: None,
        trace: None,
        buses: Vec::new(),
        drives: Vec::new(),
        latency: stats.summary(),
    };
    print!("{}", rep.text());
    if let Some(dir) = report {
        let title = format!(
            "dnurbs latency: {} periods of {} us",
            stats.cycles,
            period as f64 / 1000.0
        );
        rep.write(&dir, &stats, &title, period)?;
        eprintln!("report: {}", dir.display());
    }
    Ok(outcome)
}
