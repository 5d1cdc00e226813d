//! Conformance with LinuxCNC's RS274/NGC interpreter.
//!
//! Every program under `tests/conformance/programs/` is read by dnurbs (G54..G59 at 0 and the
//! reference position at 0 0 0 as LinuxCNC starts there, rs274's default tool table) and its motion compared with the
//! reference motion LinuxCNC's interpreter produced for it (`tests/conformance/expected/`,
//! written by `tests/conformance/regen.py`, which also checks it against `rs274 -g`):
//!
//! - the same moves in the same order (moves of zero length left out on both sides), each a
//!   rapid, a feed or an arc as LinuxCNC's, ending within [`END_TOL_MM`] of its end point
//!   and at the same rotary angles;
//! - an arc's path within [`PATH_TOL_MM`] of LinuxCNC's circle or helix (the same centre,
//!   radius, turn and rise), sampled along dnurbs's curve;
//! - where LinuxCNC stops with an error, dnurbs stops too, at the same line, after the same
//!   moves.
//!
//! A program dnurbs cannot run yet is listed in `tests/conformance/differences.txt` with the
//! words of its refusal: it must be refused with them, after the same moves as LinuxCNC up to
//! that line, and the list must not hold a program that now conforms. A program whose motion
//! differs for a reason given there (`motion: ...`) must be read without error.
//!
//! `CONFORMANCE_DUMP=gen/arcs-00.ngc` prints dnurbs's moves of that program.

use nc_geom::program::{Block, Orientation};
use nc_lang::{Entries, Entry, ParseError, Setup, StrLines};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use test_support::nurbs::point as nurbs_point;

/// How far an end point may be from LinuxCNC's (mm).
const END_TOL_MM: f64 = 1e-6;
/// How far an arc's path may be from LinuxCNC's circle or helix (mm).
const PATH_TOL_MM: f64 = 1e-3;
/// Rotary angles (degrees).
const ANGLE_TOL_DEG: f64 = 1e-9;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/conformance")
}

/// One move of LinuxCNC's reference.
#[derive(Debug)]
enum Move {
    Rapid([f64; 6]),
    Feed([f64; 6]),
    Arc {
        plane: String,
        turn: i32,
        end: [f64; 6],
        centre: [f64; 2],
    },
}

impl Move {
    fn end(&self) -> [f64; 6] {
        match self {
            Move::Rapid(e) | Move::Feed(e) | Move::Arc { end: e, .. } => *e,
        }
    }
}

struct Reference {
    moves: Vec<(u32, Move)>,
    error: Option<(u32, String)>,
    /// How exact its numbers are (mm): 0 for full precision, else rs274's rounding.
    rounding: f64,
}

fn numbers(words: &[&str]) -> Vec<f64> {
    words.iter().map(|w| w.parse().expect("a number")).collect()
}

fn reference(path: &Path) -> Reference {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out = Reference {
        moves: Vec::new(),
        error: None,
        rounding: 0.0,
    };
    for l in text.lines().filter(|l| !l.starts_with('#')) {
        let w: Vec<&str> = l.split_whitespace().collect();
        if w[0] == "P" {
            out.rounding = w[1].parse().unwrap_or(0.0);
            continue;
        }
        let line: u32 = w[1].parse().expect("a line number");
        let six = |v: &[f64]| -> [f64; 6] { v[..6].try_into().expect("six values") };
        let m = match w[0] {
            "T" => Move::Rapid(six(&numbers(&w[2..]))),
            "F" => Move::Feed(six(&numbers(&w[2..]))),
            "A" => {
                let v = numbers(&w[4..]);
                Move::Arc {
                    plane: w[2].to_owned(),
                    turn: w[3].parse().expect("a turn"),
                    end: [v[0], v[1], v[2], v[5], v[6], v[7]],
                    centre: [v[3], v[4]],
                }
            }
            "E" => {
                out.error = Some((line, w[2..].join(" ")));
                continue;
            }
            k => panic!("{}: unknown record {k}", path.display()),
        };
        out.moves.push((line, m));
    }
    out
}

