//! `dnurbs run` on a real SocketCAN interface (vcan0 in the PREEMPT_RT guest, see
//! tests/vcan/run) against a `dnurbs sim-drives` process: the paper example and a
//! multi-block program run to their end; every target the simulated drives recorded lies
//! on the interpolated path of `dnurbs simulate --trace` (same machine, same period), and
//! the drives end at the program's end within 1 count.

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
    let machine_file = data("vcan-machine.toml");
    let machine = config::load(&machine_file).expect("vcan machine file");
    let bin = env!("CARGO_BIN_EXE_dnurbs");
    let prog = data(program);

    let mut sim = Command::new(bin)
        .args(["sim-drives", "--iface", &iface, "--machine"])
        .arg(&machine_file)
        .arg("--record")
        .arg(&record)
        .spawn()
        .expect("start dnurbs sim-drives");
    std::thread::sleep(Duration::from_millis(500));
    let run = Command::new(bin)
        .arg("run")
        .arg(&prog)
        .arg("--machine")
        .arg(&machine_file)
        .arg("--approach")
        .arg("--report")
        .arg(&report)
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
    for line in stdout.lines().filter(|l| l.starts_with("axis ")) {
        let n: Vec<i64> = line
            .split_whitespace()
            .filter_map(|w| w.trim_end_matches(':').parse().ok())
            .collect();
        assert!((n[2] - n[3]).abs() <= 1, "{line}");
    }
    println!(
        "{program}: {checked} targets checked against {} trace rows, all within 2 counts",
        path.len()
    );
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
