//! Helpers shared by the integration tests: run the real `dnurbs` binary, read its trace,
//! and evaluate NURBS independently of the nc crate.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::atomic::{AtomicU32, Ordering};

/// The workspace root (tests/ sits directly under it).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub fn data(name: &str) -> PathBuf {
    root().join("tests/data").join(name)
}

pub fn machine(name: &str) -> PathBuf {
    root().join("config/machines").join(name)
}

/// A shipped machine file's text, its tool table named by absolute path, so the text can be
/// edited and written anywhere.
pub fn machine_text(name: &str) -> String {
    let text = std::fs::read_to_string(machine(name)).expect("a shipped machine file");
    let table = machine("mill.tbl");
    text.replace(
        "tool_table = \"mill.tbl\"",
        &format!("tool_table = {:?}", table.to_str().unwrap()),
    )
}

/// The CAM-post programs of `tests/data/posts` (see its README), with their machine,
/// `machine.toml`, and tool table, `tool.tbl`.
pub const POSTS: [&str; 5] = [
    "fusion-fanuc-3axis.nc",
    "mastercam-fanuc-3axis.nc",
    "nx-5axis-g43-4.nc",
    "hypermill-5axis-g93.nc",
    "powermill-3axis-incremental.nc",
];

/// A file of `tests/data/posts`.
pub fn posts(name: &str) -> PathBuf {
    root().join("tests/data/posts").join(name)
}

/// The posts' tool table, as `--tools` loads it.
pub fn posts_shop() -> dnurbs_tools::shop::ShopOptions {
    dnurbs_tools::shop::ShopArgs {
        tools: Some(posts("tool.tbl")),
        ..dnurbs_tools::shop::ShopArgs::default()
    }
    .load()
    .expect("the tool table")
}

/// The posts' machine as the planner and as the parser see it (its tool table loaded).
pub fn posts_machine() -> (dnurbs_tools::setup::MachineSetup, nc_lang::Setup) {
    let m = config::load(&posts("machine.toml")).expect("the posts machine");
    let parse = dnurbs_tools::shop::parse_setup(&m, &posts_shop()).expect("the parse setup");
    (dnurbs_tools::setup::MachineSetup::new(&m), parse)
}

/// Run `dnurbs` with the given arguments.
pub fn dnurbs(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("dnurbs runs")
}

/// A fresh path in the system temp directory.
pub fn temp(name: &str) -> PathBuf {
    static N: AtomicU32 = AtomicU32::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("dnurbs-test-{}-{n}-{name}", std::process::id()))
}

/// One row of a `--trace` CSV.
#[derive(Debug, Clone)]
pub struct Row {
    pub cycle: u64,
    pub t: f64,
    pub block: u32,
    pub u: Option<f64>,
    pub p: [f64; 3],
    pub tool: [f64; 3],
    pub feed: f64,
    pub axes: [f64; 5],
}

pub const TRACE_HEADER: &str = "cycle,t,block,u,x,y,z,i,j,k,feed,X,Y,Z,A,C";

pub fn read_trace(path: &std::path::Path) -> Vec<Row> {
    let text = std::fs::read_to_string(path).expect("trace written");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(TRACE_HEADER));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 16, "row {l}");
            let x = |i: usize| {
                f[i].parse::<f64>()
                    .unwrap_or_else(|_| panic!("field {i} of {l}"))
            };
            Row {
                cycle: f[0].parse().unwrap(),
                t: x(1),
                block: f[2].parse().unwrap(),
                u: (!f[3].is_empty()).then(|| x(3)),
                p: [x(4), x(5), x(6)],
                tool: [x(7), x(8), x(9)],
                feed: x(10),
                axes: [x(11), x(12), x(13), x(14), x(15)],
            }
        })
        .collect()
}

