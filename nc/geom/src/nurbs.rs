//! Rational B-spline evaluation for the double-NURBS block: the cutter-centre curve C(u) and
//! the orientation curve CT(u) share degree, knots and weights (paper eq. 2-3), so one basis
//! evaluation per period serves both curves.
//!
//! Algorithms are the standard ones from Piegl & Tiller, *The NURBS Book*: span search (A2.1),
//! basis functions with derivatives (A2.3) and derivatives of a rational curve from the
//! derivatives of its homogeneous form (A4.2). The recursive definition (paper eq. 4, 13) is
//! used only by the tests, as an independent check.
//!
//! Nothing here allocates: control nets are `heapless` vectors of fixed capacity and the
//! scratch space of A2.3 lives on the stack, sized by [`MAX_DEGREE`]. Loops are bounded by the
//! degree or by `log2(MAX_KNOTS)`. Evaluation outside the knot range clamps `u` to it.

use crate::program::{MAX_CTRL, MAX_DEGREE, MAX_KNOTS};
use heapless::Vec as HVec;
use nalgebra::{Vector3, Vector4};

/// Position, first and second derivative with respect to u of one curve.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ders {
    pub p: Vector3<f64>,
    pub d1: Vector3<f64>,
    pub d2: Vector3<f64>,
}

/// Why a control net cannot form a curve. The parser reports these with source positions;
/// this type guards the constructor for programmatic use.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum CurveError {
    #[error("degree {0} is outside 1..={MAX_DEGREE}")]
    Degree(usize),
    #[error("{ctrl} control points need {expected} knots, got {knots}")]
    KnotCount {
        ctrl: usize,
        knots: usize,
        expected: usize,
    },
    #[error("{0} control points: a degree-p block needs p+1 to {max} (a piece the real-time thread evaluates holds at most {MAX_CTRL})", max = crate::program::MAX_BLOCK_CTRL)]
    CtrlCount(usize),
    #[error("knot vector is not non-decreasing, clamped and finite with a non-empty range")]
    Knots,
    #[error("weight {0} is not finite and > 0")]
    Weight(f64),
    #[error("control point is not finite")]
    NonFinite,
    #[error("the orientation net has {tool} points, the cutter net {ctrl}")]
    ToolCount { ctrl: usize, tool: usize },
    #[error("the weights span a ratio of {ratio:.3e} (largest / smallest): at most {MAX_WEIGHT_RATIO:e} within one block")]
    WeightRatio { ratio: f64 },
    #[error("knot {knot} is repeated {mult} times, more than the degree {degree}: the curve is discontinuous there")]
    Discontinuous {
        knot: f64,
        mult: usize,
        degree: usize,
    },
    #[error("the end knot {knot} is repeated {mult} times: a clamped curve of degree {degree} repeats it exactly {} times, a control point past them would have no span", degree + 1)]
    EndKnots {
        knot: f64,
        mult: usize,
        degree: usize,
    },
}

/// Largest ratio of the weights within one block: beyond it the curve's parametric speed
/// varies over more orders of magnitude than its arc-length table can follow to 1e-9 mm.
pub const MAX_WEIGHT_RATIO: f64 = 1e6;

/// A pair of rational curves with shared degree, knots and weights. For a 3-axis block
/// (`G06.2`) the orientation net is empty and only C(u) is defined.
#[derive(Clone, Debug, PartialEq)]
pub struct DoubleNurbs {
    degree: usize,
    knots: HVec<f64, MAX_KNOTS>,
    /// Homogeneous cutter control points (w x, w y, w z, w).
    cw: HVec<Vector4<f64>, MAX_CTRL>,
    /// Homogeneous tool vectors, the orientation net less the cutter net
    /// (w (u - x), w (v - y), w (w - z), w); empty for G06.2. CT(u) - C(u) is the rational
    /// curve of this net: evaluated directly, its direction keeps full relative precision
    /// where the tool is near the vertical (a difference of the two curves' points would
    /// carry the rounding of the coordinates, 1e-15 of 20 mm, into a tilt of 1e-12).
    dw: HVec<Vector4<f64>, MAX_CTRL>,
}

