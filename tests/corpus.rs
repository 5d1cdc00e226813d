//! Real programs from public repositories (`tests/corpus/MANIFEST.md` names each source), as
//! their authors or their CAM posts wrote them, unchanged, on the shipped machine files.
//!
//! `tests/corpus/runs.txt` says which machine each runs on and whether dnurbs refuses it (and
//! with which words). Each program is read with that machine's setup (start-up modes,
//! reference position, work offsets, tool table, `[mcodes]`, `[io]`) and its path compared with
//! LinuxCNC's interpreter's (`tests/corpus/expected/`, written by `tests/conformance/regen.py`
//! with `rs274`'s default setup): every end point within [`TOL_MM`], every arc's path within
//! it of LinuxCNC's circle or helix; then `dnurbs check` on the machine holds every
//! programmed point within the travel, or refuses the program with `file:line:col`. A program
//! listed as refused must be refused with its words, after the same moves as LinuxCNC up to
//! there.

mod common;

use nc_geom::program::{Block, Orientation};
use std::path::{Path, PathBuf};

/// How far an end point or the path may be from LinuxCNC's (mm).
const TOL_MM: f64 = 0.005;

fn corpus() -> PathBuf {
    common::root().join("tests/corpus")
}

/// One move of LinuxCNC's: rapid, feed or arc, with its end (X Y Z A B C) and, for an arc,
/// its plane's axes, centre and turn.
#[derive(Debug)]
struct Move {
    end: [f64; 6],
    arc: Option<([usize; 3], [f64; 2], i32)>,
}

#[derive(Debug, Default)]
struct Reference {
    moves: Vec<Move>,
    error: Option<u32>,
}

/// rs274's error at the end of a file without `M02`/`M30` or a closing `%`: it has run every
/// move by then, as dnurbs does (which ends such a program at its last line).
const NO_END: &str = "File ended with no percent sign or program end";

fn reference(name: &str) -> Reference {
    let stem = Path::new(name)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or(name);
    let path = corpus().join("expected").join(format!("{stem}.txt"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (tests/conformance/regen.py writes it)",
            path.display()
        )
    });
    let mut r = Reference::default();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        let num = |i: usize| w[i].parse::<f64>().unwrap();
        match w.first().copied() {
            Some("T" | "F") => r.moves.push(Move {
                end: std::array::from_fn(|i| num(2 + i)),
                arc: None,
            }),
            Some("A") => {
                let axes = match w[2] {
                    "XY" => [0, 1, 2],
                    "YZ" => [1, 2, 0],
                    _ => [2, 0, 1],
                };
                let v: Vec<f64> = (4..w.len()).map(num).collect();
                r.moves.push(Move {
                    end: [v[0], v[1], v[2], v[5], v[6], v[7]],
                    arc: Some((axes, [v[3], v[4]], w[3].parse().unwrap())),
                });
            }
            Some("E") if !line.contains(NO_END) => r.error = w[1].parse().ok(),
            _ => {}
        }
    }
    r
}

/// A block's end pose as LinuxCNC reports it: X Y Z A B C (`tilt`: the machine's tilting axis).
fn end_of(b: &Block, tilt: char) -> [f64; 6] {
    let (xyz, o) = match b {
        Block::Linear(m) => (m.end, m.orientation),
        Block::Nurbs(n) => (
            n.ctrl.last().copied().unwrap_or_default(),
            n.turn_to
                .map(|(r1_deg, r2_deg)| Orientation::Angles { r1_deg, r2_deg })
                .unwrap_or(Orientation::Vector([0.0, 0.0, 1.0])),
        ),
    };
    let (a, bb, c) = match o {
        Orientation::Angles { r1_deg, r2_deg } if tilt == 'B' => (0.0, r1_deg, r2_deg),
        Orientation::Angles { r1_deg, r2_deg } => (r1_deg, 0.0, r2_deg),
        Orientation::Vector(_) => (0.0, 0.0, 0.0),
    };
    [xyz[0], xyz[1], xyz[2], a, bb, c]
}

