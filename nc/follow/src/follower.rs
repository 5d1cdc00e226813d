//! The real-time interpolator over streamed chunks: a period is the override moved
//! ([`Tracker`]), the plan time advanced by it and held where the path waits ([`Gates`]),
//! the path position found in the chunk at hand, then the pose there.

use crate::chunk::{Chunk, Start};
use crate::gates::Gates;
use crate::hold::{AxisHold, HoldConfig};
use crate::queue::{Inlet, LOOKAHEAD};
use crate::tracker::{Jerk, Tracker};
use heapless::Deque;
use nc_geom::kinematics::{Joints, MachineKinematics, RotaryLimits};
use nc_geom::program::Aux;
use nc_geom::scurve::Motion;
use nc_geom::segment::Pose;
use nc_geom::setpoint::Setpoint;
use std::cmp::Ordering as Cmp;
use std::sync::atomic::Ordering;

/// Counters of a streamed run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamCounters {
    /// Holds started because the path that had arrived was about to run out.
    pub underruns: u64,
    /// Periods spent holding for data (k < 1 for lack of data).
    pub hold_periods: u64,
    /// Periods where the path ran out before the hold stopped the tool (the tool was stopped
    /// at the end of the data: on the path, but without deceleration). Should stay 0.
    pub hard_stops: u64,
    /// Chunks that could not be handed back (cannot happen by the depth rule; leaked
    /// rather than freed in the real-time thread).
    pub leaked: u64,
}

/// The real-time interpolator over streamed chunks (arc-length method).
pub struct Follower<'q> {
    inlet: Inlet<'q>,
    local: Deque<Box<Chunk>, LOOKAHEAD>,
    kin: MachineKinematics,
    lim: RotaryLimits,
    hold: HoldConfig,
    axis_hold: AxisHold,
    /// The program's last chunk has arrived.
    complete: bool,
    cycle: u64,
    /// Plan time.
    tau: f64,
    tracker: Tracker,
    phase: usize,
    motion: Motion,
    stop_requested: bool,
    holding: bool,
    /// Held for data closer to its end than the least stop distance, the path creeps on
    /// with its jerk scaled by this, chosen at rest, until it is at rest again or the
    /// whole jerk's stop fits ([`Follower::plan_time`]).
    creep: Option<f64>,
    /// The operator's feed override (0..=1) and pause: the tracker's target when the
    /// data suffices.
    feed_override: f64,
    paused: bool,
    gates: Gates,
    /// Spindle and coolant commanded now.
    aux: Aux,
    done: bool,
    pose: Pose,
    joints: Joints,
    block: u32,
    /// Where the segment of the last pose starts along the path.
    seg_start: f64,
    counters: StreamCounters,
    pending: Pending,
}

/// What [`Follower::advance`] leaves for [`Follower::evaluate`].
#[derive(Clone, Copy, Debug, PartialEq)]
enum Pending {
    /// The path position moved: evaluate the pose there (cycle).
    Pose(u64),
    /// The pose stands: report it again (cycle, feed).
    Fixed(u64, f64),
}

impl<'q> Follower<'q> {
    pub fn new(
        inlet: Inlet<'q>,
        start: Start,
        kin: MachineKinematics,
        lim: RotaryLimits,
        hold: HoldConfig,
    ) -> Self {
        Follower {
            inlet,
            local: Deque::new(),
            kin,
            lim,
            hold,
            axis_hold: AxisHold::new(&hold, &start.margins),
            complete: start.empty,
            cycle: 0,
            tau: 0.0,
            tracker: Tracker::new(),
            phase: 0,
            pending: Pending::Fixed(0, 0.0),
            motion: Motion::default(),
            stop_requested: false,
            holding: false,
            creep: None,
            feed_override: 1.0,
            paused: false,
            gates: Gates::default(),
            aux: Aux::default(),
            done: start.empty,
            pose: start.pose,
            joints: start.joints,
            block: 1,
            seg_start: 0.0,
            counters: StreamCounters::default(),
        }
    }

