//! The operator's control socket through the real binaries: `dnurbs demo --control` serves
//! it, `dnurbs ctl` pauses, overrides, resumes and stops the run, and the run's report says
//! the operator stopped it (exit 4).

mod common;

use std::io::{BufRead, BufReader, Write};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::net::UnixStream;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn ctl(sock: &Path, args: &[&str]) -> std::process::Output {
    let mut all = vec!["ctl", sock.to_str().unwrap()];
    all.extend(args);
    common::dnurbs(&all)
}

/// `ctl status` until `want(line)`, at most 30 s.
fn wait_for(sock: &Path, want: impl Fn(&str) -> bool) -> String {
    let t0 = Instant::now();
    loop {
        let out = ctl(sock, &["status"]);
        let line = String::from_utf8_lossy(&out.stdout).to_string();
        if out.status.success() && want(&line) {
            return line;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "last status: {line}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The feed in a status line.
fn feed(line: &str) -> f64 {
    let i = line.find("  F ").expect("F in the status") + 4;
    line[i..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn ctl_pauses_overrides_resumes_and_stops_a_run() {
    let sock = common::temp("control.sock");
    let report = common::temp("control-report");
    let demo = Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .args(["demo", "--control", sock.to_str().unwrap()])
        .args(["--report", report.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("dnurbs demo starts");
    let t0 = Instant::now();
    while !sock.exists() {
        assert!(t0.elapsed() < Duration::from_secs(30), "no socket");
        std::thread::sleep(Duration::from_millis(50));
    }
    let mode = std::fs::metadata(&sock).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o660, "socket mode {mode:o}");

    // Into the program at its feed (F400 = 400 mm/min).
    let running = wait_for(&sock, |l| l.starts_with("running") && feed(l) > 399.0);
    assert!(
        running.contains("line 11") && running.contains("X "),
        "{running}"
    );

    // Pause: along the path to rest, and it stays there.
    assert!(ctl(&sock, &["pause"]).status.success());
    let paused = wait_for(&sock, |l| l.contains("(paused)") && feed(l) == 0.0);
    std::thread::sleep(Duration::from_millis(500));
    let still = wait_for(&sock, |l| l.contains("(paused)"));
    let axes = |l: &str| l[l.find("X ").unwrap()..l.find("  F ").unwrap()].to_owned();
    assert_eq!(axes(&paused), axes(&still), "moved while paused");

    // Above 100 % is refused, by the client and by the server.
    let over = ctl(&sock, &["override", "150"]);
    assert_eq!(over.status.code(), Some(2));
    let mut raw = UnixStream::connect(&sock).unwrap();
    raw.write_all(b"{\"cmd\":\"override\",\"percent\":120}\n")
        .unwrap();
    let mut answer = String::new();
    BufReader::new(raw).read_line(&mut answer).unwrap();
    assert!(
        answer.contains("\"ok\":false") && answer.contains("refused"),
        "{answer}"
    );

    // 50 %, resumed: the feed settles at half the programmed one.
    assert!(ctl(&sock, &["override", "50"]).status.success());
    assert!(ctl(&sock, &["resume"]).status.success());
    let half = wait_for(&sock, |l| {
        l.contains("override 50 %") && (feed(l) - 200.0).abs() < 1.0
    });
    assert!(!half.contains("(paused)"), "{half}");

    // Stop: along the path, drives disabled, exit 4, the report says who.
    assert!(ctl(&sock, &["stop"]).status.success());
    let out = demo.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(4), "{stdout}");
    assert!(stdout.contains("dnurbs ctl stop"), "{stdout}");
    assert!(!sock.exists(), "the socket file is removed with the run");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(json["outcome"], "stopped by the operator");
    assert_eq!(json["stop_line"], 11);
    // After the run, ctl cannot reach it: exit 1.
    assert_eq!(ctl(&sock, &["status"]).status.code(), Some(1));
    let _ = std::fs::remove_dir_all(&report);
}
