//! Cutter radius compensation: tool-centre paths checked by hand on a square (concave and
//! convex corners), the held actions, the tool table, and each refusal with its column.
//! (The conformance suite compares generated contours with LinuxCNC's interpreter.)

use super::{at, linear, nurbs};
use crate::{parse_with, ParseErrorKind as E, Setup};
use nc_geom::program::{ActionKind, Coolant};

fn setup() -> Setup {
    let mut s = Setup::default();
    s.tools.insert(1, 50.0);
    s.tool_diameters.insert(1, 6.0);
    s.tools.insert(2, 40.0);
    s
}

fn ends(src: &str) -> Vec<[f64; 3]> {
    super::block_ends(src, &setup())
}

#[track_caller]
fn near(got: &[[f64; 3]], want: &[[f64; 2]]) {
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g[0] - w[0]).abs() < 1e-12 && (g[1] - w[1]).abs() < 1e-12,
            "{got:?} vs {want:?}"
        );
    }
}

#[track_caller]
fn fails(src: &str, line: u32, col: u32) -> E {
    let e = parse_with(src, &setup()).expect_err(src);
    let first = e.errors[0];
    assert_eq!(first.pos, at(line, col), "{first}");
    first.kind
}

const SQUARE: &str = "G0 X0 Y-5 Z0\nG1 X10 Y0 F100\nG1 X10 Y10\nG1 X0 Y10\nG40\nG0 X-5 Y20\nM2";

#[test]
fn left_of_a_counter_clockwise_square_the_tool_stops_short_of_each_inside_corner() {
    // Entry from (0,-5): the line's end offset left by 1 mm; the inside corners are where
    // the offset lines meet.
    let src = SQUARE.replace("G1 X10 Y0 F100", "G41.1 D2 G1 X10 Y0 F100");
    let e = ends(&src);
    near(&e[..1], &[[0.0, -5.0]]);
    assert!((e[1][0] - 9.0).abs() < 1e-12, "{e:?}");
    near(&e[2..], &[[9.0, 9.0], [0.0, 9.0], [-5.0, 20.0]]);
}

#[test]
fn right_of_it_the_tool_rounds_each_outside_corner_on_an_arc_of_its_radius() {
    let src = "G0 X-5 Y0 Z0\nG42.1 D2 G1 X0 Y0 F100\nG1 X10\nG1 Y10\nG1 X0\nG40\nG0 X-5 Y20\nM2";
    let p = parse_with(src, &setup()).unwrap();
    let e = ends(src);
    // Entry to (0,-1); along y = -1; round (10,0) to (11,0); up x = 11; round (10,10) to
    // (10,11); along y = 11 to (0,11); G40; the next move from there.
    near(
        &e,
        &[
            [-5.0, 0.0],
            [0.0, -1.0],
            [10.0, -1.0],
            [11.0, 0.0],
            [11.0, 10.0],
            [10.0, 11.0],
            [0.0, 11.0],
            [-5.0, 20.0],
        ],
    );
    let corner = nurbs(&p.blocks[3]);
    // A quarter circle about the programmed corner.
    assert_eq!(corner.degree, 2);
    assert_eq!(corner.pos, at(4, 1));
    assert_eq!(linear(&p.blocks[4]).pos, at(4, 1));
}

#[test]
fn the_tool_table_gives_the_diameter_and_g41_without_d_takes_the_loaded_tool() {
    let with_d = "G0 X-5 Y0 Z0\nG42 D1 G1 X0 Y0 F100\nG1 X10\nG40\nM2";
    near(&ends(with_d)[1..], &[[0.0, -3.0], [10.0, -3.0]]);
    let loaded = "T1 M6\nG0 X-5 Y0 Z0\nG42 G1 X0 Y0 F100\nG1 X10\nG40\nM2";
    near(&ends(loaded)[1..], &[[0.0, -3.0], [10.0, -3.0]]);
    // A tool without a diameter compensates nothing (LinuxCNC's radius 0).
    let none = "G0 X-5 Y0 Z0\nG42 D2 G1 X0 Y0 F100\nG1 X10\nG40\nM2";
    near(&ends(none)[1..], &[[0.0, 0.0], [10.0, 0.0]]);
    // A negative diameter swaps the sides.
    let negative = "G0 X-5 Y0 Z0\nG41.1 D-2 G1 X0 Y0 F100\nG1 X10\nG40\nM2";
    near(&ends(negative)[1..], &[[0.0, -1.0], [10.0, -1.0]]);
}

