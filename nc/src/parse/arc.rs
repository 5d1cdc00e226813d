//! `G02` / `G03` arcs as rational quadratic NURBS: the circle exactly, so the interpolator,
//! the planner and their limit proofs apply to arcs unchanged.
//!
//! An arc of sweep `theta` in the active plane is cut into `n` equal pieces of sweep
//! `2 alpha <= 90 deg`. Each piece is the textbook rational quadratic: end points on the
//! circle with weight 1, the middle control point where the end tangents meet
//! (`R / cos alpha` from the centre) with weight `cos alpha`; interior knots are doubled.
//! The curve is then exactly the circle, tangent-continuous at every joint.
//!
//! A helix (the axis normal to the plane changes along the arc) is not a rational curve: its
//! normal coordinate is linear in the angle, and no rational function of the circle's
//! parameter is. The normal coordinate's control points are placed at each piece's ends and
//! middle (weighted like the circle's); the point at angle `phi` is then off the true helix
//! along the normal by at most `0.0684 alpha^3 |dz / dphi|` (the coefficient measured over
//! `alpha <= 45 deg`; 0.0642 for small `alpha`), so the pieces are made small enough that
//! this is below [`HELIX_TOL_MM`]. In the plane, the helix's projection is still exactly
//! the circle.
//!
//! The centre comes from `I J K` (offsets from the start, in the plane's letters) or from `R`
//! (`R > 0`: the arc of at most 180 deg, `R < 0`: the longer one). Posted coordinates are
//! rounded, so the start and end radii differ slightly: up to [`ARC_RADIUS_TOL_MM`] is
//! accepted, and the centre is moved onto the bisector of start and end (the nearest point to
//! the programmed centre), so the arc runs exactly from the start to the programmed end.

use super::codes::Plane;
use super::error::ParseErrorKind;
use core::f64::consts::{FRAC_PI_2, TAU};

/// Largest accepted difference between the start and end radius, mm.
pub const ARC_RADIUS_TOL_MM: f64 = 0.002;
/// Smallest arc radius, mm.
pub const MIN_ARC_RADIUS_MM: f64 = 1e-3;
/// Largest distance of a helix's points from the true helix, mm (along its axis): a
/// hundredth of a 0.1 um drive count (about 70 pieces a turn at a 1 mm pitch). 1e-9 was
/// tried: ten times the pieces, and a helix took twice as long to run (more segment
/// junctions) and ten times as long to plan.
pub const HELIX_TOL_MM: f64 = 1e-6;
/// Most pieces one arc is cut into: a block's control points, `2 pieces + 1`, stay within
/// [`MAX_BLOCK_CTRL`](crate::split::MAX_BLOCK_CTRL). A helix within a machine's travel needs
/// far fewer (a full turn rising 200 000 mm: about 4 100); beyond it the arc is an error.
const MAX_PIECES: usize = (crate::split::MAX_BLOCK_CTRL - 1) / 2;

/// How the arc's centre is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Centre {
    /// Offsets from the start point along the plane's first and second axis, mm.
    Offsets(f64, f64),
    /// `R`, mm (negative: the longer arc).
    Radius(f64),
}

/// The control net of an arc: points, weights, knots (degree 2).
#[derive(Clone, Debug, PartialEq)]
pub struct ArcNet {
    pub ctrl: Vec<[f64; 3]>,
    pub weights: Vec<f64>,
    pub knots: Vec<f64>,
    /// Centre (in the plane; its normal coordinate is the start's), radius and signed sweep
    /// (positive counter-clockwise seen from +normal), for tests and reports.
    pub centre: [f64; 3],
    pub radius: f64,
    pub sweep: f64,
}