/// Run `simulate` with `--json` and a trace, which must exit 0; returns the summary and
/// the rows.
pub fn simulate(
    program: &str,
    machine_file: &str,
    extra: &[&str],
) -> (serde_json::Value, Vec<Row>) {
    let (out, summary, rows) = simulate_output(program, machine_file, extra);
    assert!(
        out.status.success(),
        "dnurbs simulate {program} {machine_file} {extra:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    (summary, rows)
}

/// [`simulate`], whatever its exit: the process's output, the summary and the rows.
pub fn simulate_output(
    program: &str,
    machine_file: &str,
    extra: &[&str],
) -> (std::process::Output, serde_json::Value, Vec<Row>) {
    let trace = temp(&format!("trace-{}.csv", std::process::id()));
    let prog = data(program);
    let mach = machine(machine_file);
    let mut args = vec![
        "simulate",
        prog.to_str().unwrap(),
        "--machine",
        mach.to_str().unwrap(),
        "--json",
        "--trace",
        trace.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = dnurbs(&args);
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "dnurbs {args:?}: no JSON summary ({e}): {}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let rows = read_trace(&trace);
    let _ = std::fs::remove_file(&trace);
    (out, summary, rows)
}

/// Cox-de Boor recursion (paper eq. 4), closed on the right at the end of the knot range.
pub fn basis(i: usize, p: usize, u: f64, k: &[f64]) -> f64 {
    if p == 0 {
        let last = k[k.len() - 1];
        let inside = (k[i] <= u && u < k[i + 1]) || (u >= last && k[i] < last && k[i + 1] == last);
        return if inside { 1.0 } else { 0.0 };
    }
    let mut v = 0.0;
    if k[i + p] > k[i] {
        v += (u - k[i]) / (k[i + p] - k[i]) * basis(i, p - 1, u, k);
    }
    if k[i + p + 1] > k[i + 1] {
        v += (k[i + p + 1] - u) / (k[i + p + 1] - k[i + 1]) * basis(i + 1, p - 1, u, k);
    }
    v
}

/// Rational curve point (paper eq. 2).
pub fn nurbs_point(p: usize, ctrl: &[[f64; 3]], w: &[f64], k: &[f64], u: f64) -> [f64; 3] {
    let mut num = [0.0; 3];
    let mut den = 0.0;
    for (i, c) in ctrl.iter().enumerate() {
        let b = basis(i, p, u, k) * w[i];
        den += b;
        for a in 0..3 {
            num[a] += b * c[a];
        }
    }
    [num[0] / den, num[1] / den, num[2] / den]
}

/// The paper's block (docs/paper.md): degree, C net, CT net, knots.
pub const PAPER_C: [[f64; 3]; 5] = [
    [47.7773, 71.0202, 58.8006],
    [44.3229, 75.6066, 54.4778],
    [37.2164, 84.6443, 44.5755],
    [28.7567, 101.5653, 29.7151],
    [-1.6963, 163.6796, 5.8369],
];
pub const PAPER_T: [[f64; 3]; 5] = [
    [47.8066, 71.9791, 59.0828],
    [44.3651, 76.5494, 54.8138],
    [37.2554, 85.5421, 45.0342],
    [28.7081, 102.3535, 30.3361],
    [-1.8572, 163.9906, 6.7762],
];
pub const PAPER_K: [f64; 9] = [0.0, 0.0, 0.0, 0.0, 0.5046, 1.0, 1.0, 1.0, 1.0];

pub fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

pub fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

/// paper-ac-table.toml: X Y Z, A, C velocity / acceleration / jerk (mm or degrees, s), and
/// its period.
pub const PAPER_LIMITS: [(f64, f64, f64); 5] = [
    (250.0, 2500.0, 50000.0),
    (250.0, 2500.0, 50000.0),
    (250.0, 2500.0, 50000.0),
    (90.0, 900.0, 20000.0),
    (180.0, 1800.0, 40000.0),
];
pub const PAPER_PERIOD: f64 = 0.002;

/// Largest velocity and acceleration of each axis over a trace of the paper machine, as
/// fractions of its limits, by finite differences at the period over the trace padded with
/// the rest before and after.
pub fn fractions(rows: &[Row]) -> [(f64, f64); 5] {
    let mut q: Vec<[f64; 5]> = vec![rows[0].axes; 2];
    q.extend(rows.iter().map(|r| r.axes));
    q.extend([rows[rows.len() - 1].axes; 2]);
    let ts = PAPER_PERIOD;
    let mut out = [(0.0f64, 0.0f64); 5];
    for w in q.windows(3) {
        for j in 0..5 {
            let v = (w[2][j] - w[1][j]).abs() / ts;
            let a = (w[2][j] - 2.0 * w[1][j] + w[0][j]).abs() / (ts * ts);
            out[j].0 = out[j].0.max(v / PAPER_LIMITS[j].0);
            out[j].1 = out[j].1.max(a / PAPER_LIMITS[j].1);
        }
    }
    out
}

/// The overruns a run's summary reports (its `overruns: N ...` line), if it has one.
pub fn overruns(stdout: &str) -> Option<u64> {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix("overruns: "))
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
}

/// A run that completed: exit 0 without overruns, exit 5 with them (a loaded machine may
/// miss deadlines, and says so); anything else fails the test. Returns the overruns.
#[track_caller]
pub fn assert_completed(out: &Output) -> u64 {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let overruns =
        overruns(&stdout).unwrap_or_else(|| panic!("no overruns line:\n{stdout}\n{stderr}"));
    match out.status.code() {
        Some(0) => assert_eq!(overruns, 0, "exit 0 with overruns:\n{stdout}"),
        Some(5) => assert!(overruns > 0, "exit 5 without overruns:\n{stdout}"),
        c => panic!("exit {c:?}:\n{stdout}\n{stderr}"),
    }
    overruns
}

/// Simulated nodes for every bus of `machine` (its axes' drives, spindle drive and coolant
/// I/O module, as `dnurbs sim-drives` plays them), each bus on an in-memory link, with
/// `faults(node)`, at SCHED_FIFO 79 where the privileges allow (as in `dnurbs demo`, so a
/// loaded machine cannot starve them). Returns the master's ends of the links, bus by bus.
pub fn sim_drives(
    machine: &config::Machine,
    faults: impl Fn(u8) -> drives::sim::Faults,
) -> (Vec<drives::link::MemLink>, Sims) {
    let mut links = Vec::new();
    let mut sims = Vec::new();
    for bus in 0..machine.buses.len() {
        let (master_end, drive_end) = drives::link::MemLink::pair(1024);
        let mut nodes = dnurbs_tools::simdrives::sim_nodes(machine, bus, 0.0, &Default::default());
        for n in nodes.iter_mut() {
            n.faults = faults(n.node.get());
        }
        let sim = drives::sim::SimThread::start_with(
            drive_end,
            nodes,
            machine.period_s,
            std::time::Duration::from_micros(200),
            || {
                let _ = rt_loop::os::set_fifo(79);
            },
        )
        .expect("simulated drives");
        links.push(master_end);
        sims.push(sim);
    }
    (links, Sims(sims))
}

/// The simulated buses of [`sim_drives`].
pub struct Sims(Vec<drives::sim::SimThread>);

impl Sims {
    /// Stops every bus; what every node recorded, bus by bus.
    pub fn finish(self) -> Vec<drives::sim::Record> {
        self.0.into_iter().flat_map(|s| s.finish()).collect()
    }
}

/// [`sim_drives`] on a virtual clock: per bus, the master's end of an in-memory link and
/// the drives on the other, stepped in turn with the loop (`dnurbs_tools::run::simulated`).
pub fn simulated_buses(
    machine: &config::Machine,
    faults: impl Fn(u8) -> drives::sim::Faults,
) -> Vec<(
    drives::link::MemLink,
    drives::sim::Lockstep<drives::link::MemLink>,
)> {
    (0..machine.buses.len())
        .map(|bus| {
            let (master_end, drive_end) = drives::link::MemLink::pair(1024);
            let mut nodes =
                dnurbs_tools::simdrives::sim_nodes(machine, bus, 0.0, &Default::default());
            for n in nodes.iter_mut() {
                n.faults = faults(n.node.get());
            }
            let sim = drives::sim::Lockstep::new(drive_end, nodes, machine.period_s);
            (master_end, sim)
        })
        .collect()
}

/// Run `src` on `machine`'s drives simulated with `faults(node)`, on simulated time;
/// `operator` acts once a period on what the loop published. The result and every target
/// the drives took.
pub fn run_simulated(
    src: &[u8],
    machine: &config::Machine,
    faults: impl Fn(u8) -> drives::sim::Faults,
    opts: &dnurbs_tools::run::RunOptions,
    operator: impl FnMut(
        &rt_loop::pipeline::Progress,
        &mut rt_loop::control::Producer<'_, rt_loop::control::Command>,
    ),
) -> (dnurbs_tools::run::RunResult, Vec<drives::sim::Record>) {
    dnurbs_tools::run::simulated::run_simulated(
        dnurbs_tools::feed::Input::Text(src.into()),
        machine,
        simulated_buses(machine, faults),
        opts,
        operator,
    )
    .expect("the run starts")
}

/// The operator of a simulated run who resumes every operator stop (`M00`, `M01`, `M06`)
/// the path waits at, noting its line.
pub fn resume_every_stop(
    resumed: &mut Vec<u32>,
) -> impl FnMut(
    &rt_loop::pipeline::Progress,
    &mut rt_loop::control::Producer<'_, rt_loop::control::Command>,
) + '_ {
    let mut at = None;
    move |p, tx| {
        let now = p.snapshot().awaiting;
        if now.is_some() && now != at {
            resumed.extend(now);
            let _ = tx.enqueue(rt_loop::control::Command::Resume);
        }
        at = now;
    }
}

