//! An arc whose end radius differs from its start radius (posted numbers are rounded) as
//! LinuxCNC runs it: about the programmed centre, the radius changing linearly with the
//! angle from the start's to the end's (a spiral), the normal coordinate too (a helix).
//!
//! Each piece of half-sweep `alpha` is the rational quadratic circle piece of unit radius,
//! homogeneous `N(s)` with weight `W(s)` (`s` in [-1, 1]), scaled by the radius: the point
//! is `C W + (rho_mid + k theta(s)) N(s)` with `theta(s) = 2 atan(tan(alpha / 2) s)` the
//! circle's angle from the piece's middle. `theta` is replaced by the odd cubic
//! `c1 s + c3 s^3` that matches it in value and slope at both ends, which makes the
//! numerator a polynomial of degree 5: the piece is exact at its ends, tangent-continuous at
//! its joints, and off the true spiral by at most `k` times the cubic's error
//! (`SPIRAL_ERR alpha^5`). The normal coordinate gets the same cubic. Pieces are made small
//! enough for [`HELIX_TOL_MM`].

use crate::error::ParseErrorKind;
use crate::rules::HELIX_TOL_MM;
use core::f64::consts::FRAC_PI_2;

/// `max |theta(s) - (c1 s + c3 s^3)| <= SPIRAL_ERR alpha^5` for `|alpha| <= 45 deg`
/// (0.00363 measured at 45 deg, 0.00358 for small `alpha`).
const SPIRAL_ERR: f64 = 0.0037;

/// Control points, weights and knots.
pub(super) type Net = (Vec<[f64; 3]>, Vec<f64>, Vec<f64>);

/// The degree of a spiral's pieces.
pub(super) const DEGREE: usize = 5;

/// The arc about `(ca, cb)` in the plane of axes `a`, `b` (normal `n`), from `start`
/// (radius `r0`, angle `phi0`) through `sweep` radians to `end` (radius `r1`): control
/// points, weights and knots of degree [`DEGREE`].
#[allow(clippy::too_many_arguments)]
pub(super) fn net(
    start: [f64; 3],
    end: [f64; 3],
    [a, b, n]: [usize; 3],
    (ca, cb): (f64, f64),
    phi0: f64,
    sweep: f64,
    (r0, r1): (f64, f64),
    max_ctrl: usize,
) -> Result<Net, ParseErrorKind> {
    let z0 = start.get(n).copied().unwrap_or(0.0);
    let rise = end.get(n).copied().unwrap_or(0.0) - z0;
    // Growth of the radius and of the normal coordinate per radian along the sweep.
    let (k, kz) = ((r1 - r0) / sweep, rise / sweep);
    let steep = k.abs().max(kz.abs());
    let pieces = pieces(sweep, rise, steep, SPIRAL_ERR, DEGREE, max_ctrl)?;
    let alpha = sweep / (2.0 * pieces as f64);
    let w1 = alpha.cos();
    let c3 = (alpha.sin() - alpha) / 2.0;
    let c1 = alpha - c3;
    // Bernstein coefficients (in t = (s + 1) / 2) of s, s^3, and the cubic.
    let cubic: [f64; 4] = core::array::from_fn(|i| {
        const S: [f64; 4] = [-1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0];
        const S3: [f64; 4] = [-1.0, 1.0, -1.0, 1.0];
        c1 * S[i] + c3 * S3[i]
    });
    let weight = [1.0, w1, 1.0];
    let w5 = elevate(&weight, DEGREE);
    let count = DEGREE * pieces + 1;
    let mut ctrl = Vec::with_capacity(count);
    let mut weights = Vec::with_capacity(count);
    let mut knots = Vec::with_capacity(count + DEGREE + 1);
    ctrl.push(start);
    weights.push(1.0);
    knots.extend(core::iter::repeat_n(0.0, DEGREE + 1));
    let cubic_w = product(&cubic, &weight);
    for i in 0..pieces {
        let last = i + 1 == pieces;
        let at = |f: f64| phi0 + sweep * (2.0 * i as f64 + f) / (2.0 * pieces as f64);
        let (pa, pm, pb) = (at(0.0), at(1.0), at(2.0));
        let rho_mid = r0 + k * (pm - phi0);
        let z_mid = z0 + kz * (pm - phi0);
        // The unit circle piece, homogeneous: its middle point times its weight is the
        // unit vector of the middle angle.
        let axis = |f: fn(f64) -> f64, c: f64| {
            let unit = [f(pa), f(pm), f(pb)];
            let spiral = product(&cubic, &unit);
            let circle = elevate(&unit, DEGREE);
            let centre = &w5;
            core::array::from_fn::<f64, 6, _>(|j| {
                c * centre[j] + rho_mid * circle[j] + k * spiral[j]
            })
        };
        let (ha, hb) = (axis(f64::cos, ca), axis(f64::sin, cb));
        for j in 1..=DEGREE {
            if last && j == DEGREE {
                ctrl.push(end);
                weights.push(1.0);
                break;
            }
            let w = w5[j];
            let mut p = [0.0; 3];
            if let Some(v) = p.get_mut(a) {
                *v = ha[j] / w;
            }
            if let Some(v) = p.get_mut(b) {
                *v = hb[j] / w;
            }
            if let Some(v) = p.get_mut(n) {
                *v = z_mid + kz * cubic_w[j] / w;
            }
            ctrl.push(p);
            weights.push(w);
        }
        let kk = (i + 1) as f64;
        knots.extend(core::iter::repeat_n(
            kk,
            if last { DEGREE + 1 } else { DEGREE },
        ));
    }
    Ok((ctrl, weights, knots))
}

