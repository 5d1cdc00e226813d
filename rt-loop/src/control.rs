//! The operator's side of a running program: commands into the real-time thread and its
//! status out, both lock-free and allocation-free on the real-time side.
//!
//! * [`Command`]s travel through a preallocated `heapless` SPSC queue of [`QUEUE`] slots
//!   ([`Commands::split`]): the control socket's thread enqueues, [`crate::pipeline`]
//!   dequeues at most [`QUEUE`] of them at the start of each period.
//! * [`Progress`] is what the loop publishes every period in atomics (relaxed: each field is
//!   a value of its own); [`Progress::snapshot`] reads them on any thread.

use core::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, AtomicU8, Ordering::Relaxed};
use heapless::spsc::Queue;
pub use heapless::spsc::{Consumer, Producer};

/// An operator's command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// Decelerate along the path and hold there.
    Pause,
    /// Go on after a pause.
    Resume,
    /// Decelerate along the path, then disable the drives: the run ends.
    Stop,
    /// Feed override, percent of the planned feed, 0..=100.
    Override(u8),
}

/// Slots of the command queue (it holds one fewer).
pub const QUEUE: usize = 16;

/// The command queue's storage, allocated once before the run.
pub struct Commands {
    queue: Queue<Command, QUEUE>,
}

impl Commands {
    pub fn new() -> Commands {
        Commands {
            queue: Queue::new(),
        }
    }

    /// The sending end (control thread) and the receiving end (real-time thread).
    pub fn split(&mut self) -> (Producer<'_, Command>, Consumer<'_, Command>) {
        self.queue.split()
    }
}

impl Default for Commands {
    fn default() -> Self {
        Commands::new()
    }
}

/// Where the run is, as [`Progress::stage`] publishes it.
pub const STAGES: [&str; 6] = [
    "enabling",
    "approach",
    "running",
    "stopping",
    "disabling",
    "finished",
];

/// What the real-time thread publishes every period, for the progress line and
/// `dnurbs ctl status`.
#[derive(Debug, Default)]
pub struct Progress {
    pub cycles: AtomicU64,
    pub overruns: AtomicU64,
    /// Program progress, parts per million.
    pub ppm: AtomicU64,
    /// Feed holds because the planner fell behind.
    pub underruns: AtomicU64,
    /// Index into [`STAGES`].
    pub stage: AtomicU8,
    pub paused: AtomicBool,
    /// Source line of the operator stop (`M00`, `M01`, `M06`) the path waits at; 0: none.
    pub awaiting: AtomicU32,
    /// Source line of the block being machined, and its N number (or index).
    pub line: AtomicU32,
    pub block: AtomicU32,
    /// Axis positions commanded (mm, degrees), f64 bits.
    pub axes: [AtomicU64; 5],
    /// Path feed, mm/min, f64 bits.
    pub feed: AtomicU64,
    /// Feed override, percent.
    pub override_pct: AtomicU8,
}

/// One reading of [`Progress`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Snapshot {
    pub stage: &'static str,
    pub paused: bool,
    /// The line of the operator stop the path waits at (`M00`, `M01`, `M06`).
    pub awaiting: Option<u32>,
    pub line: u32,
    pub block: u32,
    pub axes: [f64; 5],
    pub feed_mm_min: f64,
    pub override_pct: u8,
    pub cycles: u64,
    pub overruns: u64,
    pub feed_holds: u64,
    pub progress: f64,
}

impl Progress {
    /// Publish the per-period status (real-time thread; allocation-free).
    ///
    /// Real-time thread.
    #[allow(clippy::too_many_arguments)]
    pub fn publish(
        &self,
        stage: usize,
        paused: bool,
        awaiting: Option<u32>,
        line: u32,
        block: u32,
        axes: &[f64; 5],
        feed_mm_min: f64,
        override_pct: u8,
    ) {
        self.stage.store(stage.min(STAGES.len() - 1) as u8, Relaxed);
        self.paused.store(paused, Relaxed);
        self.awaiting.store(awaiting.unwrap_or(0), Relaxed);
        self.line.store(line, Relaxed);
        self.block.store(block, Relaxed);
        for (a, v) in self.axes.iter().zip(axes) {
            a.store(v.to_bits(), Relaxed);
        }
        self.feed.store(feed_mm_min.to_bits(), Relaxed);
        self.override_pct.store(override_pct, Relaxed);
    }

    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            stage: STAGES[usize::from(self.stage.load(Relaxed)).min(STAGES.len() - 1)],
            paused: self.paused.load(Relaxed),
            awaiting: Some(self.awaiting.load(Relaxed)).filter(|&l| l != 0),
            line: self.line.load(Relaxed),
            block: self.block.load(Relaxed),
            axes: core::array::from_fn(|j| f64::from_bits(self.axes[j].load(Relaxed))),
            feed_mm_min: f64::from_bits(self.feed.load(Relaxed)),
            override_pct: self.override_pct.load(Relaxed),
            cycles: self.cycles.load(Relaxed),
            overruns: self.overruns.load(Relaxed),
            feed_holds: self.underruns.load(Relaxed),
            progress: self.ppm.load(Relaxed) as f64 / 1e6,
        }
    }
}