/// Run options of the tests: approach, the controller at SCHED_FIFO 80 where allowed, no
/// report, no progress line.
pub fn run_options(name: &str, control: Option<PathBuf>) -> dnurbs_tools::run::RunOptions {
    dnurbs_tools::run::RunOptions {
        name: name.into(),
        approach: true,
        rt: rt_loop::thread::RtSettings {
            priority: Some(80),
            cpu: None,
            idle_poll: false,
        },
        lead_ns: 0,
        rt_fallback: true,
        report: None,
        progress: false,
        control,
        shop: Default::default(),
        trace: None,
    }
}

/// The first spindle speed a program starts (`M03`/`M04` with a speed above 0), rpm.
pub fn first_spindle_rpm(prog: &nc_geom::program::Program) -> Option<f64> {
    prog.actions.iter().find_map(|a| match a.kind {
        nc_geom::program::ActionKind::Spindle { rpm, .. } if rpm > 0.0 => Some(rpm),
        _ => None,
    })
}

/// Every `axis ... target T actual A ...` line `dnurbs run` printed has |T - A| <= 1 count.
pub fn assert_axes_settled(stdout: &str) {
    for line in stdout.lines().filter(|l| l.starts_with("axis ")) {
        let n: Vec<i64> = line
            .split_whitespace()
            .filter_map(|w| w.trim_end_matches(':').parse().ok())
            .collect();
        assert!((n[2] - n[3]).abs() <= 1, "{line}");
    }
}

