//! `dnurbs latency`: the periodic real-time loop with nothing to do, like cyclictest, to
//! characterise a controller PC before deploying. Same set-up, same histograms and same
//! report as the interpolating loop.
//!
//! Per period: sleep until the absolute deadline, read the clock, record the wake-up latency
//! (actual minus scheduled), advance the deadline by one period. A period whose work ends
//! after the next deadline is an overrun; the missed deadlines are skipped (counted once),
//! never caught up in a burst.

use crate::interval::{Interval, Queues, Recorder};
use crate::os::{self, RtError};
use crate::report::HlogFile;
use crate::stats::Stats;
use crate::thread::RtSettings;
use heapless::spsc::{Consumer, Producer};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// Length of one interval of the `.hlog`, ns.
pub const INTERVAL_NS: u64 = 1_000_000_000;

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Rt(#[from] RtError),
    #[error("{path}: {error}")]
    Report { path: String, error: std::io::Error },
}

/// Run for `duration_ns` at `period_ns`; with `hlog`, write each second's histograms there
/// (HdrHistogram V2 interval log, tags `wakeup`, `compute`, `cycle`, values in ns).
/// Returns the totals over the whole run.
pub fn run(
    period_ns: u64,
    duration_ns: u64,
    rt: RtSettings,
    hlog: Option<&Path>,
) -> Result<Stats, RunError> {
    let (mut queues, first) = Queues::new();
    let (full_p, mut full_c) = queues.full.split();
    let (mut free_p, free_c) = queues.free.split();
    let finished = AtomicBool::new(false);
    let mut log = match hlog {
        Some(p) => Some(HlogFile::create(p).map_err(|error| RunError::Report {
            path: p.display().to_string(),
            error,
        })?),
        None => None,
    };
    let _poller = rt.idle_poller()?;
    let t0 = os::now();
    std::thread::scope(|scope| -> Result<Stats, RunError> {
        let finished = &finished;
        let rt_thread = crate::thread::spawn_rt(
            scope,
            rt,
            false,
            move |_mode| rt_body(first, full_p, free_c, period_ns, duration_ns),
            move || finished.store(true, Ordering::Release),
        )?;
        // This thread is the reporter: write out and total each interval, return the box.
        let mut totals = Stats::new();
        let mut report = |iv: &Interval, totals: &mut Stats| -> Result<(), RunError> {
            totals.add(&iv.stats);
            match (&mut log, hlog) {
                (Some(l), Some(p)) => l.append(iv, t0).map_err(|error| RunError::Report {
                    path: p.display().to_string(),
                    error,
                }),
                _ => Ok(()),
            }
        };
        loop {
            let done = finished.load(Ordering::Acquire);
            while let Some(mut iv) = full_c.dequeue() {
                report(&iv, &mut totals)?;
                iv.stats.clear();
                let _ = free_p.enqueue(iv);
            }
            if done {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let (last, faults) = rt_thread
            .join()
            .unwrap_or(Err(RtError::Thread("panicked")))?;
        report(&last, &mut totals)?;
        totals.minor_faults = faults;
        Ok(totals)
    })
}

/// The real-time thread's work after [`crate::thread::set_up`]: warm-up, loop. Returns the
/// last interval and the minor page faults that happened during the loop.
fn rt_body(
    first: Box<Interval>,
    full: Producer<'_, Box<Interval>>,
    free: Consumer<'_, Box<Interval>>,
    period_ns: u64,
    duration_ns: u64,
) -> (Box<Interval>, i64) {
    let mut rec = Recorder::new(first, full, free, INTERVAL_NS, os::now());
    // First calls map the vDSO data page and touch every path the loop takes: do them
    // now, then start from empty statistics.
    os::sleep_until(os::now());
    rec.stats().record(1, 1, 1);
    rec.stats().clear();
    let faults = os::minor_faults();
    periodic(&mut rec, period_ns, duration_ns);
    let faults = os::minor_faults() - faults;
    (rec.finish(os::now()), faults)
}

/// The loop proper: allocation-free, bounded by `duration_ns / period_ns` iterations.
/// Public for the allocation and page-fault test; `run` is the way to use it.
///
/// Real-time thread.
pub fn periodic(rec: &mut Recorder<'_>, period_ns: u64, duration_ns: u64) {
    let period = period_ns.max(1);
    let start = os::now();
    let end = start.saturating_add(duration_ns);
    let mut next = start.saturating_add(period);
    let mut run = crate::stats::OverrunRun::default();
    while next <= end {
        os::sleep_until(next);
        let woke = os::now();
        let compute_start = os::now();
        let compute_end = os::now();
        let done = os::now();
        let stats = rec.stats();
        stats.record(
            woke.saturating_sub(next),
            compute_end - compute_start,
            done.saturating_sub(woke),
        );
        next += period;
        let overrun = done > next;
        run.period(overrun, stats);
        if overrun {
            next += (done - next) / period * period + period;
        }
        rec.maybe_rotate(done);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_run_without_privileges_measures_every_period() {
        let stats = run(
            1_000_000,
            200_000_000,
            RtSettings {
                priority: None,
                cpu: None,
                idle_poll: false,
            },
            None,
        )
        .unwrap();
        // 200 periods, fewer if the VM stalled long enough to skip some (counted as overruns).
        assert!(
            stats.cycles + stats.overruns * 2 >= 150 && stats.cycles <= 200,
            "{} cycles, {} overruns",
            stats.cycles,
            stats.overruns
        );
        let s = stats.summary();
        assert!(
            s.histograms.wakeup_latency_ns.min > 0
                && s.histograms.wakeup_latency_ns.max >= s.histograms.wakeup_latency_ns.p50
        );
    }

    #[test]
    fn the_interval_log_reads_back_with_the_hdrhistogram_parser() {
        use hdrhistogram::serialization::interval_log::{IntervalLogIterator, LogEntry};
        use hdrhistogram::serialization::Deserializer;
        let path = std::env::temp_dir().join(format!("dnurbs-{}-latency.hlog", std::process::id()));
        // 2.5 s at 1 ms: two full one-second intervals and a partial one.
        let stats = run(
            1_000_000,
            2_500_000_000,
            RtSettings {
                priority: None,
                cpu: None,
                idle_poll: false,
            },
            Some(&path),
        )
        .unwrap();
        let text = std::fs::read(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        let mut counts = std::collections::BTreeMap::new();
        let mut intervals = 0;
        for entry in IntervalLogIterator::new(&text) {
            if let Ok(LogEntry::Interval(iv)) = entry {
                let tag = iv.tag().map(|t| t.as_str().to_owned()).unwrap_or_default();
                let bytes = base64_decode(iv.encoded_histogram());
                let h: hdrhistogram::Histogram<u64> =
                    Deserializer::new().deserialize(&mut &bytes[..]).unwrap();
                *counts.entry(tag).or_insert(0u64) += h.len();
                intervals += 1;
            }
        }
        assert!(intervals >= 9, "{intervals} histogram lines");
        for tag in ["wakeup", "compute", "cycle"] {
            assert_eq!(counts.get(tag), Some(&stats.cycles), "{tag}: {counts:?}");
        }
    }

    /// Standard base64 (the log's encoding), decoded by hand to need no extra crate.
    fn base64_decode(s: &str) -> Vec<u8> {
        let val = |c: u8| match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            _ => 63,
        };
        let mut out = Vec::new();
        let (mut acc, mut bits) = (0u32, 0);
        for &c in s.as_bytes().iter().filter(|&&c| c != b'=') {
            acc = (acc << 6) | u32::from(val(c));
            bits += 6;
            if bits >= 8 {
                bits -= 8;
                out.push((acc >> bits) as u8);
            }
        }
        out
    }
}
