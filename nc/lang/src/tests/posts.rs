//! The language of CAM posts: modal groups, units, incremental moves, planes and arcs, work
//! offsets, tool length, machine-coordinate moves, stops and words without axes, and every
//! error of a program reported. Arcs are checked against an independent evaluation: the
//! circle (and helix) by its centre, radius and angle, not by the NURBS code.

use super::super::{parse, parse_with, ParseErrorKind as E, Setup};
use core::f64::consts::PI;
use nc_geom::program::{ActionKind, Block, Coolant, LengthMode, NurbsBlock, Spindle};

fn nurbs(b: &Block) -> &NurbsBlock {
    match b {
        Block::Nurbs(n) => n,
        Block::Linear(m) => panic!("expected an arc, got {m:?}"),
    }
}

fn end(b: &Block) -> [f64; 3] {
    match b {
        Block::Linear(m) => m.end,
        Block::Nurbs(n) => *n.ctrl.last().unwrap(),
    }
}

/// Points of the block's curve at `n + 1` parameters, by a rational B-spline evaluation of
/// its own (Cox-de Boor basis), independent of `nc_geom::nurbs`.
fn curve_points(b: &NurbsBlock, n: usize) -> Vec<[f64; 3]> {
    let p = b.degree as usize;
    let k = &b.knots;
    let (u0, u1) = (k[p], k[k.len() - p - 1]);
    (0..=n)
        .map(|i| {
            let u = u0 + (u1 - u0) * i as f64 / n as f64;
            // The span: k[span] <= u < k[span + 1], the last one closed.
            let span = (p..k.len() - p - 1)
                .rev()
                .find(|&s| k[s] <= u && k[s] < k[s + 1])
                .unwrap();
            let mut basis = vec![0.0; k.len() - 1];
            basis[span] = 1.0;
            for d in 1..=p {
                for j in 0..k.len() - 1 - d {
                    let l = if k[j + d] > k[j] {
                        (u - k[j]) / (k[j + d] - k[j]) * basis[j]
                    } else {
                        0.0
                    };
                    let r = if k[j + d + 1] > k[j + 1] {
                        (k[j + d + 1] - u) / (k[j + d + 1] - k[j + 1]) * basis[j + 1]
                    } else {
                        0.0
                    };
                    basis[j] = l + r;
                }
            }
            let mut num = [0.0; 3];
            let mut den = 0.0;
            for (j, c) in b.ctrl.iter().enumerate() {
                let w = basis[j] * b.weights[j];
                den += w;
                for a in 0..3 {
                    num[a] += w * c[a];
                }
            }
            num.map(|x| x / den)
        })
        .collect()
}

#[test]
fn full_circle_is_the_circle_to_a_nanometre() {
    let p = parse("G17 G90 G21\nG00 X10 Y0 Z0\nG02 X10 Y0 I-10 J0 F600\n").unwrap();
    let b = nurbs(&p.blocks[1]);
    assert_eq!(b.degree, 2);
    let mut turned = 0.0;
    let mut prev = 0.0f64;
    for q in curve_points(b, 4000) {
        let r = q[0].hypot(q[1]);
        assert!((r - 10.0).abs() < 1e-9, "radius {r} off the circle");
        assert_eq!(q[2], 0.0);
        let ang = q[1].atan2(q[0]);
        let mut d = ang - prev;
        if d > PI {
            d -= 2.0 * PI;
        }
        if d < -PI {
            d += 2.0 * PI;
        }
        assert!(d <= 1e-12, "G02 turns clockwise: step {d}");
        turned += d;
        prev = ang;
    }
    assert!((turned + 2.0 * PI).abs() < 1e-9, "a full turn: {turned}");
}

