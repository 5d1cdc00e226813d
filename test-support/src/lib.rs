//! Test-only helpers shared by the dnurbs crates' tests. A dev-dependency only.
//!
//! [`CountingAlloc`]: the global allocator of the allocation proofs (`no_alloc` tests). It
//! forwards to the system allocator and, while armed, counts every allocation and free:
//! made by any thread ([`arm_all`]), or by the arming thread only ([`arm_this_thread`],
//! for a loop running beside threads that may allocate freely).
//!
//! [`generated`]: case counts and seeds of the generated-input suites, from the environment.
//! [`nurbs`]: a NURBS curve's points, of any length.
//!
//! ```ignore
//! #[global_allocator]
//! static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;
//! ```

pub mod generated;
pub mod nurbs;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Counts allocations and frees while armed; see the crate doc.
pub struct CountingAlloc;

static ALL_ARMED: AtomicBool = AtomicBool::new(false);
static ALL_EVENTS: AtomicU64 = AtomicU64::new(0);

thread_local! {
    static THIS_ARMED: Cell<bool> = const { Cell::new(false) };
    static THIS_EVENTS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    if ALL_ARMED.load(Ordering::Relaxed) {
        ALL_EVENTS.fetch_add(1, Ordering::Relaxed);
    }
    // try_with: the thread-locals may be gone while a thread is torn down.
    if THIS_ARMED.try_with(Cell::get).unwrap_or(false) {
        let _ = THIS_EVENTS.try_with(|e| e.set(e.get() + 1));
    }
}

unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        count();
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Count every thread's allocations from now on (the count starts at 0).
pub fn arm_all() {
    ALL_EVENTS.store(0, Ordering::SeqCst);
    ALL_ARMED.store(true, Ordering::SeqCst);
}

/// Stop counting every thread's; the count since [`arm_all`].
pub fn disarm_all() -> u64 {
    ALL_ARMED.store(false, Ordering::SeqCst);
    ALL_EVENTS.load(Ordering::SeqCst)
}

/// Count this thread's allocations from now on (its count starts at 0).
pub fn arm_this_thread() {
    THIS_EVENTS.with(|e| e.set(0));
    THIS_ARMED.with(|a| a.set(true));
}

/// Stop counting this thread's; its count since [`arm_this_thread`].
pub fn disarm_this_thread() -> u64 {
    THIS_ARMED.with(|a| a.set(false));
    THIS_EVENTS.with(Cell::get)
}

/// Stop counting this thread's for a while, keeping its count (work beside the proof that
/// runs in the same thread: simulated drives stepped between two periods).
pub fn pause_this_thread() {
    THIS_ARMED.with(|a| a.set(false));
}

/// Count this thread's again, on from where [`pause_this_thread`] left the count.
pub fn resume_this_thread() {
    THIS_ARMED.with(|a| a.set(true));
}

#[cfg(test)]
#[global_allocator]
static ALLOC: CountingAlloc = CountingAlloc;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_this_threads_allocations_and_only_them() {
        arm_this_thread();
        let b = std::hint::black_box(Box::new(7u64));
        drop(b);
        let other = std::thread::spawn(|| std::hint::black_box(vec![1u8; 64]).len());
        let mine = disarm_this_thread();
        assert_eq!(other.join().unwrap(), 64);
        // The Box and its free, and the spawn's own allocations in this thread.
        assert!(mine >= 2, "{mine}");
        arm_this_thread();
        let idle = disarm_this_thread();
        assert_eq!(idle, 0);
        // Paused, nothing is counted; resumed, counting goes on from the count kept.
        arm_this_thread();
        drop(std::hint::black_box(Box::new(1u8)));
        pause_this_thread();
        drop(std::hint::black_box(Box::new(2u8)));
        resume_this_thread();
        drop(std::hint::black_box(Box::new(3u8)));
        assert_eq!(disarm_this_thread(), 4);
    }
}