    /// The same interpolator for the next program, from `start`: every chunk of the last
    /// one still held or still queued is handed back to the planner (bounded by the queue's
    /// capacity), and the state is as [`Follower::new`] leaves it. The planner must have
    /// stopped pushing the last program's chunks before this, and pushes the next one's
    /// only after: what `dnurbs serve` runs one program or MDI line after another with,
    /// on one pair of queues for the machine's life. The stream counters carry on.
    ///
    /// Real-time thread: allocates nothing (the chunks go back to be freed by the planner).
    pub fn next_program(mut self, start: Start) -> Self {
        while let Some(c) = self.local.pop_front() {
            self.give_back(c);
        }
        for _ in 0..crate::queue::QUEUE_N {
            let Some(c) = self.inlet.ready.dequeue() else {
                break;
            };
            self.give_back(c);
        }
        let counters = self.counters;
        let mut next = Follower::new(self.inlet, start, self.kin, self.lim, self.hold);
        next.counters = counters;
        next
    }

    /// Decelerate along the path to a stop and stay there (SIGINT, a drive fault).
    pub fn request_stop(&mut self) {
        self.stop_requested = true;
    }

    /// The source line at which the planner refused the program, once it has: the follower
    /// is stopping along the path (allocation-free, one atomic load).
    ///
    /// Real-time thread.
    pub fn refused(&self) -> Option<u32> {
        match self.inlet.refused.load(Ordering::Acquire) {
            0 => None,
            line => Some(line),
        }
    }

    /// The operator's feed override, a fraction of the planned feed in 0..=1 (clamped; NaN
    /// counts as 0). Reached, like a feed hold, by the rate- and jerk-limited tracker.
    pub fn set_override(&mut self, k: f64) {
        self.feed_override = if k.is_nan() { 0.0 } else { k.clamp(0.0, 1.0) };
    }

    pub fn feed_override(&self) -> f64 {
        self.feed_override
    }

    /// Decelerate along the path and hold there until [`Self::resume`]. Unlike a stop, the
    /// run is not over.
    pub fn pause(&mut self) {
        self.paused = true;
    }

    pub fn resume(&mut self) {
        self.paused = false;
        self.gates.awaiting = None;
    }

    /// The line of the operator stop (`M00`, `M01`, `M06`) the path stands at, waiting for
    /// [`Self::resume`].
    pub fn awaiting(&self) -> Option<u32> {
        self.gates.awaiting
    }

    /// Hold at every move that needs the spindle at speed until [`Self::spindle_at_speed`]
    /// reports that speed (a machine with a spindle drive). Off by default: the spindle
    /// words then change [`Setpoint::aux`] and nothing waits.
    pub fn wait_for_spindle(&mut self, on: bool) {
        self.gates.spindle_on = on;
    }

    /// The speed (rpm, signed as [`Aux::spindle_rpm`]) the spindle drive reports it has
    /// reached, or `None` while it is not at the speed it was sent. Every period, before
    /// [`Self::advance`].
    pub fn spindle_at_speed(&mut self, rpm: Option<f64>) {
        self.gates.spindle_at = rpm;
    }

    /// The line of the move that waits for the spindle to reach its speed, while it waits.
    pub fn awaiting_spindle(&self) -> Option<u32> {
        self.gates.awaiting_spindle
    }

    /// The program's digital inputs as read this period (bit n: `M66 P<n>`), or `None`
    /// without an I/O module (an `M66` then passes at once). Every period, before
    /// [`Self::advance`].
    pub fn inputs(&mut self, bits: Option<u64>) {
        self.gates.inputs = bits;
    }

    /// The line of the `M66` the path waits at, while it waits.
    pub fn awaiting_input(&self) -> Option<u32> {
        self.gates.awaiting_input
    }

