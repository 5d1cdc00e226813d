//! `G10 L1`/`L2`/`L20`: tables set from the program, read back through the moves and the
//! parameters, and each refusal at its word.

use super::at;
use crate::{parse_with, ParseErrorKind as E, Setup};

fn setup() -> Setup {
    Setup {
        work_offsets: [Some([0.0; 3]); 6],
        reference: Some([0.0, 0.0, 100.0]),
        ..Setup::default()
    }
}

fn ends(src: &str) -> Vec<[f64; 3]> {
    super::block_ends(src, &setup())
}

#[test]
fn l2_sets_an_offset_and_its_parameters_in_mm() {
    // G55 set in inches; the move lands there; #5241 (G55 X) reads mm, the machine's units.
    let e = ends("G20\nG10 L2 P2 X1 Z-1\nG55\nG0 X0 Y0 Z0\nG21\nG0 X[#5241] Y[#5243]\nM2");
    assert_eq!(e[0], [25.4, 0.0, -25.4]);
    assert_eq!(e[1], [50.8, -25.4, -25.4]);
    // P0 is the offset in effect, and moves at once.
    let e = ends("G0 X0 Y0 Z0\nG10 L2 P0 Y5\nG0 X0 Y0 Z0\nM2");
    assert_eq!(e[1], [0.0, 5.0, 0.0]);
}

#[test]
fn l20_makes_the_current_point_the_coordinates_given() {
    let e = ends("G0 X10 Y20 Z30\nG10 L20 P1 X0 Y0\nG0 X1 Y1\nM2");
    assert_eq!(e[1], [11.0, 21.0, 30.0]);
}

#[test]
fn l1_sets_a_tools_length_and_radius() {
    let e =
        ends("G10 L1 P7 Z50 R3\nG0 X-10 Y0 Z0\nG43 H7 G0 Z0\nG42 D7 G1 X0 F100\nG1 X10\nG40\nM2");
    // The tip stays at Z0 (the length lives in the tooling); right of +X by the radius 3.
    assert_eq!(e[1][2], 0.0);
    let want = [[0.0, -3.0, 0.0], [10.0, -3.0, 0.0]];
    for (g, w) in e[2..].iter().zip(want) {
        assert!(g.iter().zip(w).all(|(a, b)| (a - b).abs() < 1e-12), "{e:?}");
    }
}

#[test]
fn each_refusal_is_at_its_word() {
    let fails = |src: &str| {
        let e = parse_with(src, &setup()).expect_err(src).errors[0];
        (e.kind, e.pos)
    };
    assert_eq!(fails("G10 L10 P1 Z5"), (E::G10Kind, at(1, 5)));
    assert_eq!(fails("G10 P1 Z5"), (E::G10Kind, at(1, 1)));
    assert!(matches!(fails("G10 L2 P7 X1"), (E::G10Index { l: 2, .. }, p) if p == at(1, 8)));
    assert!(matches!(
        fails("G10 L20 P1 X1 R30"),
        (E::G10Rotary { letter: 'R', .. }, p) if p == at(1, 15)
    ));
    assert!(matches!(
        fails("G10 L2 P1 A90"),
        (E::G10Rotary { letter: 'A', .. }, _)
    ));
    assert!(matches!(
        fails("G0 X-10 Y0 Z0\nG41.1 D1\nG10 L2 P1 X1"),
        (E::CompensationForbids { .. }, p) if p == at(3, 1)
    ));
    // A rotation of 0 (a post's habit) is no rotation.
    assert!(parse_with("G10 L2 P1 X0 Y0 Z0 R0\nG0 X1 Y1 Z1\nM2", &setup()).is_ok());
}

