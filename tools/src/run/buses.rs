//! Each bus's nodes set up (SDO, PDO mapping, NMT start) and handed to a master: the same
//! for a real bus on wall time and for simulated drives on a virtual clock.

use super::node_setups;
use config::Machine;
use drives::link::CanLink;
use drives::master::{configure_nodes, Clock, Master, SetupOptions, Supervision};
use rt_loop::pipeline::BusDrives;
use std::time::Duration;

/// The set-up's timeouts and the cycle's supervision, from the machine file.
pub(super) fn options(machine: &Machine) -> (SetupOptions, Supervision) {
    let rtc = &machine.realtime;
    let period = machine.period_s;
    let mut sopts = SetupOptions::new(period);
    sopts.boot_timeout = Duration::from_secs_f64(rtc.boot_timeout_s);
    sopts.sdo_timeout = Duration::from_secs_f64(rtc.sdo_timeout_s);
    let sup = Supervision {
        heartbeat_timeout_s: rtc.heartbeat_timeout_s,
        feedback_timeout_cycles: (rtc.feedback_timeout_s / period).ceil() as u32,
    };
    (sopts, sup)
}

/// Set up bus `bi` of `machine` over `link`, its waits on `clock`; the master starts its
/// supervision at `now(clock)` (s, the loop's clock).
pub(super) fn set_up<L: CanLink, C: Clock>(
    machine: &Machine,
    bi: usize,
    mut link: L,
    clock: &mut C,
    now: impl FnOnce(&C) -> f64,
) -> anyhow::Result<BusDrives<L>> {
    let (sopts, sup) = options(machine);
    let drives: Vec<config::bus::Drive> = machine
        .drives
        .iter()
        .filter(|d| d.bus == bi)
        .cloned()
        .collect();
    let setups = node_setups(machine, bi);
    let bus_name = &machine.buses[bi].interface;
    let initial = configure_nodes(&mut link, &setups, &sopts, clock, &mut |_| {})
        .map_err(|e| anyhow::anyhow!("drive set-up on {bus_name}: {e}"))?;
    let kinds: Vec<_> = setups.iter().map(|s| (s.node(), s.kind())).collect();
    let master = Master::with_kinds(link, &kinds, &initial, sup, now(clock))
        .ok_or_else(|| anyhow::anyhow!("{bus_name}: too many drives on one bus"))?;
    let mut bus = BusDrives::new(master, &drives)
        .ok_or_else(|| anyhow::anyhow!("{bus_name}: too many drives"))?;
    if let Some(s) = machine.spindle.as_ref().filter(|s| s.on_bus(bi).is_some()) {
        bus = bus.with_spindle(s.clone());
    }
    if let Some(c) = machine.coolant.as_ref().filter(|c| c.on_bus(bi).is_some()) {
        bus = bus.with_coolant(c.clone());
    }
    if let Some(io) = machine.bus_io.filter(|b| b.on_bus(bi)) {
        bus = bus.with_io(io);
    }
    Ok(bus)
}
