//! Programs as CAM post-processors write them (`tests/data/posts`, see its README): each is
//! accepted unchanged, plans within every limit of the machine, and reports its spindle,
//! coolant and tool words. All five run against simulated CiA-402 drives, spindle drive and
//! coolant I/O module on the in-memory link (the code path of `dnurbs run`, on simulated
//! time); an operator resumes their tool-change stops, and what
//! the nodes received is checked: the axes' targets follow the path `dnurbs simulate`
//! interpolates to the drives' rounding, within the velocity and acceleration limits by
//! finite differences at the period, ending at the program's end; the spindle drive at its
//! speed before the first feed move leaves; the spindle speeds and coolant valves in the
//! order the program commands them, on during the cut and off at the end. The NX post runs
//! once more with on-line compression on (`run --compress`), under the same checks.

mod common;
use common::{posts, POSTS};

use dnurbs_tools::run::RunOptions;
use dnurbs_tools::setup::MachineSetup;
use dnurbs_tools::shop::{parse_setup, ShopArgs};

fn machine() -> config::Machine {
    config::load(&posts("machine.toml")).expect("the posts machine")
}

fn shop() -> dnurbs_tools::shop::ShopOptions {
    common::posts_shop()
}

#[test]
fn every_post_plans_within_the_machine_limits() {
    let m = machine();
    let parse = parse_setup(&m, &shop()).unwrap();
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

/// `dnurbs fit` streams the program (`nc_fit::rewrite`): on every post it writes what the
/// whole-text fit writes, byte for byte, and its own check finds the result within the
/// tolerances.
#[test]
fn every_post_is_fitted_as_the_whole_text_fit_fits_it() {
    let m = machine();
    let mut parse = parse_setup(&m, &shop()).unwrap();
    parse.work_offsets = [Some([0.0; 3]); 6];
    let setup = MachineSetup::new(&m);
    let opts = nc_fit::options::Options::default();
    let mut fitted = 0;
    for name in POSTS {
        let src = std::fs::read_to_string(posts(name)).expect("the post");
        let prog = nc_lang::parse_with(&src, &parse).unwrap_or_else(|e| panic!("{name}: {e:?}"));
        let whole = nc_fit::runs::fit_program(&src, &prog, &setup.kin, &opts);
        let mut out = Vec::new();
        let done = nc_fit::rewrite::rewrite(
            src.as_bytes(),
            &parse,
            &setup.kin,
            &setup.build,
            &opts,
            0.002,
            &mut out,
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(String::from_utf8(out).unwrap(), whole.text, "{name}");
        assert_eq!(done.summary, whole.summary, "{name}");
        assert!(
            done.dev.point_mm <= opts.tol.mm + 5e-7,
            "{name}: {:?}",
            done.dev
        );
        assert!(done.dev.point_deg <= 0.01 * 1.001, "{name}: {:?}", done.dev);
        fitted += done.summary.fitted_blocks;
    }
    assert!(fitted >= 1, "no post had a run fitted");
}

/// What each simulated node recorded, per SYNC, indexed by node id.
type PerNode = Vec<Vec<drives::sim::Record>>;

/// Runs `name` on simulated drives on simulated time; the operator resumes every stop.
/// Returns the lines it resumed at, the run's report and the records of every node (per
/// node, in order).
fn run_post(
    name: &str,
    m: &config::Machine,
    compress: Option<bool>,
) -> (Vec<u32>, dnurbs_tools::report::Report, PerNode) {
    let opts = RunOptions {
        shop: dnurbs_tools::shop::ShopOptions { compress, ..shop() },
        ..common::run_options(name, None)
    };
    let src = std::fs::read(posts(name)).unwrap();
    let mut resumed = Vec::new();
    let (r, records) = common::run_simulated(
        &src,
        m,
        |_| Default::default(),
        &opts,
        common::resume_every_stop(&mut resumed),
    );
    let mut per_node = vec![Vec::new(); 8];
    for rec in records {
        per_node[usize::from(rec.node)].push(rec);
    }
    (resumed, r.report(name, &m.name), per_node)
}

#[test]
fn every_post_runs_on_simulated_drives_as_simulated_with_the_spindle_and_coolant_it_commands() {
    let m = slow_spindle_machine();
    // The five run at once, each on simulated time; every failure is reported, post by post.
    // `DNURBS_POSTS=nx` runs only the posts whose file name starts with it.
    let only = std::env::var("DNURBS_POSTS").unwrap_or_default();
    let runs: Vec<_> = POSTS
        .into_iter()
        .filter(|n| n.starts_with(&only))
        .map(|name| {
            let m = m.clone();
            std::thread::Builder::new()
                .name(name.into())
                .spawn(move || {
                    check_run(name, &m, None);
                })
                .unwrap()
        })
        .collect();
    let failed: Vec<String> = runs
        .into_iter()
        .filter_map(|h| h.join().err().map(|e| panic_text(&*e)))
        .collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// The posts' machine with a spindle slower to reach its speed (6 s to 12000 rpm) than the
/// rapid moves between M03 and the first feed move take: the move must wait for it.
fn slow_spindle_machine() -> config::Machine {
    let mut m = machine();
    if let Some(s) = m.spindle.as_mut() {
        s.acceleration_rpm_s = 2000.0;
        s.at_speed_timeout_s = 20.0;
    }
    m
}

/// The message of a check that panicked (each names its post).
fn panic_text(e: &(dyn std::any::Any + Send)) -> String {
    e.downcast_ref::<String>()
        .cloned()
        .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_default()
}

/// One post on simulated drives: the operator resumes every stop, the axes' targets are the
/// offline interpolation's setpoints, within the velocity and acceleration limits, and the
/// spindle and coolant follow the program.
fn check_run(
    name: &str,
    m: &config::Machine,
    compress: Option<bool>,
) -> dnurbs_tools::report::Report {
    let setup = MachineSetup::new(m).with_compress(compress);
    let parse = parse_setup(m, &shop()).unwrap();
    let prog = dnurbs_tools::load_program(&posts(name), &parse).unwrap();
    // The program the planner plans, compressed where compression is on.
    let prog = setup.prepare(prog).0;
    let stops: Vec<u32> = prog
        .blocks
        .iter()
        .filter_map(|b| match b {
            nc_geom::program::Block::Linear(l) => l.tooling.wait.operator,
            nc_geom::program::Block::Nurbs(n) => n.tooling.wait.operator,
        })
        .map(|p| p.line)
        .collect();
    let (resumed, rep, records) = run_post(name, m, compress);
    assert!(
        rep.exit_code == 0 || rep.exit_code == 5,
        "{name}: {}",
        rep.text()
    );
    // The first block's wait (a tool change before the first move) is not a stop.
    let expected: Vec<u32> = match prog.blocks.first() {
        Some(nc_geom::program::Block::Linear(l)) if l.tooling.wait.operator.is_some() => {
            stops[1..].to_vec()
        }
        _ => stops,
    };
    assert_eq!(resumed, expected, "{name}: {}", rep.text());
    for d in &rep.drives {
        assert_eq!(Some(d.target_counts), d.program_end_counts, "{name}: {d:?}");
    }
    let axes = common::drive_targets(m, &records);
    common::within_the_limits_at_the_period(name, m, &setup.limits, &axes);
    the_offline_interpolation(name, m, &setup, &prog, &axes);
    let leave = spindle_at_speed_before_the_first_feed_move(name, m, &prog, &records);
    coolant_on_for_the_cut_and_off_at_the_end(name, m, &prog, &records, leave);
    spindle_and_coolant_as_programmed(name, m, &prog, &records);
    rep
}

/// `run --compress` end to end: the NX post's swarf pass (63 G01 moves with A and C) and the
/// hyperMILL post's pass in inverse time (`G93`, 62 moves) each run fitted into a G06.5
/// block, and every check of the posts holds on what the drives received: the targets
/// follow the compressed path `simulate --compress` interpolates, within the limits at the
/// period, to the program's end; spindle, coolant and the operator stops as programmed. The
/// report says what compression did.
#[test]
fn the_nx_and_g93_posts_run_compressed_as_simulate_compresses_them() {
    let m = slow_spindle_machine();
    for (name, moves_in) in [("nx-5axis-g43-4.nc", 63), ("hypermill-5axis-g93.nc", 62)] {
        let rep = check_run(name, &m, Some(true));
        let c = rep
            .compressed
            .expect("the report says what compression did");
        assert_eq!(
            (c.moves_in, c.moves_fitted, c.fitted_blocks),
            (moves_in, 60, 1),
            "{name}: {c:?}"
        );
        let line = format!("compressed         60 of {moves_in} G01 moves into 1 G06.5 blocks");
        assert!(rep.text().contains(&line), "{name}: {}", rep.text());
    }
    // Off, the report has no such line.
    let plain = check_run("nx-5axis-g43-4.nc", &m, Some(false));
    assert!(plain.compressed.is_none());
}

/// The path the drives received is the path `dnurbs simulate` interpolates (whose chord
/// error and limits the planner proves), from the program's start to its end: after the
/// approach move, every target lies within [`ROUNDING`] counts (the drives' rounding of five
/// axes) of the polyline of the setpoints simulated at a quarter of the period with every block's start inserted, in
/// drive counts, and the targets pass along all of it in order.
fn the_offline_interpolation(
    name: &str,
    m: &config::Machine,
    setup: &MachineSetup,
    prog: &nc_geom::program::Program,
    axes: &[Vec<i32>],
) {
    // Sampled at a quarter of the period: the same path, its polyline 16 times closer to
    // the curve the joints trace (what the drives received lies on that curve).
    let mut fine = setup.clone();
    fine.period /= FINER;
    fine.plan.period /= FINER;
    let sim = dnurbs_tools::simulate::run(prog, &fine, setup.method).unwrap();
    let counts = |j: &nc_geom::kinematics::Joints| -> Vec5 {
        Vec5::from_iterator(m.drives.iter().map(|d| {
            let v = if d.axis >= 3 {
                j[d.axis].to_degrees()
            } else {
                j[d.axis]
            };
            v * d.counts_per_unit * f64::from(d.sign) + f64::from(d.offset)
        }))
    };
    // The samples cut across a corner, the path does not: the start of every block the path
    // entered since the last setpoint goes in before it, in order (inside a block the
    // path is tangent-continuous, or comes to rest where it is not).
    let segs = &sim.path.segments;
    let mut path: Vec<Vec5> = Vec::new();
    let mut next = 0;
    for sp in &sim.setpoints {
        while next < segs.len() && segs[next].block <= sp.block {
            if next == 0 || segs[next - 1].block != segs[next].block {
                let start = segs[next].pose(0.0);
                let j = start.joints(&setup.kin, &sp.joints, &setup.plan.rotary);
                path.push(counts(&j));
            }
            next += 1;
        }
        path.push(counts(&sp.joints));
    }
    path.dedup();
    let mut got = axes.to_vec();
    got.dedup();
    let first = joint_counts(m, &sim.setpoints[0].joints);
    let close = |a: &[i32]| a.iter().zip(&first).all(|(x, y)| (x - y).abs() <= 1);
    // The approach move ends at the program's start: the last target within a count of it
    // before the path leaves.
    let start = (0..got.len().saturating_sub(1))
        .find(|&k| close(&got[k]) && !close(&got[k + 1]))
        .unwrap_or_else(|| panic!("{name}: never at the program's start {first:?}"));
    // A target is one period's travel along the path on from the last. That travel is at
    // most the last period's plus what the axes' accelerations add in a period (the speed
    // along the path is continuous, also through a corner, where the axes' velocities jump),
    // and at most twice the chord from the last target on a curve (an arc of up to 180
    // degrees is at most pi/2 times its chord); plus rounding. Through a sharp corner the
    // path is many times the chord: there only the first bound holds.
    let gain: f64 = m
        .drives
        .iter()
        .map(|d| setup.limits[d.axis].acceleration * d.counts_per_unit * m.period_s * m.period_s)
        .sum();
    let along: Vec<f64> = std::iter::once(0.0)
        .chain(path.windows(2).scan(0.0, |s, w| {
            *s += (w[1] - w[0]).norm();
            Some(*s)
        }))
        .collect();
    let mut at = 0;
    let mut worst = 0.0f64;
    let mut prev = Vec5::from_iterator(got[start].iter().map(|&x| f64::from(x)));
    let (mut pos, mut step) = (0.0, 0.0);
    for (i, c) in got[start..].iter().enumerate() {
        let q = Vec5::from_iterator(c.iter().map(|&x| f64::from(x)));
        let ahead = (2.0 * (q - prev).norm()).max(step + gain) + 4.0 * ROUNDING;
        // The window is walked from the start of the last match's segment.
        let (k, s, d) = nearest(&path, at, &q, ahead + pos - along[at]);
        let here = along[k] + s * (along[(k + 1).min(path.len() - 1)] - along[k]);
        (prev, at, step, pos) = (q, k, here - pos, here);
        worst = worst.max(d);
        assert!(
            d <= ROUNDING,
            "{name}: target {i} {c:?} is {d:.2} counts from the simulated path near {:?}",
            path[k].as_slice()
        );
    }
    // They followed it to its end: what is left after the last match is within rounding.
    let left: f64 = path[at..].windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    assert!(
        left <= ROUNDING,
        "{name}: the targets followed the simulated path to point {at} of {}, {left:.1} counts short",
        path.len()
    );
    eprintln!(
        "{name}: {} targets on the simulated path, at most {worst:.3} counts off",
        got.len() - start
    );
}

type Vec5 = nalgebra::SVector<f64, 5>;

/// How many times finer than the period the reference path is sampled.
const FINER: f64 = 4.0;

/// Half a count on each of five drives, Euclidean: how far rounding moves a target.
const ROUNDING: f64 = 1.118_034;

/// The segment of the polyline `pts` nearest to `q`, searched from segment `from` on, at
/// most `ahead` counts of path further: its index, the nearest point's fraction of it and
/// the distance.
fn nearest(pts: &[Vec5], from: usize, q: &Vec5, ahead: f64) -> (usize, f64, f64) {
    let last = pts.len() - 1;
    let mut best = (from, 0.0, f64::INFINITY);
    let mut walked = 0.0;
    for k in from..last.max(from + 1) {
        let (a, b) = (pts[k], pts[(k + 1).min(last)]);
        let ab = b - a;
        let s = if ab.norm_squared() > 0.0 {
            ((q - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = (a + ab * s - q).norm();
        if d < best.2 {
            best = (k, s, d);
        }
        walked += ab.norm();
        if walked > ahead {
            break;
        }
    }
    best
}

/// Drive counts of a setpoint's joints, in drive order.
fn joint_counts(m: &config::Machine, j: &nc_geom::kinematics::Joints) -> Vec<i32> {
    m.drives
        .iter()
        .map(|d| {
            let v = if d.axis >= 3 {
                j[d.axis].to_degrees()
            } else {
                j[d.axis]
            };
            d.counts(v).unwrap()
        })
        .collect()
}

/// The spindle drive's targets and the module's outputs, consecutive repeats removed, are
/// the program's spindle speeds and valves in the order it commands them, ending off.
fn spindle_and_coolant_as_programmed(
    name: &str,
    m: &config::Machine,
    prog: &nc_geom::program::Program,
    records: &PerNode,
) {
    let (spindle, coolant) = (m.spindle.as_ref().unwrap(), m.coolant.as_ref().unwrap());
    let mut aux = nc_geom::program::Aux::default();
    let (mut speeds, mut valves) = (vec![0], vec![0]);
    for b in 0..prog.blocks.len() {
        for a in prog.actions.iter().filter(|a| a.before_block == b) {
            aux.apply(&a.kind);
        }
        speeds.push(spindle.velocity(aux.spindle_rpm));
        valves.push(i32::from(coolant.outputs(aux.mist, aux.flood)));
    }
    speeds.push(0);
    valves.push(0);
    speeds.dedup();
    valves.dedup();
    let sent = |node: u8| {
        let mut v: Vec<i32> = records[usize::from(node)]
            .iter()
            .map(|r| r.target_counts)
            .collect();
        v.dedup();
        v
    };
    assert_eq!(
        sent(spindle.at.expect("the spindle on a bus").node),
        speeds,
        "{name}: spindle targets"
    );
    assert_eq!(
        sent(coolant.at.expect("the coolant module on a bus").node),
        valves,
        "{name}: coolant outputs"
    );
}

/// The axes' targets (counts, in node order) where the program's first feed move starts,
/// from the offline interpolation of the program (the path comes to rest there).
fn first_feed_start(m: &config::Machine, prog: &nc_geom::program::Program) -> Vec<i32> {
    let setup = MachineSetup::new(m);
    let sim = dnurbs_tools::simulate::run(prog, &setup, setup.method).unwrap();
    let seg = sim.path.segments.iter().find(|s| s.wait.spindle).unwrap();
    let first = sim
        .setpoints
        .iter()
        .position(|sp| sp.block == seg.block)
        .unwrap();
    joint_counts(m, &sim.setpoints[first - 1].joints)
}

/// The drives received the first feed move only once the spindle drive reported the
/// programmed speed: the axes stand at the move's start while it ramps up, and leave when
/// its velocity is within the window of the command and its target-reached bit is set.
/// Returns the index of the SYNC where the move leaves.
fn spindle_at_speed_before_the_first_feed_move(
    name: &str,
    m: &config::Machine,
    prog: &nc_geom::program::Program,
    records: &PerNode,
) -> usize {
    let spindle = m.spindle.as_ref().unwrap();
    let rpm = common::first_spindle_rpm(prog).unwrap();
    let at = first_feed_start(m, prog);
    let axis = |k: usize| -> Vec<i32> {
        m.drives
            .iter()
            .map(|d| records[usize::from(d.node)][k].target_counts)
            .collect()
    };
    let n = records[usize::from(m.drives[0].node)].len();
    // Where the axes come to rest at the move's start (the offline interpolation samples
    // the approach a period apart: within 0.01 mm), and the SYNC at which they move on.
    let near = |a: &[i32]| a.iter().zip(&at).all(|(x, y)| (x - y).abs() <= 100);
    let arrive = (0..n.saturating_sub(10))
        .find(|&k| near(&axis(k)) && (k..k + 10).all(|i| axis(i) == axis(k)))
        .unwrap_or_else(|| panic!("{name}: the axes never rest at the first feed move {at:?}"));
    let rest = axis(arrive);
    let leave = (arrive..n)
        .find(|&k| axis(k) != rest)
        .unwrap_or_else(|| panic!("{name}: the axes never leave {rest:?}"));
    // Every node records every SYNC in operational, so index k is the same SYNC for all.
    let sp = &records[usize::from(spindle.at.expect("the spindle on a bus").node)];
    assert_eq!(sp.len(), n, "{name}: spindle records");
    let before = &sp[leave - 1];
    let want = spindle.velocity(rpm);
    assert_eq!(before.target_counts, want, "{name}: spindle command");
    assert!(
        (before.actual_counts - want).unsigned_abs() <= u32::from(spindle.window_units()),
        "{name}: the first feed move left at SYNC {} with the spindle at {} of {want}",
        before.sync,
        before.actual_counts,
    );
    assert!(
        before.statusword & (1 << 10) != 0,
        "{name}: target reached not set: 0x{:04X}",
        before.statusword
    );
    // It waited there for the ramp (at least half of it: the rapids ran meanwhile).
    let ramp_periods = rpm / spindle.acceleration_rpm_s / m.period_s;
    let from = sp.iter().position(|r| r.target_counts == want).unwrap();
    assert!(
        (leave - from) as f64 >= ramp_periods,
        "{name}: left {} periods after the spindle command, ramp {ramp_periods}",
        leave - from
    );
    // At the end the spindle is stopped.
    let last = sp.last().unwrap();
    assert_eq!((last.target_counts, last.actual_counts), (0, 0), "{name}");
    leave
}

/// The coolant valves (outputs of the I/O module) are on, as M07/M08 ask, when the first
/// feed move leaves (SYNC index `leave`), and off at the end (M09).
fn coolant_on_for_the_cut_and_off_at_the_end(
    name: &str,
    m: &config::Machine,
    prog: &nc_geom::program::Program,
    records: &PerNode,
    leave: usize,
) {
    let coolant = m.coolant.as_ref().unwrap();
    let mut aux = nc_geom::program::Aux::default();
    let first_feed = prog
        .blocks
        .iter()
        .position(|b| !matches!(b, nc_geom::program::Block::Linear(l) if l.rapid))
        .unwrap();
    for a in prog.actions.iter().filter(|a| a.before_block <= first_feed) {
        aux.apply(&a.kind);
    }
    let want = coolant.outputs(aux.mist, aux.flood);
    assert_ne!(want, 0, "{name}: the post turns coolant on before cutting");
    let io = &records[usize::from(coolant.at.expect("the coolant module on a bus").node)];
    let on: Vec<usize> = (0..io.len())
        .filter(|&k| io[k].target_counts == i32::from(want))
        .collect();
    assert!(!on.is_empty(), "{name}: outputs 0x{want:02X} never set");
    assert_eq!(
        io[leave - 1].target_counts,
        i32::from(want),
        "{name}: coolant when the first feed move leaves"
    );
    // The module's inputs echo its outputs (the valves' switches): the outputs took effect.
    assert!(on.iter().any(|&k| io[k].actual_counts == i32::from(want)));
    let last = io.last().unwrap();
    assert_eq!((last.target_counts, last.actual_counts), (0, 0), "{name}");
}

#[test]
fn a_stop_for_the_operator_without_a_control_socket_is_refused_before_motion() {
    let m = machine();
    let (master_end, _drive_end) = drives::link::MemLink::pair(16);
    let opts = RunOptions {
        shop: shop(),
        ..common::run_options("nx-5axis-g43-4.nc", None)
    };
    let src = std::fs::read(posts("nx-5axis-g43-4.nc")).unwrap();
    let e = dnurbs_tools::run::run(&src, &m, move || Ok(vec![master_end]), &opts).unwrap_err();
    let msg = format!("{e:#}");
    assert!(msg.starts_with("nx-5axis-g43-4.nc:9:"), "{msg}");
    assert!(
        msg.contains("only the control socket can resume it"),
        "{msg}"
    );
}

#[test]
fn work_offsets_from_a_linuxcnc_parameter_file_move_the_program_and_errors_name_their_line() {
    let m = machine();
    let var = common::temp("linuxcnc.var");
    // G54 as LinuxCNC writes it (tabs, six decimals), among parameters dnurbs ignores.
    std::fs::write(
        &var,
        "5161\t0.000000\n5220\t1.000000\n5221\t10.000000\n5222\t-20.000000\n5223\t5.000000\n\
         5224\t0.000000\n5230\t0.000000\n5241\t0.000000\n5242\t0.000000\n5243\t0.000000\n",
    )
    .unwrap();
    let with = ShopArgs {
        tools: Some(posts("tool.tbl")),
        offsets: Some(var.clone()),
        ..ShopArgs::default()
    }
    .load()
    .unwrap();
    let end = |b: &nc_geom::program::Block| match b {
        nc_geom::program::Block::Linear(l) => l.end,
        nc_geom::program::Block::Nurbs(n) => *n.ctrl.last().unwrap(),
    };
    for name in ["fusion-fanuc-3axis.nc", "mastercam-fanuc-3axis.nc"] {
        let plain =
            dnurbs_tools::load_program(&posts(name), &parse_setup(&m, &shop()).unwrap()).unwrap();
        let moved =
            dnurbs_tools::load_program(&posts(name), &parse_setup(&m, &with).unwrap()).unwrap();
        assert_eq!(plain.blocks.len(), moved.blocks.len());
        let mut shifted = 0;
        for (a, b) in plain.blocks.iter().zip(&moved.blocks) {
            let d: Vec<f64> = (0..3).map(|i| end(b)[i] - end(a)[i]).collect();
            let by_offset = d
                .iter()
                .zip([10.0, -20.0, 5.0])
                .all(|(x, o)| (x - o).abs() < 1e-9);
            // G28 / G53 move their axes in machine coordinates: the offset does not move
            // those (`G28 G91 Z0` sends Z to the reference, X and Y stay where they were).
            let each = d
                .iter()
                .zip([10.0, -20.0, 5.0])
                .all(|(x, o)| (x - o).abs() < 1e-9 || x.abs() < 1e-9);
            assert!(each, "{name}: moved by {d:?}");
            shifted += usize::from(by_offset);
        }
        assert!(
            shifted * 10 >= plain.blocks.len() * 8,
            "{name}: {shifted} moved"
        );
    }
    // A rotary offset dnurbs cannot apply: exit 2 naming the file, line and value.
    std::fs::write(&var, "5221\t1.0\n5222\t2.0\n5223\t3.0\n5226\t90.000000\n").unwrap();
    let out = common::dnurbs(&[
        "simulate",
        posts("fusion-fanuc-3axis.nc").to_str().unwrap(),
        "--machine",
        posts("machine.toml").to_str().unwrap(),
        "--offsets",
        var.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(&format!("{}:4:1:", var.display())) && stderr.contains("G54 C is 90"),
        "{stderr}"
    );
    let _ = std::fs::remove_file(&var);
}
