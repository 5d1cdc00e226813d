use super::*;

fn pt(p: [f64; 3], a: [f64; 3]) -> Point {
    Point {
        p: Vector3::from(p),
        axis: Vector3::from(a).normalize(),
    }
}

const TOL: Tolerance = Tolerance {
    mm: 0.001,
    rad: 0.01 * core::f64::consts::PI / 180.0,
};

#[test]
fn points_on_a_cubic_fit_into_one_span() {
    // A cubic polynomial curve: one Bezier span reproduces it.
    let points: Vec<Point> = (0..=40)
        .map(|k| {
            let t = f64::from(k) / 40.0;
            pt(
                [10.0 * t, 5.0 * t * t, 2.0 * t * t * t],
                [0.0, 0.1 * t, 1.0],
            )
        })
        .collect();
    let f = fit(&points, TOL, 3).unwrap();
    assert!(f.ctrl.len() <= 8, "{} control points", f.ctrl.len());
    assert!(f.dev_mm <= TOL.mm && f.dev_rad <= TOL.rad);
}

#[test]
fn a_circle_of_short_chords_needs_few_control_points_and_stays_within_tolerance() {
    let r = 20.0;
    let points: Vec<Point> = (0..=600)
        .map(|k| {
            let a = f64::from(k) * 0.1 / r;
            pt(
                [r * a.cos(), r * a.sin(), 0.0],
                [a.cos() * 0.3, a.sin() * 0.3, 1.0],
            )
        })
        .collect();
    let f = fit(&points, TOL, 3).unwrap();
    assert!(
        f.ctrl.len() * 10 <= points.len(),
        "{} control points",
        f.ctrl.len()
    );
    assert!(
        f.dev_mm <= TOL.mm && f.dev_rad <= TOL.rad,
        "{} {}",
        f.dev_mm,
        f.dev_rad
    );
}

#[test]
fn noise_above_the_tolerance_is_followed_not_smoothed_away() {
    // Points 5 um off a line on alternate moves: every point must still be within 1 um,
    // which takes a control point for nearly every point.
    let points: Vec<Point> = (0..=50)
        .map(|k| {
            let y = if k % 2 == 1 { 0.005 } else { 0.0 };
            pt([f64::from(k) * 0.1, y, 0.0], [0.0, 0.0, 1.0])
        })
        .collect();
    if let Some(f) = fit(&points, TOL, 3) {
        assert!(f.dev_mm <= TOL.mm, "{}", f.dev_mm);
        assert!(f.ctrl.len() > 25, "{} control points", f.ctrl.len());
    }
}

#[test]
fn nothing_moving_is_not_fitted() {
    let points = vec![pt([1.0, 2.0, 3.0], [0.0, 0.0, 1.0]); 6];
    assert!(fit(&points, TOL, 3).is_none());
}

/// A straight pass of 0.08 mm moves with one point 3 um off it (a post's noise, against a
/// 1 um tolerance). Knots would cluster at that point until the curve hooked back over
/// them (as it did 3.6 um on a generated post, over four knots within 5e-6); instead the
/// curve takes a corner on the point, and runs forward everywhere: no two knots nearer
/// than the quarter step, X never decreasing along the curve.
#[test]
fn a_point_off_its_neighbours_takes_a_corner_not_a_hook() {
    for (off, at) in [(0.003, 100), (-0.0025, 37), (0.004, 250)] {
        let points: Vec<Point> = (0..=300)
            .map(|k| {
                let y = if k == at { off } else { 0.0 };
                pt([f64::from(k) * 0.08, y, 0.0], [0.0, 0.0, 1.0])
            })
            .collect();
        let f = fit(&points, TOL, 3).expect("fitted");
        assert!(f.dev_mm <= TOL.mm, "{}", f.dev_mm);
        let mut distinct = f.knots.clone();
        distinct.dedup();
        let step = 1.0 / 300.0;
        for w in distinct.windows(2) {
            assert!(
                w[1] - w[0] > CLUSTER * step * 0.9,
                "knots {w:?}: {:?}",
                f.knots
            );
        }
        // Where the old fit clustered its knots, a knot of multiplicity 3 on the point.
        if at == 100 {
            let u = f
                .knots
                .iter()
                .find(|&&u| u > 0.0 && u < 1.0 && f.knots.iter().filter(|&&k| k == u).count() == 3);
            let u = u.unwrap_or_else(|| panic!("no corner: {:?}", f.knots));
            assert!((f.eval(*u).0 - points[at as usize].p).norm() < 1e-12);
        }
        let mut last = f64::NEG_INFINITY;
        for i in 0..=30_000 {
            let x = f.eval(f64::from(i) / 30_000.0).0.x;
            assert!(x >= last - 1e-9, "back from {last} to {x} at {i}");
            last = last.max(x);
        }
    }
}

