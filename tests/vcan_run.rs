//! `dnurbs run` on a real SocketCAN interface (vcan0 in the PREEMPT_RT guest, see
//! tests/vcan/run) against a `dnurbs sim-drives` process: the paper example and a
//! multi-block program run to their end; every target the simulated drives recorded lies
//! on the interpolated path of `dnurbs simulate --trace` (same machine, same period), the
//! targets `run --trace` says it sent are, node by node and period by period, those
//! `sim-drives --record` took, and the drives end at the program's end within 1 count.

mod common;

use common::{data, read_trace, Row};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

fn out_dir() -> PathBuf {
    PathBuf::from(
        std::env::var("VCAN_OUT").unwrap_or_else(|_| std::env::temp_dir().display().to_string()),
    )
}

/// Distance from `q` to the segment a-b, axis by axis scaled to counts (so that 1 means one
/// count on the axis with the finest resolution involved).
fn dist_counts(q: &[f64; 5], a: &[f64; 5], b: &[f64; 5], cpu: &[f64; 5]) -> f64 {
    let mut ab = 0.0;
    let mut aq = 0.0;
    for j in 0..5 {
        ab += ((b[j] - a[j]) * cpu[j]).powi(2);
        aq += ((q[j] - a[j]) * cpu[j]) * ((b[j] - a[j]) * cpu[j]);
    }
    let t = if ab > 0.0 {
        (aq / ab).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..5)
        .map(|j| ((q[j] - (a[j] + (b[j] - a[j]) * t)) * cpu[j]).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn run_on_vcan(program: &str) {
    let iface = std::env::var("DNURBS_VCAN").unwrap_or_else(|_| "vcan0".into());
    let out = out_dir();
    let stem = Path::new(program)
        .file_stem()
        .unwrap()
        .to_str()
        .unwrap()
        .to_owned();
    let record = out.join(format!("run-{stem}-drives.csv"));
    let trace = out.join(format!("run-{stem}-trace.csv"));
    let report = out.join(format!("run-{stem}-report"));
    let sent = out.join(format!("run-{stem}-sent.csv"));
    let machine_file = data("vcan-machine.toml");
    let machine = config::load(&machine_file).expect("vcan machine file");
    let bin = env!("CARGO_BIN_EXE_dnurbs");
    let prog = data(program);

    let boot = common::BootWatch::open(&iface);
    let mut sim = Command::new(bin)
        .args(["sim-drives", "--iface", &iface, "--machine"])
        .arg(&machine_file)
        .arg("--record")
        .arg(&record)
        .spawn()
        .expect("start dnurbs sim-drives");
    boot.wait(Duration::from_secs(60));
    let run = Command::new(bin)
        .arg("run")
        .arg(&prog)
        .arg("--machine")
        .arg(&machine_file)
        .arg("--approach")
        .arg("--report")
        .arg(&report)
        .arg("--trace")
        .arg(&sent)
        .output()
        .expect("dnurbs run");
    // sim-drives flushes its record every 100 ms; let it write the last targets.
    std::thread::sleep(Duration::from_millis(400));
    let _ = Command::new("kill").arg(sim.id().to_string()).status();
    let _ = sim.wait();
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    println!("dnurbs run {program}:\n{stdout}{stderr}");
    common::assert_completed(&run);
    assert!(stdout.contains("outcome: completed"), "{stdout}");
    assert!(report.join("summary.json").is_file());

    let sim_out = Command::new(bin)
        .arg("simulate")
        .arg(&prog)
        .arg("--machine")
        .arg(&machine_file)
        .arg("--trace")
        .arg(&trace)
        .output()
        .expect("dnurbs simulate");
    assert!(sim_out.status.success());
    let rows: Vec<Row> = read_trace(&trace);
    let path: Vec<[f64; 5]> = rows.iter().map(|r| r.axes).collect();

    // Drives by node: axis index and resolution.
    let by_node: BTreeMap<u8, &config::bus::Drive> =
        machine.drives.iter().map(|d| (d.node, d)).collect();
    let mut cpu = [0.0; 5];
    for d in &machine.drives {
        cpu[d.axis] = d.counts_per_unit;
    }
    // Targets per SYNC, in axis units.
    let text = std::fs::read_to_string(&record).expect("sim-drives record");
    let mut syncs: BTreeMap<u64, [Option<f64>; 5]> = BTreeMap::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (sync, node, target): (u64, u8, i32) = (
            f[0].parse().unwrap(),
            f[1].parse().unwrap(),
            f[2].parse().unwrap(),
        );
        let d = by_node[&node];
        syncs.entry(sync).or_insert([None; 5])[d.axis] = Some(d.position(target));
    }
    same_as_sent(&sent, &text, &machine);
    let targets: Vec<[f64; 5]> = syncs
        .values()
        .filter_map(|t| {
            let mut q = [0.0; 5];
            for j in 0..5 {
                q[j] = t[j]?;
            }
            Some(q)
        })
        .collect();
    assert!(
        targets.len() > path.len() / 2,
        "{} targets recorded",
        targets.len()
    );
    // The approach ends on the program's start; from there on every target is on the path.
    let start = path[0];
    let first = targets
        .iter()
        .position(|q| dist_counts(q, &start, &start, &cpu) <= 1.0)
        .expect("the drives reached the program's start");
    let mut cursor = 0;
    let mut checked = 0;
    for q in &targets[first..] {
        // Nearest trace segment at or after the cursor (the path is followed forwards).
        let (mut best, mut at) = (f64::INFINITY, cursor);
        for i in cursor..path.len() - 1 {
            let d = dist_counts(q, &path[i], &path[i + 1], &cpu);
            if d < best {
                best = d;
                at = i;
            }
            if best <= 1.0 && i > at + 50 {
                break;
            }
        }
        assert!(
            best <= 2.0,
            "target {q:?} is {best:.2} counts off the interpolated path (near trace row {at})"
        );
        cursor = at;
        checked += 1;
    }
    let end = path[path.len() - 1];
    let last = targets.last().unwrap();
    for j in 0..5 {
        assert!(
            ((last[j] - end[j]) * cpu[j]).abs() <= 1.0,
            "axis {j}: last target {} vs program end {}",
            last[j],
            end[j]
        );
    }
    // The actual positions at the end, as printed by `run`.
    common::assert_axes_settled(&stdout);
    println!(
        "{program}: {checked} targets checked against {} trace rows, all within 2 counts",
        path.len()
    );
}

/// `run --trace` (what the controller sent, period by period) against `sim-drives --record`
/// (what the drives took, SYNC by SYNC): node by node, the same targets in the same order,
/// from the first SYNC (the record may lack the last period, sent as the run ended).
fn same_as_sent(sent: &Path, record: &str, machine: &config::Machine) {
    let text = std::fs::read_to_string(sent).expect("the run's trace");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let mut compared = 0;
    for d in &machine.drives {
        let col = header
            .iter()
            .position(|h| h.ends_with(&format!(":{}", d.node)))
            .expect("a column per node");
        let sent: Vec<i32> = rows.iter().map(|r| r[col].parse().unwrap()).collect();
        let mut took: Vec<(u64, i32)> = record
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|f| f[1].parse::<u8>().ok() == Some(d.node))
            .map(|f| (f[0].parse().unwrap(), f[2].parse().unwrap()))
            .collect();
        took.sort();
        let took: Vec<i32> = took.into_iter().map(|t| t.1).collect();
        assert!(
            sent.len() >= took.len() && sent.len() - took.len() <= 1,
            "node {}: {} targets sent, {} taken",
            d.node,
            sent.len(),
            took.len()
        );
        let first_diff = took.iter().zip(&sent).position(|(a, b)| a != b);
        assert_eq!(first_diff, None, "node {}: sent and taken differ", d.node);
        compared += took.len();
    }
    println!("run --trace: {compared} targets, the same as sim-drives recorded");
}

