//! NURBS-block rules, and positions on the continuation lines of the paper's example.

use super::{fails, g065, message, KNOTS, OPEN, POINT};
use crate::tests::{at, PAPER};
use crate::{Motion, ParseErrorKind as E};

// ---- NURBS blocks --------------------------------------------------------------------------

#[test]
fn g065_without_degree() {
    let src = g065("G06.5 X0 Y0 Z0 U0 V0 W1 K0", POINT, KNOTS);
    assert_eq!(fails(&src, 2, 1), E::MissingDegree);
}

#[test]
fn degree_out_of_range() {
    for p in ["P0", "P6", "P2.5"] {
        let src = g065(&OPEN.replace("P1", p), POINT, KNOTS);
        assert!(
            matches!(
                fails(&src, 2, 7),
                E::BadDegree {
                    motion: Motion::G065,
                    ..
                }
            ),
            "{p}"
        );
    }
    let src = "G01 X0 Y0 Z0 F500\nG06.2 P7 K0 X0 Y0 Z0";
    assert_eq!(
        fails(src, 2, 7),
        E::BadDegree {
            motion: Motion::G062,
            value: 7.0
        }
    );
    let src = "G01 X0 Y0 Z0 F500\nG06.2 P1 K0 X0 Y0 Z0";
    assert_eq!(
        fails(src, 2, 7),
        E::BadDegree {
            motion: Motion::G062,
            value: 1.0
        }
    );
    assert!(
        message(src).ends_with("G06.2 P1: the rank (degree + 1) must be an integer from 2 to 6")
    );
}

#[test]
fn weight_must_be_positive() {
    let src = g065(OPEN, "X10 Y0 Z0 U10 V0 W1 R0 K0", KNOTS);
    assert_eq!(fails(&src, 3, 21), E::BadWeight { value: 0.0 });
}

#[test]
fn too_few_control_points() {
    let src = g065(&OPEN.replace("P1", "P3"), POINT, "K1 K1 K1 K1");
    assert_eq!(
        fails(&src, 2, 1),
        E::TooFewControlPoints { count: 2, min: 4 }
    );
}

#[test]
fn too_many_control_points() {
    let points: String = (1..=100_000)
        .map(|i| format!("X{i} Y0 Z0 U{i} V0 W1 K0\n"))
        .collect();
    let src = format!("G01 X0 Y0 Z0 F500\n{OPEN}\n{points}K1 K1\n");
    assert_eq!(fails(&src, 100_002, 1), E::TooManyControlPoints);
    assert!(message(&src).contains("MAX_BLOCK_CTRL = 100000"));
}

#[test]
fn block_cut_short() {
    let src = g065(OPEN, POINT, "K1\nG01 X1");
    assert_eq!(
        fails(&src, 5, 1),
        E::IncompleteKnots {
            opened: at(2, 1),
            have: 3,
            need: 4
        }
    );
    assert_eq!(
        message(&src),
        "5:1: block opened at 2:1 has 3 knots, needs 4 (control points + degree + 1)"
    );
    // End of file: the position just past the last character.
    assert!(matches!(
        fails(&g065(OPEN, POINT, "K1"), 4, 3),
        E::IncompleteKnots {
            have: 3,
            need: 4,
            ..
        }
    ));
    // Bare coordinates (a forgotten knot line before a modal G01 line).
    let src = g065(OPEN, POINT, "X5 Y5 Z5");
    assert!(matches!(
        fails(&src, 4, 1),
        E::IncompleteKnots {
            have: 2,
            need: 4,
            ..
        }
    ));
    // A control point after the knots started.
    let src = g065(OPEN, POINT, "K1\nX20 Y0 Z0 U20 V0 W1 K1");
    assert!(matches!(
        fails(&src, 5, 1),
        E::IncompleteKnots {
            have: 3,
            need: 4,
            ..
        }
    ));
}

