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
//! parameter is. A helix's pieces are therefore raised to degree 4: each circle piece is
//! degree-elevated (the same circle, exactly), which frees the normal coordinate's five
//! control points. Times the piece's weight function `W`, the normal coordinate is a
//! polynomial of degree 4 in the piece's parameter `s` in [-1, 1]; the true helix's is
//! `k phi(s) W(s)` with `phi(s) = 2 atan(tan(alpha / 2) s)` the circle's angle (odd in `s`).
//! The odd cubic `a1 s + a3 s^3` that matches it in value and slope at both ends makes
//! every joint's tangent the true helix's, and leaves the point at angle `phi` off the true
//! helix along the normal by at most `0.00259 k alpha^5` (`k = |dz / dphi|`, the
//! coefficient measured over `alpha <= 45 deg`; 0.00239 for small `alpha`). The pieces are
//! made small enough that this is below [`HELIX_TOL_MM`](crate::rules::HELIX_TOL_MM): about 43 pieces a turn at a 1 mm
//! pitch. In the plane, the helix's projection is still exactly the circle.
//!
//! The centre comes from `I J K` (offsets from the start, in the plane's letters) or from `R`
//! (`R > 0`: the arc of at most 180 deg, `R < 0`: the longer one). Posted coordinates are
//! rounded, so the start and end radii differ slightly: what LinuxCNC accepts is accepted
//! ([`ArcTol`]: [`ARC_RADIUS_TOL_MM`], or up to 100 times it within
//! [`ARC_RADIUS_REL_TOL`] of the radius), and run as LinuxCNC runs it: about the programmed
//! centre, the radius turning linearly with the angle from the start's to the end's
//! (`spiral.rs`: pieces of degree 5), so the arc runs exactly from the start to the
//! programmed end on LinuxCNC's path.

mod spiral;

use super::error::ParseErrorKind;
use crate::rules::{
    ARC_RADIUS_REL_TOL, ARC_RADIUS_TOL_IN, ARC_RADIUS_TOL_MM, ARC_REACH_TOL_IN, ARC_REACH_TOL_MM,
    MIN_ARC_RADIUS_MM,
};
use crate::vocab::Plane;
use core::f64::consts::TAU;

/// `e <= HELIX_ERR * k * alpha^5`: the largest normal error of a degree-4 helix piece of
/// half-sweep `alpha <= 45 deg` rising `k` mm a radian (measured 0.00259 at 45 deg).
const HELIX_ERR: f64 = 0.0027;
/// Most control points one arc may have: a block's,
/// [`MAX_BLOCK_CTRL`](nc_geom::program::MAX_BLOCK_CTRL). A helix within a machine's travel needs
/// far fewer (a full turn of radius 0.01 mm rising 200 000 mm: about 510 pieces); beyond it
/// the arc is an error.
const MAX_CTRL: usize = nc_geom::program::MAX_BLOCK_CTRL;

/// Start and end radii closer than this are one radius (a circle, not a spiral).
const SAME_RADIUS_MM: f64 = 1e-9;

/// How far an arc's numbers may be off, in mm: LinuxCNC's tolerances in the program's units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArcTol {
    /// Start and end radii may differ by this ([`ARC_RADIUS_TOL_MM`]).
    pub radius_mm: f64,
    /// `R` may fall short of half the chord by this ([`ARC_REACH_TOL_MM`]).
    pub reach_mm: f64,
}

impl ArcTol {
    /// The tolerances of a program in inches (`G20`) or millimetres.
    pub fn for_units(inch: bool) -> ArcTol {
        if inch {
            ArcTol {
                radius_mm: ARC_RADIUS_TOL_IN * 25.4,
                reach_mm: ARC_REACH_TOL_IN * 25.4,
            }
        } else {
            ArcTol {
                radius_mm: ARC_RADIUS_TOL_MM,
                reach_mm: ARC_REACH_TOL_MM,
            }
        }
    }

    /// Whether radii `rs` and `re` differ by too much: by more than 100 times the
    /// tolerance, or by more than the tolerance and [`ARC_RADIUS_REL_TOL`] of the radius.
    fn mismatch(&self, rs: f64, re: f64) -> bool {
        let abs = (rs - re).abs();
        let rel = abs / rs.max(re);
        abs.is_nan()
            || abs > 100.0 * self.radius_mm
            || (rel > ARC_RADIUS_REL_TOL && abs > self.radius_mm)
    }
}

