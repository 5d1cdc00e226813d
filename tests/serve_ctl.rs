//! `dnurbs serve --sim` driven through `dnurbs ctl` only, the real binaries: the paper
//! machine's file with a home table for every axis (a switch, a switch and the index, the
//! position where it stands, an absolute encoder), its drives simulated in the serve
//! process, every target they take recorded (`--record`).
//!
//! The session: refusals while off (and of the watch socket, malformed and unknown
//! requests), on, home, jog by a step, a jog beyond the travel, a continuous jog whose ctl
//! is killed, MDI, load and run a program with a pause and an override, run it again and
//! stop it, single block (two blocks stepped, then resumed; refused in the middle of a
//! program started with run), restart it from a line (the approach said, then
//! confirmed), the e-stop and its reset, home again, run to the end, off. Then a second serve whose node 2 faults: the
//! status names it, reset, home, run to the end.
//!
//! The recorded targets are checked by finite differences at the period against the
//! machine's limits, outside the homing and e-stop windows the status's cycle count marks.

mod common;

use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const PROGRAM: &str = "G90 G21 G17\nG1 X10 Y0 F1200\nG2 X20 Y10 I10 J0\nG1 Y30\nG1 X0\n\
                       G0 Y0\nM30\n";

struct Serve {
    child: Child,
    sock: PathBuf,
    record: PathBuf,
}

impl Serve {
    fn start(dir: &Path, extra: &[&str]) -> Serve {
        let sock = dir.join(format!("serve{}.sock", extra.len()));
        let watch = dir.join(format!("watch{}.sock", extra.len()));
        let record = dir.join(format!("record{}.csv", extra.len()));
        let child = Command::new(env!("CARGO_BIN_EXE_dnurbs"))
            .args(["serve", "--sim", "--machine"])
            .arg(dir.join("machine.toml"))
            .arg("--control")
            .arg(&sock)
            .arg("--watch")
            .arg(&watch)
            .arg("--record")
            .arg(&record)
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("dnurbs serve starts");
        let t0 = Instant::now();
        while !(sock.exists() && watch.exists()) {
            assert!(t0.elapsed() < Duration::from_secs(30), "no socket");
            std::thread::sleep(Duration::from_millis(20));
        }
        Serve {
            child,
            sock,
            record,
        }
    }

    fn ctl(&self, args: &[&str]) -> Output {
        let mut all = vec!["ctl", self.sock.to_str().unwrap()];
        all.extend(args);
        common::dnurbs(&all)
    }

    /// `ctl ARGS` answered: its state.
    fn ok(&self, args: &[&str]) -> String {
        let out = self.ctl(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "ctl {args:?}: {stderr}");
        String::from_utf8_lossy(&out.stdout).trim().to_owned()
    }

    /// `ctl ARGS` refused with exit 2 and `says`, the state unchanged.
    fn refused(&self, args: &[&str], says: &str) {
        let before = self.state();
        let out = self.ctl(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "ctl {args:?}: {stderr}");
        assert!(stderr.contains(says), "ctl {args:?}: {stderr}");
        assert_eq!(
            self.state(),
            before,
            "ctl {args:?} refused, the state moved"
        );
    }

    fn status(&self) -> serde_json::Value {
        serde_json::from_str(&self.ok(&["status"])).expect("a status line")
    }

    fn state(&self) -> String {
        self.status()["state"].as_str().unwrap().to_owned()
    }

