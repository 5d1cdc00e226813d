//! `dnurbs fit` as a stream (`nc_fit::rewrite`): on every program in `tests/data` it writes
//! what the whole-text fit (`fit_program`) writes, byte for byte; a run longer than the
//! window is cut on a programmed point and every point stays within the tolerances by the
//! independent measurement of the whole paths; line endings and lines that move nothing
//! are kept as they were.

use nalgebra::Vector3;
use nc_fit::deviation::measure;
use nc_fit::online::MAX_RUN;
use nc_fit::options::Options;
use nc_fit::rewrite::{rewrite, Rewritten};
use nc_fit::runs::fit_program;
use nc_geom::kinematics::{MachineKinematics, Tilt};
use nc_geom::program::{Block, NurbsKind};
use nc_geom::segment::build;
use nc_plan::fixtures::{blade, g01_program, resample, small_mill};
use std::path::{Path, PathBuf};

const PAPER: MachineKinematics = MachineKinematics::Paper;

fn stream(src: &str, kin: &MachineKinematics, opts: &Options) -> (String, Rewritten) {
    let (_, bl) = small_mill(0.002);
    let mut out = Vec::new();
    let setup = nc_lang::Setup::default();
    let done = rewrite(src.as_bytes(), &setup, kin, &bl, opts, 0.002, &mut out)
        .unwrap_or_else(|e| panic!("{e}"));
    (String::from_utf8(out).expect("UTF-8"), done)
}

fn programs(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("tests/data") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            programs(&path, out);
        } else if path.extension().is_some_and(|e| e == "nc") {
            out.push(path);
        }
    }
}

#[test]
fn the_stream_writes_what_the_whole_text_fit_writes_on_every_test_program() {
    let trt = MachineKinematics::Trt {
        tilt: Tilt::A,
        tilt_point: Vector3::zeros(),
        c_point: Vector3::zeros(),
    };
    let (_, bl) = small_mill(0.002);
    let mut files = Vec::new();
    programs(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data"),
        &mut files,
    );
    files.sort();
    let (mut compared, mut fitted) = (0, 0);
    for file in &files {
        let src = std::fs::read_to_string(file).expect("read");
        let Ok(input) = nc_lang::parse(&src) else {
            continue;
        };
        // The machine the program's words are for: angle words need the tilting table.
        let Some(kin) = [PAPER, trt]
            .into_iter()
            .find(|k| build(&input, k, &bl).is_ok())
        else {
            continue;
        };
        let opts = Options::default();
        let whole = fit_program(&src, &input, &kin, &opts);
        let (text, done) = stream(&src, &kin, &opts);
        assert_eq!(text, whole.text, "{}", file.display());
        assert_eq!(done.summary, whole.summary, "{}", file.display());
        compared += 1;
        fitted += done.summary.fitted_blocks;
    }
    // The posts need their machine's reference and tool table: `tests/posts.rs` compares them.
    assert!(
        compared >= 15 && fitted >= 2,
        "{compared} programs, {fitted} blocks"
    );
}

/// The blade sweep at 0.05 mm a move, `n` moves.
fn sweep(n: usize) -> String {
    g01_program(&resample(blade, 40.0, n, 0.05), 3000.0)
}