/// What dnurbs made of a program: its blocks (until its first error) and that error.
struct Read {
    blocks: Vec<Block>,
    tilt: char,
    error: Option<ParseError>,
}

fn read(src: &str) -> Read {
    // rs274's default tool table (inches): T1 Z0.511, T2 Z0.1, T3 Z1.273, T99999 Z0.1.
    let tools = [(1, 0.511), (2, 0.1), (3, 1.273), (99_999, 0.1)]
        .into_iter()
        .map(|(t, z)| (t, z * 25.4))
        .collect();
    // G54..G59 at the machine zero, as in rs274's empty parameter file.
    // rs274's default tool table also gives diameters (inches) for cutter compensation. rs274
    // converts them with its external length unit, 0.03937007874016 inch per mm (not exactly
    // 1 / 25.4): a diameter is then 8e-15 below its value, which decides a program whose
    // entry move is exactly a radius long (useful-subroutines.ngc).
    let tool_diameters = [(1, 0.125), (2, 0.0625), (3, 0.201)]
        .into_iter()
        .map(|(t, d)| (t, d / 0.039_370_078_740_16))
        .collect();
    let setup = Setup {
        reference: Some([0.0; 3]),
        work_offsets: [Some([0.0; 3]); 6],
        tools,
        tool_diameters,
        ..Setup::default()
    };
    let mut entries = Entries::new(StrLines::new(src), &setup);
    let mut blocks = Vec::new();
    let mut error = None;
    for e in entries.by_ref() {
        match e {
            Ok(Entry::Block(_, b)) => blocks.push(b),
            Ok(Entry::Action(_)) => {}
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    let tilt = entries.tilt_word().map_or('A', |t| t.0);
    // The move to the reference position where the program leaves out an axis of its first
    // move: the machine is there already (LinuxCNC's is at its 0 0 0, the reference here).
    if let Some(k) = entries.from_reference().filter(|&k| k < blocks.len()) {
        blocks.remove(k);
    }
    Read {
        blocks,
        tilt,
        error,
    }
}

/// A block's end pose as LinuxCNC reports it: X Y Z A B C.
fn end_of(b: &Block, tilt: char) -> [f64; 6] {
    let (xyz, o) = match b {
        Block::Linear(m) => (m.end, m.orientation),
        Block::Nurbs(n) => (
            n.ctrl.last().copied().unwrap_or_default(),
            Orientation::Vector([0.0, 0.0, 1.0]),
        ),
    };
    let (a, bb, c) = match (o, b) {
        (_, Block::Nurbs(n)) => match n.turn_to {
            Some((r1, r2)) if tilt == 'B' => (0.0, r1, r2),
            Some((r1, r2)) => (r1, 0.0, r2),
            None => (f64::NAN, f64::NAN, f64::NAN),
        },
        (Orientation::Angles { r1_deg, r2_deg }, _) if tilt == 'B' => (0.0, r1_deg, r2_deg),
        (Orientation::Angles { r1_deg, r2_deg }, _) => (r1_deg, 0.0, r2_deg),
        (Orientation::Vector(_), _) => (0.0, 0.0, 0.0),
    };
    [xyz[0], xyz[1], xyz[2], a, bb, c]
}

fn same_pose(a: &[f64; 6], b: &[f64; 6]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= 1e-9) && (3..6).all(|i| (a[i] - b[i]).abs() <= 1e-9)
}

/// The plane's first, second and normal axes (indices into X Y Z).
fn axes(plane: &str) -> [usize; 3] {
    match plane {
        "XY" => [0, 1, 2],
        "YZ" => [1, 2, 0],
        _ => [2, 0, 1],
    }
}

/// The largest deviations seen against full-precision references: of an end point, of an
/// arc's path (mm).
#[derive(Default)]
struct Dev {
    end: f64,
    path: f64,
}

/// LinuxCNC's arc: its plane, turn, end pose and centre (in the plane's axes).
struct Arc<'a> {
    plane: &'a str,
    turn: i32,
    end: [f64; 6],
    centre: [f64; 2],
}

