//! Run from a line (`nc_lang::restart`, issue 55) on the CAM-post programs of
//! `tests/data/posts` and their machine, the machine standing 50 mm under the program's
//! start: restarted from every line of each program, from the restart line on it is the
//! program itself: the same segments, built by the segment builder from both programs,
//! within 1 um and 1e-9 of the tool axis, with the spindle, coolant and outputs the whole
//! run has there (the builder's own account of them, not the restart's). Restarted from
//! four lines spread through each, every restart plans within every limit of the machine,
//! its approach included.

mod common;
use common::{posts, POSTS};

use dnurbs_tools::setup::MachineSetup;
use dnurbs_tools::shop::parse_setup;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::{Block, Program};
use nc_geom::segment::{build, Segment};
use nc_lang::restart::{from_line, RestartError, Standing};

/// The two segments are the same move: length, feed, kind, and the pose at five points.
fn same_segment(kin: &MachineKinematics, a: &Segment, b: &Segment) -> Result<(), String> {
    let close = |x: f64, y: f64, tol: f64| (x - y).abs() <= tol;
    if !(close(a.length, b.length, 1e-9) && close(a.feed, b.feed, 1e-9) && a.rapid == b.rapid) {
        return Err(format!(
            "length {} / {}, feed {} / {}, rapid {} / {}",
            a.length, b.length, a.feed, b.feed, a.rapid, b.rapid
        ));
    }
    if a.aux != b.aux {
        return Err(format!("aux {:?} / {:?}", a.aux, b.aux));
    }
    for k in 0..=4 {
        let s = a.length * f64::from(k) / 4.0;
        let (pa, pb) = (a.pose(s), b.pose(s));
        let dp = (pa.p - pb.p).norm();
        let dt = (pa.axis(kin) - pb.axis(kin)).norm();
        if dp > 1e-6 || dt > 1e-9 || !close(pa.z, pb.z, 1e-9) {
            return Err(format!(
                "at s = {s}: {dp} mm, axis {dt}, z {} / {}",
                pa.z, pb.z
            ));
        }
    }
    Ok(())
}

/// Restarts from every line of `prog` (every `stride`-th) checked against the whole
/// program, and with `plan` those from four lines spread through it planned: (restarts
/// built, planned, lines inside a NURBS block, lines in a loop or a subroutine).
fn every_line(
    name: &str,
    prog: &Program,
    setup: &MachineSetup,
    plan: bool,
    stride: usize,
) -> (usize, usize, usize, usize) {
    let kin = setup.kin;
    let (mut restarts, mut plans, mut inside_nurbs, mut looped) = (0, 0, 0, 0);
    let whole = build(prog, &kin, &setup.build).unwrap();
    // Where the program starts (some start at the top of Z's travel), 50 mm lower.
    let mut joints = whole.start_joints;
    joints[2] -= 50.0;
    let standing = Standing {
        joints,
        tool_length: whole.start.z,
    };
    let last = prog
        .blocks
        .iter()
        .flat_map(|b| match b {
            Block::Linear(l) => vec![l.pos.line],
            Block::Nurbs(n) => n
                .ctrl_pos
                .iter()
                .map(|p| p.line)
                .chain([n.pos.line])
                .collect(),
        })
        .max()
        .unwrap();
    let mut moves: Vec<u32> = prog.blocks.iter().map(|b| b.pos().line).collect();
    moves.dedup();
    // Planned where the whole program plans on the machine (helix-500 turns C past the
    // A/C mill's +-3600 degrees, and is refused there whole as well).
    let plans_whole = plan && dnurbs_tools::simulate::run(prog, setup, setup.method).is_ok();
    let planned: Vec<u32> = match plans_whole {
        true => (1..=4).map(|k| moves[moves.len() * k / 5]).collect(),
        false => Vec::new(),
    };
    // Every line of the program, with a move or not: the segment builder's account of
    // the restart from there on is the whole program's.
    for line in (1..=last).step_by(stride.max(1)) {
        let r = match from_line(prog, line, &kin, &setup.build, &standing, 5.0) {
            Ok(r) => r,
            Err(RestartError::InsideNurbs { .. }) => {
                inside_nurbs += 1;
                continue;
            }
            Err(RestartError::Repeated { .. }) => {
                looped += 1;
                continue;
            }
            Err(e) => panic!("{name}: line {line}: {e}"),
        };
        let path = build(&r.program, &kin, &setup.build)
            .unwrap_or_else(|e| panic!("{name} from line {line}: {e}"));
        // From the restart line on: the whole program's segments (`Segment::block`
        // counts from 1; the restart's program has four blocks before the line's).
        let first = r.block.max(1);
        let theirs: Vec<&Segment> = whole
            .segments
            .iter()
            .filter(|g| g.block as usize > first)
            .collect();
        let ours: Vec<&Segment> = path.segments.iter().filter(|g| g.block > 4).collect();
        assert_eq!(theirs.len(), ours.len(), "{name} from line {line}");
        for (i, (a, b)) in theirs.iter().zip(&ours).enumerate() {
            if let Err(e) = same_segment(&kin, a, b) {
                panic!(
                    "{name} from line {line}, segment {i} (line {}): {e}",
                    a.src.line
                );
            }
        }
        // The approach ends on the pose the program's own move there starts from (where
        // the moves from the line on are not all null moves, which build no segment).
        if let (Some(a), Some(b)) = (ours.first(), theirs.first()) {
            assert!(
                (a.pose(0.0).p - b.pose(0.0).p).norm() < 1e-6,
                "{name} {line}"
            );
        }
        restarts += 1;
        if !planned.contains(&line) {
            continue;
        }
        let ran = dnurbs_tools::simulate::run(&r.program, setup, setup.method)
            .unwrap_or_else(|e| panic!("{name} from line {line}: {e}"));
        let s = dnurbs_tools::simulate::summarize(&ran, setup, r.program.blocks.len());
        let s = serde_json::to_value(&s).unwrap();
        if std::panic::catch_unwind(|| common::assert_within_limits(&s)).is_err() {
            panic!("{name} from line {line}: over a limit");
        }
        plans += 1;
    }
    (restarts, plans, inside_nurbs, looped)
}

