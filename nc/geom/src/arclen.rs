//! Arc length of the cutter curve and its inverse u(s), for the `arclength` parameter update.
//!
//! Built once per block, outside the real-time thread: every non-empty knot span is cut into
//! a few equal parameter steps, halved where the table is least accurate, and each step's
//! length is integrated with 8-point Gauss-Legendre on the span's Bezier piece
//! ([`crate::bezier`]), giving a table of nodes (u_i, s_i, du/ds, d2u/ds2) with du/ds = 1/|C'| and
//! d2u/ds2 = -(C'.C'')/|C'|^4. Per period, u(s) is found by
//!   1. locating the node interval holding s (binary search, bounded);
//!   2. quintic Hermite interpolation between the two nodes, matching u, du/ds and d2u/ds2
//!      at both ends (error of order h^6);
//!   3. only for a table whose build-time check found the interpolation error above
//!      [`TOLERANCE`]: one Newton step on S(u) - s = 0 with S(u) = s_i + integral from u_i to
//!      u of |C'| (4-point Gauss-Legendre inside one knot span) and dS/du = |C'(u)|.
//!
//! The build-time check ([`ArcTable::new`]) measures the inversion error at the middle of
//! every interval against the 8-point integral, so the cheap path is used only where it
//! is shown to be accurate. On the paper's block and on a 61-span helix the interpolation
//! alone stays below a picometre; a real-time step then costs one basis evaluation for
//! the pose instead of six (see `cargo bench -p nc --bench step`).

use crate::bezier::Spans;
use crate::nurbs::DoubleNurbs;
use heapless::Vec as HVec;

/// Table capacity per block.
pub const MAX_NODES: usize = 2049;
/// Newton steps per evaluation when the interpolation alone is not accurate enough (bounded,
/// no convergence loop in the real-time path).
pub const NEWTON_STEPS: usize = 1;
/// Largest arc-length error (mm) of the interpolated inverse for which the Newton step is
/// skipped. A picometre keeps the feed fluctuation far below 1e-4 at any practical V Ts.
pub const TOLERANCE: f64 = 1e-9;
/// Intervals per knot span before refinement. Each costs some 50 evaluations of |C'| to
/// estimate and tabulate; the refinement puts nodes where the curve needs them. Measured:
/// 512 (the earlier start) spent 3.7 ms on the paper's block, 16 spend 0.9 ms and reach
/// [`MARGIN`] there; on tests/data/helix-ramp.nc 0.66 s against 0.02 s.
pub const START_PER_SPAN: usize = 16;
/// What the table's refinement aims at once every interval is within [`TOLERANCE`], with
/// the node budget left: a thousandth of it, so that the interpolated inverse alone is the
/// rule and the Newton step the exception.
pub const MARGIN: f64 = 1e-12;

/// Gauss-Legendre 8-point nodes and weights on [-1, 1] (published to more digits than an
/// f64 holds; the compiler rounds them correctly).
#[expect(
    clippy::excessive_precision,
    reason = "tabulated values, rounded by the compiler"
)]
pub const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329_0, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362_0),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362_0),
    (0.525_532_409_916_329_0, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];
/// Gauss-Legendre 4-point nodes and weights on [-1, 1].
pub const GL4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
];

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Node {
    u: f64,
    s: f64,
    /// |C'(u)|, clamped away from 0.
    speed: f64,
    /// d2u/ds2 = -(C'.C'')/|C'|^4.
    curl: f64,
}

impl Node {
    /// The node at parameter `u`, arc length `s` from the start.
    fn at(curve: &DoubleNurbs, u: f64, s: f64) -> Node {
        let d = curve.cutter(u, 2);
        let speed = d.d1.norm().max(MIN_SPEED);
        Node {
            u,
            s,
            speed,
            curl: -d.d1.dot(&d.d2) / speed.powi(4),
        }
    }
}

/// Smallest parametric speed used as a divisor (mm per unit u). A curve that slows below it
/// is treated as having a cusp there; the parser rejects such nets.
const MIN_SPEED: f64 = 1e-12;

/// Arc-length table of one block's cutter curve.
#[derive(Clone, Debug, PartialEq)]
pub struct ArcTable {
    nodes: HVec<Node, MAX_NODES>,
    /// Largest inversion error of the interpolation alone found at build time, mm; above
    /// [`TOLERANCE`], [`ArcTable::u_of_s`] refines with Newton.
    interp_error: f64,
}