/// How the arc's centre is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Centre {
    /// Offsets from the start point along the plane's first and second axis, mm.
    Offsets(f64, f64),
    /// `R`, mm (negative: the longer arc).
    Radius(f64),
}

/// The control net of an arc: degree, points, weights, knots.
#[derive(Clone, Debug, PartialEq)]
pub struct ArcNet {
    /// 2 for a circular arc; 4 for a helix (see the module doc).
    pub degree: u8,
    pub ctrl: Vec<[f64; 3]>,
    pub weights: Vec<f64>,
    pub knots: Vec<f64>,
    /// Centre (in the plane; its normal coordinate is the start's), radius and signed sweep
    /// (positive counter-clockwise seen from +normal), for tests and reports.
    pub centre: [f64; 3],
    pub radius: f64,
    pub sweep: f64,
}

impl ArcNet {
    /// The `G02`/`G03` block of this net, every control point at the line's `pos`.
    pub(crate) fn into_block(
        self,
        (pos, n): (nc_geom::program::SrcPos, Option<u32>),
        feed_mm_min: f64,
        tooling: nc_geom::program::MoveTooling,
        turn_to: Option<(f64, f64)>,
    ) -> nc_geom::program::NurbsBlock {
        let count = self.ctrl.len();
        nc_geom::program::NurbsBlock {
            pos,
            n,
            kind: nc_geom::program::NurbsKind::G062,
            degree: self.degree,
            ctrl: self.ctrl,
            tool_ctrl: Vec::new(),
            ctrl_pos: vec![pos; count],
            weights: self.weights,
            knots: self.knots,
            feed_mm_min,
            tooling,
            turn_to,
        }
    }
}