/// Basis functions and their first two derivatives at one parameter (A2.3 output).
#[derive(Clone, Copy, Debug)]
struct Basis {
    span: usize,
    /// `n[k][j]`: k-th derivative of N_{span-p+j,p}.
    n: [[f64; MAX_DEGREE + 1]; 3],
}

/// The rules of a control net, whatever its size: degree, counts, a clamped non-decreasing
/// resolvable knot vector, no interior knot above the degree, weights finite and positive
/// within [`MAX_WEIGHT_RATIO`]. Used by [`DoubleNurbs::new`] and by the block splitter.
pub(crate) fn validate_net(
    degree: usize,
    n: usize,
    tool_len: usize,
    weights: &[f64],
    knots: &[f64],
) -> Result<(), CurveError> {
    if !(1..=MAX_DEGREE).contains(&degree) {
        return Err(CurveError::Degree(degree));
    }
    if n < degree + 1 || weights.len() != n {
        return Err(CurveError::CtrlCount(n));
    }
    if tool_len != 0 && tool_len != n {
        return Err(CurveError::ToolCount {
            ctrl: n,
            tool: tool_len,
        });
    }
    let expected = n + degree + 1;
    if knots.len() != expected {
        return Err(CurveError::KnotCount {
            ctrl: n,
            knots: knots.len(),
            expected,
        });
    }
    let ok = knots.iter().all(|k| k.is_finite())
        && knots.windows(2).all(|w| w[0] <= w[1])
        && knots[..=degree].iter().all(|&k| k == knots[0])
        && knots[n..].iter().all(|&k| k == knots[n + degree])
        // The range must be resolvable: u steps of 1e-12 of it stay distinct.
        && knots[n + degree] - knots[0] > 1e-9 * knots[0].abs().max(knots[n + degree].abs());
    if !ok {
        return Err(CurveError::Knots);
    }
    // Clamped means exactly degree + 1 at each end: one more leaves an empty first or last
    // span, where A2.3 divides 0 by 0 (measured: NaN at the block's start, then reported
    // as a travel error).
    let (first, last) = (knots[0], knots[n + degree]);
    for (knot, mult) in [
        (first, knots.iter().take_while(|&&k| k == first).count()),
        (last, knots.iter().rev().take_while(|&&k| k == last).count()),
    ] {
        if mult > degree + 1 {
            return Err(CurveError::EndKnots { knot, mult, degree });
        }
    }
    // An interior knot repeated more than the degree breaks the curve in two.
    let mut i = degree + 1;
    while i < n {
        let mult = knots[i..n].iter().take_while(|&&k| k == knots[i]).count();
        if mult > degree {
            return Err(CurveError::Discontinuous {
                knot: knots[i],
                mult,
                degree,
            });
        }
        i += mult;
    }
    if let Some(&w) = weights.iter().find(|w| !(w.is_finite() && **w > 0.0)) {
        return Err(CurveError::Weight(w));
    }
    let (wmin, wmax) = weights
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &w| {
            (lo.min(w), hi.max(w))
        });
    if wmax / wmin > MAX_WEIGHT_RATIO {
        return Err(CurveError::WeightRatio { ratio: wmax / wmin });
    }
    Ok(())
}