/// Error estimate of one table interval [a, b], mm: how far the 8-point length is from the
/// sum over the two halves, and how far the quintic inverse misses at the middle.
fn interval_error(curve: &Build, a: f64, b: f64) -> f64 {
    let m = 0.5 * (a + b);
    let whole = integrate(curve, a, b, &GL8);
    let left = integrate(curve, a, m, &GL8);
    let halves = left + integrate(curve, m, b, &GL8);
    let (na, nb) = (
        Node::at(curve.curve, a, 0.0),
        Node::at(curve.curve, b, halves),
    );
    let s = 0.5 * halves;
    let u = ArcTable::interpolate(&na, &nb, s);
    let inverse = if u <= m {
        integrate(curve, a, u, &GL8) - s
    } else {
        left + integrate(curve, m, u, &GL8) - s
    };
    (whole - halves).abs().max(inverse.abs())
}

/// What [`integrate`] integrates: the parametric speed, from the curve itself (real time)
/// or from its Bezier pieces (build time, [`Build`]).
trait Speed {
    fn speed(&self, u: f64) -> f64;

    /// The integral of the speed over [a, b] by the Gauss-Legendre `rule`.
    fn integrate(&self, a: f64, b: f64, rule: &[(f64, f64)]) -> f64 {
        let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
        rule.iter()
            .map(|&(x, w)| w * self.speed(m + h * x))
            .sum::<f64>()
            * h
    }
}

impl Speed for DoubleNurbs {
    fn speed(&self, u: f64) -> f64 {
        DoubleNurbs::speed(self, u)
    }
}

/// The curve as the table's build evaluates it, tens of thousands of times: the speed from
/// its Bezier pieces (no span search, no division but by the weight), the nodes' second
/// derivatives from A2.3 (a few per interval, and exact on the narrowest spans).
struct Build<'a> {
    curve: &'a DoubleNurbs,
    spans: Spans,
}

impl Speed for Build<'_> {
    fn speed(&self, u: f64) -> f64 {
        self.spans.speed(u)
    }

    /// As the default, with the span found once: the table's intervals never straddle a
    /// knot (they are cut within spans).
    fn integrate(&self, a: f64, b: f64, rule: &[(f64, f64)]) -> f64 {
        let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
        let piece = self.spans.piece(m);
        rule.iter()
            .map(|&(x, w)| w * piece.speed(m + h * x))
            .sum::<f64>()
            * h
    }
}

fn integrate(curve: &impl Speed, a: f64, b: f64, rule: &[(f64, f64)]) -> f64 {
    curve.integrate(a, b, rule)
}

impl ArcTable {
    /// Tabulate the curve: [`START_PER_SPAN`] intervals on each non-empty span (at most half
    /// the node budget spread evenly), then halved where the table is least accurate
    /// ([`ArcTable::refine`]).
    pub fn new(curve: &DoubleNurbs) -> Self {
        Self::with_span_nodes(curve, START_PER_SPAN, true)
    }

    /// As [`ArcTable::new`] with at most `most` intervals per knot span to start from, and
    /// the error-driven refinement only when `refine`.
    fn with_span_nodes(curve: &DoubleNurbs, most: usize, refine: bool) -> Self {
        let knots = curve.knots();
        let build = Build {
            curve,
            spans: Spans::new(curve),
        };
        let spans = knots.windows(2).filter(|w| w[1] > w[0]).count().max(1);
        let per_span = ((MAX_NODES - 1) / 2 / spans).clamp(1, most.max(1));
        let mut cuts: Vec<(f64, f64)> = Vec::with_capacity(MAX_NODES);
        for w in knots.windows(2).filter(|w| w[1] > w[0]) {
            let (a, b) = (w[0], w[1]);
            for i in 0..per_span {
                let ua = a + (b - a) * i as f64 / per_span as f64;
                let ub = if i + 1 == per_span {
                    b
                } else {
                    a + (b - a) * (i + 1) as f64 / per_span as f64
                };
                cuts.push((ua, ub));
            }
        }
        if refine {
            Self::refine(&build, &mut cuts);
        }
        let mut nodes: HVec<Node, MAX_NODES> = HVec::new();
        let (u0, _) = curve.range();
        let _ = nodes.push(Node::at(curve, u0, 0.0));
        let mut s = 0.0;
        for &(ua, ub) in &cuts {
            s += integrate(&build, ua, ub, &GL8);
            // cuts.len() + 1 <= MAX_NODES by construction.
            let _ = nodes.push(Node::at(curve, ub, s));
        }
        let mut table = ArcTable {
            nodes,
            interp_error: 0.0,
        };
        table.interp_error = table.check(&build);
        table
    }

