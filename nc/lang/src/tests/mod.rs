//! Parser tests: the programs in `tests/data`, accepted syntax, modal resolution (here), one
//! test per error rule (`errors`), the no-panic property tests (`fuzz`) and reading as a
//! stream (`source`).

mod comp;
mod errors;
mod fuzz;
mod g10;
mod interp;
mod io;
mod posts;
mod source;
mod startup;

use super::parse;
use nc_geom::program::{Block, LinearMove, NurbsBlock, NurbsKind, Orientation, Program, SrcPos};

const PAPER: &str = include_str!("../../../../tests/data/paper-example.nc");
const G062: &str = include_str!("../../../../tests/data/g062-example.nc");
const G01_5AXIS: &str = include_str!("../../../../tests/data/g01-5axis.nc");

/// The end point of each block `src` parses to under `setup`.
#[track_caller]
fn block_ends(src: &str, setup: &crate::Setup) -> Vec<[f64; 3]> {
    let p = crate::parse_with(src, setup).unwrap_or_else(|e| panic!("{src}: {:?}", e.errors));
    p.blocks
        .iter()
        .map(|b| match b {
            Block::Linear(m) => m.end,
            Block::Nurbs(n) => *n.ctrl.last().expect("a control point"),
        })
        .collect()
}

fn at(line: u32, col: u32) -> SrcPos {
    SrcPos { line, col }
}

fn hvec<T: Clone>(items: &[T]) -> Vec<T> {
    items.to_vec()
}

fn linear(block: &Block) -> &LinearMove {
    match block {
        Block::Linear(m) => m,
        Block::Nurbs(b) => panic!("expected a linear move, got {b:?}"),
    }
}

fn nurbs(block: &Block) -> &NurbsBlock {
    match block {
        Block::Nurbs(b) => b,
        Block::Linear(m) => panic!("expected a NURBS block, got {m:?}"),
    }
}

fn assert_vector(o: Orientation, expected: [f64; 3]) {
    let Orientation::Vector(v) = o else {
        panic!("expected a vector, got {o:?}")
    };
    let len = expected.iter().map(|c| c * c).sum::<f64>().sqrt();
    for (a, e) in v.iter().zip(expected) {
        assert!(
            (a - e / len).abs() < 1e-15,
            "{v:?} is not {expected:?} normalised"
        );
    }
}

#[test]
fn paper_example_parses_into_the_expected_program() {
    let program = parse(PAPER).unwrap();
    assert_eq!(program.end, Some(at(22, 1)));
    assert_eq!(program.blocks.len(), 2);

    let start = linear(&program.blocks[0]);
    assert_eq!(
        (start.pos, start.n, start.rapid),
        (at(10, 5), Some(20), false)
    );
    assert_eq!(
        (start.end, start.feed_mm_min),
        ([47.7773, 71.0202, 58.8006], 400.0)
    );
    assert_vector(start.orientation, [0.0293, 0.9589, 0.2822]);

    let expected = NurbsBlock {
        pos: at(11, 5),
        n: Some(30),
        kind: NurbsKind::G065,
        degree: 3,
        ctrl: hvec(&[
            [47.7773, 71.0202, 58.8006],
            [44.3229, 75.6066, 54.4778],
            [37.2164, 84.6443, 44.5755],
            [28.7567, 101.5653, 29.7151],
            [-1.6963, 163.6796, 5.8369],
        ]),
        tool_ctrl: hvec(&[
            [47.8066, 71.9791, 59.0828],
            [44.3651, 76.5494, 54.8138],
            [37.2554, 85.5421, 45.0342],
            [28.7081, 102.3535, 30.3361],
            [-1.8572, 163.9906, 6.7762],
        ]),
        ctrl_pos: hvec(&[at(11, 14), at(13, 1), at(15, 1), at(17, 1), at(19, 1)]),
        weights: hvec(&[1.0; 5]),
        knots: hvec(&[0.0, 0.0, 0.0, 0.0, 0.5046, 1.0, 1.0, 1.0, 1.0]),
        feed_mm_min: 400.0,
        tooling: Default::default(),
        turn_to: None,
    };
    assert_eq!(nurbs(&program.blocks[1]), &expected);
}

#[test]
fn g062_example_converts_rank_to_degree() {
    let program = parse(G062).unwrap();
    assert_eq!(program.blocks.len(), 4);
    let b = nurbs(&program.blocks[2]);
    assert_eq!(
        (b.kind, b.degree, b.pos, b.n),
        (NurbsKind::G062, 3, at(8, 5), Some(30))
    );
    assert_eq!(b.ctrl.len(), 6);
    assert!(b.tool_ctrl.is_empty());
    assert_eq!(b.ctrl[3], [45.0, 10.0, -2.0]);
    assert_eq!(b.weights, hvec(&[1.0, 1.0, 0.8, 1.2, 1.0, 1.0]));
    assert_eq!(
        b.knots,
        hvec(&[0.0, 0.0, 0.0, 0.0, 0.3333, 0.6667, 1.0, 1.0, 1.0, 1.0])
    );
    assert_eq!((b.ctrl_pos[0], b.ctrl_pos[1]), (at(8, 14), at(9, 5)));
    assert_eq!(b.feed_mm_min, 1500.0);
    // After the block: its last control point, the G01 mode, the same (vertical) tool.
    let last = linear(&program.blocks[3]);
    assert_eq!(
        (last.end, last.rapid, last.feed_mm_min),
        ([70.0, 20.0, 5.0], false, 1500.0)
    );
    assert_eq!(last.orientation, Orientation::Vector([0.0, 0.0, 1.0]));
}