impl DoubleNurbs {
    /// Build from a control net. `tool` is either empty or as long as `ctrl`.
    pub fn new(
        degree: usize,
        ctrl: &[[f64; 3]],
        tool: &[[f64; 3]],
        weights: &[f64],
        knots: &[f64],
    ) -> Result<Self, CurveError> {
        // A longer tool net would pass as its first ctrl.len() points; a net over MAX_CTRL
        // is refused by `with_tool_vectors` (whatever the pushes below dropped).
        if !tool.is_empty() && tool.len() != ctrl.len() {
            return Err(CurveError::ToolCount {
                ctrl: ctrl.len(),
                tool: tool.len(),
            });
        }
        let mut vectors: HVec<[f64; 3], MAX_CTRL> = HVec::new();
        for (t, c) in tool.iter().zip(ctrl) {
            // At most MAX_CTRL: cannot fail.
            let _ = vectors.push([t[0] - c[0], t[1] - c[1], t[2] - c[2]]);
        }
        Self::with_tool_vectors(degree, ctrl, &vectors, weights, knots)
    }

    /// Build from the cutter net and the tool vectors (orientation point less cutter point,
    /// per control point); `vectors` is either empty or as long as `ctrl`.
    pub fn with_tool_vectors(
        degree: usize,
        ctrl: &[[f64; 3]],
        vectors: &[[f64; 3]],
        weights: &[f64],
        knots: &[f64],
    ) -> Result<Self, CurveError> {
        let n = ctrl.len();
        if n > MAX_CTRL {
            return Err(CurveError::CtrlCount(n));
        }
        validate_net(degree, n, vectors.len(), weights, knots)?;
        let mut out = DoubleNurbs {
            degree,
            knots: HVec::new(),
            cw: HVec::new(),
            dw: HVec::new(),
        };
        // Capacities were checked above, so these pushes cannot fail.
        out.knots
            .extend_from_slice(knots)
            .map_err(|_| CurveError::Knots)?;
        for (i, (&p, &w)) in ctrl.iter().zip(weights).enumerate() {
            if !(w.is_finite() && w > 0.0) {
                return Err(CurveError::Weight(w));
            }
            let hp = homogeneous(p, w).ok_or(CurveError::NonFinite)?;
            let _ = out.cw.push(hp);
            if let Some(&d) = vectors.get(i) {
                let hd = homogeneous(d, w).ok_or(CurveError::NonFinite)?;
                let _ = out.dw.push(hd);
            }
        }
        Ok(out)
    }

    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Whether the block carries an orientation curve (G06.5).
    pub fn has_tool_curve(&self) -> bool {
        !self.dw.is_empty()
    }

    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The homogeneous cutter control points (w x, w y, w z, w).
    pub(crate) fn cutter_net(&self) -> &[Vector4<f64>] {
        &self.cw
    }

    /// Parameter range [u_min, u_max].
    pub fn range(&self) -> (f64, f64) {
        let k = &self.knots;
        (k[self.degree], k[k.len() - 1 - self.degree])
    }

    /// Index of the knot span holding u (A2.1), with `u` already clamped to the range.
    /// Returns the last non-empty span for u = u_max. At most log2(MAX_KNOTS) iterations.
    fn find_span(&self, u: f64) -> usize {
        let n = self.cw.len() - 1; // index of the last control point
        let k = &self.knots;
        if u >= k[n + 1] {
            return n;
        }
        if u <= k[self.degree] {
            return self.degree;
        }
        let (mut low, mut high) = (self.degree, n + 1);
        let mut mid = (low + high) / 2;
        // Each pass halves [low, high]: bounded by log2(MAX_KNOTS) + 1.
        for _ in 0..16 {
            if u < k[mid] {
                high = mid;
            } else if u >= k[mid + 1] {
                low = mid;
            } else {
                break;
            }
            mid = (low + high) / 2;
        }
        mid
    }

