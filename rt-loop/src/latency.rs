//! `dnurbs latency`: the periodic real-time loop with nothing to do, like cyclictest, to
//! characterise a controller PC before deploying. Same set-up, same histograms and same
//! report as the interpolating loop.
//!
//! Per period: sleep until the absolute deadline, read the clock, record the wake-up latency
//! (actual minus scheduled), advance the deadline by one period. A period whose work ends
//! after the next deadline is an overrun; the missed deadlines are skipped (counted once),
//! never caught up in a burst.

use crate::os::{self, RtError};
use crate::stats::Stats;

/// How the loop thread is set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RtSettings {
    /// SCHED_FIFO priority; `None` runs the same loop without real-time privileges (--no-rt).
    pub priority: Option<i32>,
    /// Pin the loop to this CPU.
    pub cpu: Option<usize>,
}

/// Stack the loop may use, touched before the first period.
pub const STACK_PREFAULT: usize = 256 * 1024;

/// Run for `duration_ns` at `period_ns` and return the statistics.
pub fn run(period_ns: u64, duration_ns: u64, rt: RtSettings) -> Result<Stats, RtError> {
    let handle = std::thread::Builder::new()
        .name("dnurbs-rt".into())
        .stack_size(STACK_PREFAULT * 2)
        .spawn(move || -> Result<Stats, RtError> {
            if let Some(priority) = rt.priority {
                os::lock_memory()?;
                os::set_fifo(priority)?;
            }
            if let Some(cpu) = rt.cpu {
                os::pin_to_cpu(cpu)?;
            }
            os::set_timer_slack(1);
            os::prefault_stack(STACK_PREFAULT);
            let mut stats = Stats::new();
            // First calls map the vDSO data page and touch every path the loop takes: do
            // them now, then start from empty statistics.
            os::sleep_until(os::now());
            stats.record(1, 1, 1);
            stats.clear();
            let faults = os::minor_faults();
            periodic(&mut stats, period_ns, duration_ns);
            stats.minor_faults = os::minor_faults() - faults;
            Ok(stats)
        })
        .map_err(|_| RtError::Thread("could not be started"))?;
    handle.join().unwrap_or(Err(RtError::Thread("panicked")))
}

/// The loop proper: allocation-free, bounded by `duration_ns / period_ns` iterations.
/// Public for the allocation and page-fault test; `run` is the way to use it.
pub fn periodic(stats: &mut Stats, period_ns: u64, duration_ns: u64) {
    let period = period_ns.max(1);
    let start = os::now();
    let end = start.saturating_add(duration_ns);
    let mut next = start.saturating_add(period);
    while next <= end {
        os::sleep_until(next);
        let woke = os::now();
        let compute_start = os::now();
        let compute_end = os::now();
        let done = os::now();
        stats.record(
            woke.saturating_sub(next),
            compute_end - compute_start,
            done.saturating_sub(woke),
        );
        next += period;
        if done > next {
            stats.overruns += 1;
            next += (done - next) / period * period + period;
        }
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
            },
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
}
