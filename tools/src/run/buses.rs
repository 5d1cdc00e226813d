//! Each bus's nodes set up (SDO, PDO mapping, NMT start) and handed to a master: the same
//! for a real bus on wall time and for simulated drives on a virtual clock.

use super::node_setups;
use config::Machine;
use drives::link::CanLink;
use drives::master::{
    configure_nodes, Clock, HomeRequest, Master, Protections, SetupOptions, Supervision,
    FOLLOWING_OFF,
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

/// The CiA-402 homing request for drive `d` (`[axes.*.home]` in counts), or `None` for an
/// axis without homing or with an absolute encoder. The timeout allows crossing the whole
/// travel (360 degrees for an endless axis) twice at the search velocity and once at the
/// latch velocity, and 10 s more, at `period_s`.
pub fn home_request(
    d: &config::bus::Drive,
    limits: &config::AxisLimits,
    period_s: f64,
) -> Option<HomeRequest> {
    let h = d.home?;
    let method = d.homing_method(h.method)?;
    let counts = |v: f64| {
        (v * d.counts_per_unit)
            .round()
            .clamp(1.0, f64::from(u32::MAX)) as u32
    };
    let span = if limits.is_unlimited() {
        360.0
    } else {
        limits.max - limits.min
    };
    let timeout_s = 2.0 * span / h.search_velocity + span / h.latch_velocity + 10.0;
    Some(HomeRequest {
        method,
        switch_speed: counts(h.search_velocity),
        index_speed: counts(h.latch_velocity),
        acceleration: counts(h.acceleration),
        offset: d.counts(h.position)?,
        timeout_cycles: (timeout_s / period_s).ceil().min(f64::from(u32::MAX)) as u32,
    })
}

/// The set-up's timeouts and the cycle's supervision, from the machine file.
pub(crate) fn options(machine: &Machine) -> (SetupOptions, Supervision) {
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
pub(crate) fn set_up<L: CanLink, C: Clock>(
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
        if let Some(input) = io.estop_input {
            let node = drives::wire::NodeId::new(io.at.node)
                .ok_or_else(|| anyhow::anyhow!("{bus_name}: node {} of [io]", io.at.node))?;
            bus.master
                .watch_estop(node, input)
                .map_err(|e| anyhow::anyhow!("{bus_name}: [io] estop_input: {e}"))?;
        }
        bus = bus.with_io(io);
    }
    Ok(bus)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_home_table_becomes_the_drives_homing_request_in_counts() {
        let m = crate::demo::demo_machine().expect("the demo machine");
        let x = config::bus::Drive {
            home: Some(config::bus::Home {
                method: config::bus::HomeMethod::SwitchIndex { positive: false },
                position: -2.5,
                search_velocity: 10.0,
                latch_velocity: 1.0,
                acceleration: 100.0,
                sequence: 0,
            }),
            ..m.drives[0].clone()
        };
        let r = home_request(&x, &m.axes.x, m.period_s).expect("a request");
        let cpu = x.counts_per_unit;
        assert_eq!(r.method, if x.sign > 0 { 5 } else { 3 });
        assert_eq!(r.switch_speed, (10.0 * cpu).round() as u32);
        assert_eq!(r.index_speed, cpu.round() as u32);
        assert_eq!(r.acceleration, (100.0 * cpu).round() as u32);
        assert_eq!(Some(r.offset), x.counts(-2.5));
        let span = m.axes.x.max - m.axes.x.min;
        let want = ((2.0 * span / 10.0 + span / 1.0 + 10.0) / m.period_s).ceil() as u32;
        assert_eq!(r.timeout_cycles, want);
        let absolute = config::bus::Drive {
            home: x.home.map(|h| config::bus::Home {
                method: config::bus::HomeMethod::Absolute,
                ..h
            }),
            ..x.clone()
        };
        assert_eq!(home_request(&absolute, &m.axes.x, m.period_s), None);
        assert_eq!(home_request(&m.drives[0], &m.axes.x, m.period_s), None);
    }

    /// The machine file's `[axes.*.home]` from end to end on simulated drives: each axis's
    /// simulated switch and index where its file says (`sim-drives`), the master homing
    /// every axis with its request, and each ends at its home position (past it by the stop
    /// from the search or latch velocity), the absolute axis untouched.
    #[test]
    fn a_simulated_machine_homes_where_its_file_says() {
        use config::bus::{Home, HomeMethod};
        let mut m = crate::demo::demo_machine().expect("the demo machine");
        let home = |method, position: f64, limits: &config::AxisLimits| Home {
            method,
            position,
            search_velocity: limits.velocity / 10.0,
            latch_velocity: limits.velocity / 100.0,
            acceleration: limits.acceleration / 2.0,
            sequence: 0,
        };
        let limits = [&m.axes.x, &m.axes.y, &m.axes.z, &m.axes.tilt, &m.axes.c].map(|l| l.clone());
        let methods = [
            (HomeMethod::Switch { positive: false }, -5.0),
            (HomeMethod::SwitchIndex { positive: true }, 4.0),
            (HomeMethod::Current, 2.5),
            (HomeMethod::Absolute, 0.0),
            (HomeMethod::Switch { positive: true }, 3.0),
        ];
        for d in m.drives.iter_mut() {
            let (method, pos) = methods[d.axis];
            d.home = Some(home(method, pos, &limits[d.axis]));
        }
        let nodes = crate::simdrives::sim_nodes(&m, 0, 0.0, &Default::default());
        let (link, drive_end) = drives::link::MemLink::pair(1024);
        let mut sim = drives::sim::Lockstep::new(drive_end, nodes, m.period_s);
        let mut bus = set_up(&m, 0, link, &mut sim, |c| Clock::now(c).as_secs_f64()).unwrap();
        let cycle = |bus: &mut BusDrives<_>, sim: &mut drives::sim::Lockstep<_>| {
            let now = sim.now();
            let t: Vec<i32> = bus.master.status().iter().map(|n| n.target).collect();
            bus.master.cycle(&t, now.as_secs_f64());
            sim.advance_to(now);
            sim.advance_to(now + Duration::from_secs_f64(m.period_s));
        };
        bus.master.set_goal(drives::cia402::Goal::Enabled);
        for _ in 0..200 {
            cycle(&mut bus, &mut sim);
        }
        assert!(bus.master.all_in(drives::cia402::State::OperationEnabled));
        let drives_ = m.drives.clone();
        for (i, d) in drives_.iter().enumerate() {
            if let Some(r) = home_request(d, &limits[d.axis], m.period_s) {
                bus.master.home(i, r).unwrap();
            }
        }
        let running = |bus: &BusDrives<_>| {
            (0..drives_.len())
                .any(|i| matches!(bus.master.homing(i), drives::master::HomingState::Running))
        };
        for _ in 0..200_000 {
            if !running(&bus) {
                break;
            }
            cycle(&mut bus, &mut sim);
        }
        for (i, d) in drives_.iter().enumerate() {
            let h = d.home.unwrap();
            let l = &limits[d.axis];
            let got = d.position(bus.master.status()[i].actual);
            match (h.method, bus.master.homing(i)) {
                (HomeMethod::Absolute, s) => {
                    assert_eq!(s, drives::master::HomingState::Idle);
                    assert_eq!(got, 0.0);
                }
                (method, drives::master::HomingState::Attained { .. }) => {
                    let v = match method {
                        HomeMethod::SwitchIndex { .. } => h.latch_velocity,
                        _ => h.search_velocity,
                    };
                    // The stop from v at the homing acceleration, and a period at v.
                    let slack = v * v / (2.0 * h.acceleration) + 2.0 * v * m.period_s + 1e-3;
                    assert!(
                        (got - h.position).abs() <= slack,
                        "axis {}: at {got}, home {} (slack {slack}, limits {l:?})",
                        d.axis,
                        h.position
                    );
                }
                (_, other) => panic!("axis {}: {other:?}", d.axis),
            }
        }
    }

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