/// A child process (a `dnurbs sim-drives` on a CAN interface) killed when the guard drops,
/// also when a test panics: a process left on the bus answers the next test's SDOs too.
pub struct KillOnDrop(pub std::process::Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Boot-up messages on a CAN interface, watched from before a `dnurbs sim-drives` process
/// starts: once one arrives the process is up and listening (its nodes announce themselves
/// at power-on). A fixed sleep instead was outlasted in CI by a loaded guest under software
/// emulation, whose simulated drives then missed the master's NMT reset.
pub struct BootWatch(drives::link::SocketLink);

impl BootWatch {
    pub fn open(iface: &str) -> BootWatch {
        BootWatch(drives::link::SocketLink::open(iface).expect("open the CAN interface"))
    }

    /// Wait for a boot-up message (0x701..=0x77F, data 0x00), up to `timeout`.
    pub fn wait(mut self, timeout: std::time::Duration) {
        use drives::link::CanLink;
        let t0 = std::time::Instant::now();
        while t0.elapsed() < timeout {
            match self.0.recv() {
                Ok(Some(f)) if (0x701..=0x77f).contains(&f.id()) && f.data() == [0] => return,
                Ok(_) => std::thread::sleep(std::time::Duration::from_millis(5)),
                Err(e) => panic!("watching for boot-up: {e}"),
            }
        }
        panic!("no boot-up message within {timeout:?} of starting dnurbs sim-drives");
    }
}

/// The targets the drives of `m` received, SYNC by SYNC, in drive order, from the records of
/// every node (`per_node[node]`, in order).
pub fn drive_targets(m: &config::Machine, per_node: &[Vec<drives::sim::Record>]) -> Vec<Vec<i32>> {
    let n = m
        .drives
        .iter()
        .map(|d| per_node[usize::from(d.node)].len())
        .min()
        .unwrap_or(0);
    (0..n)
        .map(|k| {
            m.drives
                .iter()
                .map(|d| per_node[usize::from(d.node)][k].target_counts)
                .collect()
        })
        .collect()
}

/// Velocity and acceleration of every axis by finite differences of the targets at the
/// period, in counts, against its limits (quantization: 1 and 2 counts).
pub fn within_the_limits_at_the_period(
    name: &str,
    m: &config::Machine,
    limits: &[config::AxisLimits; 5],
    axes: &[Vec<i32>],
) {
    for (j, d) in m.drives.iter().enumerate() {
        let t: Vec<f64> = axes.iter().map(|a| f64::from(a[j])).collect();
        let lim = &limits[d.axis];
        let vlim = lim.velocity * d.counts_per_unit * m.period_s;
        let alim = lim.acceleration * d.counts_per_unit * m.period_s * m.period_s;
        let v = t
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        let a = t
            .windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
            .fold(0.0, f64::max);
        assert!(
            v <= vlim * (1.0 + 1e-6) + 1.0,
            "{name}: node {} stepped {v} counts in a period, limit {vlim}",
            d.node
        );
        assert!(
            a <= alim * (1.0 + 1e-6) + 2.0,
            "{name}: node {} changed its step by {a} counts, limit {alim}",
            d.node
        );
    }
}

/// A number of a `--json` summary.
pub fn f(v: &serde_json::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("summary has no number {key}: {v}"))
}