    /// `M66` waits that ended at their timeout, and the line of the last.
    pub fn input_timeouts(&self) -> (u64, Option<u32>) {
        (self.gates.input_timeouts, self.gates.last_timeout)
    }

    /// Spindle and coolant as commanded now: those of the segment being machined, or of
    /// the one waiting for the spindle.
    pub fn aux(&self) -> Aux {
        self.aux
    }

    pub fn is_paused(&self) -> bool {
        self.paused
    }

    /// At rest after [`Self::request_stop`], or at the end of the program.
    pub fn is_stopped(&self) -> bool {
        self.done || (self.stop_requested && self.tracker.at_rest())
    }

    pub fn is_done(&self) -> bool {
        self.done
    }

    pub fn counters(&self) -> StreamCounters {
        self.counters
    }

    /// Path position, plan time and override of the last step.
    pub fn state(&self) -> (f64, f64, f64) {
        (self.motion.s, self.tau, self.tracker.k)
    }

    /// The last setpoint (the start pose before the first step).
    pub fn last(&self) -> Setpoint {
        self.setpoint(self.cycle.saturating_sub(1), self.motion.v)
    }

    /// Source line of the block being machined (0 before the first has arrived).
    pub fn line(&self) -> u32 {
        self.local
            .front()
            .and_then(|c| c.segment_at(self.motion.s))
            .map_or(0, |(seg, _)| seg.src.line)
    }

    /// Where the segment of the last setpoint starts along the path: setpoints with the
    /// same value lie on one segment, inside which the plan's jerk is limited (a junction
    /// that is not G2-continuous is not).
    pub fn segment_start(&self) -> f64 {
        self.seg_start
    }

    /// How far into the program the tool is, 0..=1 ([`Chunk::progress`] of the chunk at
    /// hand).
    pub fn progress(&self) -> f64 {
        if self.done {
            return 1.0;
        }
        self.local.front().map_or(0.0, |c| c.progress)
    }

    /// Take what the planner has pushed, up to the look-ahead.
    fn pull(&mut self) {
        while !self.local.is_full() {
            match self.inlet.ready.dequeue() {
                Some(c) => {
                    self.complete |= c.last;
                    // The deque is not full: cannot fail.
                    if let Err(c) = self.local.push_back(c) {
                        self.give_back(c);
                    }
                }
                None => break,
            }
        }
    }

    fn give_back(&mut self, c: Box<Chunk>) {
        if let Err(c) = self.inlet.retired.enqueue(c) {
            core::mem::forget(c);
            self.counters.leaked += 1;
        }
    }

    fn retire_front(&mut self) {
        if let Some(c) = self.local.pop_front() {
            self.give_back(c);
        }
        self.phase = 0;
    }

    fn motion_in(c: &Chunk, tau: f64, cursor: &mut usize) -> Motion {
        let n = c.phases.len();
        if n == 0 {
            return Motion {
                s: c.s1,
                v: 0.0,
                a: 0.0,
            };
        }
        while *cursor + 1 < n && tau >= c.phases[*cursor + 1].t0 {
            *cursor += 1;
        }
        let ph = &c.phases[(*cursor).min(n - 1)];
        let mut m = ph.at((tau - ph.t0).clamp(0.0, ph.dur));
        m.v = m.v.max(0.0);
        m
    }

    /// One period: the next setpoint ([`Follower::advance`] then [`Follower::evaluate`]).
    /// Allocation-free; loops bounded by [`LOOKAHEAD`].
    pub fn step(&mut self) -> Setpoint {
        self.advance();
        self.evaluate()
    }