#[test]
fn g01_5axis_example_resolves_modal_values() {
    let program = parse(G01_5AXIS).unwrap();
    let moves: Vec<&LinearMove> = program.blocks.iter().map(linear).collect();
    assert_eq!(moves.len(), 11);
    assert_eq!(
        (moves[1].rapid, moves[1].pos, moves[1].n),
        (true, at(6, 1), Some(20))
    );
    assert_eq!(
        (moves[2].end, moves[2].rapid, moves[2].feed_mm_min),
        ([20.0, 10.0, 5.0], false, 1000.0)
    );
    assert_eq!(moves[2].orientation, Orientation::Vector([0.0, 0.0, 1.0]));
    assert_vector(moves[3].orientation, [0.0, 0.2588, 0.9659]);
    assert_eq!(moves[5].feed_mm_min, 2000.0);
    assert_eq!(
        moves[7].orientation,
        Orientation::Angles {
            r1_deg: 10.0,
            r2_deg: 0.0
        }
    );
    assert_eq!(
        moves[9].orientation,
        Orientation::Angles {
            r1_deg: 15.0,
            r2_deg: 45.0
        }
    );
    assert_eq!((moves[10].end, moves[10].rapid), ([80.0, 25.0, 50.0], true));
    assert_eq!(program.end, Some(at(16, 1)));
}

#[test]
fn accepts_compact_lower_case_and_commented_syntax() {
    let src = "%\n(header)\nn1 g90g21 g00x0y0z10 ; rapid\nG01X1.Y-.5Z+2F500(inline)\nM2\n\n% \n";
    let program = parse(src).unwrap();
    assert_eq!(program.blocks.len(), 2);
    let m = linear(&program.blocks[1]);
    assert_eq!(
        (m.end, m.pos, program.end),
        ([1.0, -0.5, 2.0], at(4, 1), Some(at(5, 1)))
    );
}

#[test]
fn empty_program_and_program_without_end_are_fine() {
    assert_eq!(parse("").unwrap(), Program::default());
    assert_eq!(parse("G00 X0 Y0 Z0\n").unwrap().end, None);
}

#[test]
fn mode_only_lines_emit_no_block() {
    let program = parse("G90 G21\nF300\nG01\nN5\nG00 X0 Y0 Z0\nG01\nX5\n").unwrap();
    assert_eq!(program.blocks.len(), 2);
    assert_eq!(
        (
            linear(&program.blocks[1]).rapid,
            linear(&program.blocks[1]).feed_mm_min
        ),
        (false, 300.0)
    );
}

#[test]
fn modal_continuation_line_is_placed_at_its_first_word() {
    let program = parse("G00 X0 Y0 Z0\nN7 X1\n  Y2\n").unwrap();
    assert_eq!(program.blocks[1].pos(), at(2, 1));
    assert_eq!(program.blocks[2].pos(), at(3, 3));
}

#[test]
fn angles_inherit_missing_values() {
    let program = parse("G00 X0 Y0 Z0 A10\nC5\nA20\n").unwrap();
    let o: Vec<Orientation> = program
        .blocks
        .iter()
        .map(|b| linear(b).orientation)
        .collect();
    assert_eq!(
        o[0],
        Orientation::Angles {
            r1_deg: 10.0,
            r2_deg: 0.0
        }
    );
    assert_eq!(
        o[1],
        Orientation::Angles {
            r1_deg: 10.0,
            r2_deg: 5.0
        }
    );
    assert_eq!(
        o[2],
        Orientation::Angles {
            r1_deg: 20.0,
            r2_deg: 5.0
        }
    );
    // Both angles after a vector are fine, and B C machines work the same way.
    let bc = parse("G00 X0 Y0 Z0 I1 J0 K1\nB30 C90\n").unwrap();
    assert_eq!(
        linear(&bc.blocks[1]).orientation,
        Orientation::Angles {
            r1_deg: 30.0,
            r2_deg: 90.0
        }
    );
}

#[test]
fn g065_sets_the_orientation_and_motion_mode_resumes_after_it() {
    let src =
        "G00 X0 Y0 Z0\nF500\nG06.5 P1 X0 Y0 Z0 U0 V0 W1 K0\nX10 Y0 Z0 U10 V3 W4 K0\nK1 K1\nX20\n";
    let program = parse(src).unwrap();
    let after = linear(&program.blocks[2]);
    assert_eq!(
        (after.end, after.rapid, after.pos),
        ([20.0, 0.0, 0.0], true, at(6, 1))
    );
    assert_vector(after.orientation, [0.0, 3.0, 4.0]);
}

#[test]
fn g062_rank_defaults_to_4() {
    let src = "G01 X0 Y0 Z0 F500\nG06.2 K0 X0 Y0 Z0\nK0 X1 Y1 Z0\nK0 X2 Y1 Z0\nK0 X3 Y0 Z0\nK1 K1 K1 K1\n";
    let b = nurbs(&parse(src).unwrap().blocks[1]).clone();
    assert_eq!((b.degree, b.ctrl.len(), b.knots.len()), (3, 4, 8));
}

#[test]
fn start_within_one_micron_is_accepted() {
    let src = "G01 X0 Y0 Z0 F500\nG06.2 P2 K0 X0.001 Y-0.001 Z0\nK0 X10 Y0 Z0\nK1 K1\n";
    assert_eq!(nurbs(&parse(src).unwrap().blocks[1]).degree, 1);
}

#[test]
fn continuation_keeps_physical_positions() {
    // The backslash may be followed by spaces; words on the next line keep their own place.
    let src = "G00 X0 \\  \n  Y0 Z0\nG01 X1 \\\n(c) F500 \\\n Y2\n";
    let program = parse(src).unwrap();
    assert_eq!(program.blocks.len(), 2);
    assert_eq!(linear(&program.blocks[1]).end, [1.0, 2.0, 0.0]);
    assert_eq!(program.blocks[1].pos(), at(3, 1));
}
