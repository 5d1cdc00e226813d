//! Programs as CAM post-processors write them (`tests/data/posts`, see its README): each is
//! accepted unchanged, plans within every limit of the machine, and reports its spindle,
//! coolant and tool words. Two run against simulated CiA-402 drives on the in-memory link
//! (the code path of `dnurbs run`); an operator resumes their tool-change stop through the
//! control socket, and the targets the drives received are checked: within the travel and
//! the velocity limits by finite differences at the period, ending at the program's end;
//! the spindle drive at its speed before the first feed move leaves, the coolant valves on
//! during the cut and off at the end.

mod common;

use dnurbs_tools::control::{Connection, Request};
use dnurbs_tools::run::{run, RunOptions};
use dnurbs_tools::setup::MachineSetup;
use dnurbs_tools::shop::{parse_setup, ShopArgs};
use drives::link::MemLink;
use std::path::{Path, PathBuf};
use std::time::Duration;

const POSTS: [&str; 5] = [
    "fusion-fanuc-3axis.nc",
    "mastercam-fanuc-3axis.nc",
    "nx-5axis-g43-4.nc",
    "hypermill-5axis-g93.nc",
    "powermill-3axis-incremental.nc",
];

fn posts(name: &str) -> PathBuf {
    common::root().join("tests/data/posts").join(name)
}

fn machine() -> config::Machine {
    config::load(&posts("machine.toml")).expect("the posts machine")
}

fn shop() -> dnurbs_tools::shop::ShopOptions {
    ShopArgs {
        tools: Some(posts("tool.tbl")),
        ..ShopArgs::default()
    }
    .load()
    .expect("the tool table")
}

#[test]
fn every_post_plans_within_the_machine_limits() {
    let m = machine();
    let parse = parse_setup(&m, &shop());
    let setup = MachineSetup::new(&m);
    for name in POSTS {
        let prog = dnurbs_tools::load_program(&posts(name), &parse)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let result = dnurbs_tools::simulate::run(&prog, &setup, setup.method)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let s = dnurbs_tools::simulate::summarize(&result, &setup, prog.blocks.len());
        for map in [
            &s.axis_velocity_fraction,
            &s.axis_acceleration_fraction,
            &s.axis_jerk_fraction,
        ] {
            for (axis, v) in map {
                let v = v.as_f64().unwrap();
                assert!(v <= 1.0 + 1e-9, "{name}: {axis} at {v} of its limit");
            }
        }
        assert!(s.axis_travel_ok, "{name}");
        assert!(s.chord_error_max_mm <= s.chord_tolerance_mm, "{name}");
        assert!(
            s.end_position_error_mm < 1e-6,
            "{name}: {}",
            s.end_position_error_mm
        );
        let words = dnurbs_tools::words::describe(&prog);
        assert!(
            words.iter().any(|w| w.contains("M03 spindle clockwise")),
            "{name}: {words:?}"
        );
        assert!(
            words.iter().any(|w| w.contains("M09 coolant off")),
            "{name}: {words:?}"
        );
        assert!(
            words.iter().any(|w| w.contains("M06 tool change")),
            "{name}: {words:?}"
        );
    }
}

/// What each simulated node recorded, per SYNC, indexed by node id.
type PerNode = Vec<Vec<drives::sim::Record>>;

/// Runs `name` on simulated drives; a client thread resumes every operator stop. Returns the
/// lines it resumed at, the run's report and the records of every node (per node, in order).
fn run_post(name: &str, m: &config::Machine) -> (Vec<u32>, dnurbs_tools::report::Report, PerNode) {
    let mut m = m.clone();
    m.realtime.feedback_timeout_s = 2.0;
    m.realtime.heartbeat_timeout_s = 5.0;
    m.realtime.max_consecutive_overruns = 100_000;
    let (links, sim) = common::sim_drives(&m, |_| Default::default());
    let sock = common::temp(&format!("{name}.sock"));
    let opts = RunOptions {
        shop: shop(),
        ..common::run_options(name, Some(sock.clone()))
    };
    let src = std::fs::read(posts(name)).unwrap();
    let operator = std::thread::spawn(move || resume_every_stop(&sock));
    let r = run(&src, &m, move || Ok(links), &opts).expect("the run starts");
    let records = sim.finish();
    let resumed = operator.join().unwrap();
    let mut per_node = vec![Vec::new(); 8];
    for rec in records {
        per_node[usize::from(rec.node)].push(rec);
    }
    (resumed, r.report(name, &m.name), per_node)
}