    /// Spend the rest of the node budget where the table is least accurate. A weight far
    /// below its neighbours' packs most of a curve's length into a sliver of its parameter
    /// range (a measured case: 22 of 37.6 mm within u in [0.998, 1]); intervals even in u
    /// then cannot follow it. Every interval's error is estimated once, when it is made
    /// (the 8-point length against the sum over its halves, and the quintic inverse at its
    /// middle); each pass halves the worst ones, until all are below [`TOLERANCE`], then
    /// below [`MARGIN`] with what budget is left, or until the budget is spent. The
    /// tolerance comes first so that no budget goes to the margin while an interval is
    /// still above it; and since the middle can hide an interval's error (the inverse's
    /// error crosses zero there), halving can find children worse than their parent: if
    /// the margin's passes end with an interval above the tolerance, the table stays as
    /// the tolerance's passes left it (measured on the butterfly: 1.1e-8 where the
    /// tolerance's passes had 9.9e-10).
    /// Bounded: at most `MAX_NODES` intervals, and each pass adds at least one.
    fn refine(curve: &Build, cuts: &mut Vec<(f64, f64)>) {
        let budget = MAX_NODES - 1;
        // Each interval's error is estimated once, when it is made.
        let error = |(a, b): (f64, f64)| {
            let e = interval_error(curve, a, b);
            if e.is_nan() {
                f64::INFINITY
            } else {
                e
            }
        };
        let mut errs: Vec<f64> = cuts.iter().map(|&c| error(c)).collect();
        let mut within: Option<Vec<(f64, f64)>> = None;
        for target in [TOLERANCE, MARGIN] {
            if target == MARGIN {
                if errs.iter().any(|&e| e > TOLERANCE) {
                    return; // the budget is spent
                }
                within = Some(cuts.clone());
            }
            while cuts.len() < budget {
                let mut bad: Vec<(f64, usize)> = errs
                    .iter()
                    .enumerate()
                    .filter(|&(_, &e)| e > target)
                    .map(|(i, &e)| (e, i))
                    .collect();
                if bad.is_empty() {
                    break;
                }
                bad.sort_by(|x, y| y.0.total_cmp(&x.0));
                bad.truncate(budget - cuts.len());
                let mut split: Vec<usize> = bad.iter().map(|&(_, i)| i).collect();
                split.sort_unstable();
                let mut out = Vec::with_capacity(cuts.len() + split.len());
                let mut out_errs = Vec::with_capacity(cuts.len() + split.len());
                let mut next = split.iter().peekable();
                for (i, &(a, b)) in cuts.iter().enumerate() {
                    let m = 0.5 * (a + b);
                    if next.peek() == Some(&&i) && m > a && m < b {
                        next.next();
                        out.extend([(a, m), (m, b)]);
                        out_errs.extend([error((a, m)), error((m, b))]);
                    } else {
                        out.push((a, b));
                        out_errs.push(errs[i]);
                    }
                }
                if out.len() == cuts.len() {
                    break; // nothing could be halved any more (f64 resolution)
                }
                *cuts = out;
                errs = out_errs;
            }
        }
        if let Some(within) = within {
            if errs.iter().any(|&e| e > TOLERANCE) {
                *cuts = within;
            }
        }
    }

    /// Largest |S(u_interp(s)) - s| at the middle of every interval (build time), where
    /// the quintic Hermite's leading error term, proportional to t^3 (1-t)^3, peaks.
    fn check(&self, curve: &Build) -> f64 {
        let mut worst: f64 = 0.0;
        for w in self.nodes.windows(2) {
            let (a, b) = (w[0], w[1]);
            let s = 0.5 * (a.s + b.s);
            let u = Self::interpolate(&a, &b, s);
            let err = a.s + integrate(curve, a.u, u, &GL8) - s;
            if err.is_nan() {
                return f64::INFINITY; // counts as too large: Newton stays on
            }
            worst = worst.max(err.abs());
        }
        worst
    }

    /// Largest inversion error of the interpolation alone found at build time, mm.
    pub fn interpolation_error(&self) -> f64 {
        self.interp_error
    }

