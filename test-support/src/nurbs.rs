//! A NURBS curve's points by de Boor's algorithm, for tests that check a curve against
//! another interpreter's (any number of control points, unlike the real-time evaluator's
//! pieces), and LinuxCNC's reading of an arc's sweep.

/// A point of a NURBS curve of any length (de Boor on homogeneous points).
pub fn point(degree: usize, ctrl: &[[f64; 3]], weights: &[f64], knots: &[f64], u: f64) -> [f64; 3] {
    let n = ctrl.len();
    // The knot span: knots[k] <= u < knots[k + 1], the last span for u at the end.
    let k = (degree..n).rev().find(|&k| knots[k] <= u).unwrap_or(degree);
    let mut d: Vec<[f64; 4]> = (0..=degree)
        .map(|j| {
            let (p, w) = (ctrl[k - degree + j], weights[k - degree + j]);
            [p[0] * w, p[1] * w, p[2] * w, w]
        })
        .collect();
    for r in 1..=degree {
        for j in (r..=degree).rev() {
            let i = k - degree + j;
            let den = knots[i + degree + 1 - r] - knots[i];
            let a = if den == 0.0 {
                0.0
            } else {
                (u - knots[i]) / den
            };
            let prev = d[j - 1];
            for (v, p) in d[j].iter_mut().zip(prev) {
                *v = (1.0 - a) * p + a * *v;
            }
        }
    }
    let h = d[degree];
    [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
}

/// The signed sweep (rad) of a LinuxCNC arc from angle `a0` to `a1` about its centre:
/// `turn` > 0 counter-clockwise in the plane's (first, second) axes, < 0 clockwise, and
/// |`turn`| - 1 extra full turns (its `ARC_FEED`'s `rotation`).
pub fn sweep(a0: f64, a1: f64, turn: i32) -> f64 {
    let tau = std::f64::consts::TAU;
    let mut sweep = a1 - a0;
    if turn > 0 {
        while sweep <= 1e-12 {
            sweep += tau;
        }
        sweep += f64::from(turn - 1) * tau;
    } else {
        while sweep >= -1e-12 {
            sweep -= tau;
        }
        sweep -= f64::from(-turn - 1) * tau;
    }
    sweep
}