#[test]
fn a_run_longer_than_the_window_is_cut_on_a_programmed_point() {
    let n = 2 * MAX_RUN + 1234;
    let src = sweep(n);
    let opts = Options::default();
    let (text, done) = stream(&src, &PAPER, &opts);
    let s = &done.summary;
    assert_eq!(s.moves_in, n);
    assert_eq!(s.moves_fitted, n, "{s:?}");
    assert!(s.fitted_blocks >= 3, "{s:?}");
    // Measured again here on the whole paths, not by the rewrite's own check.
    let (_, bl) = small_mill(0.002);
    let input = nc_lang::parse(&src).expect("input");
    let output = nc_lang::parse(&text).expect("output parses");
    let (a, b) = (
        build(&input, &PAPER, &bl).expect("input builds"),
        build(&output, &PAPER, &bl).expect("output builds"),
    );
    let dev = measure(&a, &b, &PAPER, 0.002, opts.tol.mm);
    assert!(dev.point_mm <= opts.tol.mm + 5e-7, "{dev:?}");
    assert!(
        dev.point_deg <= opts.tol.rad.to_degrees() * 1.001,
        "{dev:?}"
    );
    assert!(done.dev.point_mm <= opts.tol.mm + 5e-7, "{:?}", done.dev);
    assert_eq!(done.dev.points, dev.points);
    // Every block starts where a programmed move ends, and no block holds more moves than
    // the window.
    let ends: Vec<[f64; 3]> = input
        .blocks
        .iter()
        .map(|b| match b {
            Block::Linear(m) => m.end,
            Block::Nurbs(_) => unreachable!("the input is G01"),
        })
        .collect();
    let mut at = 0;
    for block in output.blocks.iter().skip(1) {
        let Block::Nurbs(nb) = block else {
            panic!("a move left unfitted: {block:?}");
        };
        assert_eq!(nb.kind, NurbsKind::G065);
        let first = nb.ctrl[0];
        let k = ends
            .iter()
            .position(|e| (0..3).all(|i| (e[i] - first[i]).abs() < 5e-5))
            .unwrap_or_else(|| panic!("block starts at {first:?}, on no programmed point"));
        assert!(k >= at, "blocks out of order");
        at = k;
    }
    assert!(
        ends.len() - 1 - at <= MAX_RUN,
        "the last block holds {} moves",
        ends.len() - 1 - at
    );
}

#[test]
fn line_endings_continued_lines_and_lines_that_move_nothing_are_kept() {
    let src = sweep(300);
    let opts = Options::default();
    let parse = |s: &str| nc_lang::parse(s).expect("parses");
    // Windows line endings, and no ending on the last line.
    let crlf = src.replace('\n', "\r\n").trim_end().to_owned();
    let whole = fit_program(&crlf, &parse(&crlf), &PAPER, &opts);
    let (text, _) = stream(&crlf, &PAPER, &opts);
    assert_eq!(text, whole.text);
    assert!(
        text.contains("G06.5") && text.ends_with("M30\r\n%"),
        "{text}"
    );
    // More lines that move nothing (a feed word alone) between two moves than the window
    // holds: the run ends there, as in the whole text, and every line is written.
    let mut lines: Vec<&str> = src.lines().collect();
    let feeds = vec!["F3000"; 2 * MAX_RUN + 100];
    lines.splice(150..150, feeds);
    let padded = lines.join("\n") + "\n";
    let whole = fit_program(&padded, &parse(&padded), &PAPER, &opts);
    let (text, done) = stream(&padded, &PAPER, &opts);
    assert_eq!(text, whole.text);
    assert_eq!(done.summary.fitted_blocks, 2, "{:?}", done.summary);
    assert_eq!(
        text.lines().filter(|l| *l == "F3000").count(),
        2 * MAX_RUN + 100
    );
    // A move continued on the next line (a backslash) between two runs: the check parses
    // each written line as it goes, the continued one with its next.
    let mut lines: Vec<&str> = src.lines().collect();
    lines.splice(150..150, ["(a note) G01 X30 \\", " Y-10 Z12"]);
    let continued = lines.join("\n") + "\n";
    let whole = fit_program(&continued, &parse(&continued), &PAPER, &opts);
    let (text, done) = stream(&continued, &PAPER, &opts);
    assert_eq!(text, whole.text);
    assert_eq!(done.summary.fitted_blocks, 2, "{:?}", done.summary);
    assert!(text.contains("G01 X30 \\\n Y-10 Z12\n"), "{text}");
}

