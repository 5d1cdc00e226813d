//! On-line compression inside the streaming window (`nc::fit::online::Compressing`: the
//! parser's entries in, runs of moves out as G06.5 blocks, holding only the run being
//! gathered) makes the blocks and words that compressing the whole parsed program makes
//! (`nc::fit::compress::compress`), on programs written here and generated ones with
//! corners, rapids, dwells, words, feed changes and tool turns; and a run longer than it
//! holds is fitted in pieces that meet at programmed points, each within the tolerances.

use nalgebra::Vector3;
use nc::fit::compress::{compress, Compressed};
use nc::fit::deviation::measure;
use nc::fit::online::{Compressing, MAX_RUN};
use nc::fit::runs::Options;
use nc::kinematics::MachineKinematics;
use nc::parse::{Entries, Entry, Setup, StrLines};
use nc::program::{Action, Block, Program};
use nc::segment::build;
use proptest::prelude::*;
use std::fmt::Write;

const KIN: MachineKinematics = MachineKinematics::Paper;

/// The blocks and actions the streaming compressor gives for `text`, and what it did.
fn streamed(text: &str, opts: &Options) -> (Vec<Block>, Vec<Action>, Compressed) {
    let setup = Setup::default();
    let mut c = Compressing::new(Entries::new(StrLines::new(text), &setup), &KIN, Some(*opts));
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
    (blocks, actions, c.compressed().expect("compression is on"))
}

fn same_as_whole(name: &str, text: &str, opts: &Options) -> Compressed {
    let program = nc::parse::parse(text).expect("parses");
    let (whole, done) = compress(&program, &KIN, opts);
    let (blocks, actions, got) = streamed(text, opts);
    assert_eq!(blocks, whole.blocks, "{name}: blocks");
    assert_eq!(actions, whole.actions, "{name}: words");
    assert_eq!(got, done, "{name}: what the compressor did");
    got
}

#[test]
fn the_stream_compresses_as_the_whole_program_is_compressed() {
    let opts = Options::default();
    let mut fitted = 0;
    for rel in nc::fixtures::TEST_PROGRAMS {
        fitted += same_as_whole(rel, &nc::fixtures::test_program(rel), &opts).fitted_blocks;
    }
    for rel in ["fit/blade-sweep-3000.nc", "fit/paper-fig7-20-moves.nc"] {
        fitted += same_as_whole(rel, &nc::fixtures::test_program(rel), &opts).fitted_blocks;
    }
    for seed in 1..4 {
        let name = format!("generated, seed {seed}");
        fitted += same_as_whole(&name, &generated(seed, 3000), &opts).fitted_blocks;
    }
    assert!(fitted >= 20, "{fitted} blocks fitted");
}

/// A generated program: moves of 0.05 to 0.3 mm along a wandering direction whose turns
/// are mostly gentle, some sharper than the corner angle; the tool axis swinging a little,
/// sometimes jumping; and now and then a word, a dwell, a rapid or a feed change.
fn generated(seed: u64, moves: usize) -> String {
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
    let mut feed = 2000.0;
    for k in 0..moves {
        let r = next();
        if r < 0.01 {
            s += "M08\n";
        } else if r < 0.015 {
            s += "G04 P0.1\n";
        } else if r < 0.02 {
            feed = 1000.0 + (next() * 4.0).floor() * 500.0;
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
        p += Vector3::new(dir.cos(), dir.sin(), 0.05 * (k as f64 * 0.01).sin()) * step;
        let t = Vector3::new(tilt.sin() * dir.cos(), tilt.sin() * dir.sin(), tilt.cos());
        let g = if next() < 0.005 { "G00 " } else { "G01 " };
        let _ = writeln!(
            s,
            "{g}X{:.4} Y{:.4} Z{:.4} I{:.6} J{:.6} K{:.6} F{feed}",
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
        same_as_whole(&format!("seed {seed}, {moves} moves"), &generated(seed, moves), &opts);
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
    let text = nc::fixtures::g01_program(&points, 3000.0);
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
    let input = nc::parse::parse(&text).unwrap();
    let output = Program {
        blocks,
        ..input.clone()
    };
    let (_, bl) = nc::fixtures::small_mill(0.002);
    let (a, b) = (
        build(&input, &KIN, &bl).unwrap(),
        build(&output, &KIN, &bl).unwrap(),
    );
    let dev = measure(&a, &b, &KIN, 0.005);
    // As nc/tests/fit.rs allows: the sampling resolves the distance to 0.5 um.
    assert!(dev.point_mm <= opts.tol.mm + 5e-7, "{dev:?}");
}