/// The net of the arc from `start` to `end` in `plane`, clockwise (`G02`) or not (`G03`),
/// going round `turns` times (`P`, at least 1: the turns beyond the first are whole circles).
pub fn arc(
    start: [f64; 3],
    end: [f64; 3],
    plane: Plane,
    (clockwise, turns): (bool, u32),
    centre: Centre,
    tol: ArcTol,
) -> Result<ArcNet, ParseErrorKind> {
    let (a, b, n) = plane.axes();
    let at = |p: &[f64; 3], i: usize| p.get(i).copied().unwrap_or(0.0);
    let (sa, sb) = (at(&start, a), at(&start, b));
    let (ea, eb) = (at(&end, a), at(&end, b));
    let (da, db) = (ea - sa, eb - sb);
    let chord = da.hypot(db);
    let full = chord <= 1e-9;
    let mut end_radius = None;
    let (ca, cb) = match centre {
        Centre::Offsets(i, j) => {
            let (ca, cb) = (sa + i, sb + j);
            let rs = (sa - ca).hypot(sb - cb);
            let re = (ea - ca).hypot(eb - cb);
            if tol.mismatch(rs, re) {
                return Err(ParseErrorKind::ArcRadiusMismatch {
                    start: rs,
                    end: re,
                    tol: tol.radius_mm,
                });
            }
            if !full && (rs - re).abs() > SAME_RADIUS_MM {
                end_radius = Some(re);
            }
            (ca, cb)
        }
        Centre::Radius(r) => {
            if full {
                return Err(ParseErrorKind::ArcFullCircleRadius);
            }
            let half = chord / 2.0;
            if r.abs() < half - tol.reach_mm {
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
    // `P`: the turns beyond the first, each a whole circle more (LinuxCNC's rule).
    let more = f64::from(turns.saturating_sub(1)) * TAU;
    sweep += if clockwise { -more } else { more };
    // A sweep of (nearly) a whole turn between distinct points is a rounding artefact of a
    // tiny arc programmed the other way round: keep it, it is what the words say.
    if let Some(re) = end_radius {
        let (ctrl, weights, knots) = spiral::net(
            start,
            end,
            [a, b, n],
            (ca, cb),
            phi0,
            sweep,
            (radius, re),
            MAX_CTRL,
        )?;
        let mut centre = start;
        if let Some(v) = centre.get_mut(a) {
            *v = ca;
        }
        if let Some(v) = centre.get_mut(b) {
            *v = cb;
        }
        return Ok(ArcNet {
            degree: spiral::DEGREE as u8,
            ctrl,
            weights,
            knots,
            centre,
            radius,
            sweep,
        });
    }
    let rise = at(&end, n) - at(&start, n);
    let helix = rise != 0.0;
    let degree: usize = if helix { 4 } else { 2 };
    let steep = if helix { rise.abs() / sweep.abs() } else { 0.0 };
    let pieces = spiral::pieces(sweep, rise, steep, HELIX_ERR, degree, MAX_CTRL)?;
    let alpha = sweep / (2.0 * pieces as f64);
    let w1 = alpha.cos();
    let mid_r = radius / w1;
    let count = degree * pieces + 1;
    let mut ctrl = Vec::with_capacity(count);
    let mut weights = Vec::with_capacity(count);
    let mut knots = Vec::with_capacity(count + degree + 1);
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
    knots.extend(core::iter::repeat_n(0.0, degree + 1));
    let z0 = at(&start, n);
    // The normal coordinate of a helix piece, times its weights, relative to its middle
    // (see the module doc): Bernstein coefficients of `a1 s + a3 s^3`.
    let helix_z = {
        let (al, kk) = (alpha.abs(), rise / sweep.abs());
        let slope = kk * (al.sin() + al * (1.0 - al.cos()));
        let a3 = (slope - kk * al) / 2.0;
        let a1 = kk * al - a3;
        const S1: [f64; 5] = [-1.0, -0.5, 0.0, 0.5, 1.0];
        const S3: [f64; 5] = [-1.0, 0.5, 0.0, -0.5, 1.0];
        core::array::from_fn::<f64, 5, _>(|i| a1 * S1[i] + a3 * S3[i])
    };
    for i in 0..pieces {
        let f = |k: f64| (2.0 * i as f64 + k) / (2.0 * pieces as f64);
        let last = i + 1 == pieces;
        let z_mid = z0 + rise * f(1.0);
        let p0 = *ctrl.last().unwrap_or(&start);
        let p1 = point(phi0 + sweep * f(1.0), mid_r, z_mid);
        let p2 = if last {
            end
        } else {
            point(phi0 + sweep * f(2.0), radius, z0 + rise * f(2.0))
        };
        if helix {
            // The circle piece raised to degree 4 (homogeneous: Q1 = (P0 + w P1) / 2,
            // Q2 = (P0 + 4 w P1 + P2) / 6, Q3 = (w P1 + P2) / 2), its normal coordinate
            // replaced by the fitted one.
            let blend = |wt: f64, idx: usize| {
                let mut q = [0.0; 3];
                for (j, v) in q.iter_mut().enumerate() {
                    let p = |x: &[f64; 3]| x.get(j).copied().unwrap_or(0.0);
                    *v = match idx {
                        1 => (p(&p0) + w1 * p(&p1)) / (2.0 * wt),
                        2 => (p(&p0) + 4.0 * w1 * p(&p1) + p(&p2)) / (6.0 * wt),
                        _ => (w1 * p(&p1) + p(&p2)) / (2.0 * wt),
                    };
                }
                if let (Some(v), Some(h)) = (q.get_mut(n), helix_z.get(idx)) {
                    *v = z_mid + h / wt;
                }
                q
            };
            let (wa, wb) = ((1.0 + w1) / 2.0, (1.0 + 2.0 * w1) / 3.0);
            for (idx, wt) in [(1, wa), (2, wb), (3, wa)] {
                ctrl.push(blend(wt, idx));
                weights.push(wt);
            }
        } else {
            ctrl.push(p1);
            weights.push(w1);
        }
        ctrl.push(p2);
        weights.push(1.0);
        let k = (i + 1) as f64;
        let mult = if last { degree + 1 } else { degree };
        knots.extend(core::iter::repeat_n(k, mult));
    }
    let mut centre = start;
    if let Some(v) = centre.get_mut(a) {
        *v = ca;
    }
    if let Some(v) = centre.get_mut(b) {
        *v = cb;
    }
    Ok(ArcNet {
        degree: degree as u8,
        ctrl,
        weights,
        knots,
        centre,
        radius,
        sweep,
    })
}