/// A trunnion table tilting about `tilt` 50 mm below the C table, and the parse setup
/// that reads angle words for it.
fn trunnion(tilt: Tilt) -> (MachineKinematics, nc_lang::Setup) {
    let kin = MachineKinematics::Trt {
        tilt,
        tilt_point: Vector3::new(0.0, 0.0, -50.0),
        c_point: Vector3::zeros(),
    };
    let setup = nc_lang::Setup {
        reference: Some([0.0, 0.0, 300.0]),
        kinematics: Some(kin),
        ..nc_lang::Setup::default()
    };
    (kin, setup)
}

/// `src` fitted as a stream with the default options: it must write what the whole-text
/// fit writes and read back within both tolerances by the independent measurement. The
/// text written, what the stream did, and the input's and the output's paths.
fn fit_checked(
    src: &str,
    kin: &MachineKinematics,
    setup: &nc_lang::Setup,
    what: &str,
) -> (
    String,
    Rewritten,
    nc_geom::segment::Path,
    nc_geom::segment::Path,
) {
    let opts = Options::default();
    let input = nc_lang::parse_with(src, setup).expect("input parses");
    let whole = fit_program(src, &input, kin, &opts);
    let (_, bl) = small_mill(0.002);
    let mut out = Vec::new();
    let done = rewrite(src.as_bytes(), setup, kin, &bl, &opts, 0.002, &mut out)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    let text = String::from_utf8(out).unwrap();
    assert_eq!(text, whole.text, "{what}");
    let output = nc_lang::parse_with(&text, setup).expect("the output parses");
    let (a, b) = (
        build(&input, kin, &bl).expect("input builds"),
        build(&output, kin, &bl).expect("output builds"),
    );
    let dev = measure(&a, &b, kin, 0.002, opts.tol.mm);
    assert!(dev.point_mm <= opts.tol.mm + 5e-7, "{what}: {dev:?}");
    assert!(
        dev.point_deg <= opts.tol.rad.to_degrees() * 1.001,
        "{what}: {dev:?}"
    );
    (text, done, a, b)
}

/// A run given in machine angles, followed by `after`: 400 moves of about 0.1 mm along an
/// arc, A and C turning a little on every move, as an A/C post writes them.
fn in_angles(after: &str) -> String {
    use std::fmt::Write;
    let mut s = String::from("%\nG90 G21 G94\n");
    for k in 0..=400 {
        let t = k as f64 * 0.1 / 20.0;
        let (x, y) = (20.0 * t.cos(), 20.0 * t.sin());
        let (a, c) = (10.0 + 5.0 * (3.0 * t).sin(), 30.0 * t.to_degrees() / 57.3);
        let g = if k < 2 { "G01 " } else { "" };
        let f = if k == 0 { " F2000" } else { "" };
        let _ = writeln!(s, "{g}X{x:.4} Y{y:.4} Z5 A{a:.4} C{c:.4}{f}");
    }
    s.push_str(after);
    s.push_str("M30\n%\n");
    s
}

/// After a `G06.5` block the tool axis is modal as a vector: a block fitted to moves given
/// in angles is followed by a line that gives both angles: the line after the run where it
/// does, else, where that line is a move that leaves an angle modal, that move with the
/// modal angle written out (else the run's last move, kept as written); so a move that
/// gives one angle, or a `G28` under the tilted table, still reads as it did.
#[test]
fn a_run_in_angles_leaves_the_angles_modal_after_its_block() {
    let (trt, setup) = trunnion(Tilt::A);
    for (after, fitted, written) in [
        // The next move gives both angles: the whole run is one block.
        (
            "X19.9 Y2.5 Z6 A12 C20 F1000\n",
            400,
            "X19.9 Y2.5 Z6 A12 C20 F1000\n",
        ),
        // A move that gives C alone, or no angle (then a G28 with A at 10 degrees): the
        // whole run is one block, and the move gives both angles.
        (
            "X19.9 Y2.5 Z6 C20 F1000\n",
            400,
            "X19.9 Y2.5 Z6 C20 F1000 A8.6029\n",
        ),
        (
            "X19.9 Y2.5 Z6 F1000\nG91 G28 Z0\nG90\n",
            400,
            "X19.9 Y2.5 Z6 F1000 A8.6029 C59.9956\nG91 G28 Z0\n",
        ),
        // A line that is not a move, then a move with C alone: the run's last move stays
        // as written (it gives both angles).
        (
            "(next)\nX19.9 Y2.5 Z6 C20 F1000\n",
            399,
            "Z5 A8.6029 C59.9956\n(next)\nX19.9 Y2.5 Z6 C20 F1000\n",
        ),
    ] {
        let src = in_angles(after);
        let (text, done, _, _) = fit_checked(&src, &trt, &setup, after);
        assert!(text.contains(written), "{after}: {text}");
        assert_eq!(
            done.summary.moves_fitted, fitted,
            "{after}: {:?}",
            done.summary
        );
        assert_eq!(done.summary.fitted_blocks, 1, "{after}");
    }
}

