//! The targets as the drives receive them, period by period (`run --trace`, `demo
//! --trace`): the real-time thread enqueues one [`TraceRow`] a period into a preallocated
//! `heapless` SPSC queue ([`TraceRing`]), never blocking (a full queue counts the row as
//! dropped); a thread outside the real-time one dequeues and writes them.

use heapless::spsc::Queue;
pub use heapless::spsc::{Consumer, Producer};

/// Slots of the queue (it holds one fewer): at a 1 ms period, four seconds of rows for a
/// writer that falls behind.
pub const TRACE_SLOTS: usize = 4096;

/// Most nodes a row holds, every bus's together.
pub const TRACE_NODES: usize = 16;

/// One period: its index, the stage, and each node's target as sent, bus by bus in the
/// master's node order (axis drives in counts, a spindle drive in velocity units, an I/O
/// module its output byte).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceRow {
    pub period: u64,
    /// As [`crate::control::STAGES`] names it.
    pub stage: u8,
    pub targets: [i32; TRACE_NODES],
    /// How many of `targets` are nodes'.
    pub nodes: u8,
}

impl TraceRow {
    /// The nodes' targets.
    pub fn targets(&self) -> &[i32] {
        &self.targets[..usize::from(self.nodes).min(TRACE_NODES)]
    }
}

/// The queue's storage, allocated once before the run.
pub struct TraceRing {
    queue: Queue<TraceRow, TRACE_SLOTS>,
}

impl TraceRing {
    pub fn new() -> TraceRing {
        TraceRing {
            queue: Queue::new(),
        }
    }

    /// The real-time thread's end and the writer's.
    pub fn split(&mut self) -> (Producer<'_, TraceRow>, Consumer<'_, TraceRow>) {
        self.queue.split()
    }
}

impl Default for TraceRing {
    fn default() -> Self {
        TraceRing::new()
    }
}
