//! The real-time loop: sleep to each deadline (or wake a lead before it), run one
//! [`Pipeline::cycle`], record the histograms, publish the status. Runs in the real-time
//! thread.

use super::{Pipeline, Progress};
use crate::clock::LoopClock;
use drives::link::CanLink;

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
/// Time is `clock`'s: the monotonic clock in the real-time thread
/// ([`OsClock`](crate::clock::OsClock)), or a virtual one that steps the rest of the machine
/// while the loop sleeps ([`VirtualClock`](crate::clock::VirtualClock)).
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
///
/// Real-time thread.
#[allow(clippy::too_many_arguments)]
pub fn drive_loop<L: CanLink>(
    rec: &mut crate::interval::Recorder<'_>,
    pipeline: &mut Pipeline<'_, L>,
    clock: &mut impl LoopClock,
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
    let mut next = clock.now().saturating_add(period);
    let (mut underruns, mut total_overruns) = (0, 0);
    let mut run = crate::stats::OverrunRun::default();
    for _ in 0..max_cycles {
        let wake_at = next.saturating_sub(lead);
        clock.sleep_until(wake_at);
        let woke = clock.now();
        let start = if lead > 0 {
            // Rehearsing only right before the step gave a compute p99.9 of 0.69-0.73 us in
            // pinned demo runs here; also at the wake-up and after each pause, 0.47-0.63 us.
            pipeline.rehearse();
            let slot = next.saturating_sub(slots.before[slots.choose(woke)]);
            clock.spin_until(slot, lead, GAP_NS, |at| {
                slots.disturbed(at, next);
                pipeline.rehearse();
            });
            pipeline.rehearse();
            let t0 = clock.now();
            pipeline.prepare();
            if clock.now().saturating_sub(t0) > GAP_NS {
                slots.disturbed(t0, next);
            }
            clock
                .spin_until(next, lead, GAP_NS, |at| slots.disturbed(at, next))
                .max(woke)
        } else {
            woke
        };
        let info = pipeline.cycle(start, stop.load(Relaxed));
        let done = clock.now();
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
