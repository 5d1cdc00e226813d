//! How a run ends, as the operator reads it: the outcome, its exit code, the reason with
//! the node and the program line, in the report. Against simulated drives on the in-memory
//! link on simulated time (`dnurbs_tools::run::simulated`, the stages of `dnurbs run`), and
//! through the binary, in real time, for SIGTERM.

mod common;

use dnurbs_tools::demo::DEMO_PROGRAM;
use dnurbs_tools::exit;
use dnurbs_tools::run::run;
use drives::sim::Faults;
use std::time::Duration;

/// The paper example on the paper's machine, its drives simulated with `faults(node)`, on
/// simulated time.
fn run_with(faults: impl Fn(u8) -> Faults) -> dnurbs_tools::run::RunResult {
    let machine = dnurbs_tools::demo::demo_machine().expect("the demo machine");
    let opts = common::run_options("paper-example.nc", None);
    common::run_simulated(DEMO_PROGRAM.as_bytes(), &machine, faults, &opts, |_, _| {}).0
}

#[test]
fn a_drive_fault_ends_the_run_with_exit_3_naming_node_and_line() {
    // Node 3 (Z) faults 3000 SYNCs in: after the approach, inside the G06.5 block (line 11).
    let r = run_with(|n| Faults {
        fault_at_sync: (n == 3).then_some(3000),
        ..Faults::default()
    });
    let rep = r.report("paper-example.nc", "paper-ac-table");
    assert_eq!(rep.exit_code, exit::STOPPED_FAULT, "{}", rep.text());
    assert_eq!(rep.outcome, "stopped by a fault");
    assert_eq!(rep.stop_node, Some(3), "{}", rep.text());
    assert_eq!(rep.stop_line, Some(11), "{}", rep.text());
    let text = rep.text();
    assert!(text.contains("node 3"), "{text}");
    assert!(text.contains("at program line 11 (exit 3)"), "{text}");
}

#[test]
fn a_run_that_completes_says_so_with_exit_0_or_5() {
    let r = run_with(|_| Faults::default());
    let rep = r.report("paper-example.nc", "paper-ac-table");
    // On simulated time no period overruns: the clean exit.
    assert_eq!(rep.overruns, 0, "{}", rep.text());
    assert_eq!(rep.exit_code, exit::COMPLETED, "{}", rep.text());
    assert_eq!(rep.stop_reason, None);
    assert_eq!(rep.stop_line, None);
    for d in &rep.drives {
        assert_eq!(Some(d.target_counts), d.program_end_counts, "{d:?}");
    }
}

