//! A NURBS curve's points by de Boor's algorithm, for tests that check a curve against
//! another interpreter's (any number of control points, unlike the real-time evaluator's
//! pieces).

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