/// Checks dnurbs's arc `b` from `start` against LinuxCNC's arc.
fn check_arc(
    dev: &mut Dev,
    b: &Block,
    start: [f64; 6],
    arc: Arc<'_>,
    rounding: f64,
) -> Result<(), String> {
    let Arc {
        plane,
        turn,
        end,
        centre,
    } = arc;
    let Block::Nurbs(n) = b else {
        return Err(format!(
            "dnurbs has a straight move where LinuxCNC has an arc: {b:?}"
        ));
    };
    let degree = usize::from(n.degree);
    let [f, s, h] = axes(plane);
    let polar = |p: [f64; 3]| {
        let (d1, d2) = (p[f] - centre[0], p[s] - centre[1]);
        ((d1 * d1 + d2 * d2).sqrt(), d2.atan2(d1))
    };
    let (r0, a0) = polar([start[0], start[1], start[2]]);
    let (r1, a1) = polar([end[0], end[1], end[2]]);
    let tau = std::f64::consts::TAU;
    let sweep = test_support::nurbs::sweep(a0, a1, turn);
    let (u0, u1) = (n.knots[degree], n.knots[n.knots.len() - 1 - degree]);
    let samples = 64 * (1 + (sweep.abs() / tau) as usize);
    let mut angle = 0.0;
    let mut prev = a0;
    for k in 0..=samples {
        let u = u0 + (u1 - u0) * k as f64 / samples as f64;
        let p = nurbs_point(degree, &n.ctrl, &n.weights, &n.knots, u);
        let (r, a) = polar(p);
        let mut d = a - prev;
        while d > std::f64::consts::PI {
            d -= tau;
        }
        while d < -std::f64::consts::PI {
            d += tau;
        }
        angle += d;
        prev = a;
        let t = (angle / sweep).clamp(0.0, 1.0);
        let want_r = r0 + (r1 - r0) * t;
        let want_h = start[h] + (end[h] - start[h]) * t;
        if rounding == 0.0 {
            dev.path = dev.path.max((r - want_r).abs()).max((p[h] - want_h).abs());
        }
        // Rounded numbers (start, end, centre) move the reference's radius by up to twice
        // their rounding.
        let tol = PATH_TOL_MM + 4.0 * rounding;
        if (r - want_r).abs() > tol || (p[h] - want_h).abs() > tol {
            return Err(format!(
                "arc point {p:?} at {:.3} of the sweep: radius {r} (LinuxCNC {want_r}), height {} (LinuxCNC {want_h})",
                t, p[h]
            ));
        }
    }
    // Rounded numbers turn the reference's angles by up to their rounding over the radius
    // (a corner arc of cutter compensation has the tool's small radius).
    let sweep_tol = 1e-6 + 4.0 * rounding / r0.min(r1).max(1e-9);
    if (angle - sweep).abs() > sweep_tol {
        return Err(format!("arc sweeps {angle} rad, LinuxCNC's {sweep} rad"));
    }
    Ok(())
}