/// The net of the arc from `start` to `end` in `plane`, clockwise (`G02`) or not (`G03`).
pub fn arc(
    start: [f64; 3],
    end: [f64; 3],
    plane: Plane,
    clockwise: bool,
    centre: Centre,
) -> Result<ArcNet, ParseErrorKind> {
    let (a, b, n) = plane.axes();
    let at = |p: &[f64; 3], i: usize| p.get(i).copied().unwrap_or(0.0);
    let (sa, sb) = (at(&start, a), at(&start, b));
    let (ea, eb) = (at(&end, a), at(&end, b));
    let (da, db) = (ea - sa, eb - sb);
    let chord = da.hypot(db);
    let full = chord <= 1e-9;
    let (ca, cb) = match centre {
        Centre::Offsets(i, j) => {
            let (ca, cb) = (sa + i, sb + j);
            let rs = (sa - ca).hypot(sb - cb);
            let re = (ea - ca).hypot(eb - cb);
            if (rs - re).is_nan() || (rs - re).abs() > ARC_RADIUS_TOL_MM {
                return Err(ParseErrorKind::ArcRadiusMismatch { start: rs, end: re });
            }
            if full {
                (ca, cb)
            } else {
                // The point of the bisector of start and end nearest the programmed centre.
                let (ma, mb) = ((sa + ea) / 2.0, (sb + eb) / 2.0);
                let (ua, ub) = (-db / chord, da / chord);
                let t = (ca - ma) * ua + (cb - mb) * ub;
                (ma + t * ua, mb + t * ub)
            }
        }
        Centre::Radius(r) => {
            if full {
                return Err(ParseErrorKind::ArcFullCircleRadius);
            }
            let half = chord / 2.0;
            if r.abs() < half - ARC_RADIUS_TOL_MM {
                return Err(ParseErrorKind::ArcRadiusTooSmall { value: r, half });
            }
            let h = (r * r - half * half).max(0.0).sqrt();
            // Left of the chord (seen from +normal) for a counter-clockwise arc of at most
            // 180 degrees; the other side for clockwise, and both swap for R < 0.
            let left = clockwise == (r < 0.0);
            let sign = if left { 1.0 } else { -1.0 };
            let (ua, ub) = (-db / chord, da / chord);
            (
                (sa + ea) / 2.0 + sign * h * ua,
                (sb + eb) / 2.0 + sign * h * ub,
            )
        }
    };
    let radius = (sa - ca).hypot(sb - cb);
    if radius.is_nan() || radius < MIN_ARC_RADIUS_MM {
        return Err(ParseErrorKind::ArcTooSmall { radius });
    }
    let phi0 = (sb - cb).atan2(sa - ca);
    let phi1 = (eb - cb).atan2(ea - ca);
    let mut sweep = phi1 - phi0;
    if clockwise {
        while sweep >= 0.0 {
            sweep -= TAU;
        }
        if full {
            sweep = -TAU;
        }
    } else {
        while sweep <= 0.0 {
            sweep += TAU;
        }
        if full {
            sweep = TAU;
        }
    }
    // A sweep of (nearly) a whole turn between distinct points is a rounding artefact of a
    // tiny arc programmed the other way round: keep it, it is what the words say.
    let rise = at(&end, n) - at(&start, n);
    let mut pieces = (sweep.abs() / FRAC_PI_2).ceil().max(1.0);
    if rise != 0.0 {
        let k = rise.abs() / sweep.abs();
        let alpha_max = (HELIX_TOL_MM / (0.07 * k)).cbrt();
        pieces = pieces.max((sweep.abs() / (2.0 * alpha_max)).ceil());
    }
    if pieces.is_nan() || pieces > MAX_PIECES as f64 {
        return Err(ParseErrorKind::HelixTooSteep {
            rise,
            sweep_deg: sweep.abs().to_degrees(),
            pieces,
        });
    }
    let pieces = (pieces as usize).max(1);
    let alpha = sweep / (2.0 * pieces as f64);
    let w1 = alpha.cos();
    let mid_r = radius / w1;
    let mut ctrl = Vec::with_capacity(2 * pieces + 1);
    let mut weights = Vec::with_capacity(2 * pieces + 1);
    let mut knots = Vec::with_capacity(2 * pieces + 4);
    let point = |phi: f64, r: f64, normal: f64| {
        let mut p = [0.0; 3];
        if let Some(v) = p.get_mut(a) {
            *v = ca + r * phi.cos();
        }
        if let Some(v) = p.get_mut(b) {
            *v = cb + r * phi.sin();
        }
        if let Some(v) = p.get_mut(n) {
            *v = normal;
        }
        p
    };
    ctrl.push(start);
    weights.push(1.0);
    knots.extend([0.0; 3]);
    let z0 = at(&start, n);
    for i in 0..pieces {
        let f = |k: f64| (2.0 * i as f64 + k) / (2.0 * pieces as f64);
        let phi_mid = phi0 + sweep * f(1.0);
        ctrl.push(point(phi_mid, mid_r, z0 + rise * f(1.0)));
        weights.push(w1);
        let last = i + 1 == pieces;
        ctrl.push(if last {
            end
        } else {
            point(phi0 + sweep * f(2.0), radius, z0 + rise * f(2.0))
        });
        weights.push(1.0);
        let k = (i + 1) as f64;
        if last {
            knots.extend([k; 3]);
        } else {
            knots.extend([k; 2]);
        }
    }
    let mut centre = start;
    if let Some(v) = centre.get_mut(a) {
        *v = ca;
    }
    if let Some(v) = centre.get_mut(b) {
        *v = cb;
    }
    Ok(ArcNet {
        ctrl,
        weights,
        knots,
        centre,
        radius,
        sweep,
    })
}
