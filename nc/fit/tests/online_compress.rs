//! On-line compression inside the streaming window (`nc_fit::online::Compressing`: the
//! parser's entries in, runs of moves out as G06.5 blocks, holding only the run being
//! gathered) makes the blocks and words that compressing the whole parsed program makes
//! (`nc_fit::compress::compress`), on programs written here and generated ones with
//! corners, rapids, dwells, words, feed changes, stretches in inverse time (`G93`) and tool
//! turns; a run in inverse time becomes a block at its length over its time; and a run
//! longer than it holds is fitted in pieces that meet at programmed points, each within
//! the tolerances.

use nalgebra::Vector3;
use nc_fit::compress::{compress, Compressed};
use nc_fit::deviation::{measure, Deviation};
use nc_fit::online::{Compressing, MAX_RUN};
use nc_fit::options::{Options, Policy};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::{Action, Block, Program};
use nc_geom::segment::build;
use nc_lang::{Entries, Entry, Setup, StrLines};
use proptest::prelude::*;
use std::fmt::Write;

const KIN: MachineKinematics = MachineKinematics::Paper;

/// The blocks and actions the streaming compressor gives for `text`, and what it did.
fn streamed(text: &str, opts: &Options) -> (Vec<Block>, Vec<Action>, Compressed) {
    let (blocks, actions, done) = streamed_under(text, &Policy::on(*opts));
    (blocks, actions, done.expect("compression is on"))
}

/// [`streamed`] under `policy`; None: it was never on.
fn streamed_under(text: &str, policy: &Policy) -> (Vec<Block>, Vec<Action>, Option<Compressed>) {
    let setup = Setup::default();
    let mut c = Compressing::new(Entries::new(StrLines::new(text), &setup), &KIN, *policy);
    let (mut blocks, mut actions) = (Vec::new(), Vec::new());
    for e in c.by_ref() {
        match e.expect("parses") {
            Entry::Block(i, b) => {
                assert_eq!(i, blocks.len(), "blocks are numbered as given");
                blocks.push(b);
            }
            Entry::Action(a) => {
                assert_eq!(
                    a.before_block,
                    blocks.len(),
                    "a word comes before its block"
                );
                actions.push(a);
            }
        }
    }
    (blocks, actions, c.compressed())
}

/// How far the path of `blocks` (what the compressor gave for `text`) lies from the path of
/// `text` as parsed, both built on the small mill: measured, not taken from the fit.
fn built_deviation(text: &str, blocks: Vec<Block>, tol_mm: f64) -> Deviation {
    let input = nc_lang::parse(text).unwrap();
    let output = Program {
        blocks,
        ..input.clone()
    };
    let (_, bl) = nc_plan::fixtures::small_mill(0.002);
    let (a, b) = (
        build(&input, &KIN, &bl).unwrap(),
        build(&output, &KIN, &bl).unwrap(),
    );
    measure(&a, &b, &KIN, 0.005, tol_mm)
}

fn same_as_whole(name: &str, text: &str, opts: &Options) -> Compressed {
    same_as_whole_under(name, text, &Policy::on(*opts)).expect("compression is on")
}

fn same_as_whole_under(name: &str, text: &str, policy: &Policy) -> Option<Compressed> {
    let program = nc_lang::parse(text).expect("parses");
    let (whole, done) = compress(&program, &KIN, policy);
    let (blocks, actions, got) = streamed_under(text, policy);
    assert_eq!(blocks, whole.blocks, "{name}: blocks");
    assert_eq!(actions, whole.actions, "{name}: words");
    assert_eq!(got, done, "{name}: what the compressor did");
    got
}

