//! The two preallocated SPSC queues between the planner thread and the real-time thread:
//! chunks go out on one and come back on the other to be freed by the planner.

use crate::chunk::Chunk;
use heapless::spsc::{Consumer, Producer, Queue};
use std::sync::atomic::{AtomicU32, Ordering};

/// Deepest segment queue a machine file may ask for.
pub const MAX_DEPTH: usize = 1024;
/// Shallowest: the interpolator keeps a segment until it has passed its end, and a hold
/// stops before the end of the data it has, so with one segment alive it would wait at the
/// end of each for the next, which the planner could not push.
pub const MIN_DEPTH: usize = 2;
/// Queue storage (an SPSC queue of N holds N - 1).
pub const QUEUE_N: usize = MAX_DEPTH + 1;
/// Chunks the interpolator looks ahead over (taken from the queue as they arrive).
pub const LOOKAHEAD: usize = 64;

/// The two queues; create them before the threads, then [`Queues::split`].
pub struct Queues {
    ready: Queue<Box<Chunk>, QUEUE_N>,
    retired: Queue<Box<Chunk>, QUEUE_N>,
    /// The source line the planner refused the program at (0: none), [`Feeder::refuse`].
    refused: AtomicU32,
}

impl Default for Queues {
    fn default() -> Self {
        Queues {
            ready: Queue::new(),
            retired: Queue::new(),
            refused: AtomicU32::new(0),
        }
    }
}

impl Queues {
    /// Boxed: two queues of pointers, 16 KiB.
    pub fn new() -> Box<Queues> {
        Box::default()
    }

    /// The planner's end and the interpolator's end. `depth` (1..=[`MAX_DEPTH`]) is the most
    /// chunks alive at once.
    pub fn split(&mut self, depth: usize) -> (Feeder<'_>, Inlet<'_>) {
        let (rp, rc) = self.ready.split();
        let (tp, tc) = self.retired.split();
        let refused = &self.refused;
        (
            Feeder {
                ready: rp,
                retired: tc,
                depth: depth.clamp(MIN_DEPTH, MAX_DEPTH),
                alive: 0,
                pushed: 0,
                refused,
            },
            Inlet {
                ready: rc,
                retired: tp,
                refused,
            },
        )
    }
}

/// The planner's side of the queues.
pub struct Feeder<'q> {
    ready: Producer<'q, Box<Chunk>>,
    retired: Consumer<'q, Box<Chunk>>,
    depth: usize,
    alive: usize,
    pushed: usize,
    refused: &'q AtomicU32,
}

impl Feeder<'_> {
    /// Free the chunks the interpolator is done with, then push from `source` while fewer
    /// than `depth` are alive. Returns how many were pushed.
    pub fn feed(&mut self, source: &mut impl Iterator<Item = Box<Chunk>>) -> usize {
        self.reclaim();
        let mut n = 0;
        while self.alive < self.depth {
            let Some(c) = source.next() else { break };
            match self.ready.enqueue(c) {
                Ok(()) => {
                    self.alive += 1;
                    self.pushed += 1;
                    n += 1;
                }
                // Cannot happen (alive < depth <= capacity); dropping here is outside the
                // real-time thread, but the chunk would be lost: stop feeding instead.
                Err(_) => break,
            }
        }
        n
    }

    /// Free the chunks the interpolator handed back; returns how many are still alive (in
    /// the queue or held by the interpolator).
    pub fn reclaim(&mut self) -> usize {
        while let Some(done) = self.retired.dequeue() {
            drop(done);
            self.alive = self.alive.saturating_sub(1);
        }
        self.alive
    }

    /// A new program follows on the same queues: its refusal, if any, is its own
    /// ([`Follower::next_program`](crate::Follower::next_program) hands the last one's
    /// chunks back).
    pub fn next_program(&mut self) {
        self.refused.store(0, Ordering::Release);
    }

    /// Chunks pushed so far.
    pub fn pushed(&self) -> usize {
        self.pushed
    }

    /// The program is refused at source line `line` (an error the planner met ahead of the
    /// tool): the follower stops along the path with what it has ([`Follower::refused`]).
    pub fn refuse(&self, line: u32) {
        self.refused.store(line.max(1), Ordering::Release);
    }
}

/// The interpolator's side of the queues.
pub struct Inlet<'q> {
    pub(crate) ready: Consumer<'q, Box<Chunk>>,
    pub(crate) retired: Producer<'q, Box<Chunk>>,
    pub(crate) refused: &'q AtomicU32,
}
