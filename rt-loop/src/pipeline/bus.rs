//! The drives of one bus ([`BusDrives`]), and what the pipeline reads and writes of them
//! every period: axis positions to targets in counts, spindle speed and coolant outputs,
//! the drives' states.

use super::{Pipeline, Stage, StopReason};
use drives::cia402::{State, Statusword};
use drives::link::CanLink;
use drives::master::{BusCondition, BusHealth, Master, NodeKind, NodeStatus, Reaction, MAX_NODES};
use heapless::Vec as HVec;
use machine::bus::Drive;
use nc_geom::kinematics::Joints;
use nc_geom::program::Aux;

/// The drives of one bus and the master driving them.
pub struct BusDrives<L: CanLink> {
    pub master: Master<L>,
    /// The axes' drives, first in the master's node order.
    pub drives: HVec<Drive, MAX_NODES>,
    /// The spindle drive and its index in the master's node order (after the axes).
    pub spindle: Option<(usize, machine::Spindle)>,
    /// The coolant valves on the I/O module, and its index in the master's node order (last).
    pub coolant: Option<(usize, machine::Coolant)>,
    /// The program's digital I/O on the same module, and its index.
    pub io: Option<(usize, machine::BusIo)>,
    pub(crate) targets: [i32; MAX_NODES],
}

impl<L: CanLink> BusDrives<L> {
    /// `drives` in the order of the master's nodes; at most [`MAX_NODES`].
    pub fn new(master: Master<L>, drives: &[Drive]) -> Option<Self> {
        let mut v = HVec::new();
        for d in drives {
            v.push(d.clone()).ok()?;
        }
        let mut targets = [0; MAX_NODES];
        for (t, s) in targets.iter_mut().zip(master.status()) {
            *t = s.actual;
        }
        Some(BusDrives {
            master,
            drives: v,
            spindle: None,
            coolant: None,
            io: None,
            targets,
        })
    }

    /// The spindle drive is the master's node after the axes' drives.
    pub fn with_spindle(mut self, spindle: machine::Spindle) -> Self {
        self.spindle = Some((self.drives.len(), spindle));
        self
    }

    /// The I/O module is the master's node after the drives (and the spindle).
    fn module_index(&self) -> usize {
        self.drives.len() + usize::from(self.spindle.is_some())
    }

    /// The coolant valves are outputs of the I/O module.
    pub fn with_coolant(mut self, coolant: machine::Coolant) -> Self {
        self.coolant = Some((self.module_index(), coolant));
        self
    }

    /// The program's digital outputs and inputs are bits of the I/O module (the coolant's,
    /// when it has one: one module).
    pub fn with_io(mut self, io: machine::BusIo) -> Self {
        self.io = Some((self.module_index(), io));
        self
    }

    /// The program's digital inputs as the I/O module reported them (bit n = `M66 P<n>`).
    pub fn program_inputs(&self) -> Option<u64> {
        let (i, io) = self.io.as_ref()?;
        let st = self.master.status().get(*i)?;
        Some(io.program_inputs(st.actual as u8))
    }

    /// Spindle speed and coolant outputs as targets.
    pub(super) fn set_aux(&mut self, aux: &Aux) {
        if let Some((i, s)) = &self.spindle {
            if let Some(t) = self.targets.get_mut(*i) {
                *t = s.velocity(aux.spindle_rpm);
            }
        }
        let coolant = self
            .coolant
            .as_ref()
            .map(|(i, c)| (*i, c.outputs(aux.mist, aux.flood)));
        let io = self
            .io
            .as_ref()
            .map(|(i, b)| (*i, b.output_byte(aux.outputs)));
        // One module: its byte is the coolant's bits and the program's.
        if let Some(i) = coolant.or(io).map(|(i, _)| i) {
            let byte = coolant.map_or(0, |c| c.1) | io.map_or(0, |b| b.1);
            if let Some(t) = self.targets.get_mut(i) {
                *t = i32::from(byte);
            }
        }
    }
}

