//! The machine `serve` runs: the machine file's buses set up with their drives (simulated
//! in-process for `--sim`, on a virtual clock for the tests) and everything the life and
//! the hub are made of, allocated once for the process's life.

use crate::run::buses;
use crate::setup::MachineSetup;
use crate::simdrives::{sim_nodes, FaultArgs};
use config::Machine;
use drives::link::{CanLink, MemLink};
use drives::master::Clock;
use drives::sim::Lockstep;
use nc_follow::{Follower, Queues};
use rt_loop::life::{Life, Queues as LifeQueues, Status};
use rt_loop::pipeline::BusDrives;
use std::time::Duration;

/// Frames each direction of a simulated bus holds.
pub const SIM_QUEUE_FRAMES: usize = 1024;

/// A continuous jog's dead-man, s: it stops this long after its last renewal.
pub const DEADMAN_S: f64 = 0.2;

/// The buses' masters and the drives simulated on their far ends.
pub type SimBuses = (Vec<BusDrives<MemLink>>, Vec<Lockstep<MemLink>>);

/// Each bus of `machine` on an in-memory link to drives simulated on a virtual clock (the
/// drives' clock): set up, configured and taken over by their masters, every bus's clock
/// where the slowest set-up left its own. `faults` are injected as `sim-drives` does.
pub fn lockstep_buses(machine: &Machine, faults: &FaultArgs) -> anyhow::Result<SimBuses> {
    let mut out = Vec::new();
    let mut sims = Vec::new();
    for bi in 0..machine.buses.len() {
        let (link, drive_end) = MemLink::pair(SIM_QUEUE_FRAMES);
        let nodes = sim_nodes(machine, bi, 0.0, faults);
        let mut sim = Lockstep::new(drive_end, nodes, machine.period_s);
        let now = |c: &Lockstep<MemLink>| Clock::now(c).as_secs_f64();
        out.push(buses::set_up(machine, bi, link, &mut sim, now)?);
        sims.push(sim);
    }
    let t0 = sims.iter().map(|d| d.now()).max().unwrap_or(Duration::ZERO);
    for d in sims.iter_mut() {
        d.advance_to(t0);
    }
    Ok((out, sims))
}

/// What lives as long as the controller: the machine in the interpolator's units, the
/// shop's parse set-up, the queues and the status.
pub struct Fixed {
    pub machine: Machine,
    pub setup: MachineSetup,
    pub shop: nc_lang::Setup,
    pub chunks: Box<Queues>,
    pub life: LifeQueues,
    pub status: Status,
}

impl Fixed {
    pub fn new(machine: Machine, shop: nc_lang::Setup) -> Box<Fixed> {
        Box::new(Fixed {
            setup: MachineSetup::new(&machine),
            machine,
            shop,
            chunks: Queues::new(),
            life: LifeQueues::default(),
            status: Status::default(),
        })
    }

    /// The real-time thread's life on `buses` and the hub's ends of the queues.
    #[allow(clippy::type_complexity)]
    pub fn split<L: CanLink>(
        &mut self,
        buses: Vec<BusDrives<L>>,
    ) -> (Life<'_, L>, super::hub::Hub<'_>) {
        let Fixed {
            machine,
            setup,
            shop,
            chunks,
            life,
            status,
        } = self;
        let depth = machine.realtime.queue_depth;
        let (feeder, inlet) = chunks.split(depth);
        let idle = nc_follow::Start {
            pose: nc_geom::segment::Pose {
                p: nalgebra::Vector3::zeros(),
                tool: nc_geom::segment::Tool::Angles(0.0, 0.0),
                u: None,
                z: 0.0,
            },
            joints: [0.0; 5],
            empty: true,
            margins: Default::default(),
        };
        let follower = Follower::new(inlet, idle, setup.kin, setup.plan.rotary, setup.plan.hold());
        let (hub_ends, rt_ends) = life.split();
        let period = machine.period_s;
        let deadman = (DEADMAN_S / period).ceil() as u32;
        let enable = (machine.realtime.boot_timeout_s / period).ceil() as u64;
        let c_continuous = setup.limits[4].is_unlimited();
        let life = Life::new(
            buses,
            follower,
            rt_ends,
            period,
            enable,
            deadman,
            c_continuous,
        );
        let hub = super::hub::Hub::new(machine, setup, shop, hub_ends, feeder, status);
        (life, hub)
    }
}
