//! The simulated nodes on a virtual clock: [`Lockstep`] serves the far end of a link the
//! way [`super::SimThread`] does, but in the caller's thread, and time passes only when the
//! caller says so. A test (or `dnurbs run` on simulated time) steps the master and the
//! drives in turn: the master sends a period's frames, the drives answer them at once, the
//! clock moves on by a period. Nothing depends on how fast the machine running it is.

use super::{Record, SimBus, SimNodeConfig};
use crate::frame::CanFrame;
use crate::link::CanLink;
use crate::master::setup::Clock;
use std::time::Duration;

/// Read every frame waiting on `link`, hand it to `bus` at `now_s`, poll the bus (boot-ups,
/// heartbeats) and send what the nodes produced. Returns whether anything arrived.
pub(super) fn serve<L: CanLink>(
    bus: &mut SimBus,
    link: &mut L,
    now_s: f64,
    out: &mut Vec<CanFrame>,
) -> bool {
    let mut busy = false;
    while let Ok(Some(f)) = link.recv() {
        bus.on_frame(&f, now_s, &mut |o| out.push(o));
        busy = true;
    }
    bus.poll(now_s, &mut |o| out.push(o));
    for f in out.drain(..) {
        let _ = link.send(&f);
    }
    busy
}

/// Simulated nodes serving one end of a link on a virtual clock.
pub struct Lockstep<L: CanLink> {
    bus: SimBus,
    link: L,
    now: Duration,
    /// How far [`Clock::idle`] moves the clock.
    idle_step: Duration,
    out: Vec<CanFrame>,
}

impl<L: CanLink> Lockstep<L> {
    /// `nodes` on the drives' end of `link`, their motors advanced `period_s` per SYNC; the
    /// clock starts at 0 and moves 100 µs each time the master's set-up waits.
    pub fn new(link: L, nodes: Vec<SimNodeConfig>, period_s: f64) -> Self {
        Lockstep {
            bus: SimBus::new(nodes, period_s),
            link,
            now: Duration::ZERO,
            idle_step: Duration::from_micros(100),
            out: Vec::new(),
        }
    }

    /// Answer what the master has sent, at the present time.
    pub fn serve(&mut self) {
        serve(
            &mut self.bus,
            &mut self.link,
            self.now.as_secs_f64(),
            &mut self.out,
        );
    }

    /// Move the clock to `t` (never back) and answer what the master has sent.
    pub fn advance_to(&mut self, t: Duration) {
        self.now = self.now.max(t);
        self.serve();
    }

    /// The virtual time.
    pub fn now(&self) -> Duration {
        self.now
    }

    /// The simulated nodes (their states, counters and records so far).
    pub fn bus(&self) -> &SimBus {
        &self.bus
    }

    /// Every target the nodes took, in order, as [`super::SimThread::finish`] returns them.
    pub fn take_records(&mut self) -> Vec<Record> {
        self.bus.take_records()
    }
}

impl<L: CanLink> Clock for Lockstep<L> {
    fn now(&self) -> Duration {
        self.now
    }

    /// The master waits for an answer: the nodes answer what has arrived, then time moves
    /// on by a step (a node's boot-up or heartbeat comes due with the clock).
    fn idle(&mut self) {
        self.serve();
        self.now += self.idle_step;
        self.serve();
    }
}