/// A post that writes only the words that change (the tilt given once, `C` on every move,
/// as Fanuc-style posts suppress modal words), on an A/C and a B/C table: each of the two
/// runs (a 90-degree corner between them) becomes one block, the move after each is
/// written with the tilt it left modal, and the result reads back within the tolerances.
#[test]
fn a_post_that_writes_only_the_changing_angle_is_fitted() {
    use std::fmt::Write;
    for (tilt, letter) in [(Tilt::A, 'A'), (Tilt::B, 'B')] {
        let (kin, setup) = trunnion(tilt);
        let mut src = format!("%\nG90 G21 G94\nG01 X0 Y0 Z5 {letter}15 C0 F2000\n");
        for k in 1..=150 {
            let x = f64::from(k) * 0.1;
            let _ = writeln!(
                src,
                "X{x:.4} Y{:.4} C{:.3}",
                0.2 * (x / 3.0).sin(),
                0.05 * f64::from(k)
            );
        }
        // The corner: the next run goes along Y, C turning back.
        for k in 1..=150 {
            let y = 0.2 * (15.0f64 / 3.0).sin() + f64::from(k) * 0.1;
            let _ = writeln!(
                src,
                "Y{y:.4} X{:.4} C{:.3}",
                15.0 + 0.2 * (y / 3.0).sin(),
                7.5 - 0.05 * f64::from(k)
            );
        }
        src.push_str("Y20 C0.5 F1000\nM30\n%\n");
        let (text, done, _, _) = fit_checked(&src, &kin, &setup, &letter.to_string());
        assert_eq!(
            done.summary.fitted_blocks, 2,
            "{letter}: {:?}\n{text}",
            done.summary
        );
        assert_eq!(
            done.summary.moves_fitted, 300,
            "{letter}: {:?}",
            done.summary
        );
        assert!(
            text.contains(&format!("Y20 C0.5 F1000 {letter}15\n")),
            "{text}"
        );
    }
}