/// Compares dnurbs's reading of one program with LinuxCNC's; `refusal`: the words dnurbs's
/// refusal must have (a listed difference).
fn compare(
    dev: &mut Dev,
    name: &str,
    src: &str,
    want: &Reference,
    refusal: Option<&str>,
) -> Result<(), String> {
    let got = read(src);
    // Both sides without moves of zero length.
    let mut theirs = Vec::new();
    let mut here = [0.0; 6];
    for (line, m) in &want.moves {
        if !same_pose(&m.end(), &here) || matches!(m, Move::Arc { .. }) {
            theirs.push((*line, m, here));
        }
        here = m.end();
    }
    let mut ours = Vec::new();
    let mut here = [0.0; 6];
    for b in &got.blocks {
        let e = end_of(b, got.tilt);
        let e = [
            e[0],
            e[1],
            e[2],
            if e[3].is_nan() { here[3] } else { e[3] },
            if e[4].is_nan() { here[4] } else { e[4] },
            if e[5].is_nan() { here[5] } else { e[5] },
        ];
        if !same_pose(&e, &here) || matches!(b, Block::Nurbs(_)) {
            ours.push((b, e));
        }
        here = e;
    }
    if std::env::var("CONFORMANCE_DUMP").is_ok_and(|d| d == name) {
        for (b, e) in &ours {
            let kind = match b {
                Block::Linear(l) if l.rapid => "T",
                Block::Linear(_) => "F",
                Block::Nurbs(_) => "A",
            };
            println!("{kind} {:?}", &e[..3]);
        }
    }
    // Where dnurbs stops (a listed difference, or LinuxCNC's error) only the moves before
    // that line are compared.
    let stop_line = match (&got.error, refusal, &want.error) {
        (None, Some(words), _) => return Err(format!("listed as refused with \"{words}\" but dnurbs reads it: remove it from differences.txt")),
        (Some(e), Some(words), _) => {
            let msg = e.to_string();
            if !msg.contains(words) {
                return Err(format!("dnurbs refuses it with \"{msg}\", not with \"{words}\""));
            }
            Some(e.pos.line)
        }
        (Some(e), None, Some((line, msg))) => {
            if e.pos.line != *line {
                return Err(format!("LinuxCNC stops at line {line} ({msg}), dnurbs at {e}"));
            }
            Some(*line)
        }
        (Some(e), None, None) => return Err(format!("dnurbs refuses it: {e}")),
        (None, None, Some((line, msg))) => return Err(format!("LinuxCNC stops at line {line} ({msg}), dnurbs reads it all")),
        (None, None, None) => None,
    };
    // A reference from rs274's printout has no line numbers (0): where dnurbs stops, its
    // moves must then be the first of LinuxCNC's.
    // Where LinuxCNC stops too, its moves are those before its error already (in the order
    // they ran: a subroutine's lines may come before the line that called it).
    let lines_known = want.moves.iter().all(|(line, _)| *line > 0);
    let cut = if refusal.is_some() { stop_line } else { None };
    let theirs: Vec<_> = theirs
        .into_iter()
        .filter(|(line, _, _)| cut.is_none_or(|s| !lines_known || *line < s))
        .collect();
    if stop_line.is_some() && !lines_known && ours.len() > theirs.len() {
        return Err(format!(
            "dnurbs makes {} moves before it stops, LinuxCNC {} in all",
            ours.len(),
            theirs.len()
        ));
    }
    if stop_line.is_none() && theirs.len() != ours.len() {
        return Err(format!(
            "LinuxCNC makes {} moves, dnurbs {}",
            theirs.len(),
            ours.len()
        ));
    }
    if lines_known && ours.len() < theirs.len() {
        return Err(format!(
            "before line {stop_line:?}, LinuxCNC makes {} moves, dnurbs {}",
            theirs.len(),
            ours.len()
        ));
    }
    for (k, ((line, m, start), (b, e))) in theirs.iter().zip(&ours).enumerate() {
        let want_end = m.end();
        let off = (0..3)
            .map(|i| (want_end[i] - e[i]).abs())
            .fold(0.0, f64::max);
        let off_deg = (3..6)
            .map(|i| (want_end[i] - e[i]).abs())
            .fold(0.0, f64::max);
        let at = format!("{name}: move {k} (LinuxCNC line {line})");
        if want.rounding == 0.0 {
            dev.end = dev.end.max(off);
        }
        // rs274's 4 decimals, where the reference has them.
        let end_tol = END_TOL_MM.max(1.0001 * want.rounding);
        let deg_tol = ANGLE_TOL_DEG.max(0.5e-4);
        let deg_tol = if want.rounding > 0.0 {
            deg_tol
        } else {
            ANGLE_TOL_DEG
        };
        if off > end_tol || off_deg > deg_tol {
            return Err(format!("{at}: ends at {e:?}, LinuxCNC at {want_end:?}"));
        }
        match (m, b) {
            (Move::Rapid(_), Block::Linear(l)) if l.rapid => {}
            (Move::Feed(_), Block::Linear(l)) if !l.rapid => {}
            (
                Move::Arc {
                    plane,
                    turn,
                    end,
                    centre,
                },
                _,
            ) => {
                let arc = Arc {
                    plane,
                    turn: *turn,
                    end: *end,
                    centre: *centre,
                };
                check_arc(dev, b, *start, arc, want.rounding)
            }
            .map_err(|w| format!("{at}: {w}"))?,
            _ => return Err(format!("{at}: LinuxCNC {m:?}, dnurbs {b:?}")),
        }
    }
    Ok(())
}