/// A `--json` summary's axes within their limits, travel and chord error included.
pub fn assert_within_limits(s: &serde_json::Value) {
    for key in [
        "axis_velocity_fraction",
        "axis_acceleration_fraction",
        "axis_jerk_fraction",
    ] {
        let m = s[key]
            .as_object()
            .unwrap_or_else(|| panic!("{key} missing"));
        assert_eq!(m.len(), 5, "{key}: {m:?}");
        for (axis, frac) in m {
            let frac = frac.as_f64().unwrap();
            assert!(frac <= 1.0 + 1e-6, "{key} {axis} = {frac}");
        }
    }
    assert_eq!(s["axis_travel_ok"], true);
    assert_eq!(
        s["limits_exceeded"].as_array().map(Vec::len),
        Some(0),
        "limits_exceeded: {}",
        s["limits_exceeded"]
    );
    assert!(
        f(s, "chord_error_max_mm") <= f(s, "chord_tolerance_mm"),
        "{s}"
    );
}

/// Home tables for the paper machine's axes, one of each method the simulated drives offer:
/// X on a switch, Y on a switch and the index pulse together with it, Z where it stands,
/// A absolute, C on a switch, in three sequence groups (`dnurbs serve`'s tests).
pub const SERVE_HOMES: &str = r#"
[axes.x.home]
method = "switch"
direction = "negative"
position = -5.0

[axes.y.home]
method = "switch-index"
direction = "positive"
position = 4.0

[axes.z.home]
method = "current"
position = 2.5
sequence = 1

[axes.a.home]
method = "absolute"

[axes.c.home]
method = "switch"
direction = "positive"
position = 3.0
sequence = 2
"#;