/// A 5-axis pass in inverse time, as a post writes `G93` (each move's F is 1/minutes for
/// its own length, rounded to 0.1, the tool's speed within 0.8 % of 900 mm/min): it is
/// fitted into one block written in `G94` at the run's length over its time, the feed per
/// minute and `G93` back after it, and the programmed time of the whole program (a move
/// at the feed per minute after the section included) stays what it was.
#[test]
fn a_run_in_inverse_time_keeps_its_time() {
    use std::fmt::Write;
    let (kin, setup) = trunnion(Tilt::A);
    let mut src = String::from("%\nG90 G21 G94\nG01 X20 Y0 Z5 A10 C0 F600\nG93\n");
    let mut prev = (20.0f64, 0.0f64);
    for k in 1..=300 {
        let t = f64::from(k) * 0.015;
        let (x, y) = (20.0 * t.cos(), 20.0 * t.sin());
        let (x, y) = ((x * 1e3).round() / 1e3, (y * 1e3).round() / 1e3);
        let len = (x - prev.0).hypot(y - prev.1);
        prev = (x, y);
        // The speed wanders within 0.8 % (the spread a run may have), below and above 900.
        let speed = 900.0 * (1.0 - 0.004 * (f64::from(k) * 0.7).cos());
        let f = (speed / len * 10.0).round() / 10.0;
        let (a, c) = (10.0 + 5.0 * (2.0 * t).sin(), t.to_degrees());
        let _ = writeln!(src, "G01 X{x:.3} Y{y:.3} Z5 A{a:.3} C{c:.3} F{f:.1}");
    }
    // Back in G94, which sets the feed to 0 (LinuxCNC's rule): a move at a feed per minute
    // given again.
    src.push_str("G94 F600\nG00 Z50\nG01 X0 Y-20\nM30\n%\n");
    let (text, done, a, b) = fit_checked(&src, &kin, &setup, "G93");
    assert_eq!(done.summary.fitted_blocks, 1, "{:?}\n{text}", done.summary);
    assert!(done.summary.moves_fitted >= 297, "{:?}", done.summary);
    assert!(text.contains("G93\nG94 G06.5 P3 X20 Y0 Z5 "), "{text}");
    // The block's F replaced the feed per minute: it is given back before G93.
    assert!(text.contains("K1 K1 K1 K1\nF600\nG93\n"), "{text}");
    // The programmed time (feed moves at their feed) is the same to 1e-4.
    let time = |p: &nc_geom::segment::Path| -> f64 {
        p.segments
            .iter()
            .filter(|s| !s.rapid)
            .map(|s| s.length / s.feed)
            .sum()
    };
    let (ta, tb) = (time(&a), time(&b));
    assert!((ta - tb).abs() < 1e-4 * ta, "{ta} s posted, {tb} s fitted");
}

/// A finishing raster as `tests/data/fit/raster.py` writes it (rows of 0.1 mm moves over a
/// wavy surface, step-overs of 10 moves, 90-degree corners), `rows` rows of `steps` moves.
fn raster(rows: usize, steps: usize) -> String {
    let z = |x: f64, y: f64| 2.0 * (x / 8.0).sin() * (y / 10.0).cos();
    let mut pts = Vec::new();
    for r in 0..rows {
        let y = r as f64;
        let mut xs: Vec<f64> = (0..=steps).map(|k| k as f64 * 0.1).collect();
        if r % 2 == 1 {
            xs.reverse();
        }
        if r > 0 {
            pts.extend((1..10).map(|k| (xs[0], y - 1.0 + k as f64 * 0.1)));
        }
        pts.extend(xs.iter().map(|&x| (x, y)));
    }
    let points: Vec<_> = pts
        .iter()
        .map(|&(x, y)| (Vector3::new(x, y, z(x, y)), Vector3::z()))
        .collect();
    g01_program(&points, 3000.0)
}

/// Where a window of more than 5 000 moves holds many runs (a raster's rows), it is cut
/// where a run ends or before one begins, so the blocks are those of the whole text.
#[test]
fn a_window_full_of_short_runs_is_cut_between_them() {
    let src = raster(30, 400);
    let input = nc_lang::parse(&src).expect("parses");
    let opts = Options::default();
    let whole = fit_program(&src, &input, &PAPER, &opts);
    let (text, done) = stream(&src, &PAPER, &opts);
    assert!(done.summary.moves_in > 2 * MAX_RUN, "{:?}", done.summary);
    assert_eq!(done.summary.fitted_blocks, 59, "{:?}", done.summary);
    assert_eq!(text, whole.text);
    assert_eq!(done.summary, whole.summary);
    assert!(done.dev.point_mm <= opts.tol.mm + 5e-7, "{:?}", done.dev);
}