/// The operator: poll the status, resume whenever the path waits for them.
fn resume_every_stop(sock: &Path) -> Vec<u32> {
    let mut resumed = Vec::new();
    let t0 = std::time::Instant::now();
    let mut conn = loop {
        match Connection::connect(sock) {
            Ok(c) => break c,
            Err(_) if t0.elapsed() < Duration::from_secs(60) => {
                std::thread::sleep(Duration::from_millis(20))
            }
            Err(e) => panic!("{e}"),
        }
    };
    while let Ok(Some(answer)) = conn.ask(Request::Status) {
        if let Some(line) = answer.status.and_then(|s| s.awaiting_operator) {
            resumed.push(line);
            conn.ask(Request::Resume).unwrap();
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    resumed
}

#[test]
fn five_axis_posts_run_on_simulated_drives_with_the_operator_resuming_the_tool_change() {
    let mut m = machine();
    // A spindle slower to reach its speed (6 s to 12000 rpm) than the rapid moves between
    // M03 and the first feed move take: the move must wait for it.
    if let Some(s) = m.spindle.as_mut() {
        s.acceleration_rpm_s = 2000.0;
        s.at_speed_timeout_s = 20.0;
    }
    let setup = MachineSetup::new(&m);
    let parse = parse_setup(&m, &shop());
    for name in ["nx-5axis-g43-4.nc", "hypermill-5axis-g93.nc"] {
        let prog = dnurbs_tools::load_program(&posts(name), &parse).unwrap();
        let stops: Vec<u32> = prog
            .blocks
            .iter()
            .filter_map(|b| match b {
                nc::program::Block::Linear(l) => l.tooling.wait.operator,
                nc::program::Block::Nurbs(n) => n.tooling.wait.operator,
            })
            .map(|p| p.line)
            .collect();
        let (resumed, rep, records) = run_post(name, &m);
        let targets: Vec<Vec<i32>> = records
            .iter()
            .map(|r| r.iter().map(|r| r.target_counts).collect())
            .collect();
        assert!(
            rep.exit_code == 0 || rep.exit_code == 5,
            "{name}: {}",
            rep.text()
        );
        // The first block's wait (a tool change before the first move) is not a stop.
        let expected: Vec<u32> = match prog.blocks.first() {
            Some(nc::program::Block::Linear(l)) if l.tooling.wait.operator.is_some() => {
                stops[1..].to_vec()
            }
            _ => stops,
        };
        assert_eq!(resumed, expected, "{name}: {}", rep.text());
        for d in &rep.drives {
            assert_eq!(Some(d.target_counts), d.program_end_counts, "{name}: {d:?}");
        }
        // Velocity by finite differences at the period, in counts, against each axis limit.
        for (j, d) in m.drives.iter().enumerate() {
            let t = &targets[usize::from(d.node)];
            let lim = setup.limits[j].velocity * d.counts_per_unit * m.period_s;
            let worst = t
                .windows(2)
                .map(|w| (w[1] - w[0]).unsigned_abs())
                .max()
                .unwrap_or(0);
            assert!(
                f64::from(worst) <= lim * (1.0 + 1e-6) + 1.0,
                "{name}: node {} stepped {worst} counts in a period, limit {lim}",
                d.node
            );
        }
        assert!(
            !resumed.is_empty() || name.starts_with("hyper"),
            "{name}: no stop resumed"
        );
        let leave = spindle_at_speed_before_the_first_feed_move(name, &m, &prog, &records);
        coolant_on_for_the_cut_and_off_at_the_end(name, &m, &prog, &records, leave);
    }
}

/// The axes' targets (counts, in node order) where the program's first feed move starts,
/// from the offline interpolation of the program (the path comes to rest there).
fn first_feed_start(m: &config::Machine, prog: &nc::program::Program) -> Vec<i32> {
    let setup = MachineSetup::new(m);
    let sim = dnurbs_tools::simulate::run(prog, &setup, setup.method).unwrap();
    let seg = sim.path.segments.iter().find(|s| s.wait.spindle).unwrap();
    let first = sim
        .setpoints
        .iter()
        .position(|sp| sp.block == seg.block)
        .unwrap();
    let j = sim.setpoints[first - 1].joints;
    m.drives
        .iter()
        .map(|d| {
            let v = if d.axis >= 3 {
                j[d.axis].to_degrees()
            } else {
                j[d.axis]
            };
            d.counts(v).unwrap()
        })
        .collect()
}

/// The drives received the first feed move only once the spindle drive reported the
/// programmed speed: the axes stand at the move's start while it ramps up, and leave when
/// its velocity is within the window of the command and its target-reached bit is set.
/// Returns the index of the SYNC where the move leaves.
fn spindle_at_speed_before_the_first_feed_move(
    name: &str,
    m: &config::Machine,
    prog: &nc::program::Program,
    records: &PerNode,
) -> usize {
    let spindle = m.spindle.as_ref().unwrap();
    let rpm = common::first_spindle_rpm(prog).unwrap();
    let at = first_feed_start(m, prog);
    let axis = |k: usize| -> Vec<i32> {
        m.drives
            .iter()
            .map(|d| records[usize::from(d.node)][k].target_counts)
            .collect()
    };
    let n = records[usize::from(m.drives[0].node)].len();
    // Where the axes come to rest at the move's start (the offline interpolation samples
    // the approach a period apart: within 0.01 mm), and the SYNC at which they move on.
    let near = |a: &[i32]| a.iter().zip(&at).all(|(x, y)| (x - y).abs() <= 100);
    let arrive = (0..n.saturating_sub(10))
        .find(|&k| near(&axis(k)) && (k..k + 10).all(|i| axis(i) == axis(k)))
        .unwrap_or_else(|| panic!("{name}: the axes never rest at the first feed move {at:?}"));
    let rest = axis(arrive);
    let leave = (arrive..n)
        .find(|&k| axis(k) != rest)
        .unwrap_or_else(|| panic!("{name}: the axes never leave {rest:?}"));
    // Every node records every SYNC in operational, so index k is the same SYNC for all.
    let sp = &records[usize::from(spindle.node)];
    assert_eq!(sp.len(), n, "{name}: spindle records");
    let before = &sp[leave - 1];
    let want = spindle.velocity(rpm);
    assert_eq!(before.target_counts, want, "{name}: spindle command");
    assert!(
        (before.actual_counts - want).unsigned_abs() <= u32::from(spindle.window_units()),
        "{name}: the first feed move left at SYNC {} with the spindle at {} of {want}",
        before.sync,
        before.actual_counts,
    );
    assert!(
        before.statusword & (1 << 10) != 0,
        "{name}: target reached not set: 0x{:04X}",
        before.statusword
    );
    // It waited there for the ramp (at least half of it: the rapids ran meanwhile).
    let ramp_periods = rpm / spindle.acceleration_rpm_s / m.period_s;
    let from = sp.iter().position(|r| r.target_counts == want).unwrap();
    assert!(
        (leave - from) as f64 >= ramp_periods,
        "{name}: left {} periods after the spindle command, ramp {ramp_periods}",
        leave - from
    );
    // At the end the spindle is stopped.
    let last = sp.last().unwrap();
    assert_eq!((last.target_counts, last.actual_counts), (0, 0), "{name}");
    leave
}

/// The coolant valves (outputs of the I/O module) are on, as M07/M08 ask, when the first
/// feed move leaves (SYNC index `leave`), and off at the end (M09).
fn coolant_on_for_the_cut_and_off_at_the_end(
    name: &str,
    m: &config::Machine,
    prog: &nc::program::Program,
    records: &PerNode,
    leave: usize,
) {
    let coolant = m.coolant.as_ref().unwrap();
    let mut aux = nc::program::Aux::default();
    let first_feed = prog
        .blocks
        .iter()
        .position(|b| !matches!(b, nc::program::Block::Linear(l) if l.rapid))
        .unwrap();
    for a in prog.actions.iter().filter(|a| a.before_block <= first_feed) {
        aux.apply(&a.kind);
    }
    let want = coolant.outputs(aux.mist, aux.flood);
    assert_ne!(want, 0, "{name}: the post turns coolant on before cutting");
    let io = &records[usize::from(coolant.node)];
    let on: Vec<usize> = (0..io.len())
        .filter(|&k| io[k].target_counts == i32::from(want))
        .collect();
    assert!(!on.is_empty(), "{name}: outputs 0x{want:02X} never set");
    assert_eq!(
        io[leave - 1].target_counts,
        i32::from(want),
        "{name}: coolant when the first feed move leaves"
    );
    // The module's inputs echo its outputs (the valves' switches): the outputs took effect.
    assert!(on.iter().any(|&k| io[k].actual_counts == i32::from(want)));
    let last = io.last().unwrap();
    assert_eq!((last.target_counts, last.actual_counts), (0, 0), "{name}");
}

#[test]
fn a_stop_for_the_operator_without_a_control_socket_is_refused_before_motion() {
    let m = machine();
    let (master_end, _drive_end) = MemLink::pair(16);
    let opts = RunOptions {
        shop: shop(),
        ..common::run_options("nx-5axis-g43-4.nc", None)
    };
    let src = std::fs::read(posts("nx-5axis-g43-4.nc")).unwrap();
    let e = run(&src, &m, move || Ok(vec![master_end]), &opts).unwrap_err();
    let msg = format!("{e:#}");
    assert!(msg.starts_with("nx-5axis-g43-4.nc:9:"), "{msg}");
    assert!(
        msg.contains("only the control socket can resume it"),
        "{msg}"
    );
}
