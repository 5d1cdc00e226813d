//! The simulated drives in a thread of their own, serving one end of a link: what
//! `dnurbs demo` and the pipeline tests put on the other end of the in-process bus.

use super::{Record, SimBus, SimNodeConfig};
use crate::link::CanLink;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A running [`SimBus`]; [`SimThread::finish`] stops it and returns what it recorded.
pub struct SimThread {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Vec<Record>>>,
}

impl SimThread {
    /// Serve `link` with `nodes` at `period_s`, polling every `poll` when idle.
    pub fn start<L: CanLink + Send + 'static>(
        link: L,
        nodes: Vec<SimNodeConfig>,
        period_s: f64,
        poll: Duration,
    ) -> std::io::Result<SimThread> {
        Self::start_with(link, nodes, period_s, poll, || {})
    }

    /// As [`SimThread::start`], running `setup` first in the new thread (to give it a
    /// real-time priority, say: drives answer within their cycle, so on a loaded host their
    /// simulation must not starve).
    pub fn start_with<L: CanLink + Send + 'static>(
        mut link: L,
        nodes: Vec<SimNodeConfig>,
        period_s: f64,
        poll: Duration,
        setup: impl FnOnce() + Send + 'static,
    ) -> std::io::Result<SimThread> {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::Builder::new()
            .name("dnurbs-sim-drives".into())
            .spawn(move || {
                setup();
                let mut bus = SimBus::new(nodes, period_s);
                let t0 = Instant::now();
                let mut out = Vec::new();
                while !flag.load(Ordering::Relaxed) {
                    let now = t0.elapsed().as_secs_f64();
                    if !super::lockstep::serve(&mut bus, &mut link, now, &mut out) {
                        std::thread::sleep(poll);
                    }
                }
                bus.take_records()
            })?;
        Ok(SimThread {
            stop,
            thread: Some(thread),
        })
    }

    /// Stop the drives; every target they received, in order.
    pub fn finish(mut self) -> Vec<Record> {
        self.stop.store(true, Ordering::Relaxed);
        self.thread
            .take()
            .and_then(|t| t.join().ok())
            .unwrap_or_default()
    }
}

impl Drop for SimThread {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