#[test]
fn actions_between_held_moves_stay_between_them() {
    let src = "G0 X-5 Y0 Z0\nG42.1 D2 G1 X0 Y0 F100\nG1 X10\nM8\nG4 P1\nG1 Y10\nG40\nM2";
    let p = parse_with(src, &setup()).unwrap();
    let coolant = p
        .actions
        .iter()
        .find(|a| a.kind == ActionKind::Coolant(Coolant::Flood))
        .expect("M8");
    // After the held line to (10,-1) (block 2), before the corner arc (block 3).
    assert_eq!(coolant.before_block, 3);
    let dwell = p
        .actions
        .iter()
        .find(|a| matches!(a.kind, ActionKind::Dwell { .. }))
        .expect("G4");
    assert_eq!(dwell.before_block, 3);
    // The dwell's wait is on the corner arc, the first block after it.
    assert!(nurbs(&p.blocks[3]).tooling.wait.dwell_s > 0.0);
}

#[test]
fn each_refusal_names_its_rule_at_its_word() {
    let on = "G0 X-5 Y0 Z0\nG41.1 D2\n";
    assert!(matches!(
        fails(&format!("{on}G1 X-4 F100"), 3, 1),
        E::CompensationEntryTooShort { .. }
    ));
    assert_eq!(
        fails(&format!("{on}G42.1 D2"), 3, 1),
        E::CompensationTwice { code: 42.1 }
    );
    assert_eq!(
        fails(&format!("{on}G18"), 3, 1),
        E::CompensationForbids {
            what: "a plane change"
        }
    );
    assert!(matches!(
        fails("G18\nG41.1 D2", 2, 1),
        E::CompensationPlane { code: 41.1, .. }
    ));
    assert!(matches!(
        fails(&format!("{on}T1 M6"), 3, 4),
        E::CompensationForbids { .. }
    ));
    assert!(matches!(
        fails(&format!("{on}G28"), 3, 1),
        E::CompensationForbids { what: "G28/G30" }
    ));
    assert!(matches!(
        fails(&format!("{on}G81 X1 Y1 Z-1 R1 F100"), 3, 1),
        E::CompensationForbids { .. }
    ));
    assert!(matches!(
        fails(&format!("{on}G20"), 3, 1),
        E::CompensationForbids { .. }
    ));
    assert!(matches!(
        fails(&format!("{on}G1 X10 A5 F100"), 3, 8),
        E::CompensationUnsupported { .. }
    ));
    assert_eq!(fails("G0 X0 Y0 Z0 D2", 1, 13), E::DWithoutCompensation);
    assert_eq!(fails("G41.1", 1, 1), E::CompensationWithoutD { code: 41.1 });
    assert_eq!(fails("G41 D7", 1, 5), E::UnknownTool { tool: 7 });
    let after = "G0 X-5 Y0 Z0\nG41.1 D2 G1 X0 Y0 F100\nG1 X10\nG40\nG2 X20 R5\n";
    assert!(matches!(fails(after, 5, 1), E::ArcAfterCompensation { .. }));
}

#[test]
fn a_notch_narrower_than_the_tool_is_a_gouge_at_the_move_that_makes_it() {
    // A 1 mm wide bump, a 4 mm tool on its inside: the line down (line 6) would have to
    // run the held line back (rs274: "Straight feed in concave corner cannot be reached by
    // the tool without gouging", at the same line).
    let src = "G0 X-5 Y0 Z0\nG42.1 D4 G1 X0 Y0 F100\nG1 X10\nG1 Y5\nG1 X11\nG1 Y0\nG1 X20\nG40\nM2";
    let kind = fails(src, 6, 1);
    assert!(matches!(kind, E::CompensationGouge { .. }), "{kind:?}");
}

#[test]
fn a_three_axis_machine_refuses_what_turns_the_tool_at_its_word() {
    let xyz = Setup {
        rotary_axes: false,
        ..Setup::default()
    };
    let fails_on = |src: &str| parse_with(src, &xyz).expect_err(src).errors[0];
    let e = fails_on("G0 X0 Y0 Z0\nG1 X1 C90 F100");
    assert_eq!(
        (e.kind, e.pos),
        (E::NoRotaryAxes { what: "a C word" }, at(2, 7))
    );
    let e = fails_on("G0 X0 Y0 Z0 I0 J1 K1");
    assert!(matches!(e.kind, E::NoRotaryAxes { .. }) && e.pos == at(1, 13));
    let e = fails_on("G0 X0 Y0 Z0\nG06.5 P1 X0 Y0 Z0 U0 V0 W1 K0");
    assert!(matches!(e.kind, E::NoRotaryAxes { .. }) && e.pos == at(2, 1));
    // A vertical tool vector and everything else a 3-axis program writes are read.
    assert!(parse_with("G0 X0 Y0 Z0 I0 J0 K2\nG1 X5 F100\nG2 X10 I2.5 J0\nM2", &xyz).is_ok());
}
