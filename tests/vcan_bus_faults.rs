//! Bus faults on a real SocketCAN interface (vcan0 in the PREEMPT_RT guest, tests/vcan/run):
//! `dnurbs run` against a `dnurbs sim-drives` process, and mid-program an error frame
//! written by can-utils' `cansend` (an 8-digit id with bit 29, `CAN_ERR_FLAG`, is sent as an
//! error frame; the kernel hands it to every socket whose error mask has its class) or the
//! interface set down with `ip link`:
//! - error passive: feed hold; `dnurbs ctl resume` goes on and the run completes;
//! - bus-off: quick stop, exit 3, the bus named in the reason;
//! - the interface down: quick stop, exit 3, `ENETDOWN` named; the interface is set up
//!   again afterwards.

mod common;

use common::data;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn out_dir() -> PathBuf {
    PathBuf::from(
        std::env::var("VCAN_OUT").unwrap_or_else(|_| std::env::temp_dir().display().to_string()),
    )
}

fn iface() -> String {
    std::env::var("DNURBS_VCAN").unwrap_or_else(|_| "vcan0".into())
}

fn ctl(sock: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .arg("ctl")
        .arg(sock)
        .args(args)
        .output()
        .expect("dnurbs ctl")
}

/// `ctl status` until its line satisfies `want` (at most `within`).
fn wait_status(sock: &Path, within: Duration, want: impl Fn(&str) -> bool) -> String {
    let t0 = Instant::now();
    loop {
        let out = ctl(sock, &["status"]);
        let line = String::from_utf8_lossy(&out.stdout).into_owned();
        if out.status.success() && want(&line) {
            return line;
        }
        assert!(t0.elapsed() < within, "status never came: last {line:?}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// The paper example on vcan0 against sim-drives; once it is running, `inject(socket)`.
/// Returns the run's output.
fn session(name: &str, inject: impl FnOnce(&Path)) -> Output {
    let iface = iface();
    let out = out_dir();
    let bin = env!("CARGO_BIN_EXE_dnurbs");
    let machine_file = data("vcan-machine.toml");
    // A local file system: the guest's shared directories (9p) cannot hold a socket.
    let sock = std::env::temp_dir().join(format!("dnurbs-vcan-bus-{name}.sock"));
    let _ = std::fs::remove_file(&sock);
    let boot = common::BootWatch::open(&iface);
    let mut sim = Command::new(bin)
        .args(["sim-drives", "--iface", &iface, "--machine"])
        .arg(&machine_file)
        .stdout(Stdio::null())
        .spawn()
        .expect("start dnurbs sim-drives");
    boot.wait(Duration::from_secs(60));
    let run = Command::new(bin)
        .arg("run")
        .arg(data("paper-example.nc"))
        .arg("--machine")
        .arg(&machine_file)
        .arg("--approach")
        .arg("--control")
        .arg(&sock)
        .arg("--report")
        .arg(out.join(format!("bus-{name}-report")))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("dnurbs run");
    let mut run = run;
    let t0 = Instant::now();
    while !sock.exists() {
        if t0.elapsed() > Duration::from_secs(60) || run.try_wait().ok().flatten().is_some() {
            let _ = run.kill();
            let _ = Command::new("kill").arg(sim.id().to_string()).status();
            let o = run.wait_with_output().unwrap();
            panic!(
                "no control socket {}: {}{}",
                sock.display(),
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    wait_status(&sock, Duration::from_secs(60), |l| l.starts_with("running"));
    std::thread::sleep(Duration::from_millis(300));
    inject(&sock);
    let output = run.wait_with_output().expect("dnurbs run ends");
    let _ = Command::new("kill").arg(sim.id().to_string()).status();
    let _ = sim.wait();
    println!(
        "dnurbs run with {name}:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

fn cansend(frame: &str) {
    let st = Command::new("cansend")
        .args([&iface(), frame])
        .status()
        .expect("cansend (can-utils)");
    assert!(st.success(), "cansend {frame}");
}

fn ip_link(state: &str) {
    let st = Command::new("ip")
        .args(["link", "set", &iface(), state])
        .status()
        .expect("ip link");
    assert!(st.success(), "ip link set {state}");
}

#[test]
#[ignore = "needs a SocketCAN interface and can-utils: run by tests/vcan/run in the PREEMPT_RT guest"]
fn vcan_bus_error_passive_holds_the_feed_until_resumed() {
    let out = session("passive", |sock| {
        // CAN_ERR_CRTL, data[1] = CAN_ERR_CRTL_TX_PASSIVE.
        cansend("20000004#0020000000000000");
        wait_status(sock, Duration::from_secs(30), |l| l.contains("(paused)"));
        std::thread::sleep(Duration::from_millis(500));
        let r = ctl(sock, &["resume"]);
        assert!(r.status.success(), "{r:?}");
    });
    common::assert_completed(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("error passive") && stdout.contains("1 feed hold"),
        "{stdout}"
    );
}

#[test]
#[ignore = "needs a SocketCAN interface and can-utils: run by tests/vcan/run in the PREEMPT_RT guest"]
fn vcan_bus_off_quick_stops_the_run() {
    // CAN_ERR_BUSOFF.
    let out = session("bus-off", |_| cansend("20000040#0000000000000000"));
    assert_eq!(out.status.code(), Some(3), "{out:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("drive fault: CAN bus: bus-off") && stdout.contains("1 bus-off"),
        "{stdout}"
    );
}

#[test]
#[ignore = "needs a SocketCAN interface: run by tests/vcan/run in the PREEMPT_RT guest"]
fn vcan_interface_down_mid_run_quick_stops_the_run() {
    let out = session("down", |_| ip_link("down"));
    ip_link("up");
    assert_eq!(out.status.code(), Some(3), "{out:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("drive fault: CAN bus: CAN link: CAN interface down (ENETDOWN)"),
        "{stdout}"
    );
}