#[test]
fn the_stream_compresses_as_the_whole_program_is_compressed() {
    let opts = Options::default();
    let mut fitted = 0;
    for rel in nc_plan::fixtures::TEST_PROGRAMS {
        fitted += same_as_whole(rel, &nc_plan::fixtures::test_program(rel), &opts).fitted_blocks;
    }
    for rel in ["fit/blade-sweep-3000.nc", "fit/paper-fig7-20-moves.nc"] {
        fitted += same_as_whole(rel, &nc_plan::fixtures::test_program(rel), &opts).fitted_blocks;
    }
    for seed in 1..4 {
        let name = format!("generated, seed {seed}");
        fitted += same_as_whole(&name, &generated(seed, 3000, false), &opts).fitted_blocks;
    }
    assert!(fitted >= 20, "{fitted} blocks fitted");
}

/// A generated program: moves of 0.05 to 0.3 mm along a wandering direction whose turns
/// are mostly gentle, some sharper than the corner angle; the tool axis swinging a little,
/// sometimes jumping; and now and then a word, a dwell, a rapid, a feed change, or a switch
/// between a feed per minute and inverse time (`G93`: F on every move, 1/minutes for its
/// own length at the feed, to one decimal as a post writes it); with `path_words`, now and
/// then a path-control word too (`G61`, `G61.1`, `G64`, `G64 P`, `G64 Q`, `Q0`).
fn generated(seed: u64, moves: usize, path_words: bool) -> String {
    let mut rng = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move || {
        rng = rng
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((rng >> 11) as f64) / ((1u64 << 53) as f64)
    };
    let mut s = String::from("G90 G21 G94\nG00 X0 Y0 Z5 I0 J0 K1\nG01 Z0 F2000\n");
    let (mut p, mut dir, mut tilt) = (Vector3::new(0.0, 0.0, 0.0), 0.0f64, 0.0f64);
    let (mut feed, mut inverse) = (2000.0, false);
    for k in 0..moves {
        let r = next();
        if r < 0.01 {
            s += "M08\n";
        } else if r < 0.015 {
            s += "G04 P0.1\n";
        } else if r < 0.02 {
            feed = 1000.0 + (next() * 4.0).floor() * 500.0;
        } else if r < 0.025 {
            inverse = !inverse;
            s += if inverse { "G93\n" } else { "G94\n" };
        } else if r < 0.035 && path_words {
            let words = [
                "G61",
                "G61.1",
                "G64",
                "G64 P0.01",
                "G64 P0.01 Q0.004",
                "G64 Q0",
            ];
            let w = words[((next() * words.len() as f64) as usize).min(words.len() - 1)];
            s += &format!("{w}\n");
        }
        let turn = if next() < 0.03 {
            0.5 + next()
        } else {
            0.02 * (next() - 0.5)
        };
        dir += turn;
        tilt = if next() < 0.02 {
            0.4 * next()
        } else {
            (tilt + 0.004 * (next() - 0.5)).clamp(0.0, 0.5)
        };
        let step = 0.05 + 0.25 * next();
        let d = Vector3::new(dir.cos(), dir.sin(), 0.05 * (k as f64 * 0.01).sin()) * step;
        p += d;
        let t = Vector3::new(tilt.sin() * dir.cos(), tilt.sin() * dir.sin(), tilt.cos());
        let g = if next() < 0.005 { "G00 " } else { "G01 " };
        let f = if inverse {
            format!("{:.1}", feed / d.norm())
        } else {
            format!("{feed}")
        };
        let _ = writeln!(
            s,
            "{g}X{:.4} Y{:.4} Z{:.4} I{:.6} J{:.6} K{:.6} F{f}",
            p.x, p.y, p.z, t.x, t.y, t.z
        );
    }
    s + "M30\n"
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]
    #[test]
    fn generated_programs_compress_alike_streamed_and_whole(seed in any::<u64>(), moves in 50usize..1500) {
        let opts = Options::default();
        same_as_whole(&format!("seed {seed}, {moves} moves"), &generated(seed, moves, false), &opts);
    }

    /// The program's path-control words turn the compressor on and off and set its
    /// tolerance alike in both, whatever the machine's setting.
    #[test]
    fn path_words_compress_alike_streamed_and_whole(seed in any::<u64>(), moves in 50usize..1500, on: bool, follow: bool) {
        let policy = Policy { opts: Options::default(), on, follow_program: follow };
        let text = generated(seed, moves, true);
        same_as_whole_under(&format!("seed {seed}, {moves} moves, {policy:?}"), &text, &policy);
    }
}

