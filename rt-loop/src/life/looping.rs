//! The real-time loop of the machine's life: sleep to each absolute deadline, one
//! [`Life::cycle`], publish the status. Overruns are counted and the missed deadlines
//! skipped, never caught up. After the stop request (SIGINT/SIGTERM) the machine winds
//! down (a program stops along its path, a jog stops, homing is stopped, the drives are
//! disabled) and the loop ends once they are off, or faulted and at rest.

use super::{Doing, Life, Order, Status};
use crate::clock::LoopClock;
use crate::control::Command;
use core::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};
use drives::link::CanLink;

/// What the loop counts, for the status.
#[derive(Debug, Default)]
pub struct LoopCounts {
    pub cycles: AtomicU64,
    pub overruns: AtomicU64,
}

/// Run `life` every `period_ns` on `clock` until the stop request has wound it down (or
/// `max_cycles`, a bound for tests).
///
/// Real-time thread: allocation-free.
pub fn life_loop<L: CanLink, C: LoopClock>(
    life: &mut Life<'_, L>,
    clock: &mut C,
    period_ns: u64,
    stop: &AtomicBool,
    status: &Status,
    counts: &LoopCounts,
    max_cycles: u64,
) {
    let mut deadline = clock.now().saturating_add(period_ns);
    for _ in 0..max_cycles {
        clock.sleep_until(deadline);
        let now = clock.now();
        if stop.load(Relaxed) && life.wind_down() {
            life.publish(status);
            return;
        }
        life.cycle(now);
        life.publish(status);
        counts.cycles.fetch_add(1, Relaxed);
        deadline = deadline.saturating_add(period_ns);
        let after = clock.now();
        if after > deadline {
            let missed = (after - deadline) / period_ns.max(1) + 1;
            counts.overruns.fetch_add(missed, Relaxed);
            deadline = deadline.saturating_add(missed.saturating_mul(period_ns));
        }
    }
}

impl<L: CanLink> Life<'_, L> {
    /// One step of the shutdown: what moves is stopped, then the drives are disabled.
    /// `true` once they are off (or faulted: the master has quick-stopped and disabled them).
    pub fn wind_down(&mut self) -> bool {
        match self.doing {
            Doing::Off | Doing::Fault => return true,
            Doing::Program => {
                if let super::Parts::Running(p) = &mut self.parts {
                    p.command(Command::Stop);
                }
            }
            Doing::Jog { .. } | Doing::LineJog { .. } | Doing::Homing { .. } => {
                self.order(Order::Stop)
            }
            Doing::Holding => self.order(Order::Off),
            Doing::Enabling { .. } => self.doing = Doing::Disabling { cycles: 0 },
            Doing::Disabling { .. } => {}
        }
        false
    }
}
