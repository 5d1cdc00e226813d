//! `dnurbs serve` on a real SocketCAN interface (vcan0 in the PREEMPT_RT guest, see
//! tests/vcan/run) against a `dnurbs sim-drives` process whose node 2 faults: operated
//! through `dnurbs ctl` only. On, home every axis on the bus (CiA-402 homing mode 6 by SDO),
//! the fault (the status names node 2), reset (the fault-reset edge on the bus), on, home
//! again, jog, MDI, load and run a program to its end, off. tests/vcan/run then looks for
//! the homing objects and the fault-reset edge in its candump capture.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn out_dir() -> PathBuf {
    PathBuf::from(
        std::env::var("VCAN_OUT").unwrap_or_else(|_| std::env::temp_dir().display().to_string()),
    )
}

fn ctl(sock: &Path, args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .arg("ctl")
        .arg(sock)
        .args(args)
        .output()
        .expect("dnurbs ctl");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    println!("ctl {args:?}: {}", text.trim());
    (out.status.success(), text)
}

fn ok(sock: &Path, args: &[&str]) -> String {
    let (ok, text) = ctl(sock, args);
    assert!(ok, "ctl {args:?}: {text}");
    text.trim().to_owned()
}

fn status(sock: &Path) -> serde_json::Value {
    serde_json::from_str(&ok(sock, &["status"])).expect("a status line")
}

/// Until the state is `want` (at most 10 min: the guest is emulated).
fn until(sock: &Path, want: &str) -> serde_json::Value {
    let t0 = Instant::now();
    loop {
        let s = status(sock);
        if s["state"] == want {
            return s;
        }
        assert!(t0.elapsed() < Duration::from_secs(600), "not {want}: {s}");
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// A child process that is stopped (SIGTERM) when the test ends, however it ends: a
/// `sim-drives` left running would talk on the bus of the next test.
struct Stopped(Child);

impl Drop for Stopped {
    fn drop(&mut self) {
        let _ = Command::new("kill").arg(self.0.id().to_string()).status();
        let _ = self.0.wait();
    }
}

/// A directory where this kernel lets a Unix socket be bound (the guest's shared
/// directories are 9p, which does not).
fn socket_dir() -> PathBuf {
    for dir in ["/run", "/dev/shm", "/tmp"] {
        let probe = Path::new(dir).join(format!("dnurbs-probe-{}.sock", std::process::id()));
        if std::os::unix::net::UnixListener::bind(&probe).is_ok() {
            let _ = std::fs::remove_file(&probe);
            return PathBuf::from(dir);
        }
    }
    panic!("no directory here takes a Unix socket");
}

#[test]
#[ignore = "needs a SocketCAN interface: run by tests/vcan/run in the PREEMPT_RT guest"]
fn vcan_serve_homes_faults_resets_and_runs_on_the_bus() {
    let iface = std::env::var("DNURBS_VCAN").unwrap_or_else(|_| "vcan0".into());
    let out = out_dir();
    let machine = out.join("serve-machine.toml");
    let text = std::fs::read_to_string(common::data("vcan-machine.toml")).unwrap();
    std::fs::write(&machine, text + common::SERVE_HOMES).unwrap();
    let program = out.join("serve-part.nc");
    std::fs::write(
        &program,
        "G90 G21\nG1 X10 Y0 F1200\nG2 X20 Y10 I10 J0\nG1 X0 Y0\nM30\n",
    )
    .unwrap();
    let sock = socket_dir().join(format!("dnurbs-serve-{}.sock", std::process::id()));
    let bin = env!("CARGO_BIN_EXE_dnurbs");

    let boot = common::BootWatch::open(&iface);
    // Node 2 faults 10 s (1000 SYNCs at 10 ms) into the session.
    let sim = Command::new(bin)
        .args(["sim-drives", "--iface", &iface, "--machine"])
        .arg(&machine)
        .args(["--fault-at", "2:1000", "--record"])
        .arg(out.join("serve-drives.csv"))
        .spawn()
        .expect("start dnurbs sim-drives");
    let sim = Stopped(sim);
    boot.wait(Duration::from_secs(60));
    let serve = Command::new(bin)
        .args(["serve", "--machine"])
        .arg(&machine)
        .arg("--control")
        .arg(&sock)
        .stdout(Stdio::inherit())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start dnurbs serve");
    let serve = Stopped(serve);
    let t0 = Instant::now();
    while !sock.exists() {
        assert!(t0.elapsed() < Duration::from_secs(120), "no control socket");
        std::thread::sleep(Duration::from_millis(50));
    }

    assert_eq!(ok(&sock, &["on"]), "on");
    ok(&sock, &["home"]);
    let s = until(&sock, "fault");
    assert!(s["message"].as_str().unwrap().contains("node 2"), "{s}");
    let t0 = Instant::now();
    while !ctl(&sock, &["reset"]).0 {
        assert!(
            t0.elapsed() < Duration::from_secs(120),
            "reset refused for 2 min"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    assert_eq!(ok(&sock, &["on"]), "on");
    ok(&sock, &["home"]);
    until(&sock, "idle");
    ok(&sock, &["jog", "X", "+", "--step", "5", "--speed", "20"]);
    until(&sock, "idle");
    ok(&sock, &["mdi", "G0", "X0", "Y0"]);
    until(&sock, "idle");
    ok(&sock, &["load", program.to_str().unwrap()]);
    ok(&sock, &["run"]);
    let s = until(&sock, "idle");
    let axes = s["axes"].as_array().unwrap();
    let (x, y) = (axes[0].as_f64().unwrap(), axes[1].as_f64().unwrap());
    assert!(x.abs() < 2e-4 && y.abs() < 2e-4, "{s}");
    assert_eq!(ok(&sock, &["off"]), "off");
    drop(serve);
    std::thread::sleep(Duration::from_millis(300));
    drop(sim);
}
