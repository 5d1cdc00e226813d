//! Any curve size in fixed-capacity pieces: a NURBS block of up to [`MAX_BLOCK_CTRL`]
//! control points is cut, in the planner thread, into pieces of at most
//! [`MAX_CTRL`](crate::program::MAX_CTRL) points that the real-time thread evaluates as before.
//!
//! A cut at a parameter `u` raises the multiplicity of `u` to the degree by knot insertion
//! (Boehm's algorithm, Piegl & Tiller A5.1, one knot at a time) on the homogeneous points of
//! the cutter net and the tool vectors at once, since they share knots and weights. The curve is unchanged by
//! insertion, so the pieces join with the block's own continuity there: a cut at a simple
//! knot of a cubic keeps C2, and the planner passes the joint at speed.
//!
//! Cuts are made:
//! * at every interior knot of multiplicity = degree where the cutter's tangent turns: a
//!   kink. The piece after it is marked [`Piece::corner`], and the planner brings the path
//!   to rest exactly there;
//! * between those, at knots chosen so that no piece holds more than `MAX_CTRL` points.
//!
//! Cutting runs from the end of the net to its start, so each insertion moves only the
//! points behind it: linear in the block's size.

use crate::nurbs::{CurveError, DoubleNurbs};
use crate::program::MAX_CTRL;

use crate::program::MAX_BLOCK_CTRL;

/// Tangent turn (radians) above which a knot of multiplicity = degree is a corner.
pub const CORNER_RAD: f64 = 1e-6;

/// One piece of a cut block.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    pub curve: DoubleNurbs,
    /// The cutter's tangent turns where this piece starts (a kink inside the block).
    pub corner: bool,
}

/// A homogeneous point of the cutter net and of the tool vectors (orientation point less
/// cutter point, see [`DoubleNurbs::with_tool_vectors`]): w x, w y, w z, w (u - x),
/// w (v - y), w (w - z), w.
type Hp = [f64; 7];

/// Cut a block's net into pieces (see the module doc). The whole net is validated first
/// with the same rules as a single piece (except the size), so the errors are the block's.
pub fn split(
    degree: usize,
    ctrl: &[[f64; 3]],
    tool: &[[f64; 3]],
    weights: &[f64],
    knots: &[f64],
) -> Result<Vec<Piece>, CurveError> {
    let n = ctrl.len();
    if n > MAX_BLOCK_CTRL {
        return Err(CurveError::CtrlCount(n));
    }
    // The whole net first: the knot scan below relies on a valid knot vector.
    crate::nurbs::validate_net(degree, n, tool.len(), weights, knots)?;
    if n <= MAX_CTRL && !has_full_knots(degree, knots) {
        let curve = DoubleNurbs::new(degree, ctrl, tool, weights, knots)?;
        return Ok(vec![Piece {
            curve,
            corner: false,
        }]);
    }
    cut(degree, ctrl, tool, weights, knots)
}

/// Whether some interior knot has multiplicity >= degree (a possible kink).
fn has_full_knots(p: usize, knots: &[f64]) -> bool {
    let n = knots.len() - p - 1;
    let mut i = p + 1;
    while i < n {
        let m = knots[i..n].iter().take_while(|&&k| k == knots[i]).count();
        if m >= p {
            return true;
        }
        i += m;
    }
    false
}

