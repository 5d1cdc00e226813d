//! The pieces against an independent evaluation of the whole block (the Cox-de Boor
//! recursion of `crate::nurbs`'s tests, written from the definition, not from A2.3).

use super::*;
use crate::fixtures::n_rec;
use crate::program::MAX_CTRL;

/// The rational curve at u, evaluated only over the spans that touch it.
fn point(p: usize, net: &[[f64; 3]], w: &[f64], k: &[f64], u: f64) -> [f64; 3] {
    let span = k
        .partition_point(|&x| x <= u)
        .saturating_sub(1)
        .min(net.len() - 1);
    let (mut num, mut den) = ([0.0; 3], 0.0);
    for i in span.saturating_sub(p)..=span.min(net.len() - 1) {
        let b = n_rec(i, p, u, k) * w[i];
        for d in 0..3 {
            num[d] += b * net[i][d];
        }
        den += b;
    }
    num.map(|x| x / den)
}

/// A pseudo-random helix-like net (an LCG, so the test needs no crate).
fn net(n: usize, seed: u64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<f64>) {
    let mut x = seed;
    let mut rnd = || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut c, mut t, mut w) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..n {
        let a = i as f64 * 0.05;
        let p = [
            30.0 * a.cos() + rnd(),
            30.0 * a.sin() + rnd(),
            0.01 * i as f64,
        ];
        c.push(p);
        t.push([p[0] + rnd() - 0.5, p[1] + rnd() - 0.5, p[2] + 10.0]);
        w.push(0.2 + 4.0 * rnd());
    }
    (c, t, w)
}

fn uniform_knots(n: usize, p: usize) -> Vec<f64> {
    let mut k = vec![0.0; p + 1];
    k.extend((1..n - p).map(|i| i as f64 / (n - p) as f64));
    k.extend(vec![1.0; p + 1]);
    k
}

#[test]
fn a_block_of_ten_thousand_points_is_cut_into_pieces_that_are_the_same_curve() {
    for p in [1, 2, 3, 5] {
        let n = 10_000;
        let (c, t, w) = net(n, p as u64);
        let k = uniform_knots(n, p);
        let pieces = split(p, &c, &t, &w, &k).unwrap();
        assert!(pieces
            .iter()
            .all(|x| x.curve.knots().len() - p - 1 <= MAX_CTRL));
        // Pieces tile the parameter range without gap or overlap.
        assert_eq!(pieces[0].curve.range().0, 0.0);
        assert_eq!(pieces[pieces.len() - 1].curve.range().1, 1.0);
        for pair in pieces.windows(2) {
            assert_eq!(pair[0].curve.range().1, pair[1].curve.range().0);
        }
        if p > 1 {
            // Cut only for capacity: as few pieces as the capacity allows, no corners.
            assert!(
                pieces.len() <= n / (MAX_CTRL - p - 1) + 1,
                "{}",
                pieces.len()
            );
            assert!(pieces.iter().all(|x| !x.corner));
        }
        // Both curves at 3000 parameters against the independent evaluation.
        let mut worst: f64 = 0.0;
        for i in 0..=3000 {
            let u = i as f64 / 3000.0;
            let piece = pieces.iter().find(|x| u <= x.curve.range().1).unwrap();
            let (pc, pd) = piece.curve.cutter_and_tool(u, 0);
            let pt = pc.p + pd.p;
            let (ec, et) = (point(p, &c, &w, &k, u), point(p, &t, &w, &k, u));
            for d in 0..3 {
                worst = worst
                    .max((pc.p[d] - ec[d]).abs())
                    .max((pt[d] - et[d]).abs());
            }
        }
        assert!(worst < 1e-9, "degree {p}: {worst} mm");
    }
}

#[test]
fn a_knot_of_multiplicity_degree_is_a_corner_only_where_the_tangent_turns() {
    // Quadratic, knot 0.5 twice: the curve passes through the middle control point.
    let k = [0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
    let w = [1.0; 5];
    let kink = [
        [0.0, 0.0, 0.0],
        [5.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [10.0, 5.0, 0.0],
        [10.0, 10.0, 0.0],
    ];
    let pieces = split(2, &kink, &[], &w, &k).unwrap();
    assert_eq!(pieces.len(), 2);
    assert!(pieces[1].corner);
    let straight = [
        [0.0, 0.0, 0.0],
        [5.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [15.0, 0.0, 0.0],
        [20.0, 0.0, 0.0],
    ];
    let pieces = split(2, &straight, &[], &w, &k).unwrap();
    assert_eq!(pieces.len(), 2);
    assert!(!pieces[1].corner);
}

#[test]
fn the_whole_block_is_validated_before_it_is_cut() {
    let n = 200;
    let (c, _, mut w) = net(n, 9);
    let mut k = uniform_knots(n, 3);
    w[150] = 1e-9; // ratio above MAX_WEIGHT_RATIO
    assert!(matches!(
        split(3, &c, &[], &w, &k),
        Err(CurveError::WeightRatio { .. })
    ));
    w[150] = 1.0;
    k[100] = k[101] + 0.5; // decreasing
    assert_eq!(split(3, &c, &[], &w, &k), Err(CurveError::Knots));
    let big = MAX_BLOCK_CTRL + 1;
    let (c, _, w) = net(big, 1);
    assert_eq!(
        split(3, &c, &[], &w, &uniform_knots(big, 3)),
        Err(CurveError::CtrlCount(big))
    );
}
