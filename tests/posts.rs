//! Programs as CAM post-processors write them (`tests/data/posts`, see its README): each is
//! accepted unchanged, plans within every limit of the machine, and reports its spindle,
//! coolant and tool words. Two run against simulated CiA-402 drives on the in-memory link
//! (the code path of `dnurbs run`); an operator resumes their tool-change stop through the
//! control socket, and the targets the drives received are checked: within the travel and
//! the velocity limits by finite differences at the period, ending at the program's end.

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

/// Runs `name` on simulated drives; a client thread resumes every operator stop. Returns the
/// lines it resumed at, the run's report and the targets received (per node, in order).
fn run_post(name: &str) -> (Vec<u32>, dnurbs_tools::report::Report, Vec<Vec<i32>>) {
    let mut m = machine();
    m.realtime.feedback_timeout_s = 2.0;
    m.realtime.heartbeat_timeout_s = 5.0;
    m.realtime.max_consecutive_overruns = 100_000;
    let (master_end, sim) = common::sim_drives(&m, |_| Default::default());
    let sock = common::temp(&format!("{name}.sock"));
    let opts = RunOptions {
        shop: shop(),
        ..common::run_options(name, Some(sock.clone()))
    };
    let src = std::fs::read(posts(name)).unwrap();
    let operator = std::thread::spawn(move || resume_every_stop(&sock));
    let r = run(&src, &m, move || Ok(vec![master_end]), &opts).expect("the run starts");
    let records = sim.finish();
    let resumed = operator.join().unwrap();
    let mut per_node = vec![Vec::new(); 6];
    for rec in records {
        per_node[usize::from(rec.node)].push(rec.target_counts);
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
    let m = machine();
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
        let (resumed, rep, targets) = run_post(name);
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
    }
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