#[test]
fn sigterm_stops_the_demo_along_the_path_with_exit_4() {
    let dir = common::temp("sigterm-report");
    let sock = common::temp("sigterm.sock");
    // Real time where allowed (so a loaded machine cannot starve the simulated drives).
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .args(["demo", "--report", dir.to_str().unwrap()])
        .args(["--control", sock.to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("dnurbs demo starts");
    // Into the program: wait until the run says it is running.
    let t0 = std::time::Instant::now();
    loop {
        let out = common::dnurbs(&["ctl", sock.to_str().unwrap(), "status"]);
        if String::from_utf8_lossy(&out.stdout).starts_with("running") {
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "never running");
        std::thread::sleep(Duration::from_millis(100));
    }
    let _ = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status();
    let out = child.wait_with_output().expect("dnurbs demo ends");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(i32::from(exit::STOPPED_OPERATOR)),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("outcome: stopped by the operator"),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["exit_code"], 4);
    assert_eq!(json["stop_line"], 11);
    assert!(
        json["stop_reason"].as_str().unwrap().contains("SIGTERM"),
        "{json}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue "Dense CAM programs": `run` on 20 000 moves of 0.05 mm at F3000 takes the time the
/// plan (`simulate`) says, without a feed hold. Real time, on simulated drives, for as long
/// as the program takes (about 24 s), so not in the default suite: a measurement, run with
/// `cargo test --release -p dnurbs-tools --test run_outcomes -- --ignored --nocapture dense`.
/// Before chunks carried runs of segments, the follower saw 64 moves (3.2 mm) ahead, less
/// than its stop distance, and held the feed about 5 900 times (49.6 s).
#[test]
#[ignore = "a real-time measurement of about 25 s; see its doc"]
fn a_dense_g01_program_runs_in_the_planned_time_without_a_feed_hold() {
    dense_run(false);
}

/// The same program compressed on line (`[interpolation] compress`): the planner thread
/// fits each run of up to `MAX_RUN` moves at once, in tens of milliseconds, while the tool
/// moves on what was queued before; the run must not hold for it.
/// `cargo test --release -p dnurbs-tools --test run_outcomes -- --ignored --nocapture dense`.
#[test]
#[ignore = "a real-time measurement of about 25 s; see its doc"]
fn a_dense_g01_program_compressed_on_line_runs_without_a_feed_hold() {
    dense_run(true);
}

fn dense_run(compress: bool) {
    // A circle of radius 160 mm about the origin with a 2 mm ripple, 12 waves a turn.
    let wave = |t: f64| {
        let r = 160.0 + 2.0 * (12.0 * t).sin();
        (
            nalgebra::Vector3::new(r * t.cos(), r * t.sin(), 0.0),
            nalgebra::Vector3::new(0.0, 0.0, 1.0),
        )
    };
    let points = nc_plan::fixtures::resample(wave, std::f64::consts::TAU, 20_000, 0.05);
    let src = nc_plan::fixtures::g01_program(&points, 3000.0);
    let mut machine = dnurbs_tools::demo::demo_machine().expect("the demo machine");
    machine.realtime.feedback_timeout_s = 2.0;
    machine.realtime.heartbeat_timeout_s = 5.0;
    machine.realtime.max_consecutive_overruns = 100_000;
    machine.interpolation.compress = compress;
    let setup = dnurbs_tools::setup::MachineSetup::new(&machine);
    let program = nc_lang::parse(&src).expect("parses");
    let (program, _) = setup.prepare(program);
    let path = nc_geom::segment::build(&program, &setup.kin, &setup.build).expect("builds");
    let planned = nc_plan::plan::plan(&path, &setup.kin, &setup.plan)
        .expect("plans")
        .duration;
    let (links, sim) = common::sim_drives(&machine, |_| Faults::default());
    let opts = common::run_options("dense.nc", None);
    let t0 = std::time::Instant::now();
    let r = run(src.as_bytes(), &machine, move || Ok(links), &opts).expect("the run starts");
    let wall = t0.elapsed().as_secs_f64();
    sim.finish();
    let rep = r.report("dense.nc", &machine.name);
    let ran = r.stats.cycles as f64 * machine.period_s;
    println!(
        "20 000 moves of 0.05 mm, F3000, {}{}: planned {planned:.3} s; run {ran:.3} s of \
         periods ({} cycles, with enable and disable), {wall:.1} s wall; feed holds {}, \
         hard stops {}, overruns {}; compressed {:?}",
        machine.name,
        if compress { " compressed" } else { "" },
        r.stats.cycles,
        rep.feed_holds,
        rep.hard_stops,
        rep.overruns,
        rep.compressed
    );
    assert_eq!(rep.stop_reason, None, "{}", rep.text());
    assert_eq!((rep.feed_holds, rep.hard_stops), (0, 0), "{}", rep.text());
}

/// `program` on the demo machine's simulated drives (in-memory link, the stages of `dnurbs
/// run`, simulated time); the report and every target the drives received, SYNC by SYNC.
fn run_program(program: &str, name: &str) -> (dnurbs_tools::report::Report, Vec<Vec<i32>>) {
    try_run_program(program, name).expect("the run starts")
}

/// [`run_program`], or why the run did not start (nothing moved).
fn try_run_program(
    program: &str,
    name: &str,
) -> anyhow::Result<(dnurbs_tools::report::Report, Vec<Vec<i32>>)> {
    let machine = dnurbs_tools::demo::demo_machine().expect("the demo machine");
    let opts = common::run_options(name, None);
    let (r, records) = dnurbs_tools::run::simulated::run_simulated(
        dnurbs_tools::feed::Input::Text(program.as_bytes().into()),
        &machine,
        common::simulated_buses(&machine, |_| Faults::default()),
        &opts,
        |_, _| {},
    )?;
    let mut per_node = vec![Vec::new(); 8];
    for rec in records {
        per_node[usize::from(rec.node)].push(rec);
    }
    let targets = common::drive_targets(&machine, &per_node);
    let setup = dnurbs_tools::setup::MachineSetup::new(&machine);
    common::within_the_limits_at_the_period(name, &machine, &setup.limits, &targets);
    Ok((r.report(name, &machine.name), targets))
}

/// A dense finishing pass from the origin, where the simulated drives start (so the
/// approach is nothing): `moves` moves of 0.05 mm out along X to X285 and back at Y1, with a
/// 0.02 mm ripple in Y, at `feed` mm/min, as a post writes one; a short dwell every
/// `dwell_every` moves (0: none).
fn dense_pass(moves: usize, feed: f64, dwell_every: usize) -> String {
    use std::fmt::Write as _;
    let mut s = format!("G90 G21 G94 G17\nG01 X0 Y0 Z0 I0 J0 K1 F{feed}\n");
    for k in 1..=moves {
        let (x, y0) = if k <= 5_700 {
            (0.05 * k as f64, 0.0)
        } else {
            (285.0 - 0.05 * (k - 5_700) as f64, 1.0)
        };
        let y = y0 + 0.02 * (0.3 * k as f64).sin();
        let _ = writeln!(s, "X{x:.4} Y{y:.4}");
        if dwell_every > 0 && k % dwell_every == 0 {
            s.push_str("G04 P0.05\n");
        }
    }
    s
}

/// Issue "Dense CAM programs", streaming: an error the planner meets ahead of the tool, far
/// into a program already moving, stops the tool along the path before it gets there (every
/// target within the velocity and acceleration limits at the period), disables the drives
/// and ends the run with exit 2 and the line and reason in the report. The program is small
/// enough to be checked whole before motion, and that check passes: the arc's ends are
/// within the travel, its top (Y260) is not, which only the planner sees.
#[test]
fn an_error_met_ahead_of_the_tool_stops_it_along_the_path_with_exit_2() {
    // 570 mm of moves at F600, with a dwell every 58 mm: each dwell is a stop, where a
    // window ends, so the planner reads no further ahead than the queue it fills, and meets
    // the arc while the tool is on its way (at F3000 and F1500 the queue's chunks, cut for
    // the longer stop that keeps each axis's jerk, reached the arc before the tool moved).
    let mut src = dense_pass(11_400, 600.0, 1_160);
    let arc_line = src.lines().count() + 2;
    src.push_str("G01 X0 Y230\nG02 X60 Y230 I30 J0\nM30\n");
    let (rep, targets) = run_program(&src, "arc-past-the-travel.nc");
    let text = rep.text();
    assert_eq!(rep.exit_code, exit::BAD_INPUT, "{text}");
    assert_eq!(rep.outcome, "stopped by the program", "{text}");
    let refusal = rep.refusal.clone().unwrap_or_default();
    assert!(
        refusal.starts_with(&format!("arc-past-the-travel.nc:{arc_line}:")),
        "{refusal}\n{text}"
    );
    assert!(
        refusal.contains("the Y axis would leave its travel"),
        "{refusal}"
    );
    let stream = rep.stream.expect("the planner's notes");
    assert!(stream.checked_whole, "{text}");
    // It moved (from X0), and stopped before the arc.
    let x: Vec<i32> = targets.iter().map(|t| t[0]).collect();
    let (first, last) = (x[0], x[x.len() - 1]);
    assert!(
        first == 0 && last > 0,
        "X never moved: {first} .. {last}\n{text}"
    );
    // Stopped on the pass, short of the move up to Y230 and the arc (10 000 counts a mm).
    let y_last = targets[targets.len() - 1][1];
    assert!(y_last < 2 * 10_000, "Y at {y_last} counts\n{text}");
}

/// A program too long to check whole before motion (over 8 MiB) starts after its first
/// window while the pre-pass reads the rest; the pre-pass's refusal of a point at its end
/// (X400, past the +-300 mm travel) stops the moving tool along the path: exit 2, the line
/// and reason in the report, every target within the limits at the period. The pre-pass
/// and the first window race (in a release build the pre-pass reads these 91 000 lines
/// before the first window is planned): a refusal that comes first refuses the program
/// before anything moves, with the same line and reason, and that is checked instead.
/// On a machine where the first windows run ahead of the pre-pass, the window planner
/// meets the point first and refuses it ahead of the tool, with the same line.
#[test]
fn a_long_program_refused_by_the_pre_pass_while_it_runs_stops_with_exit_2() {
    let mut src = dense_pass(11_400, 3000.0, 1_160);
    // Over 8 MiB: comments a post writes, 80 000 lines of them.
    for k in 0..80_000 {
        src.push_str(&format!("(operation 1 toolpath segment {k:06} ... ... ... ... ... ... ... ... ... ... ... ... ... ... ... ... ... )\n"));
    }
    let bad = src.lines().count() + 1;
    src.push_str("G01 X400\nM30\n");
    assert!(src.len() > 8 << 20, "{} bytes", src.len());
    let (rep, _) = match try_run_program(&src, "long-to-x400.nc") {
        Ok(ran) => ran,
        Err(before) => {
            let why = before.to_string();
            assert!(why.starts_with(&format!("long-to-x400.nc:{bad}:")), "{why}");
            assert!(names_x_at_400(&why), "{why}");
            return;
        }
    };
    let text = rep.text();
    assert_eq!(rep.exit_code, exit::BAD_INPUT, "{text}");
    let refusal = rep.refusal.clone().unwrap_or_default();
    assert!(
        refusal.starts_with(&format!("long-to-x400.nc:{bad}:")),
        "{refusal}\n{text}"
    );
    assert!(names_x_at_400(&refusal), "{refusal}");
    assert!(!rep.stream.expect("notes").checked_whole, "{text}");
}

/// Which check reaches line `bad` first is a race too: the pre-pass ("puts the X axis at
/// 400.0000 mm") or the window planner ahead of the tool ("the X axis would leave its
/// travel: 400.0000 mm"). Either refusal names the axis, the value and the travel.
fn names_x_at_400(refusal: &str) -> bool {
    (refusal.contains("X axis at 400.0000 mm")
        || refusal.contains("X axis would leave its travel: 400.0000 mm"))
        && refusal.contains("-300 .. 300 mm")
}