/// A fitted axis that comes to the vertical sideways: its horizontal part runs along X
/// until, within 1.5e-6 of the move's end, the last term but one (1e-9 along Y) takes
/// over, and C would follow its azimuth a quarter turn where the tilt is a few
/// microradians. Eight samples of the move do not see it (the end is on the vertical,
/// where the azimuth is not measured); the halvings toward that end do. A generated post's
/// fitted block came to the vertical so: C turned 8.5 degrees in 21 periods at 1.4e-3
/// mm/s, at 1.4e-8 rad of tilt, and the program was refused compressed (C's acceleration
/// 1.9x its limit at the slowest feed) where it ran as posted.
#[test]
fn an_axis_coming_to_the_vertical_sideways_turns_more_than_programmed() {
    let tool = |x: f64, y: f64| [x, y, 1.0];
    let curve = Fitted {
        degree: 3,
        knots: vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        ctrl: vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]],
        tool: vec![
            tool(1e-3, 0.0),
            tool(0.67e-3, 0.0),
            tool(0.0, 1e-9),
            tool(0.0, 0.0),
        ],
        dev_mm: 0.0,
        dev_rad: 0.0,
    };
    let points = [
        pt([0.0; 3], tool(1e-3, 0.0)),
        pt([3.0, 0.0, 0.0], tool(0.0, 0.0)),
    ];
    assert!(turns_more_than_programmed(&curve, &points, 1, 0.0, 1.0));
    // The same curve coming straight in (the last term but one along X) does not.
    let mut straight = curve.clone();
    straight.tool[2] = tool(1e-9, 0.0);
    assert!(!turns_more_than_programmed(&straight, &points, 1, 0.0, 1.0));
    // Nor the same curve leaving the vertical, read the other way, straight.
    let mut leaving = straight.clone();
    leaving.tool.reverse();
    let back = [points[1], points[0]];
    assert!(!turns_more_than_programmed(&leaving, &back, 1, 0.0, 1.0));
    leaving.tool[1] = tool(0.0, 1e-9);
    assert!(turns_more_than_programmed(&leaving, &back, 1, 0.0, 1.0));
}

/// A run as a generated post wrote it (`nc/tests/adversarial/`): from a vertical tool, the
/// first move of 0.09 mm tilts it 8.9 degrees, the next ones 0.0575 degrees each. The fit
/// once left the start 4.8 um backwards while the tool tilted, and the planner refused A's
/// jerk even at its slowest feed. The fitted cutter goes forward along every move, sampled
/// far more densely than the fit's own check.
#[test]
fn a_fast_tool_turn_at_a_runs_start_does_not_pull_the_cutter_backwards() {
    let src = include_str!(
        "../../../tests/data/adversarial/a-fitted-block-leaving-its-start-backwards.nc"
    );
    let program = nc_lang::parse(src).expect("parses");
    let kin = nc_geom::kinematics::MachineKinematics::Paper;
    // The run: from the program's first point (its start, the tool vertical), every move.
    let points: Vec<Point> = program
        .blocks
        .iter()
        .filter_map(|b| match b {
            nc_geom::program::Block::Linear(m) => Some(find::point(m, &kin)),
            _ => None,
        })
        .collect();
    assert_eq!(points.len(), 80);
    let curve = fit(&points, TOL, 3).expect("fits");
    let mut feet = vec![0.0; points.len()];
    for (k, p) in points.iter().enumerate() {
        // The nearest of a dense sampling, in order along the curve.
        let from = feet[k.saturating_sub(1)];
        let d = |u: f64| (curve.eval(u).0 - p.p).norm();
        feet[k] = (0..=20_000)
            .map(|i| from + (1.0 - from) * i as f64 / 20_000.0)
            .min_by(|&a, &b| d(a).total_cmp(&d(b)))
            .unwrap();
        assert!(
            d(feet[k]) <= TOL.mm * 1.01,
            "point {k} off by {}",
            d(feet[k])
        );
    }
    for k in 1..points.len() {
        let chord = points[k].p - points[k - 1].p;
        let along = |u: f64| curve.eval(u).0.dot(&chord) / chord.norm();
        let (u0, u1) = (feet[k - 1], feet[k]);
        let mut last = along(u0);
        for i in 1..=1000 {
            let here = along(u0 + (u1 - u0) * i as f64 / 1000.0);
            assert!(
                here >= last - 1e-12,
                "move {k}: the cutter backs up by {:.4} um, {i}/1000 of the way",
                (last - here) * 1e3
            );
            last = here;
        }
    }
}

/// Between corners on neighbouring points no datum holds the curve: it is the chord
/// between them (what the smoothing gives where nothing else does), not pulled on past the
/// second corner by the moves before the first (it went 2.5 um past one on a post and came
/// back, backing up along the move).
#[test]
fn between_neighbouring_corners_the_curve_is_the_chord() {
    let up = [0.0, 0.0, 1.0];
    let points: Vec<Point> = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [3.0, 0.0, 0.0],
        [3.0, 1.0, 0.0],
        [4.0, 1.0, 0.0],
        [5.0, 1.0, 0.0],
        [6.0, 1.0, 0.0],
    ]
    .into_iter()
    .map(|p| pt(p, up))
    .collect();
    let u: Vec<f64> = (0..8).map(|k| k as f64 / 7.0).collect();
    let (u3, u4) = (u[3], u[4]);
    let mut knots = vec![0.0; 4];
    knots.extend([u3, u3, u3, u4, u4, u4]);
    knots.extend([1.0; 4]);
    let curve = solve(&points, &u, &knots, 3, &[(u3, 3), (u4, 4)]).expect("solves");
    for i in 0..=100 {
        let (c, _) = curve.eval(u3 + (u4 - u3) * i as f64 / 100.0);
        assert!(
            (c.x - 3.0).abs() < 1e-9 && c.z.abs() < 1e-9,
            "off the chord at {i}/100: {c:?}"
        );
        assert!(
            (c.y - i as f64 / 100.0).abs() < 1e-9,
            "not along it at {i}/100: {c:?}"
        );
    }
}