    /// The first half of a period: take arrived chunks, move the override and the plan time,
    /// and find the new path position s. No curve is evaluated here.
    ///
    /// Real-time thread.
    pub fn advance(&mut self) {
        self.pull();
        if self.refused().is_some() {
            self.stop_requested = true;
        }
        let cycle = self.cycle;
        self.cycle += 1;
        if cycle == 0 || self.done {
            self.pending = Pending::Fixed(cycle, 0.0);
            return;
        }
        // Nothing arrived yet: stay at the start (the plan starts from rest at tau = 0).
        if self.local.is_empty() {
            self.tracker.rest();
            if !self.complete && !self.stop_requested {
                self.counters.hold_periods += 1;
            }
            self.pending = Pending::Fixed(cycle, 0.0);
            return;
        }
        let tau = self.plan_time();
        let (tau, gate_aux) = self.gate(tau);
        self.move_to(tau, cycle, gate_aux);
    }

    /// The override moved one period toward its target, and the plan time it reaches.
    fn plan_time(&mut self) -> f64 {
        let ts = self.hold.period;
        // The hold's scale: the highest planned speed from here to the end, not only over
        // the chunks at hand. A faster chunk arriving mid-hold would otherwise lower the
        // hold's jerk under a rate built with the old one, which could then not be undone
        // before the data ran out.
        let vb = self
            .local
            .front()
            .map_or(1e-9, |c| c.vmax_ahead)
            .max(1e-9)
            .max(self.motion.v);
        let rmax = self.hold.acc / vb;
        let mut jerk = Jerk {
            path: self.hold.jerk / vb,
            cap: 1.0,
        };
        let avail_end = self.local.back().map_or(self.motion.s, |c| c.s1);
        let room = avail_end - self.motion.s;
        let axes = &self.axis_hold;
        let stop = |t: &Tracker, jerk: Jerk| t.stop_distance(vb, rmax, jerk, ts, axes);
        // Held at rest for data, closer to its end than the least stop distance: creep on
        // with a gentler jerk whose stop fits in half the room. The planner may be unable to
        // push more (the queue's depth is in the chunks held here) until the first is left.
        // The gentler jerk is kept while the path moves (a lower jerk is always safe, and
        // the rate was built with it), until it is at rest again or the whole jerk's stop
        // fits: dropping it as soon as the path moved made the whole jerk's longer stop
        // hold the path at once, and it crept on by a fraction of the room per hold,
        // never leaving the first chunk (the long run's seed 31 000 003: 1e-6 mm in 50 s).
        if self.complete || room <= 0.0 {
            self.creep = None;
        } else if self.tracker.at_rest() {
            let d0 = stop(&self.tracker, jerk);
            self.creep = (d0 >= room).then(|| 0.5 * room / d0);
        } else if self.creep.is_some()
            && room.partial_cmp(&stop(&self.tracker, jerk)) == Some(Cmp::Greater)
        {
            self.creep = None;
        }
        if let Some(gentler) = self.creep {
            jerk.path *= gentler;
            jerk.cap *= gentler;
        }
        // (A stop distance that is not a number holds too.)
        let fits = room.partial_cmp(&stop(&self.tracker, jerk)) == Some(Cmp::Greater);
        let underrun = !self.complete && !fits;
        let target = self.target(underrun);
        // At rest (the plan at rest, or already held), the override drops to 0 at once:
        // nothing moves. Otherwise a program whose first chunk is shorter than the distance
        // to stop from the plan's start would begin to move, then stop short at its end.
        if target == 0.0 && self.motion.v == 0.0 {
            self.tracker.rest();
        }
        let axes = &self.axis_hold;
        let rate = self.tracker.rate_bound(rmax, jerk, ts, axes);
        let covered = self.tracker.track(target, rate, jerk, ts, axes);
        self.tau + self.dwell(covered)
    }

