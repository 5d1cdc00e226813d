//! Modal-state and tool-orientation rules.

use super::fails;
use crate::tests::at;
use crate::{Motion, ParseErrorKind as E};

// ---- modal state ---------------------------------------------------------------------------

#[test]
fn feed_must_be_positive() {
    // F0 is no feed, as LinuxCNC's feed rate 0: the feed move is refused, at its code.
    assert_eq!(
        fails("G01 X0 Y0 Z0 F0", 1, 1),
        E::NoFeed {
            motion: Motion::G01
        }
    );
    // G94 (and G95) set the feed to 0, as in LinuxCNC, unless F is on its line.
    assert_eq!(
        fails("G01 X0 Y0 Z0 F100\nG94 G01 X1", 2, 5),
        E::NoFeed {
            motion: Motion::G01
        }
    );
    assert_eq!(
        fails("G0 X0 Y0 Z0\nG95 F0.1 G01 X1", 2, 10),
        E::PerRevWithoutSpeed {
            motion: Motion::G01
        }
    );
    assert_eq!(fails("F-5", 1, 1), E::BadFeed { value: -5.0 });
    // Measured: F0.01 over 27 mm ran simulate into its cycle limit at 11.5 GB.
    assert_eq!(
        fails("G01 X0 Y0 Z0 F0.0009", 1, 14),
        E::BadFeed { value: 0.0009 }
    );
}

#[test]
fn numbers_outside_the_documented_domain_are_refused_where_written() {
    // Measured: X1 followed by 200 zeros panicked in the segment builder; Z1e11 aborted
    // allocating 408 TB.
    let big = format!("G01 X0 Y0 Z0 F100\nG01 X1{}", "0".repeat(200));
    assert!(matches!(fails(&big, 2, 5), E::OutsideDomain { letter: 'X', max, .. } if max == 1e5));
    assert!(matches!(
        fails("G01 X0 Y0 Z100000000000 F100", 1, 11),
        E::OutsideDomain { letter: 'Z', .. }
    ));
    assert!(matches!(
        fails("G01 X0 Y0 Z0 A1000001 C0 F100", 1, 14),
        E::OutsideDomain { letter: 'A', .. }
    ));
    assert!(matches!(
        fails("G01 X0 Y0 Z0 F1000000001", 1, 14),
        E::OutsideDomain { letter: 'F', .. }
    ));
    // The bounds themselves are accepted.
    crate::parse("G01 X100000 Y-100000 Z0 F1000000000\n").unwrap();
}

#[test]
fn a_feed_above_the_machines_highest_is_said_where_it_stands_once_per_value() {
    use nc_geom::program::ActionKind;
    let setup = crate::Setup {
        max_feed_mm_min: Some(10_000.0),
        ..crate::Setup::default()
    };
    let src = "G01 X0 Y0 Z0 F20000\nX1 F20000\nX2 F9000\nG20 X0.1 F500\nX0.2 F393\nM2";
    let p = crate::parse_with(src, &setup).unwrap();
    let said: Vec<(f64, u32, u32)> = p
        .actions
        .iter()
        .filter_map(|a| match a.kind {
            ActionKind::FeedClamped {
                programmed_mm_min,
                used_mm_min,
            } => {
                assert_eq!(used_mm_min, 10_000.0);
                Some((programmed_mm_min, a.pos.line, a.pos.col))
            }
            _ => None,
        })
        .collect();
    // F500 inch/min is 12 700 mm/min; F393 (9 982 mm/min) is below.
    assert_eq!(said, [(20_000.0, 1, 14), (12_700.0, 4, 10)]);
}

#[test]
fn g01_without_feed() {
    assert_eq!(
        fails("G01 X0 Y0 Z0", 1, 1),
        E::NoFeed {
            motion: Motion::G01
        }
    );
    assert_eq!(
        fails("G00 X0 Y0 Z0\nG01\nX1", 3, 1),
        E::NoFeed {
            motion: Motion::G01
        }
    );
}

#[test]
fn nurbs_without_feed() {
    let src = "G00 X0 Y0 Z0\nG06.5 P1 X0 Y0 Z0 U0 V0 W1 K0\nX10 Y0 Z0 U10 V0 W1 K0\nK1 K1";
    assert_eq!(
        fails(src, 2, 1),
        E::NoFeed {
            motion: Motion::G065
        }
    );
}

