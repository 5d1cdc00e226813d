//! Interval histograms, handed from the real-time thread to a reporter thread without locks
//! and without allocation (hdrhistogram's `sync::Recorder` allocates, so it is not used).
//!
//! [`BOXES`] boxed [`Interval`]s circulate through two heapless SPSC queues: the real-time
//! side records into its current box and, once an interval has passed, takes an empty box
//! from `free` and pushes the full one onto `full`. Moving a `Box` through a queue moves a
//! pointer; nothing is allocated or freed. The reporter pops full boxes, writes them out,
//! adds them to the totals, clears them and gives them back on `free`. If the reporter is
//! late and `free` is empty, the real-time side keeps recording into its current box (one
//! interval then spans longer) and counts a late hand-off.

use crate::stats::Stats;
use heapless::spsc::{Consumer, Producer, Queue};

/// Boxes in circulation: one being recorded, the rest free or waiting for the reporter.
pub const BOXES: usize = 4;
/// Queue storage for [`BOXES`] items (an SPSC queue of N holds N - 1).
pub const QUEUE_N: usize = BOXES + 1;

/// One interval's histograms and its time span (monotonic ns).
#[derive(Debug)]
pub struct Interval {
    pub stats: Stats,
    pub start_ns: u64,
    pub end_ns: u64,
}

/// The two queues; create them before the threads and split them between the two sides.
pub struct Queues {
    pub full: Queue<Box<Interval>, QUEUE_N>,
    pub free: Queue<Box<Interval>, QUEUE_N>,
}

impl Queues {
    /// Allocate every box now (outside the real-time thread). Returns the queues, with all
    /// but one box in `free`, and that one box for the recorder to start with.
    pub fn new() -> (Queues, Box<Interval>) {
        let mut q = Queues {
            full: Queue::new(),
            free: Queue::new(),
        };
        let make = || {
            Box::new(Interval {
                stats: Stats::new(),
                start_ns: 0,
                end_ns: 0,
            })
        };
        for _ in 1..BOXES {
            // BOXES - 1 < QUEUE_N - 1 = capacity: cannot fail.
            let _ = q.free.enqueue(make());
        }
        (q, make())
    }
}

/// The real-time side.
pub struct Recorder<'q> {
    current: Box<Interval>,
    full: Producer<'q, Box<Interval>>,
    free: Consumer<'q, Box<Interval>>,
    interval_ns: u64,
    /// Hand-offs postponed because the reporter had not returned a box yet.
    pub late: u64,
}

impl<'q> Recorder<'q> {
    pub fn new(
        first: Box<Interval>,
        full: Producer<'q, Box<Interval>>,
        free: Consumer<'q, Box<Interval>>,
        interval_ns: u64,
        now: u64,
    ) -> Self {
        let mut current = first;
        current.start_ns = now;
        Recorder {
            current,
            full,
            free,
            interval_ns,
            late: 0,
        }
    }

    /// The statistics being recorded into.
    #[inline]
    pub fn stats(&mut self) -> &mut Stats {
        &mut self.current.stats
    }

    /// Hand the current interval over if it is complete. Allocation-free, lock-free.
    #[inline]
    pub fn maybe_rotate(&mut self, now: u64) {
        if now.saturating_sub(self.current.start_ns) < self.interval_ns {
            return;
        }
        let Some(mut next) = self.free.dequeue() else {
            self.late += 1;
            return;
        };
        next.start_ns = now;
        let mut done = core::mem::replace(&mut self.current, next);
        done.end_ns = now;
        // Every box is in `current`, `free`, `full` or with the reporter, and `full` holds
        // all BOXES, so this cannot fail; were it to, the box is kept, not dropped (no free).
        if let Err(back) = self.full.enqueue(done) {
            let _ = core::mem::replace(&mut self.current, back);
        }
    }

    /// End of the run: the last, partial interval.
    pub fn finish(mut self, now: u64) -> Box<Interval> {
        self.current.end_ns = now;
        self.current
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_circulate_and_a_late_reporter_is_counted() {
        let (mut q, first) = Queues::new();
        let (full_p, mut full_c) = q.full.split();
        let (mut free_p, free_c) = q.free.split();
        let mut r = Recorder::new(first, full_p, free_c, 100, 0);
        let mut t = 0;
        // Five intervals without the reporter: three hand-offs, then late ones.
        for _ in 0..5 {
            r.stats().record(5, 1, 2);
            t += 100;
            r.maybe_rotate(t);
        }
        assert_eq!(r.late, 2);
        let mut seen = 0;
        while let Some(mut iv) = full_c.dequeue() {
            assert!(iv.end_ns > iv.start_ns);
            seen += iv.stats.cycles;
            iv.stats.clear();
            free_p.enqueue(iv).unwrap();
        }
        r.stats().record(5, 1, 2);
        t += 100;
        r.maybe_rotate(t);
        let last = r.finish(t + 50);
        // Nothing recorded is lost: 3 handed off + 3 still in the box that waited.
        let in_full: u64 = core::iter::from_fn(|| full_c.dequeue())
            .map(|iv| iv.stats.cycles)
            .sum();
        assert_eq!(seen + in_full + last.stats.cycles, 6);
    }
}
