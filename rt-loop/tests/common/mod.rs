//! What the pipeline tests stand on: five CiA-402 drives (nodes 1..=5 for X Y Z A C),
//! simulated on the far end of a link, configured and taken over by a master.
#![allow(dead_code)]

use config::bus::Drive;
use drives::link::CanLink;
use drives::master::{configure, Master, SetupOptions, Supervision};
use drives::sim::{SimNodeConfig, SimThread};
use drives::wire::NodeId;
use rt_loop::os;
use rt_loop::pipeline::BusDrives;
use std::time::Duration;

/// Drives for X Y Z A C on nodes 1..=5 with these counts per mm or degree, simulated on
/// `drive_end`; the master on `link` has configured them. Supervision is lenient: these tests
/// are about function, not timing, and must hold on a loaded machine.
pub fn sim_bus<L: CanLink, D: CanLink + Send + 'static>(
    mut link: L,
    drive_end: D,
    period: f64,
    counts_per_unit: [f64; 5],
) -> (BusDrives<L>, SimThread) {
    let drives: Vec<Drive> = (0..5)
        .map(|axis| Drive {
            axis,
            bus: 0,
            node: axis as u8 + 1,
            counts_per_unit: counts_per_unit[axis],
            sign: 1,
            offset: 0,
        })
        .collect();
    let nodes: Vec<NodeId> = (1..=5).map(|n| NodeId::new(n).unwrap()).collect();
    let sims = nodes.iter().map(|&n| SimNodeConfig::new(n)).collect();
    let sim = SimThread::start(drive_end, sims, period, Duration::from_micros(20)).unwrap();
    let mut opts = SetupOptions::new(period);
    opts.boot_timeout = Duration::from_secs(5);
    let initial = configure(&mut link, &nodes, &opts, &mut |_| {}).unwrap();
    let sup = Supervision {
        heartbeat_timeout_s: 30.0,
        feedback_timeout_cycles: 1_000_000,
    };
    let master = Master::new(link, &nodes, &initial, sup, os::now() as f64 * 1e-9).unwrap();
    (BusDrives::new(master, &drives).unwrap(), sim)
}