#[test]
#[ignore = "needs a SocketCAN interface: run by tests/vcan/run in the PREEMPT_RT guest"]
fn vcan_run_paper_example_follows_the_interpolated_path() {
    run_on_vcan("paper-example.nc");
}

#[test]
#[ignore = "needs a SocketCAN interface: run by tests/vcan/run in the PREEMPT_RT guest"]
fn vcan_run_multi_block_program_follows_the_interpolated_path() {
    run_on_vcan("two-blocks-g2.nc");
}

/// A CAM post (hyperMILL style, 5-axis, G93, RTCP) on the posts machine: axis drives on
/// vcan0, the spindle drive and the coolant I/O module on vcan1, each bus played by its own
/// `dnurbs sim-drives` process. The spindle drive is commanded the program's speed and
/// stopped at the end, the coolant valves are switched on and off again, and the axes end
/// at the program's end.
#[test]
#[ignore = "needs vcan0 and vcan1: run by tests/vcan/run in the PREEMPT_RT guest"]
fn vcan_run_cam_post_with_spindle_and_coolant_on_the_bus() {
    let out = out_dir();
    let posts = common::root().join("tests/data/posts");
    // The posts machine with the vcan guest's supervision: the guest is emulated (10-50x
    // slower), so feedback and heartbeats may be late by far more than on a real bus.
    let text = std::fs::read_to_string(posts.join("machine.toml")).unwrap();
    let text = text
        .replace("heartbeat_timeout_ms = 300", "heartbeat_timeout_ms = 3000")
        .replace("feedback_timeout_ms = 20 ", "feedback_timeout_ms = 3000 ")
        .replace("boot_timeout_ms = 3000", "boot_timeout_ms = 10000")
        .replace("sdo_timeout_ms = 200", "sdo_timeout_ms = 2000")
        .replace(
            "[realtime]\n",
            "[realtime]\nmax_consecutive_overruns = 1000  # the emulated guest: exit 5\n",
        );
    let machine_file = out.join("posts-machine-vcan.toml");
    std::fs::write(&machine_file, &text).unwrap();
    let machine = config::load(&machine_file).expect("posts machine file");
    assert_eq!(
        machine.realtime.feedback_timeout_s, 3.0,
        "the guest's timeouts apply"
    );
    let program = posts.join("hypermill-5axis-g93.nc");
    let bin = env!("CARGO_BIN_EXE_dnurbs");
    let mut sims = Vec::new();
    for (iface, file) in [
        ("vcan0", "post-axes.csv"),
        ("vcan1", "post-spindle-coolant.csv"),
    ] {
        let boot = common::BootWatch::open(iface);
        let sim = Command::new(bin)
            .args(["sim-drives", "--iface", iface, "--machine"])
            .arg(&machine_file)
            .arg("--record")
            .arg(out.join(file))
            .spawn()
            .expect("start dnurbs sim-drives");
        boot.wait(Duration::from_secs(60));
        sims.push(sim);
    }
    let report = out.join("run-post-report");
    let run = Command::new(bin)
        .arg("run")
        .arg(&program)
        .arg("--machine")
        .arg(&machine_file)
        .arg("--tools")
        .arg(posts.join("tool.tbl"))
        .arg("--approach")
        .arg("--report")
        .arg(&report)
        .output()
        .expect("dnurbs run");
    std::thread::sleep(Duration::from_millis(400));
    for mut sim in sims {
        let _ = Command::new("kill").arg(sim.id().to_string()).status();
        let _ = sim.wait();
    }
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    println!("dnurbs run {}:\n{stdout}{stderr}", program.display());
    common::assert_completed(&run);
    assert!(stdout.contains("outcome: completed"), "{stdout}");

    // The program's first speed, from its own words.
    let parse = dnurbs_tools::shop::parse_setup(
        &machine,
        &dnurbs_tools::shop::ShopArgs {
            tools: Some(posts.join("tool.tbl")),
            ..Default::default()
        }
        .load()
        .unwrap(),
    )
    .unwrap();
    let prog = dnurbs_tools::load_program(&program, &parse).unwrap();
    let rpm = common::first_spindle_rpm(&prog).expect("the post starts the spindle");
    let spindle = machine.spindle.as_ref().unwrap();
    let coolant = machine.coolant.as_ref().unwrap();
    // sync, node, target, actual, statusword per line.
    let text = std::fs::read_to_string(out.join("post-spindle-coolant.csv")).unwrap();
    let rows: Vec<[i64; 5]> = text
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<i64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [f[0], f[1], f[2], f[3], f[4]]
        })
        .collect();
    let of = |node: u8| -> Vec<[i64; 5]> {
        rows.iter()
            .filter(|r| r[1] == i64::from(node))
            .copied()
            .collect()
    };
    let node = |at: Option<config::BusNode>| at.expect("on the bus").node;
    let (sp, io) = (of(node(spindle.at)), of(node(coolant.at)));
    let want = i64::from(spindle.velocity(rpm));
    assert!(
        sp.iter().any(|r| r[2] == want && (r[3] - want).abs() <= 1),
        "the spindle never ran at {want}"
    );
    assert!(
        sp.iter().any(|r| r[2] == want && r[4] & (1 << 10) != 0),
        "the spindle drive never reported the speed reached"
    );
    let last = sp.last().unwrap();
    assert_eq!((last[2], last[3]), (0, 0), "the spindle ends stopped");
    assert!(
        io.iter().any(|r| r[2] != 0 && r[3] == r[2]),
        "the coolant outputs were never switched on"
    );
    assert_eq!(io.last().unwrap()[2], 0, "the coolant ends off");
    // The axes end where they were sent (the run prints target and actual per axis).
    common::assert_axes_settled(&stdout);
    println!(
        "post: spindle {} SYNCs recorded (at {want} units), coolant {} SYNCs",
        sp.len(),
        io.len()
    );
}