#[test]
fn helix_is_on_the_true_helix_within_its_bound() {
    // Two turns of radius 5 rising 2 mm (G03, counter-clockwise), as a helical ramp.
    let src = "G00 X5 Y0 Z2\nG03 X5 Y0 Z1 I-5 J0 F600\nG03 X5 Y0 Z0 I-5 J0\n";
    let p = parse(src).unwrap();
    for (k, blk) in p.blocks[1..].iter().enumerate() {
        let b = nurbs(blk);
        let z0 = 2.0 - k as f64;
        let mut prev = 0.0f64;
        let mut phi = 0.0;
        for q in curve_points(b, 20_000) {
            let r = q[0].hypot(q[1]);
            assert!((r - 5.0).abs() < 1e-9, "radius {r}");
            let ang = q[1].atan2(q[0]);
            let mut d = ang - prev;
            if d < -PI {
                d += 2.0 * PI;
            }
            phi += d;
            prev = ang;
            // The true helix at this angle: z falls 1 mm per turn.
            let z = z0 - phi / (2.0 * PI);
            assert!(
                (q[2] - z).abs() <= super::super::HELIX_TOL_MM,
                "z {} vs helix {z} at phi {phi}",
                q[2]
            );
        }
        assert!((phi - 2.0 * PI).abs() < 1e-9);
    }
}

#[test]
fn steep_helices_are_on_the_true_helix_or_an_error() {
    // Rising 50 mm in a quarter turn of radius 2 (a ramp seen from the side), and a whole
    // turn of radius 0.5 rising 100 mm: the steepest pitches a post writes.
    for (src, r, z1, sweep) in [
        (
            "G00 X2 Y0 Z0\nG03 X0 Y2 Z50 I-2 J0 F600\n",
            2.0,
            50.0,
            PI / 2.0,
        ),
        (
            "G00 X0.5 Y0 Z0\nG03 X0.5 Y0 Z100 I-0.5 J0 F600\n",
            0.5,
            100.0,
            2.0 * PI,
        ),
    ] {
        let p = parse(src).unwrap();
        let b = nurbs(&p.blocks[1]);
        let mut phi = 0.0f64;
        let mut prev = 0.0f64;
        for q in curve_points(b, 20_000) {
            assert!((q[0].hypot(q[1]) - r).abs() < 1e-9);
            let ang = q[1].atan2(q[0]);
            let mut d = ang - prev;
            if d < -PI {
                d += 2.0 * PI;
            }
            phi += d;
            prev = ang;
            let z = z1 * phi / sweep;
            let tol = super::super::HELIX_TOL_MM;
            assert!((q[2] - z).abs() <= tol, "{src}: z {} vs {z}", q[2]);
        }
    }
    // The steepest helix the coordinate range allows (a whole turn from Z-100000 to
    // Z100000) still fits one block; beyond it the arc is an error with the numbers, not a
    // looser helix.
    let arc = |rise: f64| {
        super::super::arc(
            [0.01, 0.0, -rise / 2.0],
            [0.01, 0.0, rise / 2.0],
            super::super::vocab::Plane::Xy,
            (false, 1),
            super::super::Centre::Offsets(-0.01, 0.0),
            super::super::ArcTol::for_units(false),
        )
    };
    assert!(arc(2e5).unwrap().ctrl.len() < nc_geom::program::MAX_BLOCK_CTRL);
    let e = arc(1e15).unwrap_err();
    assert!(
        matches!(e, E::HelixTooSteep { pieces, .. } if pieces > 24_999.0),
        "{e}"
    );
    assert!(e.to_string().contains("program it as several arcs"), "{e}");
}