#[test]
fn dnurbs_moves_as_linuxcncs_interpreter_does() {
    let root = root();
    let differences: BTreeMap<String, String> =
        std::fs::read_to_string(root.join("differences.txt"))
            .unwrap_or_default()
            .lines()
            .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
            .filter_map(|l| {
                l.split_once(": ")
                    .map(|(p, w)| (p.trim().to_owned(), w.trim().to_owned()))
            })
            .collect();
    let mut programs = Vec::new();
    let mut stack = vec![root.join("programs")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("the programs") {
            let p = entry.expect("an entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "ngc") {
                programs.push(p);
            }
        }
    }
    programs.sort();
    let mut failures = Vec::new();
    let mut conforming = 0;
    let mut rounded = 0;
    let mut dev = Dev::default();
    for p in &programs {
        let rel = p
            .strip_prefix(root.join("programs"))
            .expect("under programs")
            .to_string_lossy()
            .into_owned();
        let expected = root.join("expected").join(rel.replace(".ngc", ".txt"));
        let src = std::fs::read_to_string(p).expect("the program");
        let want = reference(&expected);
        let refusal = differences.get(&rel).map(String::as_str);
        rounded += usize::from(want.rounding > 0.0);
        if let Some(why) = refusal.and_then(|r| r.strip_prefix("motion: ")) {
            // A known difference of motion, not of the language: dnurbs must read it all.
            if let Some(e) = read(&src).error {
                failures.push(format!("{rel}: dnurbs refuses it ({e}); listed for: {why}"));
            }
            continue;
        }
        match compare(&mut dev, &rel, &src, &want, refusal) {
            Ok(()) if refusal.is_none() => conforming += 1,
            Ok(()) => {}
            Err(e) => failures.push(format!("{rel}: {e}")),
        }
    }
    for d in differences.keys() {
        if !programs.iter().any(|p| p.ends_with(d)) {
            failures.push(format!("differences.txt lists {d}, which is not a program"));
        }
    }
    println!(
        "{conforming} of {} programs conform; {} listed as differences; {rounded} references \
         are rs274's 4 decimals, the others full precision: there the largest end point \
         deviation is {:.3e} mm, the largest arc path deviation {:.3e} mm",
        programs.len(),
        differences.len(),
        dev.end,
        dev.path
    );
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn the_comparison_catches_a_move_a_micrometre_off_and_an_arc_the_wrong_way() {
    let src = "G21 G0 X0 Y0 Z0\nG1 X10 F100\nG2 X20 Y0 I5 J0\nM2\n";
    let good = |end: f64, turn: i32| Reference {
        moves: vec![
            (2, Move::Feed([10.0, 0.0, 0.0, 0.0, 0.0, 0.0])),
            (
                3,
                Move::Arc {
                    plane: "XY".into(),
                    turn,
                    end: [end, 0.0, 0.0, 0.0, 0.0, 0.0],
                    centre: [15.0, 0.0],
                },
            ),
        ],
        error: None,
        rounding: 0.0,
    };
    let mut dev = Dev::default();
    assert!(compare(&mut dev, "t", src, &good(20.0, -1), None).is_ok());
    assert!(compare(&mut dev, "t", src, &good(20.0 + 2e-6, -1), None).is_err());
    assert!(compare(&mut dev, "t", src, &good(20.0, 1), None).is_err());
    let mut err = good(20.0, -1);
    err.error = Some((3, "an error".into()));
    assert!(compare(&mut dev, "t", src, &err, None).is_err());
}
