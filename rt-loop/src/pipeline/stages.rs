//! What each stage does in a period: enabling the drives, the approach, interpolating
//! (running and stopping), disabling. Each takes its stage's own state out of the run's
//! phase and returns the phase of the next period.

use super::approach::Approach;
use super::{Moving, Phase, Pipeline, Prepared, Stage, StopReason};
use crate::os;
use drives::cia402::{Goal, State};
use drives::link::CanLink;
use nc_geom::program::Aux;

impl<L: CanLink> Pipeline<'_, L> {
    /// The cache warm-up before the step: the interpolation and the count conversion run once
    /// where the next period will likely be ([`nc_follow::Follower::rehearse`]) and the
    /// result is dropped, so the timed step finds its code and data in the caches. Changes no
    /// state and sends nothing; does nothing outside the program.
    ///
    /// Real-time thread.
    pub fn rehearse(&self) {
        if !matches!(self.stage(), Stage::Running | Stage::Stopping) {
            return;
        }
        let axes = self.joints_to_axes(&self.follower.rehearse());
        for b in &self.buses {
            for d in &b.drives {
                if let Some(&p) = axes.get(d.axis) {
                    core::hint::black_box(d.counts(p));
                }
            }
        }
    }

    /// The interpolation step of the coming period, while the program runs: feed, override
    /// and chunk hand-off, then the timed span, the paper's: parameter update (u at the new
    /// s), basis functions, both curves, tool axis, inverse kinematics, to the final axis
    /// positions in counts. [`Pipeline::cycle`] sends what it computed; it calls this itself
    /// unless the loop did so before the deadline. Once per period: a second call does
    /// nothing.
    ///
    /// Real-time thread.
    pub fn prepare(&mut self) {
        let pending = match &self.phase {
            Phase::Running(m) | Phase::Stopping(m) => m.prepared.is_none(),
            _ => false,
        };
        if !pending {
            return;
        }
        let p = self.interpolate();
        if let Phase::Running(m) | Phase::Stopping(m) = &mut self.phase {
            m.prepared = Some(p);
        }
    }

    /// The follower's step and the targets it gives.
    fn interpolate(&mut self) -> Prepared {
        let at_speed = self.spindle_at_speed();
        self.follower.spindle_at_speed(at_speed);
        let inputs = self.buses.iter().find_map(|b| b.program_inputs());
        self.follower.inputs(inputs);
        self.follower.advance();
        let t0 = os::now();
        let sp = self.follower.evaluate();
        let axes = self.joints_to_axes(&sp.joints);
        let overflow = self.set_targets(&axes).err();
        let compute_ns = os::now().saturating_sub(t0);
        let at_rest = sp.done || self.follower.is_stopped();
        // At the end, or stopped: spindle, coolant and the program's outputs off.
        self.command_aux(if at_rest { Aux::default() } else { sp.aux });
        Prepared {
            compute_ns,
            at_rest,
            overflow,
        }
    }

    /// Every drive to Operation enabled; then the approach, or the program.
    pub(super) fn enabling(&mut self, approach: Option<Approach>) -> Phase {
        if self.reason.is_some() {
            Phase::Disabling
        } else if self.all_in(|s| s == State::OperationEnabled) {
            match approach {
                Some(ap) => Phase::Approach(ap),
                None => Phase::Running(Moving::default()),
            }
        } else if self.stage_cycles > self.enable_timeout_cycles {
            self.set_reason(StopReason::EnableTimeout(self.enable_timeout_cycles));
            Phase::Disabling
        } else {
            Phase::Enabling(approach)
        }
    }

    /// One period of the move to the start.
    pub(super) fn approaching(&mut self, mut ap: Approach) -> Phase {
        if self.reason.is_some() {
            // A straight axis move, not a path: the drives stop by their own quick-stop
            // ramp (CiA-402), then are disabled.
            for b in self.buses.iter_mut() {
                b.master.set_goal(Goal::QuickStop);
            }
            return Phase::Disabling;
        }
        let (axes, done) = ap.step(self.period);
        if let Err(r) = self.set_targets(&axes) {
            self.set_reason(r);
        }
        if done {
            Phase::Running(Moving::default())
        } else {
            Phase::Approach(ap)
        }
    }

    /// One period of the program (`stopping`: along the path to rest after a stop).
    pub(super) fn moving(&mut self, mut m: Moving, stopping: bool, compute_ns: &mut u64) -> Phase {
        let p = match m.prepared.take() {
            Some(p) => p,
            None => self.interpolate(),
        };
        *compute_ns = p.compute_ns;
        if let Some(r) = p.overflow {
            self.stop(r);
        }
        self.spindle_timeout(&mut m.spindle_wait);
        let stopping = stopping || self.reason.is_some();
        // At rest: let the drives reach the last target (their own lag) and the spindle stop
        // before disabling, so they stop where the path ends; bounded by SETTLE_CYCLES
        // (longer with a spindle: its ramp down).
        if p.at_rest {
            m.settle += 1;
            if self.settled() || m.settle > self.settle_limit {
                return if self.keep_enabled {
                    Phase::Finished
                } else {
                    Phase::Disabling
                };
            }
        }
        if stopping {
            Phase::Stopping(m)
        } else {
            Phase::Running(m)
        }
    }

    /// The CiA-402 disable sequence, until every drive has left Operation enabled.
    pub(super) fn disabling(&mut self) -> Phase {
        let goal_quick = self
            .buses
            .iter()
            .any(|b| b.master.goal() == Goal::QuickStop);
        for b in self.buses.iter_mut() {
            if !goal_quick || b.master.fault().is_some() {
                b.master.set_goal(Goal::Disabled);
            }
        }
        let stopped = |s: State| {
            matches!(
                s,
                State::SwitchOnDisabled
                    | State::ReadyToSwitchOn
                    | State::Fault
                    | State::NotReadyToSwitchOn
            )
        };
        // A lost drive (silent past its supervision) cannot report a state: it does not hold
        // the run up until the timeout.
        let all_stopped = self.buses.iter().all(|b| {
            b.master
                .status()
                .iter()
                .all(|s| s.state.is_some_and(stopped) || b.master.lost(s))
        });
        if all_stopped || self.stage_cycles > self.enable_timeout_cycles {
            return Phase::Finished;
        }
        if goal_quick && self.all_in(|s| s != State::OperationEnabled) {
            for b in self.buses.iter_mut() {
                b.master.set_goal(Goal::Disabled);
            }
        }
        Phase::Disabling
    }

    /// A move waiting for the spindle longer than `[spindle] at_speed_timeout_s` stops the
    /// run (the path is at rest there). `waited`: periods it has waited so far.
    fn spindle_timeout(&mut self, waited: &mut u64) {
        let Some(line) = self.follower.awaiting_spindle() else {
            *waited = 0;
            return;
        };
        *waited += 1;
        let Some((st, sp)) = self.spindle() else {
            return;
        };
        let timeout_s = sp.at_speed_timeout_s;
        if *waited as f64 * self.period > timeout_s && self.reason.is_none() {
            let reason = StopReason::SpindleNotAtSpeed {
                line,
                rpm: self.aux.spindle_rpm,
                actual_rpm: sp.rpm(st.actual),
                timeout_s,
            };
            self.stop(reason);
        }
    }
}