#[test]
fn coordinates_without_motion_mode() {
    assert_eq!(
        fails("F500\nX0 Y0 Z0", 2, 1),
        E::NoMotionMode { letter: 'X' }
    );
    assert_eq!(fails("G21 I0 J0 K1", 1, 5), E::NoMotionMode { letter: 'I' });
}

#[test]
fn first_move_without_full_start_pose() {
    assert_eq!(fails("G00 X0 Y0", 1, 1), E::MissingStartAxis { axis: 'Z' });
    assert_eq!(
        fails("G01 F500\nN10 Y0 Z0", 2, 1),
        E::MissingStartAxis { axis: 'X' }
    );
}

#[test]
fn nurbs_before_start_pose() {
    let src = "F500\nG06.5 P1 X0 Y0 Z0 U0 V0 W1 K0\nX10 Y0 Z0 U10 V0 W1 K0\nK1 K1";
    assert_eq!(
        fails(src, 2, 1),
        E::NurbsBeforeStart {
            motion: Motion::G065
        }
    );
}

#[test]
fn nurbs_block_as_the_first_move() {
    let src = "G06.2 P2 K0 X0 Y0 Z0 F500\nK0 X10 Y0 Z0\nK1 K1";
    assert_eq!(
        fails(src, 1, 1),
        E::NurbsBeforeStart {
            motion: Motion::G062
        }
    );
}

// ---- tool orientation ----------------------------------------------------------------------

#[test]
fn angles_and_vector_on_one_line() {
    assert_eq!(
        fails("G00 X0 Y0 Z0 A10 I0 J0 K1", 1, 18),
        E::MixedOrientation {
            angle: 'A',
            vector: 'I'
        }
    );
}

#[test]
fn incomplete_tool_vector() {
    assert_eq!(
        fails("G00 X0 Y0 Z0 I0 K1", 1, 14),
        E::IncompleteVector {
            given: 'I',
            missing: 'J'
        }
    );
}

#[test]
fn zero_tool_vector() {
    assert_eq!(
        fails("G00 X0 Y0 Z0 I0 J0 K0", 1, 14),
        E::ZeroVector { ijk: [0.0; 3] }
    );
    assert_eq!(
        fails("G00 X0 Y0 Z0 I0 J0 K.0000000001", 1, 14),
        E::ZeroVector {
            ijk: [0.0, 0.0, 1e-10]
        }
    );
}

#[test]
fn a_and_b_in_one_program() {
    let mixed = E::MixedRotaryAxes {
        letter: 'B',
        first: 'A',
        first_pos: at(1, 14),
    };
    assert_eq!(fails("G00 X0 Y0 Z0 A10 B5", 1, 18), mixed);
    assert_eq!(fails("G00 X0 Y0 Z0 A10\nB5 C0", 2, 1), mixed);
}

#[test]
fn one_angle_after_a_vector() {
    assert_eq!(
        fails("G00 X0 Y0 Z0 I0 J0 K1\nA10", 2, 1),
        E::PartialAngles { given: 'A' }
    );
}

#[test]
fn after_a_refused_move_the_next_lines_start_where_it_would_have_ended() {
    // The first arc's end is not on its circle; the second arc, from X10, is right. Checked
    // from the stale X0 it was refused too, with radii the program does not have.
    let src = "G0 X0 Y0 Z0\nF100\nG2 X10 Y0 I3 J0\nG2 X20 Y0 I5 J0\nG1 X[30] Y1\nG91 G1 X-1\nM2";
    let e = crate::parse_with(src, &crate::Setup::default()).unwrap_err();
    assert_eq!(e.errors.len(), 1, "{:?}", e.errors);
    assert_eq!(e.errors[0].pos.line, 3);
    // An incremental move after a refused one adds to the refused line's end too.
    let src = "G0 X0 Y0 Z0\nG91 F100\nG2 X10 Y0 I3 J0\nG2 X10 Y0 I5 J0\nM2";
    let e = crate::parse_with(src, &crate::Setup::default()).unwrap_err();
    assert_eq!(e.errors.len(), 1, "{:?}", e.errors);
}