    /// Whether the real-time inverse needs its Newton step on this curve.
    pub fn uses_newton(&self) -> bool {
        self.interp_error > TOLERANCE // never NaN: check() reports NaN as infinity
    }

    /// Quintic Hermite for u(s) between two nodes, clamped to their parameter interval.
    fn interpolate(a: &Node, b: &Node, s: f64) -> f64 {
        let h = b.s - a.s;
        if h <= 0.0 {
            return a.u;
        }
        let t = (s - a.s) / h;
        let (t2, t3) = (t * t, t * t * t);
        let (t4, t5) = (t3 * t, t3 * t2);
        let h0 = 1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5;
        let h1 = t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5;
        let h2 = 0.5 * (t2 - 3.0 * t3 + 3.0 * t4 - t5);
        let h3 = 10.0 * t3 - 15.0 * t4 + 6.0 * t5;
        let h4 = -4.0 * t3 + 7.0 * t4 - 3.0 * t5;
        let h5 = 0.5 * (t3 - 2.0 * t4 + t5);
        let u = h0 * a.u
            + h1 * h / a.speed
            + h2 * h * h * a.curl
            + h3 * b.u
            + h4 * h / b.speed
            + h5 * h * h * b.curl;
        u.clamp(a.u, b.u)
    }

    /// Total arc length of the cutter curve, mm.
    pub fn length(&self) -> f64 {
        self.nodes.last().map_or(0.0, |n| n.s)
    }

    /// Arc length from the start to parameter u (non-real-time helper for tests and reports).
    pub fn s_of_u(&self, curve: &DoubleNurbs, u: f64) -> f64 {
        let n = &self.nodes;
        let i = n
            .partition_point(|x| x.u <= u)
            .saturating_sub(1)
            .min(n.len() - 2);
        n[i].s + integrate(curve, n[i].u, u.clamp(n[i].u, n[i + 1].u), &GL8)
    }