fn near(a: &[f64; 6], b: &[f64; 6], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// dnurbs's arc against LinuxCNC's circle or helix from `start`.
fn arc_on_circle(b: &Block, start: &[f64; 6], m: &Move, end: &[f64; 6]) -> Result<(), String> {
    let (Block::Nurbs(n), Some((axes, centre, turn))) = (b, m.arc) else {
        return Err(format!("a straight move where LinuxCNC has an arc: {b:?}"));
    };
    let [f, s, h] = axes;
    let degree = usize::from(n.degree);
    let (u0, u1) = (n.knots[degree], n.knots[n.knots.len() - 1 - degree]);
    let radius = |p: [f64; 3]| (p[f] - centre[0]).hypot(p[s] - centre[1]);
    let (r0, r1) = (
        radius([start[0], start[1], start[2]]),
        radius([end[0], end[1], end[2]]),
    );
    let (h0, h1) = (start[h], end[h]);
    let length = (r0.max(r1) * std::f64::consts::TAU * f64::from(turn.unsigned_abs())).max(1.0);
    let samples = (length / 0.5).clamp(16.0, 4096.0) as usize;
    let mut angle = 0.0;
    let mut prev = (start[s] - centre[1]).atan2(start[f] - centre[0]);
    let total =
        test_support::nurbs::sweep(prev, (end[s] - centre[1]).atan2(end[f] - centre[0]), turn);
    for k in 0..=samples {
        let u = u0 + (u1 - u0) * k as f64 / samples as f64;
        let p = test_support::nurbs::point(degree, &n.ctrl, &n.weights, &n.knots, u);
        let a = (p[s] - centre[1]).atan2(p[f] - centre[0]);
        let mut d = a - prev;
        while d > std::f64::consts::PI {
            d -= std::f64::consts::TAU;
        }
        while d < -std::f64::consts::PI {
            d += std::f64::consts::TAU;
        }
        angle += d;
        prev = a;
        let t = (angle / total).clamp(0.0, 1.0);
        let (want_r, want_h) = (r0 + (r1 - r0) * t, h0 + (h1 - h0) * t);
        let off = (radius(p) - want_r).abs().max((p[h] - want_h).abs());
        if off > TOL_MM {
            return Err(format!(
                "the arc's path is {off:.6} mm off LinuxCNC's at {p:?}"
            ));
        }
    }
    Ok(())
}

/// One program on its machine, read without error.
fn read_only(name: &str, machine: &str) -> Result<(), String> {
    let m = config::load(&common::machine(machine)).map_err(|e| e.to_string())?;
    let shop = dnurbs_tools::shop::ShopOptions::default();
    let setup = dnurbs_tools::shop::parse_setup(&m, &shop).map_err(|e| e.to_string())?;
    let path = corpus().join("programs").join(name);
    let text = dnurbs_tools::read_program(&path).map_err(|e| e.to_string())?;
    nc_lang::parse_with(&text, &setup)
        .map(|_| ())
        .map_err(|e| e.errors.first().map_or(String::new(), |e| e.to_string()))
}

/// One program on its machine: its path against LinuxCNC's, or its refusal.
fn check_one(name: &str, machine: &str, refused: Option<&str>) -> Result<(), String> {
    let m = config::load(&common::machine(machine)).map_err(|e| e.to_string())?;
    let shop = dnurbs_tools::shop::ShopOptions::default();
    let setup = dnurbs_tools::shop::parse_setup(&m, &shop).map_err(|e| e.to_string())?;
    let path = corpus().join("programs").join(name);
    let text = dnurbs_tools::read_program(&path).map_err(|e| e.to_string())?;
    let mut entries = nc_lang::Entries::new(nc_lang::StrLines::new(&text), &setup);
    let mut blocks = Vec::new();
    let mut error = None;
    for e in entries.by_ref() {
        match e {
            Ok(nc_lang::Entry::Block(_, b)) => blocks.push(b),
            Ok(nc_lang::Entry::Action(_)) => {}
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    let tilt = entries.tilt_word().map_or('A', |(c, _)| c);
    let want = reference(name);
    match (&error, refused, want.error) {
        (Some(e), Some(words), _) if !e.to_string().contains(words) => {
            return Err(format!("refused with \"{e}\", not with \"{words}\""));
        }
        (Some(e), None, None) => return Err(format!("refused: {e}")),
        (Some(e), None, Some(line)) if e.pos.line != line => {
            return Err(format!("LinuxCNC stops at line {line}, dnurbs at {e}"));
        }
        (None, Some(words), _) => {
            return Err(format!(
                "listed as refused with \"{words}\" but read: remove it"
            ));
        }
        (None, None, Some(line)) => {
            return Err(format!("LinuxCNC stops at line {line}, dnurbs reads it"))
        }
        _ => {}
    }
    // Moves that go nowhere are left out on both sides. rs274 starts at its zero; dnurbs
    // at the homed machine's reference where the first move does not give X Y Z (its first
    // block), and an axis the program has not moved yet stands there: such an axis is read
    // as rs274's 0 to find the moves that go nowhere, and compared from the program's first
    // move of it.
    let home = (entries.from_reference() == Some(0) && !blocks.is_empty())
        .then(|| end_of(&blocks[0], tilt));
    let mut ours: Vec<(usize, [f64; 6])> = Vec::new();
    let mut here: Option<[f64; 6]> = Some([0.0; 6]);
    let mut moved = [home.is_none(); 3];
    for (i, b) in blocks.iter().enumerate().skip(usize::from(home.is_some())) {
        let e = end_of(b, tilt);
        let mut seen = e;
        for (a, moved) in moved.iter_mut().enumerate() {
            *moved |= home.is_some_and(|h| h[a] != e[a]);
            if !*moved {
                seen[a] = 0.0;
            }
        }
        if here.is_none_or(|h| !near(&h, &seen, 1e-9)) || matches!(b, Block::Nurbs(_)) {
            ours.push((i, e));
        }
        here = Some(seen);
    }
    let mut theirs: Vec<&Move> = Vec::new();
    let mut last: Option<[f64; 6]> = Some([0.0; 6]);
    for m in &want.moves {
        if last.is_none_or(|l| !near(&l, &m.end, 1e-9)) || m.arc.is_some() {
            theirs.push(m);
        }
        last = Some(m.end);
    }
    if std::env::var("CORPUS_DUMP").is_ok_and(|d| d == name) {
        for (k, (i, e)) in ours.iter().enumerate() {
            let their = theirs.get(k).map(|m| m.end);
            println!("{k}: block {i} {e:?}  LinuxCNC {their:?}");
        }
    }
    let stop = error.is_some();
    if (stop && ours.len() > theirs.len()) || (!stop && ours.len() != theirs.len()) {
        return Err(format!(
            "dnurbs makes {} moves, LinuxCNC {}",
            ours.len(),
            theirs.len()
        ));
    }
    // The machine's reference is rs274's 0: where an axis stands at it or went back to it
    // (`G28`, an axis not moved yet), dnurbs is that far from rs274 on that axis.
    let shift = m.reference.unwrap_or([0.0; 3]);
    let mut start = [0.0; 6];
    for (k, ((i, e), m)) in ours.iter().zip(&theirs).enumerate() {
        let mut want = m.end;
        for (a, shift) in shift.iter().enumerate() {
            if (e[a] - want[a] - shift).abs() <= TOL_MM {
                want[a] = e[a];
            }
        }
        // rs274's stand-alone canon re-reads its position after a tool change without the
        // new tool length (the conformance suite's skeleton.ngc): on the first move after a
        // length change, its Z may be off by the change where the move gives no Z.
        let length = |j: usize| match &blocks[j] {
            Block::Linear(l) => l.tooling.tool_length,
            Block::Nurbs(n) => n.tooling.tool_length,
        };
        if *i > 0 {
            let change = length(*i) - length(*i - 1);
            if change != 0.0 && (e[2] - want[2] + change).abs() <= TOL_MM {
                want[2] = e[2];
            }
        }
        if !near(e, &want, TOL_MM) {
            return Err(format!("move {k} ends at {e:?}, LinuxCNC's at {:?}", m.end));
        }
        if m.arc.is_some() || matches!(blocks[*i], Block::Nurbs(_)) {
            arc_on_circle(&blocks[*i], &start, m, &want).map_err(|s| format!("move {k}: {s}"))?;
        }
        start = *e;
    }
    Ok(())
}

/// How a program of `runs.txt` is held to LinuxCNC's reading.
enum Expect {
    /// Its path within [`TOL_MM`].
    Path,
    /// Refused with these words.
    Refused(String),
    /// Read without error; its path not compared, for the reason `runs.txt` gives (rs274
    /// prints no points for it).
    Read,
}

fn runs() -> Vec<(String, String, Expect)> {
    let text = std::fs::read_to_string(corpus().join("runs.txt")).expect("tests/corpus/runs.txt");
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let (head, expect) = match (l.split_once(" refused: "), l.split_once(" unchecked: ")) {
                (Some((h, r)), _) => (h, Expect::Refused(r.trim().to_owned())),
                (_, Some((h, _why))) => (h, Expect::Read),
                _ => (l, Expect::Path),
            };
            let mut w = head.split_whitespace();
            let name = w.next().unwrap_or_default().to_owned();
            let machine = w.next().unwrap_or_default().to_owned();
            (name, machine, expect)
        })
        .collect()
}

#[test]
fn real_programs_run_on_the_shipped_machines_as_linuxcnc_reads_them() {
    let runs = runs();
    let listed: Vec<&str> = runs.iter().map(|r| r.0.as_str()).collect();
    let mut files: Vec<String> = std::fs::read_dir(corpus().join("programs"))
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .collect();
    files.sort();
    for f in &files {
        assert!(
            listed.contains(&f.as_str()),
            "{f} is not in tests/corpus/runs.txt"
        );
    }
    let mut failures = Vec::new();
    let (mut ran, mut read, mut refused) = (0, 0, 0);
    for (name, machine, expect) in &runs {
        let result = match expect {
            Expect::Path => check_one(name, machine, None).map(|()| ran += 1),
            Expect::Refused(words) => check_one(name, machine, Some(words)).map(|()| refused += 1),
            Expect::Read => read_only(name, machine).map(|()| read += 1),
        };
        if let Err(e) = result {
            failures.push(format!("{name} on {machine}: {e}"));
        }
    }
    println!(
        "{} real programs: {ran} run as LinuxCNC reads them (within {TOL_MM} mm), {read} read \
         (their path not compared), {refused} refused as listed",
        runs.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn real_programs_are_checked_on_their_machines_with_a_position_when_refused() {
    for (name, machine, expect) in runs() {
        if matches!(expect, Expect::Refused(_)) {
            continue;
        }
        let path = corpus().join("programs").join(&name);
        let out = common::dnurbs(&[
            "check",
            path.to_str().unwrap(),
            "--machine",
            common::machine(&machine).to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let prefix = format!("{}:", path.display());
        assert!(
            out.status.success()
                || stderr.lines().any(|l| l.contains(&prefix)
                    && l.split(':')
                        .nth(2)
                        .is_some_and(|c| c.trim().parse::<u32>().is_ok())),
            "{name} on {machine}: {stderr}"
        );
    }
}
