//! Start-up modes: in effect before the first line, only codes that set a mode, each error
//! with its column.

use super::linear;
use crate::{parse_with, Setup, Startup};

fn with(startup: &str) -> Setup {
    let mut setup = Setup::default();
    setup.startup = Startup::parse(startup, &setup).unwrap_or_else(|e| panic!("{startup}: {e}"));
    setup
}

fn refused(startup: &str) -> (u32, String) {
    let e = Startup::parse(startup, &Setup::default()).expect_err(startup);
    (e.col, e.message)
}

#[test]
fn startup_modes_are_in_effect_from_the_first_line() {
    // Inches and incremental distances from the start (from the reference position): the
    // program says neither.
    let mut setup = with("G20 G91 G17 G40 G49 G94 G64 P0.001");
    setup.reference = Some([0.0; 3]);
    let p = parse_with("G0 X1 Y2 Z3\nG0 X1\nM2", &setup).unwrap();
    let ends: Vec<[f64; 3]> = p.blocks.iter().map(|b| linear(b).end).collect();
    let near = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    assert!(near(ends[1], [25.4, 50.8, 76.2]), "{ends:?}");
    assert!(near(ends[2], [50.8, 50.8, 76.2]), "{ends:?}");
    // A program's own G21 overrides them, and the predefined parameters see them.
    let src = "G0 X[#<_imperial>] Y0 Z0\nG21 G0 X1\nM2";
    let p = parse_with(src, &with("G20")).unwrap();
    assert_eq!(linear(&p.blocks[0]).end[0], 25.4);
    assert_eq!(linear(&p.blocks[1]).end[0], 1.0);
    // Without start-up modes: mm, absolute.
    let p = parse_with("G0 X1 Y2 Z3\nM2", &Setup::default()).unwrap();
    assert_eq!(linear(&p.blocks[0]).end, [1.0, 2.0, 3.0]);
    assert_eq!(with("  G21  ").startup.text(), "G21");
}

#[test]
fn a_startup_path_mode_reaches_the_compressor_and_no_other_startup_word_is_reported() {
    use nc_geom::program::{ActionKind, PathMode};
    let kinds = |startup: &str| -> Vec<ActionKind> {
        let p = parse_with("G0 X1 Y2 Z3\nM2", &with(startup)).unwrap();
        p.actions.iter().map(|a| a.kind).collect()
    };
    // LinuxCNC's default mode says nothing the compressor does not assume.
    assert_eq!(kinds("G17 G21 G64 G90"), []);
    assert_eq!(kinds("G61"), [ActionKind::PathMode(PathMode::Exact)]);
    match kinds("G20 G64 P0.001")[..] {
        [ActionKind::PathMode(PathMode::Blend {
            p_mm: Some(p),
            q_mm: None,
        })] => {
            assert!((p - 0.0254).abs() < 1e-12)
        }
        ref k => panic!("{k:?}"),
    }
}

#[test]
fn startup_modes_refuse_what_is_not_a_mode_with_its_column() {
    let (col, message) = refused("G20 G0");
    assert_eq!(col, 5);
    assert!(message.contains("only codes that set a mode"), "{message}");
    assert_eq!(refused("G21 X1").0, 5);
    assert_eq!(refused("M3").0, 1);
    assert_eq!(refused("G21 F100").0, 5);
    let (col, message) = refused("G21 P0.01");
    assert_eq!(col, 5);
    assert!(message.contains("only with G64"), "{message}");
    // Two of one modal group, as on a program's line.
    assert!(
        refused("G20 G21").1.contains("modal group"),
        "{}",
        refused("G20 G21").1
    );
    // A work offset the machine does not define.
    assert!(refused("G55").1.contains("G55"), "{}", refused("G55").1);
    // One line only, and what does not parse.
    assert_eq!(refused("G20\nG17").0, 4);
    assert_eq!(refused("G20 G2.5").0, 5);
}