#[test]
fn three_point_arcs_by_r_and_by_centre_agree_with_the_circle_through_the_points() {
    // The circle through (0,0), (10,10) and (20,0): centre (10,0), radius 10.
    for src in [
        "G00 X0 Y0 Z0\nG02 X20 Y0 R10 F500\n",
        "G00 X0 Y0 Z0\nG02 X20 Y0 I10 J0 F500\n",
        "G00 X0 Y0 Z0\nG03 X20 Y0 R-10 F500\n",
    ] {
        let p = parse(src).unwrap();
        let b = nurbs(&p.blocks[1]);
        let pts = curve_points(b, 2000);
        let mid = pts[1000];
        for q in &pts {
            assert!(
                ((q[0] - 10.0).hypot(q[1]) - 10.0).abs() < 1e-9,
                "{src}: {q:?}"
            );
        }
        // Clockwise from (0,0) to (20,0) about (10,0) goes over the top; counter-clockwise
        // (a half circle is both the shorter and the longer arc) under it.
        let top = if src.contains("G03") { -10.0 } else { 10.0 };
        assert!(
            (mid[0] - 10.0).abs() < 1e-9 && (mid[1] - top).abs() < 1e-9,
            "{src}: {mid:?}"
        );
    }
}

#[test]
fn planes_g18_and_g19_take_their_own_offsets() {
    let p = parse("G00 X10 Y0 Z0\nG18 G02 X-10 Z0 I-10 K0 F500\n").unwrap();
    for q in curve_points(nurbs(&p.blocks[1]), 500) {
        assert!((q[0].hypot(q[2]) - 10.0).abs() < 1e-9 && q[1] == 0.0);
    }
    let p = parse("G00 X0 Y10 Z0\nG19 G03 Y-10 Z0 J-10 K0 F500\n").unwrap();
    for q in curve_points(nurbs(&p.blocks[1]), 500) {
        assert!((q[1].hypot(q[2]) - 10.0).abs() < 1e-9 && q[0] == 0.0);
    }
    let e = parse("G00 X0 Y10 Z0\nG17 G02 X10 Y0 K5 F500").unwrap_err();
    assert!(
        matches!(e.kind, E::ArcOffsetOutOfPlane { letter: 'K', .. }),
        "{e}"
    );
    // After an offset in the plane too, and K0 as well (FreeCAD's grbl post writes it;
    // LinuxCNC refuses it).
    let e = parse("G00 X0 Y10 Z0\nG17 G02 X10 Y0 I0 J-10 K0 F500").unwrap_err();
    assert!(
        matches!(e.kind, E::ArcOffsetOutOfPlane { letter: 'K', .. }) && e.pos.col == 24,
        "{e}"
    );
}

#[test]
fn arc_errors_name_what_is_wrong() {
    let f = |src| parse(src).unwrap_err().kind;
    assert!(matches!(
        f("G00 X0 Y0 Z0\nG02 X10 Y0 I5.05 J0 F500"),
        E::ArcRadiusMismatch { .. }
    ));
    assert!(matches!(
        f("G00 X0 Y0 Z0\nG02 X10 Y0 R4 F500"),
        E::ArcRadiusTooSmall { .. }
    ));
    assert!(matches!(
        f("G00 X0 Y0 Z0\nG02 X0 Y0 R4 F500"),
        E::ArcFullCircleRadius
    ));
    assert!(matches!(
        f("G00 X0 Y0 Z0\nG02 X10 Y0 F500"),
        E::ArcWithoutCentre { .. }
    ));
    assert!(matches!(
        f("G00 X0 Y0 Z0\nG02 X10 Y0 R5 I5 F500"),
        E::ArcCentreAndRadius { .. }
    ));
    assert!(matches!(
        f("G00 X0 Y0 Z0\nG02 X10 Y0 C10 F500"),
        E::ArcWithoutCentre { .. }
    ));
    // Rounded posts: 0.0014 mm apart is accepted and ends exactly at the programmed point.
    let p = parse("G00 X0 Y0 Z0\nG02 X10.001 Y0 I5 J0.001 F500").unwrap();
    assert_eq!(end(&p.blocks[1]), [10.001, 0.0, 0.0]);
}

