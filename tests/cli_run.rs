//! `dnurbs demo` and `dnurbs run` through the real binary: the demo runs a short program
//! against simulated drives on each in-process link and thread set-up, ends on the
//! program's end point and writes its report; `run` reports a bad program or machine
//! before touching a bus.
//!
//! **Real time.** These demos are the suite's real-time smoke tests (every other run test
//! is on simulated time: `tests/posts.rs`, `tests/run_outcomes.rs`, `rt-loop/tests/`; the
//! paper example's whole demo runs in `.ci/run`). They pass on a loaded machine: exit 5
//! with overruns counts as completed, a simulated drive starved while the controller's own
//! thread overran is run once more ([`stalled`]), and nothing here measures speed.

mod common;

use common::{data, dnurbs, machine, temp};

/// A 2 s program (the paper example takes 18 s): what is checked is the demo's machinery,
/// not the program.
const SHORT: &str = "tests/data/two-blocks-g2.nc";

/// The real-time smoke test: `dnurbs demo` as the README runs it, on a short program;
/// `DEMO_SMOKE=paper` (`.ci/run`) runs the paper example itself, to its end point.
#[test]
fn demo_runs_a_program_to_its_end_and_writes_the_report() {
    let banner = "an in-memory CAN link, 2 ms period, 60 µs lead";
    if std::env::var("DEMO_SMOKE").is_ok_and(|p| p == "paper") {
        check_demo(&[], banner);
    } else {
        check_demo(&["--program", SHORT], banner);
    }
}

#[test]
fn demo_over_a_socketpair_runs_a_program_to_its_end() {
    check_demo(
        &["--link", "socketpair", "--program", SHORT],
        "a socketpair CAN link",
    );
}

#[test]
fn demo_pinned_with_its_cpu_idle_polled_runs_a_program_to_its_end() {
    check_demo(
        &[
            "--cpu",
            "0",
            "--idle-poll",
            "--lead",
            "0",
            "--program",
            SHORT,
        ],
        "2 ms period, real-time thread on CPU 0 (idle polled)",
    );
}

