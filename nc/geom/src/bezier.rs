//! The cutter curve as one rational Bezier piece per knot span, for the build-time work
//! that evaluates it tens of thousands of times per block: the arc-length table
//! ([`crate::arclen`]) integrates |C'(u)| with Gauss-Legendre over a thousand or more
//! intervals and checks its own inverse at each.
//!
//! A2.3 (basis functions with derivatives, [`DoubleNurbs::cutter`]) costs a span search and
//! a dozen divisions per evaluation; a span's Bezier net is evaluated by de Casteljau's
//! algorithm with no division but the final one by the weight, and is at least as well
//! conditioned (convex combinations of the homogeneous points only). The nets come from
//! Piegl & Tiller's decomposition (A5.6): each interior knot is inserted until its
//! multiplicity is the degree, which leaves the curve unchanged.
//!
//! Planner side only: the pieces live on the heap. The real-time thread keeps evaluating
//! [`DoubleNurbs`] itself.

use crate::nurbs::{Ders, DoubleNurbs};
use crate::program::MAX_DEGREE;
use nalgebra::Vector4;

type Net = [Vector4<f64>; MAX_DEGREE + 1];

/// The cutter curve of a [`DoubleNurbs`] cut into rational Bezier pieces, one per
/// non-empty knot span.
#[derive(Clone, Debug)]
pub struct Spans {
    degree: usize,
    /// Start parameter of every piece, ascending; the range's end after the last.
    starts: Vec<f64>,
    nets: Vec<Net>,
}

impl Spans {
    /// Decompose the cutter curve (A5.6). Linear in the number of control points times the
    /// degree squared.
    pub fn new(curve: &DoubleNurbs) -> Spans {
        let p = curve.degree();
        let u = curve.knots();
        let pw = curve.cutter_net();
        let m = u.len() - 1;
        let mut nets: Vec<Net> = Vec::new();
        let mut starts = Vec::new();
        let mut q: Net = [Vector4::zeros(); MAX_DEGREE + 1];
        q[..=p].copy_from_slice(&pw[..=p]);
        let (mut a, mut b) = (p, p + 1);
        let mut alphas = [0.0f64; MAX_DEGREE];
        while b < m {
            let i = b;
            while b < m && u[b + 1] == u[b] {
                b += 1;
            }
            let mult = b - i + 1;
            let mut next: Net = [Vector4::zeros(); MAX_DEGREE + 1];
            if mult < p {
                let numer = u[b] - u[a];
                for j in (mult + 1..=p).rev() {
                    alphas[j - mult - 1] = numer / (u[a + j] - u[a]);
                }
                let r = p - mult;
                for j in 1..=r {
                    let (save, s) = (r - j, mult + j);
                    for k in (s..=p).rev() {
                        let alpha = alphas[k - s];
                        q[k] = q[k] * alpha + q[k - 1] * (1.0 - alpha);
                    }
                    if b < m {
                        next[save] = q[p];
                    }
                }
            }
            starts.push(u[a]);
            nets.push(q);
            if b < m {
                let keep = p.saturating_sub(mult);
                next[keep..=p].copy_from_slice(&pw[b - p + keep..=b]);
                q = next;
                a = b;
                b += 1;
            }
        }
        let (_, end) = curve.range();
        starts.push(end);
        Spans {
            degree: p,
            starts,
            nets,
        }
    }

    /// The piece whose span holds `u` (clamped to the range): one binary search, then
    /// every evaluation inside that span is free of it.
    pub fn piece(&self, u: f64) -> Piece<'_> {
        let last = self.nets.len() - 1;
        let i = self
            .starts
            .partition_point(|&s| s <= u)
            .saturating_sub(1)
            .min(last);
        let (a, b) = (self.starts[i], self.starts[i + 1]);
        Piece {
            net: &self.nets[i],
            degree: self.degree,
            a,
            h: b - a,
        }
    }

    /// C(u) and C'(u) (see [`Piece::cutter`]).
    pub fn cutter(&self, u: f64) -> Ders {
        self.piece(u).cutter(u)
    }

    /// |C'(u)|, the integrand of arc length.
    pub fn speed(&self, u: f64) -> f64 {
        self.cutter(u).d1.norm()
    }
}

/// One span's rational Bezier piece.
#[derive(Clone, Copy, Debug)]
pub struct Piece<'a> {
    net: &'a Net,
    degree: usize,
    /// Start and width of the span.
    a: f64,
    h: f64,
}