#[test]
fn units_incremental_and_inverse_time() {
    let p = parse("G20 G91\nG00 X0 Y0 Z0\nG01 X1 Y1 F10\nX1\nG90 G21 G01 Z5\n").unwrap_err();
    // G91 before any position needs a start: without a reference it is the start-pose error.
    assert!(matches!(p.kind, E::MissingStartAxis { .. }), "{p}");
    let p = parse("G00 X0 Y0 Z0\nG20 G91 G01 X1 Y1 F10\nX1\nG90 G21 G01 Z5\n").unwrap();
    assert_eq!(end(&p.blocks[1]), [25.4, 25.4, 0.0]);
    assert_eq!(end(&p.blocks[2]), [50.8, 25.4, 0.0]);
    assert_eq!(end(&p.blocks[3]), [50.8, 25.4, 5.0]);
    let Block::Linear(m) = &p.blocks[1] else {
        panic!()
    };
    assert!((m.feed_mm_min - 254.0).abs() < 1e-9);
    // G93: F is 1/min for its move: 10 mm at F6 takes 10 s, 60 mm/min.
    let p = parse("G00 X0 Y0 Z0\nG93 G01 X10 F6\nG94 G01 X20 F100\n").unwrap();
    let Block::Linear(m) = &p.blocks[1] else {
        panic!()
    };
    assert!((m.feed_mm_min - 60.0).abs() < 1e-9);
    let e = parse("G00 X0 Y0 Z0\nG93 G01 X10 F6\nX20\n").unwrap_err();
    assert!(matches!(e.kind, E::InverseTimeWithoutFeed { .. }), "{e}");
}

fn shop() -> Setup {
    let mut s = Setup {
        reference: Some([0.0, 0.0, 300.0]),
        ..Setup::default()
    };
    s.work_offsets[0] = Some([100.0, 50.0, -20.0]);
    s.work_offsets[1] = Some([0.0, 0.0, 0.0]);
    s.tools.insert(1, 80.0);
    s
}

#[test]
fn offsets_reference_and_tool_length() {
    let src = "%\nO1001 (TEST)\nN10 G90 G94 G17 G49 G40 G80\nN15 G21\nN20 G28 G91 Z0.\nN25 G90\n\
               N30 T1 M06\nN35 S8000 M03\nN40 G54\nN45 M08\nN50 G00 X0 Y0\nN55 G43 Z15. H01\n\
               N60 G01 Z-1 F300\nN65 G00 Z15\nN70 G55 X0 Y0\nN75 G49\nN80 G53 G00 Z0\nN85 M09\nN90 M05\nN95 M30\n%\n";
    let p = parse_with(src, &shop()).unwrap();
    // Start at the reference (no X Y Z before G28): block 0.
    assert_eq!(end(&p.blocks[0]), [0.0, 0.0, 300.0]);
    let ends: Vec<[f64; 3]> = p.blocks.iter().map(end).collect();
    // G54 X0 Y0: machine (100, 50); G43 Z15 H1: tip at 15 - 20 = -5, tool 80 on Z.
    // G28 G91 Z0 from there: the (null) move to the reference.
    assert_eq!(ends[1], [0.0, 0.0, 300.0]);
    assert_eq!(ends[2], [100.0, 50.0, 300.0]);
    assert_eq!(ends[3], [100.0, 50.0, -5.0]);
    let Block::Linear(g43) = &p.blocks[3] else {
        panic!()
    };
    assert_eq!(
        (g43.tooling.tool_length, g43.tooling.mode),
        (80.0, LengthMode::Length)
    );
    assert_eq!(ends[4], [100.0, 50.0, -21.0]);
    // G55 (zero offset) X0 Y0 keeps the tip's Z; G49 then shifts the tip up by 80 so the
    // machine stays; G53 Z0 brings the spindle to machine Z0.
    assert_eq!(ends[6], [0.0, 0.0, -5.0]);
    assert_eq!(ends[7], [0.0, 0.0, 0.0]);
    let Block::Linear(g53) = &p.blocks[7] else {
        panic!()
    };
    assert_eq!(g53.tooling.tool_length, 0.0);
    let kinds: Vec<ActionKind> = p.actions.iter().map(|a| a.kind).collect();
    assert_eq!(
        kinds,
        [
            ActionKind::SelectTool { tool: 1 },
            ActionKind::ChangeTool { tool: Some(1) },
            ActionKind::Spindle {
                dir: Spindle::Cw,
                rpm: 8000.0
            },
            ActionKind::Coolant(Coolant::Flood),
            ActionKind::Coolant(Coolant::Off),
            ActionKind::Spindle {
                dir: Spindle::Off,
                rpm: 8000.0
            },
        ]
    );
}