/// A run of more moves than the compressor holds becomes blocks of at most `MAX_RUN` moves,
/// each ending on a programmed point (where the next starts), all within the tolerances
/// of the programmed path (measured on the built paths, not by the fit).
#[test]
fn a_run_longer_than_the_window_is_fitted_in_pieces_within_the_tolerances() {
    let n = 2 * MAX_RUN + 5_000;
    let points: Vec<_> = (0..=n)
        .map(|k| {
            let x = 0.05 * k as f64;
            (Vector3::new(x, 3.0 * (x / 40.0).sin(), 0.0), Vector3::z())
        })
        .collect();
    let text = nc_plan::fixtures::g01_program(&points, 3000.0);
    let opts = Options::default();
    let (blocks, _, done) = streamed(&text, &opts);
    assert_eq!(done.fitted_blocks, 3, "{done:?}");
    assert_eq!(done.moves_fitted, n, "{done:?}");
    let ends: Vec<[f64; 3]> = blocks
        .iter()
        .filter_map(|b| match b {
            Block::Nurbs(nb) => nb.ctrl.last().copied(),
            Block::Linear(_) => None,
        })
        .collect();
    for (i, e) in ends.iter().enumerate() {
        let k = (MAX_RUN * (i + 1)).min(n);
        let want = points[k].0;
        // The program gives the points to 4 decimals.
        assert!(
            (Vector3::from(*e) - want).norm() < 1e-4,
            "block {i} ends at {e:?}, not {want}"
        );
    }
    let dev = built_deviation(&text, blocks, opts.tol.mm);
    // As nc/tests/fit.rs allows: the sampling resolves the distance to 0.5 um.
    assert!(dev.point_mm <= opts.tol.mm + 5e-7, "{dev:?}");
}

/// `G93` moves along a smooth curve, F to one decimal for each move's own length at
/// `feed(k)` mm/min, `step` mm apart.
fn inverse_time_program(n: usize, step: f64, feed: impl Fn(usize) -> f64) -> String {
    let p = |k: usize| {
        let x = step * k as f64;
        Vector3::new(x, 3.0 * (x / 20.0).sin(), 0.0)
    };
    let mut s = String::from("G90 G21 G94\nG00 X0 Y0 Z0 I0 J0 K1\nG93\n");
    for k in 1..=n {
        let f = feed(k) / (p(k) - p(k - 1)).norm();
        let e = p(k);
        let _ = writeln!(s, "G01 X{:.4} Y{:.4} Z0 F{f:.1}", e.x, e.y);
    }
    s + "G94\nM30\n"
}

