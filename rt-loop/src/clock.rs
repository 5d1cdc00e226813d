//! The loop's time ([`LoopClock`]): the monotonic clock of the real-time thread
//! ([`OsClock`]), or a virtual one that runs the rest of the machine while the loop "sleeps"
//! ([`VirtualClock`]), so that the same loop, stage for stage, runs in a test without
//! waiting for real time and without depending on how busy the machine is.

use crate::os;

/// Where the loop reads the time and waits for its deadlines.
pub trait LoopClock {
    /// Monotonic time, ns.
    fn now(&mut self) -> u64;
    /// Sleep until `deadline` (absolute, ns); returns at once if it has passed.
    fn sleep_until(&mut self, deadline: u64);
    /// Wait on the clock, without sleeping, until `deadline`; returns the time then. See
    /// [`os::spin_until`] for `max_ns`, `gap_ns` and `on_gap`.
    fn spin_until(
        &mut self,
        deadline: u64,
        max_ns: u64,
        gap_ns: u64,
        on_gap: impl FnMut(u64),
    ) -> u64;
}

/// `CLOCK_MONOTONIC` and `clock_nanosleep`: the real-time thread's clock.
///
/// Real-time thread.
#[derive(Clone, Copy, Debug, Default)]
pub struct OsClock;

impl LoopClock for OsClock {
    fn now(&mut self) -> u64 {
        os::now()
    }

    fn sleep_until(&mut self, deadline: u64) {
        os::sleep_until(deadline);
    }

    fn spin_until(
        &mut self,
        deadline: u64,
        max_ns: u64,
        gap_ns: u64,
        on_gap: impl FnMut(u64),
    ) -> u64 {
        os::spin_until(deadline, max_ns, gap_ns, on_gap)
    }
}

/// Virtual time: it stands still while the loop computes, and a sleep to a deadline first
/// runs `world(deadline)` (the simulated drives answering, the planner's round, an
/// operator's script: whatever the other threads would have done meanwhile), then jumps
/// there. A loop on it wakes exactly on time, every period.
pub struct VirtualClock<F: FnMut(u64)> {
    now: u64,
    world: F,
    read_ns: u64,
}

impl<F: FnMut(u64)> VirtualClock<F> {
    /// Starts at `start` ns.
    pub fn new(start: u64, world: F) -> Self {
        VirtualClock {
            now: start,
            world,
            read_ns: 0,
        }
    }

    /// Every read of the clock moves it on by `ns`: the loop's work takes time, as much
    /// as the test says (a loop whose work outlasts its period overruns, deterministically).
    pub fn reads_take(mut self, ns: u64) -> Self {
        self.read_ns = ns;
        self
    }
}

impl<F: FnMut(u64)> LoopClock for VirtualClock<F> {
    fn now(&mut self) -> u64 {
        self.now += self.read_ns;
        self.now
    }

    fn sleep_until(&mut self, deadline: u64) {
        if deadline > self.now {
            (self.world)(deadline);
            self.now = deadline;
        }
    }

    fn spin_until(&mut self, deadline: u64, _: u64, _: u64, _: impl FnMut(u64)) -> u64 {
        self.sleep_until(deadline);
        self.now
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_virtual_clock_runs_the_world_then_jumps_to_the_deadline() {
        let mut seen = Vec::new();
        {
            let mut c = VirtualClock::new(10, |t| seen.push(t));
            assert_eq!(c.now(), 10);
            c.sleep_until(5);
            assert_eq!(c.now(), 10, "never back");
            c.sleep_until(30);
            assert_eq!(c.spin_until(50, 0, 0, |_| {}), 50);
        }
        assert_eq!(seen, [30, 50]);
        let mut c = VirtualClock::new(0, |_| {}).reads_take(7);
        assert_eq!((c.now(), c.now()), (7, 14));
    }
}