impl<L: CanLink> Pipeline<'_, L> {
    /// A feed hold or a controlled stop the buses called for this period (a quick stop is
    /// the master's fault). The hold pauses the path, as `dnurbs ctl pause` does: during
    /// the approach it takes effect at the program's start.
    pub(super) fn bus_reaction(&mut self) {
        let worst = self
            .buses
            .iter_mut()
            .filter_map(|b| b.master.take_bus_condition())
            .max_by_key(BusCondition::reaction);
        let Some(c) = worst else { return };
        if matches!(self.stage(), Stage::Disabling | Stage::Finished) {
            return;
        }
        match c.reaction() {
            Reaction::Hold => self.follower.pause(),
            Reaction::Stop => self.stop(StopReason::Bus(c)),
            Reaction::Warn | Reaction::QuickStop => {}
        }
    }

    /// Each bus's health (error frames by kind, the reactions called for) and the frames
    /// its master could not send.
    pub fn bus_health(&self) -> impl Iterator<Item = (&BusHealth, u64)> + '_ {
        self.buses
            .iter()
            .map(|b| (b.master.health(), b.master.dropped()))
    }

    /// Axis positions (mm, degrees) to targets; `false` if one did not fit.
    pub(super) fn set_targets(&mut self, axes: &[f64; 5]) -> Result<(), StopReason> {
        for b in self.buses.iter_mut() {
            for (d, t) in b.drives.iter().zip(b.targets.iter_mut()) {
                let Some(&p) = axes.get(d.axis) else { continue };
                match d.counts(p) {
                    Some(c) => *t = c,
                    None => {
                        return Err(StopReason::CountOverflow {
                            axis: d.axis,
                            position: p,
                        })
                    }
                }
            }
        }
        Ok(())
    }

    pub(super) fn joints_to_axes(&self, j: &Joints) -> [f64; 5] {
        core::array::from_fn(|k| {
            if self.rotary_deg[k] {
                j[k].to_degrees() + if k == 4 { self.c_shift_deg } else { 0.0 }
            } else {
                j[k]
            }
        })
    }

    /// Every axis within one count of its target, the spindle at its speed.
    pub(super) fn settled(&self) -> bool {
        self.buses.iter().all(|b| {
            b.master
                .status()
                .iter()
                .zip(&b.targets)
                .all(|(s, t)| match (s.kind, &b.spindle) {
                    (NodeKind::Position, _) => (s.actual.wrapping_sub(*t)).abs() <= 1,
                    (NodeKind::Velocity, Some((_, sp))) => {
                        i64::from(s.actual).abs_diff(i64::from(*t)) <= u64::from(sp.window_units())
                    }
                    _ => true,
                })
        })
    }

    /// Every CiA-402 drive's state satisfies `f` (I/O modules have none).
    pub(super) fn all_in(&self, f: impl Fn(State) -> bool) -> bool {
        self.buses.iter().all(|b| {
            b.master
                .status()
                .iter()
                .all(|s| s.kind == NodeKind::Io || s.state.is_some_and(&f))
        })
    }

    /// The spindle drive's status and configuration, if the machine has one.
    pub(super) fn spindle(&self) -> Option<(&NodeStatus, &machine::Spindle)> {
        self.buses.iter().find_map(|b| {
            let (i, s) = b.spindle.as_ref()?;
            Some((b.master.status().get(*i)?, s))
        })
    }

    /// The speed the spindle has reached, if it is the one sent: Operation enabled, target
    /// reached (bit 10) and the velocity actual within the window of it.
    pub(super) fn spindle_at_speed(&self) -> Option<f64> {
        let (st, sp) = self.spindle()?;
        let want = sp.velocity(self.aux.spindle_rpm);
        let within = i64::from(st.actual).abs_diff(i64::from(want)) <= u64::from(sp.window_units());
        (st.state == Some(State::OperationEnabled)
            && st.target == want
            && Statusword(st.statusword).target_reached()
            && within)
            .then_some(self.aux.spindle_rpm)
    }

    /// Send `aux` from this period on.
    pub(super) fn command_aux(&mut self, aux: Aux) {
        self.aux = aux;
        for b in self.buses.iter_mut() {
            b.set_aux(&aux);
        }
    }

    /// Each drive's node, last target and actual position (counts), bus by bus.
    pub fn drive_positions(&self) -> impl Iterator<Item = (usize, u8, i32, i32)> + '_ {
        self.buses.iter().flat_map(|b| {
            b.drives
                .iter()
                .zip(b.master.status())
                .map(|(d, s)| (d.axis, d.node, s.target, s.actual))
        })
    }
}