/// A run in inverse time becomes one block at its length over its time (the sum of each
/// move's length over the speed its `F` gives it), as the whole program's compression makes
/// it; a change of speed beyond the spread a post's rounding makes starts a new block; a
/// run at a speed no feed per minute can give stays as it is.
#[test]
fn a_run_in_inverse_time_becomes_a_block_at_its_length_over_its_time() {
    let opts = Options::default();
    let text = inverse_time_program(400, 0.1, |_| 2400.0);
    same_as_whole("G93 at 2400 mm/min", &text, &opts);
    let (blocks, _, done) = streamed(&text, &opts);
    assert_eq!(
        (done.fitted_blocks, done.moves_fitted),
        (1, 400),
        "{done:?}"
    );
    let program = nc_lang::parse(&text).unwrap();
    let (mut length, mut minutes) = (0.0, 0.0);
    for w in program.blocks.windows(2) {
        if let [Block::Linear(a), Block::Linear(m)] = w {
            if !m.rapid {
                assert!(m.inverse_time);
                let d = (Vector3::from(m.end) - Vector3::from(a.end)).norm();
                (length, minutes) = (length + d, minutes + d / m.feed_mm_min);
            }
        }
    }
    let Some(Block::Nurbs(nb)) = blocks.iter().find(|b| matches!(b, Block::Nurbs(_))) else {
        panic!("no G06.5 block in {blocks:?}");
    };
    assert!(
        (nb.feed_mm_min - length / minutes).abs() < 1e-9 * nb.feed_mm_min,
        "{} mm/min, not {}",
        nb.feed_mm_min,
        length / minutes
    );
    assert!((nb.feed_mm_min - 2400.0).abs() < 2.4, "{}", nb.feed_mm_min);
    // 2 % faster from move 200 on: two blocks.
    let text = inverse_time_program(400, 0.1, |k| if k < 200 { 2400.0 } else { 2448.0 });
    let done = same_as_whole("G93, 2 % faster half way", &text, &opts);
    assert_eq!(
        (done.fitted_blocks, done.moves_fitted),
        (2, 400),
        "{done:?}"
    );
    // 2 mm moves at F999999.9 (1/min): 2 000 000 mm/min, left as G01 moves and no run kept.
    let text = inverse_time_program(40, 2.0, |_| 2.0e6);
    let done = same_as_whole("G93 beyond any feed", &text, &opts);
    assert_eq!((done.fitted_blocks, done.runs_kept), (0, 0), "{done:?}");
}

/// A curve posted as 0.1 mm moves whose points zigzag 3 um off it (a coarse post), three
/// times: under `G61`, under `G64` (the machine's setting: off here) and under
/// `G64 P0.05 Q0.02`. Only the last is merged, within the program's 0.02 mm rather than the
/// machine's 0.001 mm, measured on the built paths.
#[test]
fn g64_q_turns_the_compressor_on_with_its_tolerance_and_g61_keeps_the_moves() {
    let mut s = String::from("G90 G21 G94\nG00 X0 Y0 Z0 I0 J0 K1\nG01 F3000\n");
    for section in 0..3 {
        s += ["G61\n", "G64\n", "G64 P0.05 Q0.02\n"][section];
        for k in 1..=400 {
            let x = 40.0 * section as f64 + 0.1 * k as f64;
            // 7 degrees between moves: below the corner angle.
            let zig = if k % 2 == 0 { 0.003 } else { -0.003 };
            let _ = writeln!(s, "X{x:.4} Y{:.4}", 3.0 * (x / 7.0).sin() + zig);
        }
    }
    s += "M30\n";
    let opts = Options::default();
    let machine_off = Policy {
        on: false,
        ..Policy::on(opts)
    };
    let done =
        same_as_whole_under("G61, G64, G64 Q", &s, &machine_off).expect("G64 Q turned it on");
    let (blocks, _, _) = streamed_under(&s, &machine_off);
    // The first 800 moves stay as they are (and the G00 and the G01 start).
    let linear = blocks
        .iter()
        .take_while(|b| matches!(b, Block::Linear(_)))
        .count();
    assert!(linear >= 801, "{linear} moves before the first block");
    assert_eq!(done.moves_fitted, 400, "{done:?}");
    assert!(
        done.fit_mm > 2.0 * opts.tol.mm && done.fit_mm <= 0.02,
        "{done:?}"
    );
    // Measured on the built paths, not by the fit.
    let dev = built_deviation(&s, blocks, 0.02);
    assert!(dev.point_mm <= 0.02 + 5e-7, "{dev:?}");
    // `--no-compress`: never; the machine's setting on: the G64 section at its tolerance.
    assert_eq!(
        same_as_whole_under("no-compress", &s, &Policy::off(opts)),
        None
    );
    let on = same_as_whole_under("machine on", &s, &Policy::on(opts)).unwrap();
    assert_eq!(on.moves_fitted % 400, 0, "{on:?}");
    assert!(on.moves_fitted >= 400 && on.fit_mm <= 0.02, "{on:?}");
}
