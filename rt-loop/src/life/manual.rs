//! The modes outside a program: off, enabling, holding, homing, jogging, disabling and the
//! fault, each a period at a time, and the bus's master cycled with their targets.

use super::{Doing, Happened, Life, HOMING_AT_ONCE};
use drives::cia402::{Goal, State};
use drives::link::CanLink;
use drives::master::{HomeRefused, HomeRequest, HomingState, NodeKind, Reaction, MAX_NODES};
use nc_follow::jog::{Jog, JogLimits, JogRefused};
use nc_follow::jog_line::LineJog;

impl<L: CanLink> Life<'_, L> {
    /// A period outside a program: the mode's targets, then every master's cycle.
    pub(super) fn manual_cycle(&mut self, now: f64) {
        let doing = self.doing;
        self.doing = match doing {
            Doing::Off => {
                self.set_goal(Goal::Disabled);
                self.targets_where_they_stand();
                Doing::Off
            }
            Doing::Enabling { cycles } => {
                self.set_goal(Goal::Enabled);
                self.targets_where_they_stand();
                if self.all_drives(|s| s == State::OperationEnabled) {
                    self.report(Happened::Enabled);
                    Doing::Holding
                } else if cycles > self.enable_timeout_cycles {
                    self.report(Happened::EnableTimeout);
                    Doing::Disabling { cycles: 0 }
                } else {
                    Doing::Enabling { cycles: cycles + 1 }
                }
            }
            Doing::Holding | Doing::Fault | Doing::Program => doing,
            Doing::Homing { jobs, n } => self.homing(jobs, n),
            Doing::Jog { axis, mut jog } => {
                let p = jog.step();
                self.set_axis(axis, p);
                if jog.at_rest() {
                    self.report(Happened::JogDone {
                        limited: jog.limited(),
                    });
                    Doing::Holding
                } else {
                    Doing::Jog { axis, jog }
                }
            }
            Doing::LineJog { mut jog } => {
                let p = jog.step();
                for (axis, &x) in p.iter().enumerate() {
                    self.set_axis(axis, x);
                }
                if jog.at_rest() {
                    self.report(Happened::JogDone {
                        limited: jog.limited(),
                    });
                    Doing::Holding
                } else {
                    Doing::LineJog { jog }
                }
            }
            Doing::Disabling { cycles } => {
                self.set_goal(Goal::Disabled);
                let out = |s: State| s != State::OperationEnabled;
                if self.all_drives(out) || cycles > self.enable_timeout_cycles {
                    self.report(Happened::Disabled);
                    Doing::Off
                } else {
                    Doing::Disabling { cycles: cycles + 1 }
                }
            }
        };
        let mut fault = None;
        let mut condition = None;
        for b in self.buses_mut() {
            let n = b.master.status().len().min(MAX_NODES);
            if let Some(f) = b.master.cycle(&b.targets[..n], now) {
                fault = fault.or(Some(f));
            }
            if let Some(c) = b.master.take_bus_condition() {
                condition = Some(c);
            }
        }
        if let Some(c) = condition {
            // A jog is an operator's move: anything worse than a warning stops it.
            if c.reaction() != Reaction::Warn {
                match self.doing {
                    Doing::Jog { axis, mut jog } => {
                        jog.stop();
                        self.doing = Doing::Jog { axis, jog };
                    }
                    Doing::LineJog { mut jog } => {
                        jog.stop();
                        self.doing = Doing::LineJog { jog };
                    }
                    _ => {}
                }
            }
            self.report(Happened::Bus(c));
        }
        if let Some(f) = fault {
            if !matches!(self.doing, Doing::Fault) {
                self.report(Happened::Fault(f));
                self.doing = Doing::Fault;
            }
        }
    }

    /// Start homing the drive at `index` of bus `bus` (with those homing already).
    pub(super) fn home(&mut self, bus: usize, index: usize, req: HomeRequest) {
        let (mut jobs, n) = match self.doing {
            Doing::Homing { jobs, n } => (jobs, n),
            _ => ([(0, 0); HOMING_AT_ONCE], 0),
        };
        let ids = u8::try_from(bus).ok().zip(u8::try_from(index).ok());
        let r = match (self.buses_mut().get_mut(bus), ids) {
            _ if n >= HOMING_AT_ONCE => Err(HomeRefused::Busy(0)),
            (Some(b), Some(_)) => b.master.home(index, req),
            _ => Err(HomeRefused::NoSuchAxis(index)),
        };
        match (r, ids) {
            (Ok(()), Some(id)) => {
                jobs[n] = id;
                self.doing = Doing::Homing { jobs, n: n + 1 };
                self.report(Happened::HomingStarted { bus, index });
            }
            (Err(e), _) => self.report(Happened::HomeRefused(e)),
            (Ok(()), None) => {}
        }
    }

    /// The operator's stop while homing.
    pub(super) fn stop_homing(&mut self, bus: usize, index: usize) {
        if let Some(b) = self.buses_mut().get_mut(bus) {
            b.master.stop_homing(index);
        }
    }

    /// A period of homing: each master's job sends its drive its own position; once one is
    /// over, that target is where the drive stands. Holding once all are over.
    fn homing(&mut self, mut jobs: [(u8, u8); HOMING_AT_ONCE], n: usize) -> Doing {
        let mut left = 0;
        for k in 0..n.min(HOMING_AT_ONCE) {
            let (bus, index) = (usize::from(jobs[k].0), usize::from(jobs[k].1));
            let Some(b) = self.buses_mut().get_mut(bus) else {
                continue;
            };
            let actual = b.master.status().get(index).map(|s| s.actual);
            if let (Some(t), Some(a)) = (b.targets.get_mut(index), actual) {
                *t = a;
            }
            let report = match b.master.homing(index) {
                HomingState::Running => {
                    jobs[left] = jobs[k];
                    left += 1;
                    None
                }
                HomingState::Attained { position } => {
                    if let Some(t) = b.targets.get_mut(index) {
                        *t = position;
                    }
                    Some(Happened::Homed {
                        bus,
                        index,
                        counts: position,
                    })
                }
                HomingState::Failed(error) => Some(Happened::HomingFailed { bus, index, error }),
                HomingState::Idle => None,
            };
            if let Some(h) = report {
                self.report(h);
            }
        }
        if left == 0 {
            Doing::Holding
        } else {
            Doing::Homing { jobs, n: left }
        }
    }

    /// Start a jog of `axis` from where its target is, as `begin` says.
    pub(super) fn jog(
        &mut self,
        axis: usize,
        limits: JogLimits,
        begin: impl FnOnce(&mut Jog) -> Result<(), JogRefused>,
    ) {
        let Some(position) = self.axis_target(axis) else {
            self.report(Happened::Refused {
                order: "jog",
                mode: self.mode(),
            });
            return;
        };
        let mut jog = Jog::new(position, limits, self.period, self.deadman_periods);
        match begin(&mut jog) {
            Ok(()) => {
                self.doing = Doing::Jog { axis, jog };
                self.report(Happened::JogStarted);
            }
            Err(e) => self.report(Happened::JogRefused(e)),
        }
    }

    /// Start a jog of X Y Z along `dir` from where their targets are.
    pub(super) fn line_jog(
        &mut self,
        dir: [f64; 3],
        limits: &[JogLimits; 3],
        distance: Option<f64>,
        speed: f64,
    ) {
        let origin = [0, 1, 2].map(|a| self.axis_target(a));
        let [Some(x), Some(y), Some(z)] = origin else {
            self.report(Happened::Refused {
                order: "jog along a line",
                mode: self.mode(),
            });
            return;
        };
        let started = LineJog::new([x, y, z], dir, limits, self.period, self.deadman_periods)
            .and_then(|mut jog| {
                match distance {
                    Some(d) => jog.to(d, speed)?,
                    None => jog.velocity(speed)?,
                }
                Ok(jog)
            });
        match started {
            Ok(jog) => {
                self.doing = Doing::LineJog { jog };
                self.report(Happened::JogStarted);
            }
            Err(e) => self.report(Happened::LineJogRefused(e)),
        }
    }

    /// Acknowledge the fault on every bus.
    pub(super) fn reset(&mut self) {
        let mut done = None;
        let mut refused = None;
        for b in self.buses_mut() {
            if b.master.fault().is_none() {
                continue;
            }
            match b.master.reset() {
                Ok(f) => done = done.or(Some(f)),
                Err(e) => refused = refused.or(Some(e)),
            }
        }
        if let Some(e) = refused {
            self.report(Happened::ResetRefused(e));
        }
        // Every bus acknowledged (a bus refused keeps the fault, and its master's).
        if refused.is_none() {
            if let Some(f) = done {
                self.report(Happened::ResetDone(f));
            }
            self.doing = Doing::Off;
        }
    }

    fn set_goal(&mut self, goal: Goal) {
        for b in self.buses_mut() {
            if b.master.goal() != goal {
                b.master.set_goal(goal);
            }
        }
    }

    /// Every CiA-402 drive's state satisfies `f` (I/O modules have none).
    fn all_drives(&self, f: impl Fn(State) -> bool) -> bool {
        self.buses().iter().all(|b| {
            b.master
                .status()
                .iter()
                .all(|s| s.kind == NodeKind::Io || s.state.is_some_and(&f))
        })
    }

    /// Every axis drive's target where it stands.
    fn targets_where_they_stand(&mut self) {
        for b in self.buses_mut() {
            let n = b.drives.len();
            for (t, s) in b.targets.iter_mut().zip(b.master.status()).take(n) {
                *t = s.actual;
            }
        }
    }

    /// The target of `axis`'s first drive, in its units.
    fn axis_target(&self, axis: usize) -> Option<f64> {
        self.buses().iter().find_map(|b| {
            let (i, d) = b.drives.iter().enumerate().find(|(_, d)| d.axis == axis)?;
            Some(d.position(*b.targets.get(i)?))
        })
    }

    /// Every drive of `axis` to `position` (its units). A position that does not fit the
    /// drive's counts stays where it was (the jog's travel keeps it inside).
    fn set_axis(&mut self, axis: usize, position: f64) {
        for b in self.buses_mut() {
            for (d, t) in b.drives.iter().zip(b.targets.iter_mut()) {
                if d.axis == axis {
                    if let Some(c) = d.counts(position) {
                        *t = c;
                    }
                }
            }
        }
    }
}