fn add(
    a: (usize, usize, usize, usize),
    b: (usize, usize, usize, usize),
) -> (usize, usize, usize, usize) {
    (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3)
}

#[test]
fn a_restart_is_the_program_from_its_line_on_and_plans_within_the_limits() {
    let (setup, parse) = common::posts_machine();
    let mut total = (0, 0, 0, 0);
    for name in POSTS {
        let prog = dnurbs_tools::load_program(&posts(name), &parse).unwrap();
        total = add(total, every_line(name, &prog, &setup, true, 1));
    }
    eprintln!("posts: {total:?} (restarts built, planned, inside a NURBS block, in a loop)");
    assert!(total.0 > 300 && total.1 == 20, "{total:?}");
}

/// The same on the published classics (`tests/data/classics`: NURBS blocks among them,
/// whose control-point lines are refused) on the A/C mill.
#[test]
fn a_restart_of_a_classic_is_the_classic_from_its_line_on() {
    let m = config::load(&common::machine("xyzac-trt-mill.toml")).unwrap();
    let parse = parse_setup(&m, &dnurbs_tools::shop::ShopOptions::default()).unwrap();
    let setup = MachineSetup::new(&m);
    let mut total = (0, 0, 0, 0);
    for name in CLASSICS {
        let prog =
            dnurbs_tools::load_program(&common::data(&format!("classics/{name}")), &parse).unwrap();
        total = add(total, every_line(name, &prog, &setup, true, 1));
    }
    eprintln!("classics: {total:?} (restarts built, planned, inside a NURBS block, in a loop)");
    // Some classics are a single block or two: fewer than four lines to plan from.
    assert!(total.2 > 500 && total.1 >= 12, "{total:?}");
}

