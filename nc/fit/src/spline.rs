//! The B-spline pieces the fit needs, on growable knot vectors (the real-time evaluator,
//! `nc_geom::nurbs`, has fixed capacity): the knot span, the basis functions, and a banded
//! symmetric positive-definite solve for the least-squares normal equations.

/// Highest degree the fit writes.
pub const MAX_FIT_DEGREE: usize = 5;

/// The knot span holding u: the largest i in p..n with knots[i] <= u (and n - 1 at the
/// end), for a clamped vector of n control points (the NURBS Book, A2.1).
pub fn span(knots: &[f64], p: usize, n: usize, u: f64) -> usize {
    if u >= knots[n] {
        return n - 1;
    }
    if u <= knots[p] {
        return p;
    }
    let (mut lo, mut hi) = (p, n);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if u < knots[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// The p + 1 basis functions that do not vanish on span i at u (A2.2), into `out[..=p]`.
pub fn basis(knots: &[f64], p: usize, i: usize, u: f64, out: &mut [f64; MAX_FIT_DEGREE + 1]) {
    let mut left = [0.0; MAX_FIT_DEGREE + 1];
    let mut right = [0.0; MAX_FIT_DEGREE + 1];
    out[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[i + 1 - j];
        right[j] = knots[i + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let den = right[r + 1] + left[j - r];
            let tmp = if den != 0.0 { out[r] / den } else { 0.0 };
            out[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        out[j] = saved;
    }
}

/// A symmetric banded matrix, its lower band stored by rows: `band[i][k]` is A[i][i - k],
/// for k in 0..=width.
pub struct Band {
    pub n: usize,
    pub width: usize,
    band: Vec<f64>,
}

impl Band {
    pub fn new(n: usize, width: usize) -> Self {
        Band {
            n,
            width,
            band: vec![0.0; n * (width + 1)],
        }
    }

    /// Add `x` to A[i][j] (and A[j][i]); |i - j| <= width.
    pub fn add(&mut self, i: usize, j: usize, x: f64) {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        debug_assert!(i - j <= self.width);
        self.band[i * (self.width + 1) + (i - j)] += x;
    }

    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        if i - j > self.width {
            0.0
        } else {
            self.band[i * (self.width + 1) + (i - j)]
        }
    }

    fn at(&mut self, i: usize, j: usize) -> &mut f64 {
        &mut self.band[i * (self.width + 1) + (i - j)]
    }

    /// Solve A x = b for each of the `m` right-hand sides in `rhs` (row-major, n rows of m)
    /// by a banded Cholesky factorisation, in place. `None` if A is not positive definite.
    pub fn solve<const M: usize>(mut self, rhs: &mut [[f64; M]]) -> Option<()> {
        let (n, w) = (self.n, self.width);
        for i in 0..n {
            let j0 = i.saturating_sub(w);
            for j in j0..=i {
                let mut sum = self.get(i, j);
                for k in j0.max(j.saturating_sub(w))..j {
                    sum -= self.get(i, k) * self.get(j, k);
                }
                if i == j {
                    if sum <= 0.0 || !sum.is_finite() {
                        return None;
                    }
                    *self.at(i, i) = sum.sqrt();
                } else {
                    *self.at(i, j) = sum / self.get(j, j);
                }
            }
        }
        // L y = b, then L^T x = y.
        for i in 0..n {
            for k in i.saturating_sub(w)..i {
                let l = self.get(i, k);
                let yk = rhs[k];
                for (x, y) in rhs[i].iter_mut().zip(yk) {
                    *x -= l * y;
                }
            }
            let d = self.get(i, i);
            rhs[i].iter_mut().for_each(|x| *x /= d);
        }
        for i in (0..n).rev() {
            for k in i + 1..(i + w + 1).min(n) {
                let l = self.get(k, i);
                let xk = rhs[k];
                for (x, y) in rhs[i].iter_mut().zip(xk) {
                    *x -= l * y;
                }
            }
            let d = self.get(i, i);
            rhs[i].iter_mut().for_each(|x| *x /= d);
        }
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_basis_is_a_partition_of_unity_and_matches_the_recursion() {
        let knots = [0.0, 0.0, 0.0, 0.0, 0.2, 0.5, 0.5, 0.9, 1.0, 1.0, 1.0, 1.0];
        let (p, n) = (3, knots.len() - 4);
        for k in 0..=200 {
            let u = f64::from(k) / 200.0;
            let i = span(&knots, p, n, u);
            assert!(
                knots[i] <= u && (u < knots[i + 1] || i == n - 1),
                "u {u} span {i}"
            );
            let mut b = [0.0; MAX_FIT_DEGREE + 1];
            basis(&knots, p, i, u, &mut b);
            let sum: f64 = b[..=p].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14, "sum {sum} at {u}");
            for (r, &x) in b[..=p].iter().enumerate() {
                let want = nc_geom::fixtures::n_rec(i - p + r, p, u, &knots);
                assert!(
                    (x - want).abs() < 1e-12,
                    "N{} at {u}: {x} vs {want}",
                    i - p + r
                );
            }
        }
    }

    #[test]
    fn the_banded_solve_inverts_a_banded_matrix() {
        // A pentadiagonal SPD matrix and a known solution.
        let n = 9;
        let mut a = Band::new(n, 2);
        for i in 0..n {
            a.add(i, i, 6.0 + i as f64);
            if i >= 1 {
                a.add(i, i - 1, -1.5);
            }
            if i >= 2 {
                a.add(i, i - 2, 0.5);
            }
        }
        let x: Vec<[f64; 2]> = (0..n).map(|i| [i as f64 - 3.0, (i * i) as f64]).collect();
        let mut b: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let row = |c: usize| (0..n).map(|j| a.get(i, j) * x[j][c]).sum::<f64>();
                [row(0), row(1)]
            })
            .collect();
        a.solve(&mut b).unwrap();
        for (got, want) in b.iter().zip(&x) {
            assert!((got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12);
        }
    }
}