    /// Parameter u at arc length s (clamped to [0, length]). Allocation-free and bounded:
    /// one binary search, one quintic Hermite interpolation and, only where the build-time
    /// check asks for it, [`NEWTON_STEPS`] Newton steps.
    pub fn u_of_s(&self, curve: &DoubleNurbs, s: f64) -> f64 {
        let n = &self.nodes;
        let len = n.len();
        if len < 2 {
            return n.first().map_or(0.0, |x| x.u);
        }
        let s = s.clamp(0.0, n[len - 1].s);
        let i = n
            .partition_point(|x| x.s <= s)
            .saturating_sub(1)
            .min(len - 2);
        let (a, b) = (n[i], n[i + 1]);
        let mut u = Self::interpolate(&a, &b, s);
        if !self.uses_newton() {
            return u;
        }
        for _ in 0..NEWTON_STEPS {
            let f = a.s + integrate(curve, a.u, u, &GL4) - s;
            let d = curve.speed(u).max(MIN_SPEED);
            u = (u - f / d).clamp(a.u, b.u);
        }
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::paper;

    #[test]
    fn quarter_circle_length_is_pi_over_two() {
        let s = core::f64::consts::FRAC_1_SQRT_2;
        let c = DoubleNurbs::new(
            2,
            &[[10.0, 0.0, 0.0], [10.0, 10.0, 0.0], [0.0, 10.0, 0.0]],
            &[],
            &[1.0, s, 1.0],
            &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        )
        .unwrap();
        let t = ArcTable::new(&c);
        assert!((t.length() - 5.0 * core::f64::consts::PI).abs() < 1e-12);
        // On a circle, arc length maps to angle: s = r * phi.
        for i in 0..=50 {
            let s_target = t.length() * i as f64 / 50.0;
            let p = c.cutter(t.u_of_s(&c, s_target), 0).p;
            let phi = p.y.atan2(p.x);
            assert!(
                (10.0 * phi - s_target).abs() < 1e-11,
                "s={s_target} got {}",
                10.0 * phi
            );
        }
    }

    #[test]
    fn inverse_round_trips_on_the_paper_block() {
        let c = paper();
        let t = ArcTable::new(&c);
        // Length by an independent fine Simpson sum over u.
        let n = 200_000;
        let h = 1.0 / n as f64;
        let mut simpson = c.speed(0.0) + c.speed(1.0);
        for i in 1..n {
            simpson += c.speed(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        simpson *= h / 3.0;
        assert!(
            (t.length() - simpson).abs() < 1e-9,
            "{} vs {simpson}",
            t.length()
        );
        for i in 0..=1000 {
            let s = t.length() * i as f64 / 1000.0;
            let u = t.u_of_s(&c, s);
            assert!((t.s_of_u(&c, u) - s).abs() < 1e-9, "s={s}");
        }
    }

    fn helix() -> DoubleNurbs {
        // 64 control points on a helix, cubic, uniform knots: 61 spans, 33 nodes each.
        let n = crate::program::MAX_CTRL;
        let ctrl: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let a = i as f64 * 0.4;
                [20.0 * a.cos(), 20.0 * a.sin(), i as f64 * 0.7]
            })
            .collect();
        let mut knots = vec![0.0; 4];
        knots.extend((1..n - 3).map(|i| i as f64 / (n - 3) as f64));
        knots.extend([1.0; 4]);
        DoubleNurbs::new(3, &ctrl, &[], &vec![1.0; n], &knots).unwrap()
    }

    /// Largest |S(u_of_s(s)) - s| over `n + 1` evenly spaced lengths, by the 8-point rule.
    fn inverse_error(t: &ArcTable, c: &DoubleNurbs, n: usize) -> f64 {
        (0..=n)
            .map(|i| {
                let s = t.length() * i as f64 / n as f64;
                (t.s_of_u(c, t.u_of_s(c, s)) - s).abs()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn interpolation_alone_is_exact_enough_with_the_most_spans_a_block_can_have() {
        let c = helix();
        let t = ArcTable::new(&c);
        assert!(
            !t.uses_newton(),
            "build-time error {}",
            t.interpolation_error()
        );
        let err = inverse_error(&t, &c, 4000);
        assert!(err < TOLERANCE, "inverse error {err}");
    }

    #[test]
    fn a_coarse_table_falls_back_to_newton() {
        // One interval per span: the interpolation alone is far off, the check sees it and
        // the Newton step brings the inverse much closer.
        let c = helix();
        let t = ArcTable::with_span_nodes(&c, 1, false);
        assert!(t.uses_newton());
        assert!(
            t.interpolation_error() > 1e-6,
            "{}",
            t.interpolation_error()
        );
        let refined = inverse_error(&t, &c, 4000);
        assert!(
            refined < t.interpolation_error() / 100.0,
            "with Newton {refined}, interpolation alone {}",
            t.interpolation_error()
        );
    }

    /// Found by the generated-input suite: a weight of 0.0013 after one of 0.18 puts
    /// 22 of the curve's 37.63 mm into u in [0.998, 1]. Nodes even in u mapped the last
    /// 19 mm to one point, and the planner crawled over them at its floor speed (a 5.4 h
    /// plan for a 37 mm block).
    #[test]
    fn a_curve_whose_length_hides_in_a_sliver_of_u_is_tabulated_where_the_length_is() {
        let ctrl = [
            [-43.85275966882819, -132.27819743303345, -34.55025132146647],
            [-43.85309551630374, -132.2787187819646, -34.55108549164306],
            [-39.21933400231994, -140.21129433564624, -43.02308041568442],
            [-39.22011494613549, -140.21083522161072, -43.02400796559163],
            [-56.551728926028424, -158.25220957940536, -45.45402140727964],
            [-56.55081865951343, -158.25207111806495, -45.454069719030436],
        ];
        let w = [
            1.0,
            0.016567041864111783,
            38.70446418502049,
            756.9761847349334,
            0.1828390119892949,
            0.0013366146308474776,
        ];
        let mut knots = vec![0.0; 6];
        knots.extend([1.0; 6]);
        let c = DoubleNurbs::new(5, &ctrl, &[], &w, &knots).unwrap();
        let t = ArcTable::new(&c);
        // The length by an independent polyline of 4 million chords (numpy, 37.62942132).
        assert!((t.length() - 37.629_421_32).abs() < 1e-7, "{}", t.length());
        let err = inverse_error(&t, &c, 4000);
        assert!(err < 1e-9, "inverse error {err} mm");
        // Equal steps of s are equal steps along the curve.
        let n = 1000;
        let step = t.length() / n as f64;
        let mut prev = c.cutter(t.u_of_s(&c, 0.0), 0).p;
        for i in 1..=n {
            let p = c.cutter(t.u_of_s(&c, step * i as f64), 0).p;
            let chord = (p - prev).norm();
            assert!(
                chord <= step + 2e-9 && chord > 0.5 * step,
                "step {i}: {chord}"
            );
            prev = p;
        }
    }
}