/// The same, built but not planned, from about 40 lines of every program of the corpus
/// of real programs (`tests/corpus`, each on its machine) that dnurbs reads and builds:
/// LinuxCNC's O-word loops and subroutines among them, whose lines are refused.
#[test]
fn a_restart_of_a_real_program_is_the_program_from_its_line_on() {
    let corpus = common::root().join("tests/corpus");
    let runs = std::fs::read_to_string(corpus.join("runs.txt")).unwrap();
    let mut total = (0, 0, 0, 0);
    let mut programs = 0;
    for l in runs
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
    {
        if l.contains(" refused: ") || l.contains(" unchecked: ") {
            continue;
        }
        let mut w = l.split_whitespace();
        let (Some(name), Some(machine)) = (w.next(), w.next()) else {
            panic!("runs.txt: {l}");
        };
        let m = config::load(&common::machine(machine)).unwrap();
        let parse = parse_setup(&m, &dnurbs_tools::shop::ShopOptions::default()).unwrap();
        let setup = MachineSetup::new(&m);
        // Those LinuxCNC too stops on at an error, or that do not fit the machine, are not
        // restarted.
        let Ok(prog) = dnurbs_tools::load_program(&corpus.join("programs").join(name), &parse)
        else {
            continue;
        };
        if build(&prog, &setup.kin, &setup.build).is_err() {
            continue;
        }
        // About 40 lines of each (a restart builds the program up to its line).
        let lines = prog.blocks.last().map_or(0, |b| b.pos().line as usize);
        total = add(
            total,
            every_line(name, &prog, &setup, false, lines / 40 + 1),
        );
        programs += 1;
    }
    eprintln!("corpus: {programs} programs, {total:?} (restarts built, planned, inside a NURBS block, in a loop)");
    assert!(
        programs >= 20 && total.0 > 500 && total.3 > 0,
        "{programs} {total:?}"
    );
}

const CLASSICS: [&str; 7] = [
    "butterfly.nc",
    "dual-spline.nc",
    "fan-5axis.nc",
    "figure-eight-circles.nc",
    "figure-eight-weights.nc",
    "helix-500.nc",
    "star.nc",
];

/// `dnurbs simulate --from-line`: the summary says what the restart restored and its
/// approach; a line it cannot restart from, a clearance out of range and a clearance
/// without a line are refused with exit 2 and the reason.
#[test]
fn simulate_from_a_line_reports_the_restart_and_refuses_what_it_cannot() {
    let (program, machine, tools) = (
        posts("fusion-fanuc-3axis.nc"),
        posts("machine.toml"),
        posts("tool.tbl"),
    );
    let args = |extra: &[&str]| {
        let mut a = vec![
            "simulate".to_owned(),
            program.display().to_string(),
            "--machine".into(),
            machine.display().to_string(),
            "--tools".into(),
            tools.display().to_string(),
        ];
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let run = |extra: &[&str]| {
        let a = args(extra);
        common::dnurbs(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let out = run(&["--from-line", "40", "--clearance", "8", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let s: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = &s["restart"];
    assert_eq!(
        (r["asked"].as_u64(), r["line"].as_u64()),
        (Some(40), Some(40)),
        "{r}"
    );
    assert_eq!(r["spindle_rpm"].as_f64(), Some(8000.0), "{r}");
    assert_eq!(
        (r["flood"].as_bool(), r["tool"].as_u64()),
        (Some(true), Some(1)),
        "{r}"
    );
    assert_eq!(r["clearance_mm"].as_f64(), Some(8.0), "{r}");
    common::assert_within_limits(&s);
    // Line 41 is empty, 42 a comment, 43 sets the spindle to 7500: kept, it comes on
    // before the tool comes down.
    let text = String::from_utf8_lossy(&run(&["--from-line", "41"]).stdout).into_owned();
    assert!(
        text.contains("restart            from line 44 (the first move at or after line 41)"),
        "{text}"
    );
    assert!(
        text.contains("43:12  M03 spindle clockwise at S7500"),
        "{text}"
    );
    for (extra, says) in [
        (
            &["--from-line", "4000"][..],
            "--from-line 4000: line 4000: no move at or after it",
        ),
        (
            &["--from-line", "40", "--clearance", "1e9"][..],
            "must be more than 0 and at most 1000 mm",
        ),
        (&["--from-line", "0"][..], "0 is not in 1.."),
        (&["--clearance", "5"][..], "--from-line <N>"),
    ] {
        let out = run(extra);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(says), "{extra:?}: {err}");
    }
}
