//! `dnurbs sim-drives`: one process that plays every drive of a machine's bus on a CAN
//! interface (boot-up, NMT slave, SDO server, PDO mapping, CiA-402 state machine, CSP motor
//! model, heartbeats), with fault injection, recording every target it receives; and the
//! spindle drive (profile velocity: speed ramp, at-speed bit) and the coolant I/O module
//! (CiA-401 outputs) where the machine file puts them on that bus.
//!
//! Records are flushed to the `--record` file every 100 ms, so the file is complete up to
//! the last flush whenever the process is stopped (Ctrl-C or SIGTERM need no handler).

use crate::InputError;
use config::bus::{Drive, Home, HomeMethod};
use drives::link::{CanLink, SocketLink};
use drives::sim::{Faults, HomeHardware, SimBus, SimNodeConfig};
use drives::wire::NodeId;
use std::io::Write;
use std::time::{Duration, Instant};

/// Fault injection, as given on the command line.
#[derive(Clone, Debug, Default)]
pub struct FaultArgs {
    pub fault_at: Vec<(u8, u64)>,
    pub heartbeat_stops: Vec<(u8, u64)>,
    pub never_boots: Vec<u8>,
    pub drop_every: Vec<(u8, u32)>,
    pub silent_from: Vec<(u8, u64)>,
    /// Nodes whose home switch is not wired (a search fails after a tenth of the travel).
    pub no_home_switch: Vec<u8>,
}

impl FaultArgs {
    fn for_node(&self, node: u8) -> Faults {
        let find = |v: &[(u8, u64)]| v.iter().find(|(n, _)| *n == node).map(|x| x.1);
        Faults {
            fault_at_sync: find(&self.fault_at),
            heartbeat_stops_at: find(&self.heartbeat_stops),
            never_boots: self.never_boots.contains(&node),
            drop_every: self
                .drop_every
                .iter()
                .find(|(n, _)| *n == node)
                .map(|x| x.1),
            silent_from_sync: find(&self.silent_from),
            keeps_object: None,
            estop_chain: None,
        }
    }
}

/// Parse `NODE:VALUE` (clap value parser).
pub fn node_value<T: std::str::FromStr>(s: &str) -> Result<(u8, T), String> {
    let (n, v) = s
        .split_once(':')
        .ok_or_else(|| format!("expected NODE:VALUE, got {s:?}"))?;
    let node: u8 = n
        .parse()
        .ok()
        .filter(|n| (1..=127).contains(n))
        .ok_or_else(|| format!("node {n:?} is not 1..=127"))?;
    let value = v
        .parse()
        .map_err(|_| format!("value {v:?} in {s:?} is not a number"))?;
    Ok((node, value))
}

/// The simulated nodes of bus `bus`: the axes' drives (at their `offset`), the spindle
/// drive, the I/O module (its inputs wired back from its outputs).
pub fn sim_nodes(
    m: &config::Machine,
    bus: usize,
    lag_s: f64,
    faults: &FaultArgs,
) -> Vec<SimNodeConfig> {
    let mut nodes: Vec<SimNodeConfig> = m
        .drives
        .iter()
        .filter(|d| d.bus == bus)
        .filter_map(|d| {
            let mut c = SimNodeConfig::new(NodeId::new(d.node)?);
            c.initial_position = d.offset;
            // The simulated home switch where the machine file's home point is; with an
            // index, an index pulse there and the switch half a motor turn before it,
            // on its active side.
            if let Some(h) = d.home {
                c.home = sim_home(d, h, c.home);
                // A search may cross the whole travel (a turn of an endless axis), twice.
                let l = [&m.axes.x, &m.axes.y, &m.axes.z, &m.axes.tilt, &m.axes.c][d.axis.min(4)];
                let span = if l.is_unlimited() {
                    360.0
                } else {
                    l.max - l.min
                };
                let counts = (2.0 * span * d.counts_per_unit).min(f64::from(u32::MAX));
                c.home.search_limit = c.home.search_limit.max(counts as u32);
                if faults.no_home_switch.contains(&d.node) {
                    c.home.switch = None;
                    c.home.search_limit = (0.1 * span * d.counts_per_unit).max(1.0) as u32;
                }
            }
            c.lag_s = lag_s;
            c.faults = faults.for_node(d.node);
            Some(c)
        })
        .collect();
    if let Some(node) = m.spindle.as_ref().and_then(|s| s.on_bus(bus)) {
        if let Some(n) = NodeId::new(node) {
            let mut c = SimNodeConfig::new(n);
            c.faults = faults.for_node(node);
            nodes.push(c);
        }
    }
    if let Some(node) = m.io_module(bus) {
        if let Some(n) = NodeId::new(node) {
            let mut c = SimNodeConfig::io(n);
            c.faults = faults.for_node(node);
            nodes.push(c);
        }
    }
    nodes
}

/// The header of a record CSV (`sim-drives --record`, `serve --sim --record`).
pub const RECORD_HEADER: &str = "sync,node,target_counts,actual_counts,statusword";

/// Write `records` as rows of a record CSV.
pub fn write_records<'r>(
    w: &mut impl Write,
    records: impl IntoIterator<Item = &'r drives::sim::Record>,
) -> std::io::Result<()> {
    for r in records {
        writeln!(
            w,
            "{},{},{},{},{}",
            r.sync, r.node, r.target_counts, r.actual_counts, r.statusword
        )?;
    }
    Ok(())
}