    /// Basis functions and derivatives up to `nd` (<= 2) at u (A2.3).
    fn basis(&self, u: f64, nd: usize) -> Basis {
        let (lo, hi) = self.range();
        let u = u.clamp(lo, hi);
        let p = self.degree;
        let span = self.find_span(u);
        let k = &self.knots;
        let mut ndu = [[0.0f64; MAX_DEGREE + 1]; MAX_DEGREE + 1];
        let mut left = [0.0f64; MAX_DEGREE + 1];
        let mut right = [0.0f64; MAX_DEGREE + 1];
        ndu[0][0] = 1.0;
        for j in 1..=p {
            left[j] = u - k[span + 1 - j];
            right[j] = k[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j][r] = right[r + 1] + left[j - r];
                let temp = ndu[r][j - 1] / ndu[j][r];
                ndu[r][j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j][j] = saved;
        }
        let mut out = Basis {
            span,
            n: [[0.0; MAX_DEGREE + 1]; 3],
        };
        for (j, row) in ndu.iter().enumerate().take(p + 1) {
            out.n[0][j] = row[p];
        }
        let nd = nd.min(2).min(p);
        let mut a = [[0.0f64; MAX_DEGREE + 1]; 2];
        for r in 0..=p {
            let (mut s1, mut s2) = (0usize, 1usize);
            a[0][0] = 1.0;
            for kk in 1..=nd {
                let mut d = 0.0;
                let rk = r as isize - kk as isize;
                let pk = p - kk;
                if r >= kk {
                    let rk = rk as usize;
                    a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
                    d = a[s2][0] * ndu[rk][pk];
                }
                let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
                let j2 = if r as isize - 1 <= pk as isize {
                    kk - 1
                } else {
                    p - r
                };
                for j in j1..=j2 {
                    let idx = (rk + j as isize) as usize;
                    a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                    d += a[s2][j] * ndu[idx][pk];
                }
                if r <= pk {
                    a[s2][kk] = -a[s1][kk - 1] / ndu[pk + 1][r];
                    d += a[s2][kk] * ndu[r][pk];
                }
                out.n[kk][r] = d;
                core::mem::swap(&mut s1, &mut s2);
            }
        }
        let mut factor = p as f64;
        for kk in 1..=nd {
            for j in 0..=p {
                out.n[kk][j] *= factor;
            }
            factor *= (p - kk) as f64;
        }
        out
    }

    /// Derivatives 0..=nd of one rational curve from its homogeneous net (A4.2).
    fn rational(&self, b: &Basis, net: &[Vector4<f64>], nd: usize) -> Ders {
        let p = self.degree;
        let mut aw = [Vector4::zeros(); 3];
        for (k, awk) in aw.iter_mut().enumerate().take(nd + 1) {
            for j in 0..=p {
                *awk += net[b.span - p + j] * b.n[k][j];
            }
        }
        let w0 = aw[0].w;
        let c0 = aw[0].xyz() / w0;
        let mut out = Ders {
            p: c0,
            ..Ders::default()
        };
        if nd >= 1 {
            out.d1 = (aw[1].xyz() - c0 * aw[1].w) / w0;
        }
        if nd >= 2 {
            out.d2 = (aw[2].xyz() - out.d1 * (2.0 * aw[1].w) - c0 * aw[2].w) / w0;
        }
        out
    }

    /// C(u) and its derivatives up to `nd` (0, 1 or 2).
    pub fn cutter(&self, u: f64, nd: usize) -> Ders {
        let b = self.basis(u, nd);
        self.rational(&b, &self.cw, nd)
    }

    /// C(u) and the tool vector CT(u) - C(u), each with derivatives up to `nd`, from one
    /// basis evaluation. For a block without orientation curve the tool vector is zero.
    pub fn cutter_and_tool(&self, u: f64, nd: usize) -> (Ders, Ders) {
        let b = self.basis(u, nd);
        let c = self.rational(&b, &self.cw, nd);
        if self.dw.is_empty() {
            return (c, Ders::default());
        }
        (c, self.rational(&b, &self.dw, nd))
    }

    /// |C'(u)|: the parametric speed, the integrand of arc length.
    pub fn speed(&self, u: f64) -> f64 {
        self.cutter(u, 1).d1.norm()
    }
}