/// The Bernstein coefficients of a polynomial raised to degree `to` (at most 5).
fn elevate(c: &[f64], to: usize) -> [f64; 6] {
    let mut cur = [0.0; 6];
    let mut d = c.len().saturating_sub(1);
    cur[..c.len().min(6)].copy_from_slice(&c[..c.len().min(6)]);
    while d < to.min(5) {
        let mut next = [0.0; 6];
        let m = (d + 1) as f64;
        for (i, slot) in next.iter_mut().enumerate().take(d + 2) {
            let f = i as f64 / m;
            let left = if i > 0 { cur[i - 1] } else { 0.0 };
            let right = if i <= d { cur[i] } else { 0.0 };
            *slot = f * left + (1.0 - f) * right;
        }
        cur = next;
        d += 1;
    }
    cur
}

/// The Bernstein coefficients of the product of two polynomials given by theirs (degrees
/// adding up to at most 5).
fn product(x: &[f64], y: &[f64]) -> [f64; 6] {
    let (m, n) = (x.len() - 1, y.len() - 1);
    let binom = |n: usize, k: usize| -> f64 {
        (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
    };
    let mut out = [0.0; 6];
    for (i, xi) in x.iter().enumerate() {
        for (j, yj) in y.iter().enumerate() {
            if let Some(slot) = out.get_mut(i + j) {
                *slot += binom(m, i) * binom(n, j) / binom(m + n, i + j) * xi * yj;
            }
        }
    }
    out
}

/// How many pieces an arc of `sweep` radians is cut into: at most a quarter turn each, and,
/// where its radius or normal coordinate changes by `steep` mm a radian, small enough that
/// the pieces' error (`err` times `steep` times the half-angle to the fifth) stays below
/// [`HELIX_TOL_MM`]; refused when the pieces of degree `degree` need more than `max_ctrl`
/// control points.
pub(super) fn pieces(
    sweep: f64,
    rise: f64,
    steep: f64,
    err: f64,
    degree: usize,
    max_ctrl: usize,
) -> Result<usize, ParseErrorKind> {
    let mut pieces = (sweep.abs() / FRAC_PI_2).ceil().max(1.0);
    if steep > 0.0 {
        let alpha_max = (HELIX_TOL_MM / (err * steep)).powf(0.2);
        pieces = pieces.max((sweep.abs() / (2.0 * alpha_max)).ceil());
    }
    if pieces.is_nan() || pieces * degree as f64 + 1.0 > max_ctrl as f64 {
        return Err(ParseErrorKind::HelixTooSteep {
            rise,
            sweep_deg: sweep.abs().to_degrees(),
            pieces,
        });
    }
    Ok((pieces as usize).max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Value of Bernstein coefficients `c` (degree c.len() - 1) at `t`.
    fn value(c: &[f64], t: f64) -> f64 {
        let d = c.len() - 1;
        let binom = |k: usize| (0..k).fold(1.0, |acc, i| acc * (d - i) as f64 / (i + 1) as f64);
        c.iter()
            .enumerate()
            .map(|(i, ci)| binom(i) * t.powi(i as i32) * (1.0 - t).powi((d - i) as i32) * ci)
            .sum()
    }

    #[test]
    fn bernstein_products_and_elevation_are_the_same_polynomials() {
        let x = [1.0, -2.0, 0.5];
        let y = [0.3, 4.0, -1.0, 2.0];
        let p = product(&x, &y);
        let e = elevate(&x, 5);
        for t in [0.0, 0.1, 0.37, 0.5, 0.9, 1.0] {
            assert!((value(&p, t) - value(&x, t) * value(&y, t)).abs() < 1e-12);
            assert!((value(&e, t) - value(&x, t)).abs() < 1e-12);
        }
    }

    #[test]
    fn the_spiral_turns_its_radius_linearly_with_the_angle() {
        // From radius 10 at 0 deg to radius 10.02 at 300 deg counter-clockwise, rising 3.
        let (r0, r1, sweep) = (10.0_f64, 10.02_f64, 300f64.to_radians());
        let start = [r0, 0.0, 0.0];
        let end = [r1 * sweep.cos(), r1 * sweep.sin(), 3.0];
        let (ctrl, weights, knots) = net(
            start,
            end,
            [0, 1, 2],
            (0.0, 0.0),
            0.0,
            sweep,
            (r0, r1),
            100_000,
        )
        .unwrap();
        assert_eq!((ctrl[0], *ctrl.last().unwrap()), (start, end));
        // Every piece's points are on the spiral: sample each piece's Bernstein form.
        let pieces = (ctrl.len() - 1) / DEGREE;
        assert_eq!(knots.len(), ctrl.len() + DEGREE + 1);
        let mut angle_prev = 0.0;
        for i in 0..pieces {
            let idx = i * DEGREE..=(i + 1) * DEGREE;
            let w: Vec<f64> = weights[idx.clone()].to_vec();
            let hx: Vec<f64> = idx.clone().map(|j| ctrl[j][0] * weights[j]).collect();
            let hy: Vec<f64> = idx.clone().map(|j| ctrl[j][1] * weights[j]).collect();
            let hz: Vec<f64> = idx.clone().map(|j| ctrl[j][2] * weights[j]).collect();
            for t in (0..=20).map(|q| q as f64 / 20.0) {
                let ww = value(&w, t);
                let (x, y, z) = (value(&hx, t) / ww, value(&hy, t) / ww, value(&hz, t) / ww);
                let mut ang = y.atan2(x);
                if ang < angle_prev - 1.0 {
                    ang += core::f64::consts::TAU;
                }
                angle_prev = ang;
                let want_r = r0 + (r1 - r0) * ang / sweep;
                let want_z = 3.0 * ang / sweep;
                assert!((x.hypot(y) - want_r).abs() < 1e-9, "radius at {ang}");
                assert!((z - want_z).abs() < 1e-9, "height at {ang}");
            }
        }
    }
}