/// Each bus of `m` on an in-process link (`pair` makes its two ends) to its drives
/// simulated in a thread of their own, `faults` injected: the master's ends, in bus order,
/// and the threads. With real-time privileges (`priority`, the controller's) the drives'
/// thread runs SCHED_FIFO one priority below the controller's, so that a loaded host cannot
/// starve it (`dnurbs demo`, `dnurbs serve --sim`).
pub fn sim_threads<L: CanLink + Send + 'static>(
    m: &config::Machine,
    faults: &FaultArgs,
    priority: Option<i32>,
    pair: impl Fn() -> std::io::Result<(L, L)>,
) -> anyhow::Result<(Vec<L>, Vec<drives::sim::SimThread>)> {
    let mut links = Vec::new();
    let mut sims = Vec::new();
    for bi in 0..m.buses.len() {
        let (master_end, drive_end) = pair()?;
        let nodes = sim_nodes(m, bi, 0.0, faults);
        let below = priority.map(|p| (p - 1).max(1));
        sims.push(drives::sim::SimThread::start_with(
            drive_end,
            nodes,
            m.period_s,
            Duration::from_micros(200),
            move || {
                if let Some(p) = below {
                    let _ = rt_loop::os::set_fifo(p);
                }
            },
        )?);
        links.push(master_end);
    }
    Ok((links, sims))
}

pub struct SimArgs {
    pub iface: String,
    pub machine: config::Machine,
    pub record: Option<std::path::PathBuf>,
    /// Motor lag time constant, ns.
    pub lag_ns: u64,
    /// Run this long, ns (None: until stopped).
    pub duration_ns: Option<u64>,
    pub faults: FaultArgs,
}

/// Run until `duration_s` (or forever).
pub fn run(args: SimArgs) -> anyhow::Result<()> {
    let m = &args.machine;
    // The drives on the bus whose interface is `iface`; with one bus, that bus whatever its name.
    let bus = m
        .buses
        .iter()
        .position(|b| b.interface == args.iface)
        .or_else(|| (m.buses.len() == 1).then_some(0))
        .ok_or_else(|| {
            InputError::MachineUse(format!(
                "the machine has no [[bus]] on interface {:?}",
                args.iface
            ))
        })?;
    let nodes = sim_nodes(m, bus, args.lag_ns as f64 * 1e-9, &args.faults);
    let mut link = SocketLink::open(&args.iface)
        .map_err(|e| anyhow::anyhow!("cannot open CAN interface {:?}: {e}", args.iface))?;
    let mut record = match &args.record {
        Some(p) => {
            let mut f = std::io::BufWriter::new(
                std::fs::File::create(p)
                    .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", p.display()))?,
            );
            writeln!(f, "{RECORD_HEADER}")?;
            f.flush()?;
            Some(f)
        }
        None => None,
    };
    eprintln!(
        "sim-drives: {} drives on {} (nodes {:?})",
        nodes.len(),
        args.iface,
        nodes.iter().map(|n| n.node.get()).collect::<Vec<_>>()
    );
    let mut sim = SimBus::new(nodes, m.period_s);
    let duration_s = args.duration_ns.map(|d| d as f64 * 1e-9);
    let t0 = Instant::now();
    let mut last_flush = t0;
    let mut out = Vec::new();
    loop {
        let now = t0.elapsed().as_secs_f64();
        let mut idle = true;
        for _ in 0..256 {
            match link.recv()? {
                Some(f) => {
                    sim.on_frame(&f, now, &mut |o| out.push(o));
                    idle = false;
                }
                None => break,
            }
        }
        sim.poll(now, &mut |o| out.push(o));
        for f in out.drain(..) {
            link.send(&f)?;
        }
        if last_flush.elapsed() >= Duration::from_millis(100)
            || duration_s.is_some_and(|d| now >= d)
        {
            last_flush = Instant::now();
            if let Some(w) = record.as_mut() {
                write_records(w, &sim.take_records())?;
                w.flush()?;
            } else {
                sim.take_records();
            }
        }
        if duration_s.is_some_and(|d| now >= d) {
            return Ok(());
        }
        if idle {
            std::thread::sleep(Duration::from_micros(100));
        }
    }
}

/// The simulated home switch and index of drive `d` homed by `h`, so that homing ends at the
/// home point the machine file names.
fn sim_home(d: &Drive, h: Home, hw: HomeHardware) -> HomeHardware {
    let Some(at) = d.counts(h.position) else {
        return hw;
    };
    let active_positive = |positive: bool| positive == (d.sign > 0);
    let half = i32::try_from(hw.index_pitch / 2).unwrap_or(i32::MAX);
    match h.method {
        HomeMethod::Switch { .. } => HomeHardware {
            switch: Some(at),
            ..hw
        },
        HomeMethod::SwitchIndex { positive } => {
            let side = if active_positive(positive) {
                half
            } else {
                -half
            };
            HomeHardware {
                switch: Some(at.saturating_add(side)),
                index_at: at,
                ..hw
            }
        }
        HomeMethod::Current | HomeMethod::Absolute => hw,
    }
}
