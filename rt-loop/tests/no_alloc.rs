//! The latency loop touches neither the heap nor a new page: a counting global allocator and
//! getrusage's minor-fault count watch >= 100 000 periods. This file is its own test binary,
//! with one test, so nothing else runs (or allocates, or faults) at the same time.

use rt_loop::latency::periodic;
use rt_loop::os;
use rt_loop::stats::Stats;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

struct Counting;
static ARMED: AtomicBool = AtomicBool::new(false);
static EVENTS: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ARMED.load(Ordering::Relaxed) {
            EVENTS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if ARMED.load(Ordering::Relaxed) {
            EVENTS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

#[test]
fn loop_neither_allocates_nor_faults_over_100k_periods() {
    os::set_timer_slack(1);
    os::prefault_stack(256 * 1024);
    let mut stats = Stats::new();
    os::sleep_until(os::now());
    stats.record(1, 1, 1);
    stats.clear();
    let faults = os::minor_faults();
    ARMED.store(true, Ordering::SeqCst);
    // 20 us periods for 3 s: 150 000 scheduled, >= 100 000 even if the VM loses some.
    periodic(&mut stats, 20_000, 3_000_000_000);
    ARMED.store(false, Ordering::SeqCst);
    let faulted = os::minor_faults() - faults;
    let allocs = EVENTS.load(Ordering::SeqCst);
    assert_eq!(allocs, 0, "heap touched in the loop");
    assert_eq!(faulted, 0, "minor page faults in the loop");
    assert!(
        stats.cycles >= 100_000,
        "only {} periods ({} overruns)",
        stats.cycles,
        stats.overruns
    );
}