#[test]
fn too_many_knots() {
    let extra = E::TooManyKnots {
        value: 1.0,
        opened: at(2, 1),
        need: 4,
    };
    assert_eq!(fails(&g065(OPEN, POINT, "K1 K1 K1"), 4, 7), extra);
    assert_eq!(fails(&g065(OPEN, POINT, "K1 K1\nK1"), 5, 1), extra);
}

#[test]
fn decreasing_knot() {
    let src = g065(OPEN, POINT, "X20 Y0 Z0 U20 V0 W1 K0.5\nK0.3 K1");
    assert_eq!(
        fails(&src, 5, 1),
        E::DecreasingKnot {
            value: 0.3,
            prev: 0.5
        }
    );
    assert_eq!(
        message(&src),
        "5:1: knot K0.3 is smaller than the previous knot 0.5: knots must be non-decreasing"
    );
}

#[test]
fn unclamped_start() {
    let src = g065(OPEN, "X10 Y0 Z0 U10 V0 W1 K0.5", KNOTS);
    assert_eq!(
        fails(&src, 3, 21),
        E::UnclampedStart {
            value: 0.5,
            expected: 0.0,
            count: 2
        }
    );
}

#[test]
fn unclamped_end() {
    let src = g065(OPEN, POINT, "K0.5 K1");
    assert_eq!(
        fails(&src, 4, 1),
        E::UnclampedEnd {
            value: 0.5,
            expected: 1.0,
            count: 2
        }
    );
}

#[test]
fn empty_knot_range() {
    assert_eq!(
        fails(&g065(OPEN, POINT, "K0 K0"), 4, 4),
        E::EmptyKnotRange {
            first: 0.0,
            last: 0.0
        }
    );
}

#[test]
fn first_control_point_off_the_current_position() {
    let src = g065(&OPEN.replace("X0", "X0.002"), POINT, KNOTS);
    let kind = fails(&src, 2, 10);
    assert_eq!(
        kind,
        E::StartMismatch {
            ctrl: [0.002, 0.0, 0.0],
            current: [0.0; 3]
        }
    );
    assert!(kind
        .to_string()
        .starts_with("first control point (0.002, 0, 0) is not the current position (0, 0, 0)"));
}

#[test]
fn tool_point_too_close_to_cutter_point() {
    let src = g065(OPEN, "X10 Y0 Z0 U10 V0 W0.0005 K0", KNOTS);
    let kind = E::ToolPointTooClose {
        xyz: [10.0, 0.0, 0.0],
        uvw: [10.0, 0.0, 0.0005],
        dist: 0.0005,
    };
    assert_eq!(fails(&src, 3, 11), kind);
}

// ---- positions on continuation lines (the paper's example) ---------------------------------

#[test]
fn error_on_a_continued_line_points_at_its_physical_line() {
    let src = PAPER.replace("V85.5421", "V85.5421 V1");
    assert_eq!(
        fails(&src, 16, 10),
        E::RepeatedWord {
            letter: 'V',
            first: at(16, 1)
        }
    );
}

#[test]
fn error_before_a_backslash_points_at_its_physical_line() {
    let src = PAPER.replace("U37.2554\\", "U37.2554 X1\\");
    assert_eq!(
        fails(&src, 15, 37),
        E::RepeatedWord {
            letter: 'X',
            first: at(15, 1)
        }
    );
}

#[test]
fn knot_on_a_continued_line() {
    let src = PAPER.replace("K0.5046", "K-0.5");
    assert_eq!(
        fails(&src, 20, 27),
        E::DecreasingKnot {
            value: -0.5,
            prev: 0.0
        }
    );
}

#[test]
fn paper_block_missing_a_knot() {
    let src = PAPER.replace("K1.0000 K1.0000 K1.0000 K1.0000", "K1.0000 K1.0000 K1.0000");
    assert_eq!(
        fails(&src, 22, 1),
        E::IncompleteKnots {
            opened: at(11, 5),
            have: 8,
            need: 9
        }
    );
}