#[test]
fn stops_and_dwells_wait_before_the_next_move() {
    let src =
        "G00 X0 Y0 Z0\nG04 P0.5\nG04 X1\nG01 X1 F100\nM00\nX2\n/M01\nX3\nM01\nX4\nT2 M06\nX5\n";
    let p = parse(src).unwrap();
    let waits: Vec<_> = p
        .blocks
        .iter()
        .map(|b| match b {
            Block::Linear(m) => m.tooling.wait,
            Block::Nurbs(n) => n.tooling.wait,
        })
        .collect();
    assert_eq!(waits[1].dwell_s, 1.5);
    assert_eq!(waits[2].operator.map(|p| p.line), Some(5));
    assert_eq!(
        waits[3].operator, None,
        "M01 is passed without --optional-stop"
    );
    assert_eq!(waits[5].operator.map(|p| p.line), Some(11));
    let on = Setup {
        optional_stop: true,
        block_delete: true,
        ..Setup::default()
    };
    let p = parse_with(src, &on).unwrap();
    let Block::Linear(m) = &p.blocks[4] else {
        panic!()
    };
    assert_eq!(
        m.tooling.wait.operator.map(|p| p.line),
        Some(9),
        "the /M01 line is deleted"
    );
    let e = parse("G00 X0 Y0 Z0\nG04 P1000\n").unwrap_err();
    assert!(matches!(e.kind, E::BadDwell { .. }) && e.to_string().contains("milliseconds"));
}

#[test]
fn every_error_of_a_program_is_reported_with_its_line() {
    let src = "G00 X0 Y0 Z0\nG41 D1\nG01 X1 F100\nG02 X5 Y0 F100\nQ5\nG43 H7 Z1\nG55\nG01 X2\n";
    let e = parse_with(src, &Setup::default()).unwrap_err();
    let lines: Vec<u32> = e.errors.iter().map(|x| x.pos.line).collect();
    assert_eq!(lines, [2, 4, 5, 6, 7], "{:?}", e.errors);
    assert!(!e.more);
    let many: String = (0..80).map(|_| "G41\n").collect();
    let e = parse_with(&many, &Setup::default()).unwrap_err();
    assert_eq!(e.errors.len(), super::super::MAX_ERRORS);
    assert!(e.more);
}

#[test]
fn a_speed_above_the_spindles_maximum_is_an_error_with_its_line() {
    let setup = Setup {
        max_rpm: Some(24000.0),
        ..Setup::default()
    };
    let src = "G00 X0 Y0 Z0\nS24000 M03\nS30000\nG01 X1 F100\nM04 S25000\n";
    let e = parse_with(src, &setup).unwrap_err();
    let at: Vec<String> = e.errors.iter().map(|x| x.pos.to_string()).collect();
    assert_eq!(at, ["3:1", "5:5"], "{:?}", e.errors);
    assert!(
        e.errors[0]
            .to_string()
            .contains("S30000 is above the spindle's maximum of 24000 rpm ([spindle] max_rpm)"),
        "{}",
        e.errors[0]
    );
    // Without a spindle on the machine the speed is only reported.
    assert!(parse_with(src, &Setup::default()).is_ok());
}
