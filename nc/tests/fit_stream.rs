//! `dnurbs fit` as a stream (`nc::fit::rewrite`): on every program in `tests/data` it writes
//! what the whole-text fit (`fit_program`) writes, byte for byte; a run longer than the
//! window is cut on a programmed point and every point stays within the tolerances by the
//! independent measurement of the whole paths; line endings and lines that move nothing
//! are kept as they were.

use nalgebra::Vector3;
use nc::fit::deviation::measure;
use nc::fit::online::MAX_RUN;
use nc::fit::rewrite::{rewrite, Rewritten};
use nc::fit::runs::{fit_program, Options};
use nc::fixtures::{blade, g01_program, resample, small_mill};
use nc::kinematics::{MachineKinematics, Tilt};
use nc::program::{Block, NurbsKind};
use nc::segment::build;
use std::path::{Path, PathBuf};

const PAPER: MachineKinematics = MachineKinematics::Paper;

fn stream(src: &str, kin: &MachineKinematics, opts: &Options) -> (String, Rewritten) {
    let (_, bl) = small_mill(0.002);
    let mut out = Vec::new();
    let setup = nc::parse::Setup::default();
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
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data"),
        &mut files,
    );
    files.sort();
    let (mut compared, mut fitted) = (0, 0);
    for file in &files {
        let src = std::fs::read_to_string(file).expect("read");
        let Ok(input) = nc::parse::parse(&src) else {
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
    let input = nc::parse::parse(&src).expect("input");
    let output = nc::parse::parse(&text).expect("output parses");
    let (a, b) = (
        build(&input, &PAPER, &bl).expect("input builds"),
        build(&output, &PAPER, &bl).expect("output builds"),
    );
    let dev = measure(&a, &b, &PAPER, 0.002);
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
fn line_endings_and_lines_that_move_nothing_are_kept() {
    let src = sweep(300);
    let opts = Options::default();
    let parse = |s: &str| nc::parse::parse(s).expect("parses");
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
}