/// The moves of `pts` (cutter points, tool vertical) as a post writes them.
fn program_through(pts: &[(f64, f64)]) -> String {
    let points: Vec<_> = pts
        .iter()
        .map(|&(x, y)| (Vector3::new(x, y, (x / 7.0).sin()), Vector3::z()))
        .collect();
    g01_program(&points, 2000.0)
}

/// Where the window fills in the middle of a run, or a few moves into one (too few yet to
/// be fitted), or a `;` comment ends in a backslash, or only the header's line ends in CRLF:
/// the stream still writes what the whole text gives.
#[test]
fn the_stream_matches_the_whole_text_where_the_window_fills_mid_run() {
    let opts = Options::default();
    let check = |src: &str, what: &str| {
        let input = nc_lang::parse(src).expect("parses");
        let whole = fit_program(src, &input, &PAPER, &opts);
        let (text, done) = stream(src, &PAPER, &opts);
        assert_eq!(text, whole.text, "{what}");
        assert_eq!(done.summary, whole.summary, "{what}");
        done.summary
    };
    // 1 000 moves along X, a corner, 4 500 along Y: the window fills inside the second run.
    let mut pts: Vec<(f64, f64)> = (0..=1000).map(|k| (k as f64 * 0.1, 0.0)).collect();
    pts.extend((1..=4500).map(|k| (100.0, k as f64 * 0.1)));
    let s = check(&program_through(&pts), "a run across the cut");
    assert_eq!((s.fitted_blocks, s.moves_fitted), (2, 5500), "{s:?}");
    // 4 997 moves with a corner at every one, then 100 along a line: the window fills three
    // moves into the line.
    let mut pts: Vec<(f64, f64)> = (0..=4997)
        .map(|k| (k as f64 * 0.1, if k % 2 == 0 { 0.0 } else { 0.1 }))
        .collect();
    let (x0, y0) = pts[pts.len() - 1];
    pts.extend((1..=100).map(|k| (x0 + k as f64 * 0.1, y0 + k as f64 * 0.05)));
    let s = check(&program_through(&pts), "a run starting at the cut");
    assert_eq!((s.fitted_blocks, s.moves_fitted), (1, 100), "{s:?}");
    // A `;` comment that ends in a backslash ends the line; a CRLF header in an LF file.
    let src = sweep(200).replacen(
        "G90 G21 G94\n",
        "G90 G21 G94\r\nG00 X0 Y0 Z50 ; C:\\NC\\\n",
        1,
    );
    check(&src, "a comment ending in a backslash");
}

/// Moves under cutter radius compensation are left as written (a G06.5 block is not
/// compensated, and the parser refuses one under G41/G42); the run after `G40` is fitted.
#[test]
fn moves_under_cutter_compensation_are_kept_and_the_run_after_it_fitted() {
    use std::fmt::Write;
    let mut src = String::from("%\nG90 G21 G94\nG00 X-10 Y0 Z0\nG42.1 D4\nG01 X0 Y0 F500\n");
    let curve = |k: i32| {
        let x = f64::from(k);
        (x, 0.01 * x * x)
    };
    for k in 1..=60 {
        let (x, y) = curve(k);
        let _ = writeln!(src, "G01 X{x:.4} Y{y:.4}");
    }
    src.push_str("G40\nG01 X60 Y60\n");
    for k in 1..=60 {
        let (x, y) = curve(k);
        let _ = writeln!(src, "G01 X{:.4} Y{:.4}", 60.0 + x, 60.0 + y);
    }
    src.push_str("M30\n%\n");
    let (text, done) = stream(&src, &PAPER, &Options::default());
    assert_eq!(done.summary.fitted_blocks, 1, "{:?}\n{text}", done.summary);
    let head: String = src.lines().take(66).collect::<Vec<_>>().join("\n");
    assert!(text.starts_with(&head), "{text}");
    assert!(nc_lang::parse(&text).is_ok());
    let input = nc_lang::parse(&src).expect("parses");
    let whole = fit_program(&src, &input, &PAPER, &Options::default());
    assert_eq!(whole.text, text);
}
