//! Each bus's nodes set up (SDO, PDO mapping, NMT start) and handed to a master: the same
//! for a real bus on wall time and for simulated drives on a virtual clock.

use super::node_setups;
use config::Machine;
use drives::link::CanLink;
use drives::master::{
    configure_nodes, Clock, Master, Protections, SetupOptions, Supervision, FOLLOWING_OFF,
};
use rt_loop::pipeline::BusDrives;
use std::time::Duration;

/// What drive `d` guards by itself: its following error in counts, its option codes, and
/// the axis's travel (`limits`) as its software position limits (none for an endless axis).
pub(crate) fn protections(
    d: &config::bus::Drive,
    limits: Option<config::AxisLimits>,
) -> Protections {
    let window = d.guard.following_error.map_or(FOLLOWING_OFF, |e| {
        (e * d.counts_per_unit)
            .round()
            .clamp(1.0, f64::from(FOLLOWING_OFF - 1)) as u32
    });
    let position_limits = limits
        .filter(|l| !l.is_unlimited())
        .and_then(|l| Some((d.counts(l.min)?, d.counts(l.max)?)))
        .map(|(a, b)| (a.min(b), a.max(b)));
    Protections {
        following_window: window,
        following_timeout_ms: d.guard.following_error_timeout_ms,
        quick_stop_option: d.guard.quick_stop_option,
        fault_reaction_option: d.guard.fault_reaction_option,
        position_limits,
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drive_is_told_its_following_error_in_counts_and_its_travel() {
        let m = crate::demo::demo_machine().expect("the demo machine");
        let x = &m.drives[0];
        let p = protections(x, Some(m.axes.x.clone()));
        let window = x.guard.following_error.unwrap() * x.counts_per_unit;
        assert_eq!(p.following_window, window.round() as u32);
        assert_eq!((p.quick_stop_option, p.fault_reaction_option), (2, 2));
        let (lo, hi) = (x.counts(m.axes.x.min), x.counts(m.axes.x.max));
        assert_eq!(p.position_limits, lo.zip(hi));
        // A drive turned the other way: the limits in order; an endless axis: none.
        let flipped = config::bus::Drive {
            sign: -1,
            ..x.clone()
        };
        let (a, b) = protections(&flipped, Some(m.axes.x.clone()))
            .position_limits
            .unwrap();
        assert!(a < b);
        let endless = config::AxisLimits {
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
            ..m.axes.x.clone()
        };
        assert_eq!(protections(x, Some(endless)).position_limits, None);
        let off = config::bus::Drive {
            guard: config::bus::Guard {
                following_error: None,
                ..x.guard
            },
            ..x.clone()
        };
        assert_eq!(protections(&off, None).following_window, FOLLOWING_OFF);
    }
}