#[test]
fn g95_feeds_per_revolution_of_the_speed_in_effect() {
    let p = parse_with(
        "G0 X0 Y0 Z0\nS1000 M3\nG95 F0.1\nG1 X10\nS2000\nG1 X20\nG20 F0.01 G1 X30\nM2",
        &setup(),
    )
    .unwrap();
    let feeds: Vec<f64> = p
        .blocks
        .iter()
        .filter_map(|b| match b {
            nc_geom::program::Block::Linear(m) if !m.rapid => Some(m.feed_mm_min),
            _ => None,
        })
        .collect();
    // 0.1 mm a revolution at 1000 and 2000 rpm; 0.01 inch at 2000 rpm.
    assert_eq!(feeds.len(), 3);
    assert!((feeds[0] - 100.0).abs() < 1e-9 && (feeds[1] - 200.0).abs() < 1e-9);
    assert!((feeds[2] - 0.254 * 2000.0).abs() < 1e-9, "{feeds:?}");
}

#[test]
fn g92_on_a_rotary_axis_makes_the_angle_in_effect_read_as_given() {
    use nc_geom::program::Orientation;
    // A 3D printer's post: the extruder axis reset, then written on.
    let p = parse_with(
        "G0 X0 Y0 Z0 A10 C0\nG92 A881.3\nG1 X1 A881.4 F100\n#1 = #5423\nG1 X2 A[#1 + 0.2]\nG92.1\nG1 X3 A5\nM2",
        &setup(),
    )
    .unwrap();
    let a: Vec<f64> = p
        .blocks
        .iter()
        .map(|b| match b {
            nc_geom::program::Block::Linear(m) => match m.orientation {
                Orientation::Angles { r1_deg, .. } => r1_deg,
                Orientation::Vector(_) => f64::NAN,
            },
            nc_geom::program::Block::Nurbs(_) => f64::NAN,
        })
        .collect();
    let want = [10.0, 10.1, 10.3, 5.0];
    assert!(
        a.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-9),
        "{a:?}"
    );
}

#[test]
fn l2_r_turns_the_coordinate_system_about_its_origin() {
    // G54 at X10, turned 90 deg: program X1 is machine Y+1 from the origin; G91 Y1 moves
    // along the turned Y (machine -X); #5420/#5421 read the program's coordinates and #5230
    // the rotation.
    let e = ends(
        "G10 L2 P1 X10 R90\nG54 G0 X1 Y0 Z0\nG91 G0 Y1\nG90\n#1=[#5420*100+#5421*10+#5230]\nG0 X[#1/100] Y0\nM2",
    );
    // #1 = 100 + 10 + 90: program X2, machine (10, 2).
    let want = [[10.0, 1.0, 0.0], [9.0, 1.0, 0.0], [10.0, 2.0, 0.0]];
    for (g, w) in e.iter().zip(want) {
        assert!(g.iter().zip(w).all(|(a, b)| (a - b).abs() < 1e-9), "{e:?}");
    }
    // A G17 arc's centre offsets turn with it; G55 (not rotated) does not.
    let e = ends("G10 L2 P1 R90\nG0 X0 Y0 Z0\nG2 X2 Y0 I1 J0 F100\nG55 G0 X1 Y0\nM2");
    assert!(
        (e[1][0] - 0.0).abs() < 1e-9 && (e[1][1] - 2.0).abs() < 1e-9,
        "{e:?}"
    );
    assert!(
        (e[2][0] - 1.0).abs() < 1e-9 && e[2][1].abs() < 1e-9,
        "{e:?}"
    );
}

#[test]
fn what_is_not_turned_is_refused_in_a_rotated_system() {
    let fails = |src: &str| {
        let e = parse_with(src, &setup()).expect_err(src).errors[0];
        (e.kind, e.pos)
    };
    let turned = "G10 L2 P1 R30\nG0 X0 Y0 Z0\n";
    for (line, col) in [
        ("G81 X1 Y1 Z-1 R1 F100", 1),
        ("G18 G2 X1 Z1 I0.5 K0 F100", 5),
        ("G92 X0", 1),
        ("G0 @5 ^10", 4),
        ("G5.1 X1 Y1 I1 J0 F100", 1),
    ] {
        let (kind, pos) = fails(&format!("{turned}{line}"));
        assert!(matches!(kind, E::NotRotated { .. }), "{line}: {kind:?}");
        assert_eq!(pos, at(3, col), "{line}");
    }
}