    /// Until the state is `want` (at most 60 s); the status then.
    fn until(&self, want: &str) -> serde_json::Value {
        let t0 = Instant::now();
        loop {
            let s = self.status();
            if s["state"] == want {
                return s;
            }
            assert!(t0.elapsed() < Duration::from_secs(60), "not {want}: {s}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    fn cycles(&self) -> u64 {
        self.status()["cycles"].as_u64().unwrap()
    }

    fn axes(&self) -> Vec<f64> {
        self.status()["axes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    }

    /// SIGTERM: the machine wound down, exit 0; the recorded targets by node.
    fn end(self) -> Vec<Vec<(u64, i32)>> {
        let killed = Command::new("kill")
            .args(["-TERM", &self.child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let out = self.child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "serve: {stderr}");
        assert!(stderr.contains("stopped after"), "{stderr}");
        let mut by_node = vec![Vec::new(); 8];
        let text = std::fs::read_to_string(&self.record).unwrap();
        for line in text.lines().skip(1) {
            let f: Vec<i64> = line.split(',').map(|x| x.parse().unwrap()).collect();
            by_node[f[1] as usize].push((f[0] as u64, f[2] as i32));
        }
        by_node
    }
}

fn setup() -> PathBuf {
    let dir = common::temp("serve");
    std::fs::create_dir_all(&dir).unwrap();
    let text = common::machine_text("paper-ac-table.toml");
    std::fs::write(dir.join("machine.toml"), text + common::SERVE_HOMES).unwrap();
    std::fs::copy(
        common::root().join("config/machines/mill.tbl"),
        dir.join("mill.tbl"),
    )
    .unwrap();
    std::fs::write(dir.join("part.nc"), PROGRAM).unwrap();
    dir
}

/// One raw request line on the socket: its answer.
fn raw(sock: &Path, line: &str) -> serde_json::Value {
    let s = UnixStream::connect(sock).unwrap();
    let mut w = s.try_clone().unwrap();
    writeln!(w, "{line}").unwrap();
    let mut answer = String::new();
    BufReader::new(s).read_line(&mut answer).unwrap();
    serde_json::from_str(&answer).unwrap()
}

#[test]
fn a_session_through_ctl_on_simulated_drives() {
    let dir = setup();
    let serve = Serve::start(&dir, &[]);
    let mut skip: Vec<(u64, u64)> = Vec::new();

    assert_eq!(serve.state(), "off");
    serve.refused(&["jog", "X", "+", "--step", "1"], "turn it on first");
    serve.refused(&["mdi", "G0", "X0"], "turn it on first");
    serve.refused(&["reset"], "nothing to reset");
    let watch = dir.join("watch0.sock");
    let w = common::dnurbs(&["ctl", watch.to_str().unwrap(), "on"]);
    assert!(String::from_utf8_lossy(&w.stderr).contains("watch socket"));
    let r = raw(
        &serve.sock,
        r#"{"v":1,"id":3,"cmd":"jog","axis":"Q","dir":"+"}"#,
    );
    assert_eq!(r["ok"], false);
    assert!(r["error"].as_str().unwrap().contains("axis"), "{r}");
    let r = raw(&serve.sock, r#"{"v":2,"cmd":"on"}"#);
    assert!(r["error"].as_str().unwrap().contains("version 2"), "{r}");
    let r = raw(&serve.sock, "not json");
    assert_eq!(r["ok"], false);
    assert_eq!(serve.state(), "off");

    assert_eq!(serve.ok(&["on"]), "on");
    serve.refused(&["run"], "not every axis is homed");
    let c0 = serve.cycles();
    assert_eq!(serve.ok(&["home"]), "homing");
    serve.until("idle");
    skip.push((c0, serve.cycles()));
    assert_eq!(
        serve.status()["homed"],
        serde_json::json!(["X", "Y", "Z", "A", "C"])
    );

    let x0 = serve.axes()[0];
    assert_eq!(
        serve.ok(&["jog", "X", "+", "--step", "10", "--speed", "50"]),
        "jog"
    );
    serve.until("idle");
    assert!(
        (serve.axes()[0] - (x0 + 10.0)).abs() < 2e-4,
        "{:?}",
        serve.axes()
    );
    serve.refused(&["jog", "X", "+", "--step", "1000"], "outside the travel");

    // A continuous jog whose ctl is killed: stopped at once.
    let mut jog = Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .args([
            "ctl",
            serve.sock.to_str().unwrap(),
            "jog",
            "Y",
            "-",
            "--for",
            "30s",
        ])
        .args(["--speed", "20"])
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    serve.until("jog");
    std::thread::sleep(Duration::from_millis(300));
    jog.kill().unwrap();
    jog.wait().unwrap();
    let killed = Instant::now();
    serve.until("idle");
    assert!(killed.elapsed() < Duration::from_secs(5));

    assert_eq!(serve.ok(&["mdi", "G0", "X0", "Y0"]), "mdi");
    serve.until("idle");
    let a = serve.axes();
    assert!(a[0].abs() < 2e-4 && a[1].abs() < 2e-4, "{a:?}");
    serve.refused(&["mdi", "G0", "X"], "mdi `G0 X`");

    let part = dir.join("part.nc");
    serve.refused(&["load", "/no/such/part.nc"], "/no/such/part.nc");
    assert_eq!(serve.ok(&["load", part.to_str().unwrap()]), "idle");
    assert_eq!(serve.ok(&["override", "50"]), "idle");
    assert_eq!(serve.ok(&["run"]), "running");
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(serve.ok(&["pause"]), "paused");
    serve.refused(&["jog", "X", "+", "--step", "1"], "only at rest");
    serve.refused(&["step"], "started with run");
    assert!(serve.status()["line"].as_u64().unwrap() > 0);
    assert_eq!(serve.ok(&["resume"]), "running");
    let s = serve.until("idle");
    assert_eq!(s["override_pct"], 50);
    let a = serve.axes();
    assert!(
        a[0].abs() < 2e-4 && a[1].abs() < 2e-4,
        "back at X0 Y0: {a:?}"
    );

    // Single block: step two blocks, then resume to the end.
    assert_eq!(serve.ok(&["step"]), "stepping");
    serve.until("paused");
    assert_eq!(serve.ok(&["step"]), "stepping");
    let s = serve.until("paused");
    assert!(s["message"].as_str().unwrap().contains("line 4"), "{s}");
    let a = serve.axes();
    assert!(
        (a[0] - 20.0).abs() < 2e-4 && (a[1] - 10.0).abs() < 2e-4,
        "{a:?}"
    );
    assert_eq!(serve.ok(&["resume"]), "running");
    serve.until("idle");

    assert_eq!(serve.ok(&["override", "100"]), "idle");
    assert_eq!(serve.ok(&["run"]), "running");
    std::thread::sleep(Duration::from_millis(200));
    serve.ok(&["stop"]);
    let s = serve.until("idle");
    assert!(s["message"].as_str().unwrap().contains("operator"), "{s}");
    // Restart from line 4: the approach is said, nothing moves; confirmed, it runs to
    // the end.
    serve.refused(
        &["run", "--from-line", "4"],
        "the approach: back along the tool axis",
    );
    let r = serve.ok(&["run", "--from-line", "4", "--clearance", "5", "--confirm"]);
    assert_eq!(r, "running");
    let s = serve.until("idle");
    assert!(s["message"].is_null(), "{s}");
    let a = serve.axes();
    assert!(
        a[0].abs() < 2e-4 && a[1].abs() < 2e-4,
        "back at X0 Y0: {a:?}"
    );

    let c0 = serve.cycles();
    assert_eq!(serve.ok(&["estop"]), "estop");
    serve.refused(&["on"], "reset first");
    std::thread::sleep(Duration::from_millis(700));
    assert_eq!(serve.ok(&["reset"]), "off");
    assert_eq!(serve.ok(&["on"]), "on");
    assert_eq!(serve.status()["homed"], serde_json::json!(["A"]));
    assert_eq!(serve.ok(&["home"]), "homing");
    serve.until("idle");
    skip.push((c0, serve.cycles()));
    assert_eq!(serve.ok(&["mdi", "G0", "X0", "Y0"]), "mdi");
    serve.until("idle");
    assert_eq!(serve.ok(&["run"]), "running");
    serve.until("idle");
    assert_eq!(serve.ok(&["off"]), "off");
    let records = serve.end();
    check(&records, &skip);
}

#[test]
fn a_drive_fault_is_named_reset_and_the_program_runs_again() {
    let dir = setup();
    // Node 2 (Y) faults 4 s after the loop starts: during homing or after.
    let serve = Serve::start(&dir, &["--fault-at", "2:2000"]);
    assert_eq!(serve.ok(&["on"]), "on");
    serve.ok(&["home"]);
    let s = serve.until("fault");
    let message = s["message"].as_str().unwrap();
    assert!(message.contains("node 2"), "{message}");
    serve.refused(&["on"], "reset first");
    // The reset waits for the quick stop to be over.
    let t0 = Instant::now();
    loop {
        let out = serve.ctl(&["reset"]);
        if out.status.success() {
            break;
        }
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains("quick stop"), "{e}");
        assert!(t0.elapsed() < Duration::from_secs(30));
        std::thread::sleep(Duration::from_millis(100));
    }
    assert_eq!(serve.ok(&["on"]), "on");
    serve.ok(&["home"]);
    serve.until("idle");
    serve.ok(&["mdi", "G0", "X0", "Y0"]);
    serve.until("idle");
    let part = dir.join("part.nc");
    serve.ok(&["load", part.to_str().unwrap()]);
    serve.ok(&["run"]);
    serve.until("idle");
    let a = serve.axes();
    assert!(a[0].abs() < 2e-4 && a[1].abs() < 2e-4, "{a:?}");
    serve.end();
}

/// Velocity and acceleration of every drive within its axis's limits by finite
/// differences of the recorded targets, outside the windows (SYNC counts) in `skip`.
fn check(by_node: &[Vec<(u64, i32)>], skip: &[(u64, u64)]) {
    let m = config::load(&common::machine("paper-ac-table.toml")).unwrap();
    let limits = [&m.axes.x, &m.axes.y, &m.axes.z, &m.axes.tilt, &m.axes.c];
    let p = m.period_s;
    let mut checked = 0;
    for d in &m.drives {
        let rows = &by_node[usize::from(d.node)];
        assert!(rows.len() > 1000, "node {}: {} records", d.node, rows.len());
        let l = limits[d.axis];
        let cpu = d.counts_per_unit;
        for k in 2..rows.len() {
            let (s, _) = rows[k];
            // Contiguous SYNCs, outside the windows (the SYNC count runs with the cycles,
            // give or take the set-up's few).
            if rows[k - 2].0 + 2 != s || skip.iter().any(|&(a, b)| s + 10 >= a && s <= b + 10) {
                continue;
            }
            checked += 1;
            let q = |i: usize| f64::from(rows[i].1) / cpu;
            let v = (q(k) - q(k - 1)) / p;
            let a = (q(k) - 2.0 * q(k - 1) + q(k - 2)) / (p * p);
            assert!(
                v.abs() <= l.velocity + 1.0 / cpu / p,
                "node {} SYNC {s}: velocity {v}",
                d.node
            );
            assert!(
                a.abs() <= l.acceleration + 2.0 / cpu / (p * p),
                "node {} SYNC {s}: acceleration {a}",
                d.node
            );
        }
    }
    let total: usize = m
        .drives
        .iter()
        .map(|d| by_node[usize::from(d.node)].len())
        .sum();
    eprintln!("{checked} of {total} recorded targets checked");
    assert!(checked * 2 > total, "{checked} of {total} checked");
}

/// The systemd unit's command line, as `config/systemd/dnurbs-serve.service` has it (its
/// paths moved to a temporary directory, `--sim` added): both sockets answer, the control
/// one with mode 0660 and the watch one 0666, and SIGTERM ends it cleanly.
#[test]
fn the_units_command_line_serves() {
    use std::os::unix::fs::PermissionsExt;
    let dir = setup();
    let unit = std::fs::read_to_string(common::root().join("config/systemd/dnurbs-serve.service"))
        .unwrap();
    let exec = unit
        .lines()
        .find_map(|l| l.strip_prefix("ExecStart="))
        .expect("an ExecStart= line");
    let mut words = exec.split_whitespace();
    assert_eq!(words.next(), Some("/usr/local/bin/dnurbs"));
    let here = dir.display().to_string();
    let args: Vec<String> = words
        .map(|w| {
            w.replace("/etc/dnurbs/machine.toml", &format!("{here}/machine.toml"))
                .replace("/run/dnurbs", &here)
        })
        .collect();
    assert_eq!(args[0], "serve");
    let child = Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .args(&args)
        .arg("--sim")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (control, watch) = (dir.join("control.sock"), dir.join("watch.sock"));
    let t0 = Instant::now();
    while !(control.exists() && watch.exists()) {
        assert!(t0.elapsed() < Duration::from_secs(30), "no sockets");
        std::thread::sleep(Duration::from_millis(20));
    }
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!((mode(&control), mode(&watch)), (0o660, 0o666));
    for sock in [&control, &watch] {
        let out = common::dnurbs(&["ctl", sock.to_str().unwrap(), "status"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let serve = Serve {
        child,
        sock: control,
        record: dir.join("none.csv"),
    };
    std::fs::write(
        &serve.record,
        "sync,node,target_counts,actual_counts,statusword\n",
    )
    .unwrap();
    serve.end();
}

/// Homing that never finds its switch (X's not wired, `--no-home-switch 1`): the drive's
/// homing error, named with the axis; the machine stays on, X not homed, and Y homes.
#[test]
fn a_homing_that_finds_no_switch_says_why() {
    let dir = setup();
    let serve = Serve::start(&dir, &["--no-home-switch", "1"]);
    assert_eq!(serve.ok(&["on"]), "on");
    assert_eq!(serve.ok(&["home", "X"]), "homing");
    let s = serve.until("on");
    let m = s["message"].as_str().unwrap();
    assert!(
        m.contains("homing X failed") && m.contains("did not find its switch"),
        "{s}"
    );
    assert_eq!(s["homed"], serde_json::json!(["A"]));
    assert_eq!(serve.ok(&["home", "Y"]), "homing");
    let s = serve.until("on");
    assert_eq!(s["homed"], serde_json::json!(["Y", "A"]));
    serve.refused(&["run"], "not every axis is homed");
    serve.end();
}