/// One demo at a time: two demos and an idle poller on a 2-core machine compete for the
/// same CPUs; serialised here.
static ONE_DEMO: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Run the demo with `extra` arguments; its banner on stderr must contain `banner`.
fn check_demo(extra: &[&str], banner: &str) {
    let _one = ONE_DEMO.lock().unwrap_or_else(|e| e.into_inner());
    let dir = temp(&format!("demo-report{}", extra.join("").replace('/', "_")));
    // Real time where the privileges allow (the controller SCHED_FIFO 80, the simulated
    // drives 79, so a loaded machine cannot starve them), without it otherwise.
    let mut args = vec!["demo", "--report", dir.to_str().unwrap()];
    args.extend(extra);
    let mut out = dnurbs(&args);
    if stalled(&out) {
        // Once: a stall of the whole machine is not the controller's fault, and a fault of
        // the controller's would come again.
        eprintln!(
            "demo {extra:?} lost a drive while its own thread overran (the machine stalled); \
             running it once more:\n{}",
            String::from_utf8_lossy(&out.stdout)
        );
        out = dnurbs(&args);
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    common::assert_completed(&out);
    assert!(stderr.contains(banner), "{stderr}");
    assert!(stdout.contains("outcome: completed"), "{stdout}");
    assert!(
        stdout.contains("real-time: SCHED_FIFO priority 80, memory locked")
            || stdout.contains("real-time: no ("),
        "{stdout}"
    );
    // Every drive ends where the program ends, to the count, and follows its target.
    let axes: Vec<&str> = stdout.lines().filter(|l| l.starts_with("axis ")).collect();
    assert_eq!(axes.len(), 5, "{stdout}");
    for line in axes {
        let n: Vec<i64> = line
            .split_whitespace()
            .filter_map(|w| w.trim_end_matches(':').parse().ok())
            .collect();
        // node, target, actual, program end
        assert_eq!(n.len(), 4, "{line}");
        assert_eq!(n[1], n[3], "target is not the program end: {line}");
        assert!((n[2] - n[3]).abs() <= 1, "actual is off the end: {line}");
    }
    for f in ["summary.txt", "summary.json", "latency.hlog", "latency.svg"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let paper = !extra.contains(&"--program");
    // X Y Z of the paper's end point, 10000 counts/mm.
    assert!(
        !paper
            || (stdout.contains("-16963")
                && stdout.contains("1636796")
                && stdout.contains("58369")),
        "{stdout}"
    );
    assert_eq!(
        json["program"],
        if paper { "paper-example.nc" } else { SHORT }
    );
    assert_eq!(json["machine"], "paper-ac-table");
    assert!(
        json["outcome"].as_str().unwrap().starts_with("completed"),
        "{json}"
    );
    assert_eq!(json["stop_reason"], serde_json::Value::Null);
    assert_eq!(json["drives"].as_array().unwrap().len(), 5, "{json}");
    assert!(json["started"].as_str().unwrap().ends_with('Z'), "{json}");
    let cycles = json["latency"]["cycles"].as_u64().unwrap();
    // 2.01 s of program at 2 ms (the paper's 17.87 s), plus the approach and the
    // enable/disable cycles.
    assert!(cycles > if paper { 8938 } else { 1005 }, "{cycles}");
    assert_eq!(json["feed_holds"], 0);
    assert_eq!(json["hard_stops"], 0);
    for h in ["wakeup_latency_ns", "compute_ns", "cycle_ns"] {
        for k in ["min", "p50", "p90", "p99", "p99_9", "p99_99", "max"] {
            assert!(
                json["latency"]["histograms"][h][k].as_u64().unwrap() > 0,
                "{h}.{k}"
            );
        }
    }
    let hlog = std::fs::read_to_string(dir.join("latency.hlog")).unwrap();
    assert!(hlog.contains("Tag=compute,") && hlog.contains("Tag=wakeup,"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A demo that stopped because a simulated drive went silent (its feedback or heartbeat
/// past the machine's timeout) while the controller's own thread overran: on a shared,
/// non-real-time machine (a VM whose CPU the host takes away for tens of milliseconds) the
/// drives' thread stalls with it, and the master rightly quick-stops the drives. One such
/// CI run saw a 37.8 ms wake-up and "no TPDO feedback for 11 cycles" (20 ms allowed).
fn stalled(out: &std::process::Output) -> bool {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let overran = common::overruns(&stdout).is_some_and(|n| n > 0);
    let silent = stdout.lines().any(|l| {
        l.starts_with("outcome: stopped by a fault")
            && (l.contains("no TPDO feedback") || l.contains("heartbeat"))
    });
    out.status.code() == Some(3) && overran && silent
}

/// Only a silent drive while the controller overran counts as a stall (the CI run's own
/// lines); a fault without overruns, or another fault, fails the demo at once.
#[test]
fn a_stalled_machine_is_told_from_a_fault() {
    use std::os::unix::process::ExitStatusExt;
    let out = |code: i32, overruns: u32, cause: &str| std::process::Output {
        status: std::process::ExitStatus::from_raw(code << 8),
        stdout: format!(
            "overruns: {overruns} (longest run 2)   feed holds (planner underruns): 0\n\
             outcome: stopped by a fault at program line 11 (exit 3): drive fault: node 1: \
             {cause}; drives quick-stopped and disabled\n"
        )
        .into_bytes(),
        stderr: Vec::new(),
    };
    assert!(stalled(&out(3, 239, "no TPDO feedback for 11 cycles")));
    assert!(stalled(&out(
        3,
        1,
        "heartbeat lost: none for 310 ms (timeout 300 ms)"
    )));
    assert!(!stalled(&out(3, 0, "no TPDO feedback for 11 cycles")));
    assert!(!stalled(&out(
        3,
        239,
        "following error (statusword 0x2637)"
    )));
    assert!(!stalled(&out(5, 239, "no TPDO feedback for 11 cycles")));
}

#[test]
fn run_reports_a_bad_program_with_its_position_before_touching_the_bus() {
    let prog = temp("bad.nc");
    std::fs::write(&prog, "N10 G01 X0 Y0 Z0 F100\nN20 G01 X1 D5\n").unwrap();
    let m = machine("paper-ac-table.toml");
    let out = dnurbs(&[
        "run",
        prog.to_str().unwrap(),
        "--machine",
        m.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("{}:2:12: D is the tool", prog.display()))
            && err.matches("D is the tool").count() == 1,
        "{err}"
    );
    assert!(!err.contains("CAN interface"), "{err}");
}

#[test]
fn run_refuses_a_machine_without_drives() {
    let out = dnurbs(&[
        "run",
        data("paper-example.nc").to_str().unwrap(),
        "--machine",
        machine("xyzac-trt-mill.toml").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("axis X has no drive: add [axes.x.drive]"),
        "{err}"
    );
}

#[test]
fn run_help_explains_the_start_pose_and_the_stop() {
    let out = dnurbs(&["run", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for s in [
        "--approach",
        "SIGINT",
        "disables the drives",
        "[realtime]",
        "Exit codes",
    ] {
        assert!(help.contains(s), "{s} missing from:\n{help}");
    }
}

/// SIGTERM while `run` is still reading and checking its program ends it at once with
/// exit 4, before any drive is touched. The program comes through a FIFO whose writer sends
/// its first lines and then never finishes: the pre-pass waits for the rest, as it would
/// on a program too slow to read. The machine file's `can0` does not exist here, so a run
/// that went on would fail to open it (exit 1).
#[test]
fn sigterm_while_the_program_is_read_stops_run_before_the_bus_with_exit_4() {
    use std::io::{BufRead, BufReader, Write};
    let prog = temp("program.fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&prog)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let m = machine("paper-ac-table.toml");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .args([
            "run",
            prog.to_str().unwrap(),
            "--machine",
            m.to_str().unwrap(),
            "--no-rt",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("dnurbs run starts");
    // Opening the FIFO waits for the reader; the writer stays open, the program unfinished.
    let mut writer = std::fs::OpenOptions::new()
        .write(true)
        .open(&prog)
        .expect("the FIFO opens");
    writer
        .write_all(b"G90 G21 G94\nG01 X-100 Y0 Z0 F3000\nX-99 Y0\n")
        .unwrap();
    writer.flush().unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut banner = String::new();
    err.read_line(&mut banner).unwrap();
    assert!(banner.starts_with("dnurbs run: "), "{banner}");
    std::thread::sleep(std::time::Duration::from_millis(300));
    let _ = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status();
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut err, &mut rest).unwrap();
    let status = child.wait().unwrap();
    drop(writer);
    assert_eq!(status.code(), Some(4), "{banner}{rest}");
    assert!(
        rest.contains("stop requested (SIGINT/SIGTERM) while planning the program: nothing moved"),
        "{rest}"
    );
    assert!(!rest.contains("can0") && !rest.contains("CAN"), "{rest}");
    let _ = std::fs::remove_file(&prog);
}
