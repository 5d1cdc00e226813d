//! Reference data for the tests and benchmarks of the NC crates (compiled for this crate's
//! tests, and for other crates with the `fixtures` feature): the paper's double-NURBS block
//! (docs/paper.md) and an independent evaluation of the B-spline basis.

use crate::nurbs::DoubleNurbs;

/// Degree of the paper's block (`G06.5 P3`).
pub const PAPER_DEGREE: usize = 3;
/// Cutter-centre control points X Y Z of the paper's block.
pub const PAPER_C: [[f64; 3]; 5] = [
    [47.7773, 71.0202, 58.8006],
    [44.3229, 75.6066, 54.4778],
    [37.2164, 84.6443, 44.5755],
    [28.7567, 101.5653, 29.7151],
    [-1.6963, 163.6796, 5.8369],
];
/// Orientation control points U V W of the paper's block.
pub const PAPER_T: [[f64; 3]; 5] = [
    [47.8066, 71.9791, 59.0828],
    [44.3651, 76.5494, 54.8138],
    [37.2554, 85.5421, 45.0342],
    [28.7081, 102.3535, 30.3361],
    [-1.8572, 163.9906, 6.7762],
];
/// Knots of the paper's block.
pub const PAPER_K: [f64; 9] = [0.0, 0.0, 0.0, 0.0, 0.5046, 1.0, 1.0, 1.0, 1.0];

/// The paper's block as a curve.
pub fn paper() -> DoubleNurbs {
    DoubleNurbs::new(PAPER_DEGREE, &PAPER_C, &PAPER_T, &[1.0; 5], &PAPER_K)
        .expect("the paper's block is a valid curve")
}

/// Cox-de Boor recursion (paper eq. 4), written independently of A2.2/A2.3.
pub fn n_rec(i: usize, p: usize, u: f64, k: &[f64]) -> f64 {
    if p == 0 {
        let last = k[k.len() - 1];
        // Close the last non-empty span on the right so u = u_max evaluates.
        let in_span = (k[i] <= u && u < k[i + 1]) || (u == last && k[i] < u && k[i + 1] == last);
        return if in_span { 1.0 } else { 0.0 };
    }
    let mut v = 0.0;
    if k[i + p] > k[i] {
        v += (u - k[i]) / (k[i + p] - k[i]) * n_rec(i, p - 1, u, k);
    }
    if k[i + p + 1] > k[i + 1] {
        v += (k[i + p + 1] - u) / (k[i + p + 1] - k[i + 1]) * n_rec(i + 1, p - 1, u, k);
    }
    v
}