fn homogeneous(p: [f64; 3], w: f64) -> Option<Vector4<f64>> {
    let v = Vector4::new(p[0] * w, p[1] * w, p[2] * w, w);
    v.iter().all(|x| x.is_finite()).then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{n_rec, paper};

    fn rec_point(p: usize, ctrl: &[[f64; 3]], w: &[f64], k: &[f64], u: f64) -> [f64; 3] {
        let mut num = [0.0; 3];
        let mut den = 0.0;
        for i in 0..ctrl.len() {
            let b = n_rec(i, p, u, k) * w[i];
            den += b;
            for a in 0..3 {
                num[a] += b * ctrl[i][a];
            }
        }
        [num[0] / den, num[1] / den, num[2] / den]
    }

    /// The paper's block (docs/paper.md).
    #[test]
    fn a_knot_repeated_more_than_the_degree_is_a_discontinuity() {
        // Measured: an interior knot repeated degree + 1 times stepped Y by 5 mm in a period.
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 5.0, 0.0],
            [4.0, 0.0, 0.0],
            [5.0, 0.0, 0.0],
        ];
        let k = [0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0];
        assert_eq!(
            DoubleNurbs::new(2, &c, &[], &[1.0; 6], &k),
            Err(CurveError::Discontinuous {
                knot: 0.5,
                mult: 3,
                degree: 2
            })
        );
        // One more knot at either end: an empty first or last span.
        let k = [0.0, 0.0, 0.0, 0.0, 0.5, 0.7, 1.0, 1.0, 1.0];
        assert_eq!(
            DoubleNurbs::new(2, &c, &[], &[1.0; 6], &k),
            Err(CurveError::EndKnots {
                knot: 0.0,
                mult: 4,
                degree: 2
            })
        );
        let k = [0.0, 0.0, 0.0, 0.3, 0.5, 1.0, 1.0, 1.0, 1.0];
        assert_eq!(
            DoubleNurbs::new(2, &c, &[], &[1.0; 6], &k),
            Err(CurveError::EndKnots {
                knot: 1.0,
                mult: 4,
                degree: 2
            })
        );
        // Repeated degree times: continuous (a corner), accepted.
        let k = [0.0, 0.0, 0.0, 0.3, 0.5, 0.5, 1.0, 1.0, 1.0];
        assert!(DoubleNurbs::new(2, &c, &[], &[1.0; 6], &k).is_ok());
    }

    #[test]
    fn weights_spanning_more_than_the_ratio_are_refused() {
        use crate::fixtures::*;
        let w = [1.0, 1e-3, 1.0, 1e3, 1.0];
        assert!(DoubleNurbs::new(PAPER_DEGREE, &PAPER_C, &PAPER_T, &w, &PAPER_K).is_ok());
        let w = [1.0, 1e-4, 1.0, 1e3, 1.0];
        assert!(matches!(
            DoubleNurbs::new(PAPER_DEGREE, &PAPER_C, &PAPER_T, &w, &PAPER_K),
            Err(CurveError::WeightRatio { .. })
        ));
    }

    /// Quarter circle as a rational quadratic: exact radius 1 for every u.
    fn quarter_circle() -> DoubleNurbs {
        let s = core::f64::consts::FRAC_1_SQRT_2;
        DoubleNurbs::new(
            2,
            &[[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            &[],
            &[1.0, s, 1.0],
            &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        )
        .unwrap()
    }

    #[test]
    fn rational_quadratic_is_an_exact_circle() {
        let c = quarter_circle();
        for i in 0..=100 {
            let u = i as f64 / 100.0;
            let d = c.cutter(u, 2);
            assert!((d.p.norm() - 1.0).abs() < 1e-14, "u={u} r={}", d.p.norm());
            // Tangent is perpendicular to the radius; curvature of a unit circle is 1.
            assert!(d.p.dot(&d.d1).abs() < 1e-13);
            let kappa = d.d1.cross(&d.d2).norm() / d.d1.norm().powi(3);
            assert!((kappa - 1.0).abs() < 1e-12, "u={u} kappa={kappa}");
        }
        // Known values: u=1/2 lies at 45 degrees.
        let m = c.cutter(0.5, 0).p;
        assert!(
            (m.x - m.y).abs() < 1e-15 && (m.x - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15
        );
    }

    #[test]
    fn hand_checked_linear_and_bezier_cases() {
        // Degree 1: a polyline; u=0.25 is halfway along the first leg.
        let l = DoubleNurbs::new(
            1,
            &[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 4.0, 0.0]],
            &[],
            &[1.0; 3],
            &[0.0, 0.0, 0.5, 1.0, 1.0],
        )
        .unwrap();
        assert_eq!(l.cutter(0.25, 1).p, Vector3::new(1.0, 0.0, 0.0));
        assert_eq!(l.cutter(0.25, 1).d1, Vector3::new(4.0, 0.0, 0.0));
        assert_eq!(l.cutter(0.75, 0).p, Vector3::new(2.0, 2.0, 0.0));
        // Cubic Bezier 0,0 / 1,2 / 3,2 / 4,0 at u=1/2: (0+3+9+4)/8 = 2, (0+6+6+0)/8 = 1.5.
        let b = DoubleNurbs::new(
            3,
            &[
                [0.0, 0.0, 0.0],
                [1.0, 2.0, 0.0],
                [3.0, 2.0, 0.0],
                [4.0, 0.0, 0.0],
            ],
            &[],
            &[1.0; 4],
            &[0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        )
        .unwrap();
        let d = b.cutter(0.5, 2);
        assert!((d.p - Vector3::new(2.0, 1.5, 0.0)).norm() < 1e-15);
        // B'(1/2) = 3/4 (P1-P0) + 6/4 (P2-P1) + 3/4 (P3-P2): x = 0.75 + 3 + 0.75 = 4.5, y = 1.5 + 0 - 1.5 = 0.
        assert!(
            (d.d1 - Vector3::new(4.5, 0.0, 0.0)).norm() < 1e-14,
            "{:?}",
            d.d1
        );
        // B''(1/2) = 6 (1/2 (P2 - 2P1 + P0) + 1/2 (P3 - 2P2 + P1)) = 3(P3 - P2 - P1 + P0)
        assert!(
            (d.d2 - Vector3::new(0.0, -12.0, 0.0)).norm() < 1e-13,
            "{:?}",
            d.d2
        );
    }

    #[test]
    fn paper_block_matches_cox_de_boor_and_interpolates_ends() {
        let c = paper();
        let cp = crate::fixtures::PAPER_C;
        let k = c.knots().to_vec();
        for i in 0..=200 {
            let u = i as f64 / 200.0;
            let got = c.cutter(u, 0).p;
            let want = rec_point(3, &cp, &[1.0; 5], &k, u);
            for a in 0..3 {
                assert!((got[a] - want[a]).abs() < 1e-11, "u={u} axis {a}");
            }
        }
        // A clamped curve starts and ends at its end control points.
        assert!((c.cutter(0.0, 0).p - Vector3::from(cp[0])).norm() < 1e-12);
        assert!((c.cutter(1.0, 0).p - Vector3::from(cp[4])).norm() < 1e-12);
    }

    #[test]
    fn derivatives_match_central_differences() {
        let c = paper();
        let h = 1e-5;
        for &u in &[0.05, 0.3, 0.5, 0.51, 0.8, 0.95] {
            let (d, t) = c.cutter_and_tool(u, 2);
            let (dp, tp) = c.cutter_and_tool(u + h, 1);
            let (dm, tm) = c.cutter_and_tool(u - h, 1);
            let fd1 = (dp.p - dm.p) / (2.0 * h);
            let fd2 = (dp.d1 - dm.d1) / (2.0 * h);
            assert!((fd1 - d.d1).norm() < 1e-6 * d.d1.norm(), "u={u}");
            assert!((fd2 - d.d2).norm() < 1e-5 * d.d2.norm().max(1.0), "u={u}");
            let tfd1 = (tp.p - tm.p) / (2.0 * h);
            assert!((tfd1 - t.d1).norm() < 1e-6 * t.d1.norm(), "u={u}");
        }
    }

    #[test]
    fn the_tool_vector_keeps_its_direction_where_it_leaves_the_vertical() {
        // From the adversarial suite: a degree-1 block that starts with the tool exactly
        // vertical (U V W over X Y Z) at Y -22.6. As the difference of two evaluated points,
        // (Tx, Ty) carried the coordinates' rounding (1e-15) and its direction swung by 1e-4
        // rad at a tilt of 1e-12 rad: C steps the drives see when a hold creeps off the
        // vertical. From the net of tool vectors it is exact.
        let y = -22.60927444923984;
        let c = DoubleNurbs::new(
            1,
            &[[0.0, y, 0.0], [7.4481150232466735, y, 6.752408483251727]],
            &[
                [0.0, y, 10.162275665719585],
                [10.073281307934828, -23.039876326592815, 16.56030992581492],
            ],
            &[1.0, 0.024651413916821106],
            &[0.0, 0.0, 1.0, 1.0],
        )
        .unwrap();
        let (dx, dy): (f64, f64) = (
            10.073281307934828 - 7.4481150232466735,
            -23.039876326592815 - y,
        );
        let want = (-dx).atan2(dy);
        for e in 1..=15 {
            let u = 10f64.powi(-e);
            let (_, d) = c.cutter_and_tool(u, 0);
            let got = (-d.p.x).atan2(d.p.y);
            assert!((got - want).abs() < 1e-14, "u = {u}: {got} against {want}");
        }
        assert_eq!(
            c.cutter_and_tool(0.0, 0).1.p,
            Vector3::new(0.0, 0.0, 10.162275665719585)
        );
    }

    #[test]
    fn rational_weights_against_recursion() {
        let cp = [
            [0.0, 0.0, 0.0],
            [1.0, 3.0, 1.0],
            [4.0, 3.0, -1.0],
            [6.0, 0.0, 2.0],
            [8.0, 1.0, 0.0],
        ];
        let w = [1.0, 2.5, 0.4, 1.7, 1.0];
        let k = [0.0, 0.0, 0.0, 0.3, 0.7, 1.0, 1.0, 1.0];
        let c = DoubleNurbs::new(2, &cp, &[], &w, &k).unwrap();
        for i in 0..=100 {
            let u = i as f64 / 100.0;
            let got = c.cutter(u, 0).p;
            let want = rec_point(2, &cp, &w, &k, u);
            for a in 0..3 {
                assert!((got[a] - want[a]).abs() < 1e-12, "u={u}");
            }
        }
    }

    #[test]
    fn constructor_rejects_bad_nets() {
        let cp = [[0.0; 3]; 4];
        let k = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        assert_eq!(
            DoubleNurbs::new(0, &cp, &[], &[1.0; 4], &k),
            Err(CurveError::Degree(0))
        );
        assert!(matches!(
            DoubleNurbs::new(3, &cp, &[], &[1.0; 4], &k[..7]),
            Err(CurveError::KnotCount { .. })
        ));
        assert_eq!(
            DoubleNurbs::new(3, &cp, &[], &[1.0, 1.0, -1.0, 1.0], &k),
            Err(CurveError::Weight(-1.0))
        );
        let unclamped = [0.0, 0.0, 0.0, 0.1, 0.9, 1.0, 1.0, 1.0];
        assert_eq!(
            DoubleNurbs::new(3, &cp, &[], &[1.0; 4], &unclamped),
            Err(CurveError::Knots)
        );
    }
}