fn cut(
    p: usize,
    ctrl: &[[f64; 3]],
    tool: &[[f64; 3]],
    weights: &[f64],
    knots: &[f64],
) -> Result<Vec<Piece>, CurveError> {
    let n = ctrl.len();
    let g065 = !tool.is_empty();
    let mut pts: Vec<Hp> = (0..n)
        .map(|i| {
            let (c, w) = (ctrl[i], weights[i]);
            // The tool vector (none for G06.2).
            let d = tool
                .get(i)
                .map_or([0.0; 3], |t| [t[0] - c[0], t[1] - c[1], t[2] - c[2]]);
            [
                c[0] * w,
                c[1] * w,
                c[2] * w,
                d[0] * w,
                d[1] * w,
                d[2] * w,
                w,
            ]
        })
        .collect();
    let mut kn: Vec<f64> = knots.to_vec();
    let (lo, hi) = (knots[0], knots[n + p]);
    let min_gap = 1e-9 * (hi - lo);

    // Distinct interior knots with their multiplicity and the count of knots before them.
    let mut distinct: Vec<(f64, usize, usize)> = Vec::new();
    let mut i = p + 1;
    while i < n {
        let m = knots[i..n].iter().take_while(|&&k| k == knots[i]).count();
        distinct.push((knots[i], m, i - p - 1));
        i += m;
    }
    // Where to cut: every full-multiplicity knot (a corner test comes after the cut), and
    // enough others that each piece holds at most MAX_CTRL points. A piece from cut a to
    // cut b holds (interior knots strictly between them) + p + 1 points.
    let room = MAX_CTRL - p - 1;
    let mut cuts: Vec<f64> = Vec::new();
    let mut start = 0usize; // interior knots before the current piece's first cut
    let mut last_cut = lo;
    for (k, &(u, m, before)) in distinct.iter().enumerate() {
        let inside = before - start; // interior knots strictly between last cut and u
        let next_full = m >= p;
        // Would the piece grow too large if it went on to the next distinct knot?
        let next_inside = distinct
            .get(k + 1)
            .map_or(n - p - 1 - start, |&(_, _, b)| b - start);
        let cut_here = next_full || next_inside > room;
        if cut_here && inside <= room && u - last_cut > min_gap && hi - u > min_gap {
            cuts.push(u);
            start = before + m;
            last_cut = u;
        }
    }

    // Cut from the end: each cut inserts near the tail and splits the tail off.
    let mut tails: Vec<(Vec<f64>, Vec<Hp>)> = Vec::with_capacity(cuts.len() + 1);
    for &u in cuts.iter().rev() {
        let s = kn.iter().filter(|&&k| k == u).count();
        for _ in s..p {
            insert(p, &mut kn, &mut pts, u);
        }
        // u now stands p times from index i0; the shared point is pts[i0 - 1].
        let i0 = kn.partition_point(|&k| k < u);
        let mut right_k = vec![u];
        right_k.extend_from_slice(&kn[i0..]);
        let right_p = pts[i0 - 1..].to_vec();
        kn.truncate(i0 + p);
        kn.push(u);
        pts.truncate(i0);
        tails.push((right_k, right_p));
    }
    tails.push((kn, pts));
    tails.reverse();

    let mut out: Vec<Piece> = Vec::with_capacity(tails.len());
    for (k, p_pts) in &tails {
        let w: Vec<f64> = p_pts.iter().map(|h| h[6]).collect();
        let c: Vec<[f64; 3]> = p_pts
            .iter()
            .map(|h| [h[0] / h[6], h[1] / h[6], h[2] / h[6]])
            .collect();
        let t: Vec<[f64; 3]> = if g065 {
            p_pts
                .iter()
                .map(|h| [h[3] / h[6], h[4] / h[6], h[5] / h[6]])
                .collect()
        } else {
            Vec::new()
        };
        let curve = DoubleNurbs::with_tool_vectors(p, &c, &t, &w, k)?;
        let corner = out
            .last()
            .is_some_and(|prev: &Piece| turns(&prev.curve, &curve));
        out.push(Piece { curve, corner });
    }
    Ok(out)
}

/// Does the cutter's tangent turn where `a` ends and `b` starts? A zero derivative on
/// either side (coincident control points) leaves the direction undefined: a corner.
fn turns(a: &DoubleNurbs, b: &DoubleNurbs) -> bool {
    let ta = a.cutter(a.range().1, 1).d1;
    let tb = b.cutter(b.range().0, 1).d1;
    let (na, nb) = (ta.norm(), tb.norm());
    if !(na > 1e-12 && nb > 1e-12) {
        return true;
    }
    let angle = ta.cross(&tb).norm().atan2(ta.dot(&tb));
    angle > CORNER_RAD || angle.is_nan()
}

/// Insert `u` once (Boehm): the curve is unchanged, one point and one knot more.
fn insert(p: usize, kn: &mut Vec<f64>, pts: &mut Vec<Hp>, u: f64) {
    // Span k: kn[k] <= u < kn[k + 1].
    let k = kn.partition_point(|&x| x <= u) - 1;
    let mut new = [[0.0; 7]; crate::program::MAX_DEGREE];
    for (j, i) in (k + 1 - p..=k).enumerate() {
        let a = (u - kn[i]) / (kn[i + p] - kn[i]);
        for (d, v) in new[j].iter_mut().enumerate() {
            *v = a * pts[i][d] + (1.0 - a) * pts[i - 1][d];
        }
    }
    // Q_i = P_i for i <= k - p; Q_{k-p+1..=k} = new; Q_i = P_{i-1} for i >= k + 1.
    pts.insert(k, [0.0; 7]);
    pts[k + 1 - p..=k].copy_from_slice(&new[..p]);
    kn.insert(k + 1, u);
}

#[cfg(test)]
mod tests;
