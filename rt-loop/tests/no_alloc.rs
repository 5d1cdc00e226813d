//! The latency loop touches neither the heap nor a new page: a counting global allocator and
//! getrusage's minor-fault count watch >= 100 000 periods, however long a loaded machine
//! takes to run them. This file is its own test binary,
//! with one test, so nothing else runs (or allocates, or faults) at the same time.

use rt_loop::interval::{Queues, Recorder};
use rt_loop::latency::periodic;
use rt_loop::os;

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

#[test]
fn loop_neither_allocates_nor_faults_over_100k_periods() {
    os::set_timer_slack(1);
    os::prefault_stack(256 * 1024);
    let (mut queues, first) = Queues::new();
    let (full, mut full_c) = queues.full.split();
    let (_free_p, free) = queues.free.split();
    // 0.1 s intervals: hand-offs happen inside the measured loop (and, with no reporter
    // returning boxes, late hand-offs too).
    let mut rec = Recorder::new(first, full, free, 100_000_000, os::now());
    os::sleep_until(os::now());
    rec.stats().record(1, 1, 1);
    rec.stats().clear();
    // Count periods to completion, not periods per second: on a loaded machine the loop
    // skips the periods it overran, so it runs in 1 s slices (20 us periods) until 100 000
    // periods have been measured, for at most 120 slices. Only the slices are watched; the
    // hand-offs are collected (and their boxes dropped) between them.
    let (mut faulted, mut handed, mut slices, mut allocs) = (0, 0u64, 0, 0);
    while handed + rec.stats().cycles < 100_000 && slices < 120 {
        let faults = os::minor_faults();
        test_support::arm_this_thread();
        periodic(&mut rec, 20_000, 1_000_000_000);
        allocs += test_support::disarm_this_thread();
        faulted += os::minor_faults() - faults;
        handed += core::iter::from_fn(|| full_c.dequeue())
            .map(|iv| iv.stats.cycles)
            .sum::<u64>();
        slices += 1;
    }
    assert_eq!(allocs, 0, "heap touched in the loop");
    assert_eq!(faulted, 0, "minor page faults in the loop");
    // No reporter returns boxes to `free`, so hand-offs run late after the first few.
    assert!(rec.late > 0, "the late hand-off path was not exercised");
    let last = rec.finish(os::now());
    let handed = handed
        + core::iter::from_fn(|| full_c.dequeue())
            .map(|iv| iv.stats.cycles)
            .sum::<u64>();
    let cycles = handed + last.stats.cycles;
    assert!(cycles >= 100_000, "only {cycles} periods in {slices} s");
}