impl Piece<'_> {
    /// C(u) and C'(u), as [`DoubleNurbs::cutter`] gives them (to rounding), for `u` in
    /// this span (clamped to it). Not the second derivative: on a span h wide it is a
    /// second difference of points that agree to h^2, and a span 1e-6 wide would lose 12
    /// digits of it (A2.3 keeps them).
    pub fn cutter(&self, u: f64) -> Ders {
        let t = ((u - self.a) / self.h).clamp(0.0, 1.0);
        let p = self.degree;
        let mut w = *self.net;
        // de Casteljau to level p - 1: two points, whose difference is the tangent.
        for level in 0..p - 1 {
            for j in 0..p - level {
                w[j] = w[j] * (1.0 - t) + w[j + 1] * t;
            }
        }
        let a = w[0] * (1.0 - t) + w[1] * t;
        let da = (w[1] - w[0]) * (p as f64 / self.h);
        let c0 = a.xyz() / a.w;
        Ders {
            p: c0,
            d1: (da.xyz() - c0 * da.w) / a.w,
            d2: Default::default(),
        }
    }

    /// |C'(u)| for `u` in this span.
    pub fn speed(&self, u: f64) -> f64 {
        self.cutter(u).d1.norm()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::paper;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    /// Relative to the derivative's size or the net's: a span 1e-6 wide scales C' by 1e6.
    fn rel(x: Vector3<f64>, y: Vector3<f64>, scale: f64) -> f64 {
        (x - y).norm() / (1.0 + y.norm().max(scale))
    }

    #[test]
    fn the_paper_block_evaluates_as_a2_3_does() {
        let c = paper();
        let s = Spans::new(&c);
        let (lo, hi) = c.range();
        for k in 0..=1000 {
            let u = lo + (hi - lo) * k as f64 / 1000.0;
            let (a, b) = (s.cutter(u), c.cutter(u, 1));
            assert!(rel(a.p, b.p, 100.0) < 1e-14, "u={u}: {a:?} vs {b:?}");
            assert!(rel(a.d1, b.d1, 100.0) < 1e-14, "u={u}: {a:?} vs {b:?}");
        }
    }

    proptest! {
        /// Any valid net: degree 1..=5, clustered and repeated knots (up to the degree),
        /// weights over six decades.
        #[test]
        fn any_net_evaluates_as_a2_3_does(
            p in 1usize..=5,
            extra in 0usize..12,
            pts in prop::collection::vec(
                ([-100.0..100.0f64, -100.0..100.0f64, -100.0..100.0f64], -3.0..3.0f64),
                17,
            ),
            gaps in prop::collection::vec(prop_oneof![Just(0.0), 1e-6..1e-3f64, 0.01..1.0f64], 12),
            at in prop::collection::vec(0.0..=1.0f64, 20),
        ) {
            let n = p + 1 + extra;
            let ctrl: Vec<[f64; 3]> = pts[..n].iter().map(|x| x.0).collect();
            let weights: Vec<f64> = pts[..n].iter().map(|x| 10f64.powf(x.1)).collect();
            let mut knots = vec![0.0; p + 1];
            let mut k = 0.0;
            let mut run = 1;
            for (i, g) in gaps[..extra].iter().enumerate() {
                // Clamped ends, no interior knot above the degree.
                let g = if *g == 0.0 && (run >= p || i == 0) { 0.5 } else { *g };
                run = if g == 0.0 { run + 1 } else { 1 };
                k += g;
                knots.push(k);
            }
            k += 0.25;
            knots.extend(std::iter::repeat_n(k, p + 1));
            let c = DoubleNurbs::new(p, &ctrl, &[], &weights, &knots).unwrap();
            let s = Spans::new(&c);
            let (lo, hi) = c.range();
            let mut us: Vec<f64> = at.iter().map(|t| lo + (hi - lo) * t).collect();
            us.extend(knots.iter().copied());
            let scale = ctrl.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs()));
            // Both evaluations round as the weights' spread magnifies (a net with weights
            // 4.4e4 apart differed by 3e-12 of its size): the bounds grow with it.
            let spread = weights.iter().fold(1.0f64, |m, w| m.max(*w))
                / weights.iter().fold(1.0f64, |m, w| m.min(*w));
            for u in us {
                let (a, b) = (s.cutter(u), c.cutter(u, 1));
                prop_assert!(
                    rel(a.p, b.p, scale) < 1e-12 + 1e-15 * spread,
                    "p at u={}: {:?} {:?}", u, a.p, b.p
                );
                prop_assert!(
                    rel(a.d1, b.d1, scale) < 1e-9 + 1e-12 * spread,
                    "d1 at u={}: {:?} {:?}", u, a.d1, b.d1
                );
            }
        }
    }
}