    /// The plan time a period covers, `covered` by the override, or where the plan stands
    /// still (a dwell) and the operator has not held it, at the operator's override up to
    /// the dwell's end. The path does not move there whatever the override does, so a hold
    /// for data must not stretch the dwell: its override, kept low by the stop distance
    /// from the plan's speed ahead, let the dwell pass at a fraction of the rate, and the
    /// queue (its depth in the chunks held here) never had room for the data the hold
    /// waited for (the long run's seed 31 000 003: a G82 dwell of 0.2 s at k ~ 0.002).
    /// The override itself is left as the hold has it: the path leaves the dwell with a
    /// stop that fits.
    fn dwell(&self, covered: f64) -> f64 {
        if self.stop_requested || self.paused {
            return covered;
        }
        let rate = self.hold.period * self.feed_override;
        match self.still_until(self.tau) {
            Some(end) if rate > covered => rate.min(end - self.tau).max(covered),
            _ => covered,
        }
    }

    /// Where the plan stands still at plan time `tau` in the chunk at hand (a phase at rest
    /// with nothing to change it), the time its stillness ends. Bounded by the chunk's
    /// phases.
    fn still_until(&self, tau: f64) -> Option<f64> {
        let c = self.local.front()?;
        let mut i = self.phase;
        while i + 1 < c.phases.len() && c.phases.get(i + 1).is_some_and(|p| tau >= p.t0) {
            i += 1;
        }
        let p = c.phases.get(i)?;
        let end = p.t0 + p.dur;
        let still = p.v0 == 0.0 && p.a0 == 0.0 && p.j == 0.0;
        (still && tau >= p.t0 && tau < end).then_some(end)
    }

    /// The override's target: 0 for a stop, for an underrun (the path that has arrived ends
    /// within the distance needed to stop: counted once per hold) and while paused; else
    /// the operator's override.
    fn target(&mut self, underrun: bool) -> f64 {
        let target = if self.stop_requested {
            0.0
        } else if underrun {
            if !self.holding {
                self.holding = true;
                self.counters.underruns += 1;
            }
            0.0
        } else {
            self.holding = false;
            if self.paused {
                0.0
            } else {
                self.feed_override
            }
        };
        if self.holding {
            self.counters.hold_periods += 1;
        }
        target
    }

    /// Plan time `tau` held where the path waits: at an operator stop ahead (paused there
    /// until resumed), at a move that waits for the spindle. With the spindle command that
    /// move starts, once it is reached.
    fn gate(&mut self, mut tau: f64) -> (f64, Option<Aux>) {
        if let Some(held) = self.gates.operator(self.local.iter(), tau, self.tau) {
            tau = held;
            self.tracker.rest();
            self.paused = true;
        }
        let (held, aux) = self
            .gates
            .spindle(self.local.iter(), tau, self.tau, self.paused);
        if let Some(held) = held {
            tau = held;
            self.tracker.rest();
        }
        let dt = self.hold.period;
        let (held, input_aux) = self
            .gates
            .input(self.local.iter(), tau, self.tau, self.paused, dt);
        if let Some(held) = held {
            tau = held;
            self.tracker.rest();
        }
        (tau, aux.or(input_aux))
    }

    /// The path position at plan time `tau`, in the chunk that holds it (retiring those
    /// left behind; bounded by the look-ahead).
    fn move_to(&mut self, mut tau: f64, cycle: u64, gate_aux: Option<Aux>) {
        // The data ends where the plan comes to rest (an exact stop at a kink): wait there,
        // at rest like the plan, for the next chunk. Nothing is cut short: no hard stop.
        let rest_end = match (self.local.len(), self.local.front()) {
            (1, Some(c)) => c.rests_at_end && !c.last && tau >= c.t_arrive,
            _ => false,
        };
        let mut m = self.motion;
        if let (true, Some(c)) = (rest_end, self.local.front()) {
            tau = c.t_arrive.max(self.tau);
            m = Self::motion_in(c, tau, &mut self.phase);
            m.s = m.s.min(c.s1).max(self.motion.s);
            m.v = 0.0;
            self.tracker.rest();
        }
        // Otherwise find the chunk that holds tau; bounded by the look-ahead.
        let walk = if rest_end { 0 } else { LOOKAHEAD + 1 };
        for _ in 0..walk {
            let Some(c) = self.local.front() else { break };
            m = Self::motion_in(c, tau, &mut self.phase);
            if c.last {
                if tau >= c.t_end {
                    self.done = true;
                    m = Motion {
                        s: c.s1,
                        v: 0.0,
                        a: 0.0,
                    };
                }
                break;
            }
            if m.s <= c.s1 && tau <= c.t_end {
                break;
            }
            if self.local.len() > 1 {
                self.retire_front();
            } else {
                // The data ran out before the hold had stopped: stop at its end, on the path.
                let s1 = c.s1;
                self.counters.hard_stops += 1;
                self.tracker.rest();
                self.motion.s = self.motion.s.max(s1.min(m.s));
                self.motion.v = 0.0;
                self.motion.a = 0.0;
                self.pending = Pending::Pose(cycle);
                return;
            }
        }
        self.tau = tau;
        m.v *= self.tracker.k;
        self.motion = m;
        self.aux = match (gate_aux, self.local.front()) {
            (Some(a), _) => a,
            (None, Some(c)) => c.segment_at(m.s).map_or(self.aux, |(seg, _)| seg.aux),
            (None, None) => self.aux,
        };
        self.pending = Pending::Pose(cycle);
    }

    /// The second half of a period, the interpolation proper: u at the new path position
    /// (arc-length inverse), both curves from one basis evaluation, the tool axis, inverse
    /// kinematics. Calling it again before the next [`Follower::advance`] repeats the setpoint.
    ///
    /// Real-time thread.
    pub fn evaluate(&mut self) -> Setpoint {
        match self.pending {
            Pending::Fixed(cycle, feed) => self.setpoint(cycle, feed),
            Pending::Pose(cycle) => {
                let sp = self.pose_setpoint(cycle);
                self.pending = Pending::Fixed(cycle, self.motion.v);
                sp
            }
        }
    }

    /// A dry run of [`Follower::evaluate`]'s work where the next period will likely be (one
    /// period on at the present speed, in whichever chunk holds that): the same arc-length
    /// inverse, basis functions, both curves and inverse kinematics, with nothing kept. The
    /// real-time loop calls it before the deadline so that the step's code and data, the
    /// next segment's at a hand-over, are in the caches when the timed step runs.
    /// Allocation-free; bounded by [`LOOKAHEAD`].
    ///
    /// Real-time thread.
    pub fn rehearse(&self) -> Joints {
        let s = self.motion.s + self.motion.v.max(0.0) * self.hold.period;
        let chunk = self
            .local
            .iter()
            .find(|c| s <= c.s1)
            .or_else(|| self.local.back());
        let s = chunk.map_or(s, |c| s.min(c.s1));
        match chunk.and_then(|c| c.segment_at(s)) {
            Some((seg, s0)) => seg.pose(s - s0).joints(&self.kin, &self.joints, &self.lim),
            None => self.joints,
        }
    }

    fn pose_setpoint(&mut self, cycle: u64) -> Setpoint {
        let s = self.motion.s;
        if let Some((seg, s0)) = self.local.front().and_then(|c| c.segment_at(s)) {
            self.block = seg.block;
            self.seg_start = s0;
            self.pose = seg.pose(s - s0);
        }
        self.joints = self.pose.joints(&self.kin, &self.joints, &self.lim);
        if self.done {
            // The program's last chunk is finished: hand it back now.
            self.retire_front();
        }
        self.setpoint(cycle, self.motion.v)
    }

    fn setpoint(&self, cycle: u64, feed: f64) -> Setpoint {
        Setpoint {
            cycle,
            t: cycle as f64 * self.hold.period,
            block: self.block,
            u: self.pose.u,
            p: self.pose.p,
            tool: self.pose.axis(&self.kin),
            feed: if self.done { 0.0 } else { feed },
            joints: self.joints,
            done: self.done,
            aux: self.aux,
        }
    }
}
