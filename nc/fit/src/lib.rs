//! `dnurbs fit`: runs of G01 moves fitted into G06.5 double-NURBS blocks (the paper's
//! section 4: the cutter-centre curve and the orientation curve share one knot vector and
//! one set of weights; its Fig. 7 turns 20 moves into one block).
//!
//! A run's programmed points (cutter centre and unit tool axis) are fitted by least squares
//! with a cubic B-spline (all weights 1) whose end points are the run's first and last
//! points, parameters by chord length (a radian of tool rotation counting as [`ROT_MM`]),
//! then knots are inserted in every span where a point is off the cutter curve by more than
//! the position tolerance, or the interpolated tool axis off the programmed one by more than
//! the angle tolerance, or the curve bulges away from a move's chord by more than the
//! tolerance and the sag of the arc the neighbouring moves turn on, or the cutter backs up
//! along a move's chord anywhere between its points (the NURBS Book 9.4; the normal
//! equations are banded and solved by Cholesky). Each insertion splits the data in
//! the span in two, so a run costs a few refits, each linear in its points. No knot goes
//! nearer another than a quarter of the points' step there (clustered knots let the curve
//! hook back over them): where one would have to, the curve takes a corner on the
//! programmed point instead, a knot of multiplicity = the degree whose control point is
//! that point, as the posted moves have a kink there. Near the vertical,
//! where a table's C follows the tool axis's azimuth, a span also fails where the fitted axis
//! turns about the vertical more than the programmed great circles do, measured down to a
//! hair's tilt where a move ends on the vertical.
//!
//! [`runs`] finds the runs in a program's text and writes the result; [`rewrite`] does the
//! same as the text is read, a window of moves at a time (what `dnurbs fit` runs), and
//! checks each piece as it is written (`check`); [`deviation`] measures the result against
//! the input independently of the fit, through the segment builder's own geometry.

mod check;
pub mod compress;
pub mod deviation;
mod error;
pub mod find;
pub mod online;
pub mod options;
pub mod rewrite;
pub mod runs;
mod spline;

use nalgebra::Vector3;
use spline::{basis, span, Band, MAX_FIT_DEGREE};

/// Millimetres a radian of tool rotation counts as when the points are parametrised (so a
/// move that only turns the tool still advances the parameter).
pub const ROT_MM: f64 = 10.0;
/// Refits before a run is given up (each splits every failing span).
const MAX_ROUNDS: usize = 60;
/// Parameter corrections per refit.
const CORRECTIONS: usize = 3;
/// Where a move's programmed tool axis is within this of the vertical (rad, 5 degrees), the
/// fitted axis's turn about the vertical along the move is checked: a table's C follows that
/// turn, and a fitted axis within the angle tolerance of the programmed ones can pass the
/// vertical on the other side, where C swings half a turn (farther out, a 0.01 degree
/// tolerance moves the azimuth by at most 0.12 degrees).
const NEAR_VERTICAL: f64 = 0.09;
/// How much more (rad, a quarter of a degree) the fitted axis may turn about the vertical
/// over a move than the great circle between the move's programmed axes does (what
/// `G01 I J K` interpolates).
const TURN_SLACK: f64 = 0.0044;
/// Samples per move of that check.
const TURN_SAMPLES: usize = 8;
/// Halvings of that check toward an end of the move on the vertical.
const END_HALVINGS: usize = 40;
/// Where along a move (fractions of its parameter span, between the feet of its points)
/// the cutter's advance along the move's chord is checked ([`backs_up`]), besides its ends
/// and middle: next to each end (the direction the curve leaves or arrives in) and a little
/// farther, where a curve pulled by a fast tool turn leaves its point backwards, and at the
/// quarters.
const ADVANCE_AT: [f64; 6] = [1e-6, 1.0 / 32.0, 0.25, 0.75, 31.0 / 32.0, 1.0 - 1e-6];
/// No knot is put nearer another than this share of the points' step there; where the
/// fit would need one, the curve takes a corner on the point (a knot of multiplicity = the
/// degree, where the planner brings the path to rest if the tangent turns).
const CLUSTER: f64 = 0.25;

/// Position and tool-axis tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    pub mm: f64,
    pub rad: f64,
}

/// A programmed point: cutter centre (mm, workpiece frame) and unit tool axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub p: Vector3<f64>,
    pub axis: Vector3<f64>,
}

/// A fitted double curve, weights 1: cutter control points and tool vectors (the tool
/// axis is the direction of their curve) on one knot vector.
#[derive(Clone, Debug, PartialEq)]
pub struct Fitted {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub ctrl: Vec<[f64; 3]>,
    pub tool: Vec<[f64; 3]>,
    /// The largest deviations the fit measured at its points (mm, rad).
    pub dev_mm: f64,
    pub dev_rad: f64,
}

impl Fitted {
    /// Cutter point and tool axis (not normalised) at u.
    pub fn eval(&self, u: f64) -> (Vector3<f64>, Vector3<f64>) {
        let p = self.degree;
        let n = self.ctrl.len();
        let i = span(&self.knots, p, n, u);
        let mut b = [0.0; MAX_FIT_DEGREE + 1];
        basis(&self.knots, p, i, u, &mut b);
        let (mut c, mut t) = (Vector3::zeros(), Vector3::zeros());
        for (r, &w) in b[..=p].iter().enumerate() {
            c += Vector3::from(self.ctrl[i - p + r]) * w;
            t += Vector3::from(self.tool[i - p + r]) * w;
        }
        (c, t)
    }
}

/// Chord-length parameters of the points in [0, 1]; `None` if nothing moves.
fn parameters(points: &[Point]) -> Option<Vec<f64>> {
    let mut u = Vec::with_capacity(points.len());
    let mut acc = 0.0;
    u.push(0.0);
    for w in points.windows(2) {
        let dp = (w[1].p - w[0].p).norm();
        let da = w[0].axis.angle(&w[1].axis) * ROT_MM;
        acc += dp.hypot(da);
        u.push(acc);
    }
    if !(acc > 0.0 && acc.is_finite()) {
        return None;
    }
    for x in &mut u {
        *x /= acc;
    }
    if let Some(last) = u.last_mut() {
        *last = 1.0;
    }
    Some(u)
}

/// The distance the curve may stand off move k's chord (points k - 1 .. k) at its middle:
/// the tolerance, plus four times the sag (h theta / 8) of an arc that turns as the
/// neighbouring moves do: a guard against a curve that swings between its points, not a
/// tolerance (the polyline is itself the CAM system's approximation of a smooth path).
fn bulge_allowance(points: &[Point], k: usize, tol: f64) -> f64 {
    let d = |a: usize, b: usize| points[b].p - points[a].p;
    let h = d(k - 1, k).norm();
    let turn = |a: usize, b: usize, c: usize| d(a, b).angle(&d(b, c));
    let mut theta: f64 = 0.0;
    if k >= 2 {
        theta = theta.max(turn(k - 2, k - 1, k));
    }
    if k + 1 < points.len() {
        theta = theta.max(turn(k - 1, k, k + 1));
    }
    if theta.is_nan() {
        theta = 0.0;
    }
    tol + 0.5 * h * theta
}

/// How far `tool(f)` turns about the vertical for f in 0..=1: the azimuth of its horizontal
/// part, sampled, its changes summed in magnitude (rad); `ends`: whether f = 0 and f = 1
/// are on the vertical, where the samples go on halving toward it. Samples within
/// [`VERTICAL_RHO`](nc_geom::kinematics::VERTICAL_RHO) of the vertical, where the interpolator
/// keeps C, are skipped.
fn turn_about_vertical(tool: impl Fn(f64) -> Vector3<f64>, ends: (bool, bool)) -> f64 {
    let (mut sum, mut last) = (0.0, None);
    // Toward an end on the vertical, halving down to 2^-40 of the move: the azimuth of an
    // axis that comes to the vertical sideways turns where the tilt is a hair.
    let near = |on: bool| {
        (1..=END_HALVINGS)
            .filter(move |_| on)
            .map(|k| 0.5f64.powi(k as i32))
    };
    let fractions = near(ends.0)
        .rev()
        .chain((0..=TURN_SAMPLES).map(|i| i as f64 / TURN_SAMPLES as f64))
        .chain(near(ends.1).map(|f| 1.0 - f));
    let mut fractions: Vec<f64> = fractions.collect();
    fractions.sort_by(f64::total_cmp);
    for f in fractions {
        let t = tool(f);
        let rho = t.x.hypot(t.y);
        // (NaN fails the comparison and is skipped too.)
        let tilted = rho >= nc_geom::kinematics::VERTICAL_RHO * t.norm();
        if !tilted {
            continue;
        }
        let az = t.y.atan2(t.x);
        if let Some(l) = last {
            let d: f64 = az - l;
            // Wrapped into -pi..=pi: a half turn between two samples counts as one.
            sum += (d - std::f64::consts::TAU * (d / std::f64::consts::TAU).round()).abs();
        }
        last = Some(az);
    }
    sum
}

/// The fitted axis turns about the vertical over move k (points k - 1 .. k, at parameters
/// `u0..u1`) by more than [`TURN_SLACK`] beyond the great circle between its programmed
/// axes; checked only where one of them is within [`NEAR_VERTICAL`] of the vertical, and
/// not where both are vertical: a run holds such moves only with others like them
/// ([`find::keeps_vertical`]), and its fitted axis is then as vertical as its data (the
/// horizontal parts of the tool rows of the least squares are zero, or below
/// [`VERTICAL_RHO`](nc_geom::kinematics::VERTICAL_RHO)).
fn turns_more_than_programmed(
    curve: &Fitted,
    points: &[Point],
    k: usize,
    u0: f64,
    u1: f64,
) -> bool {
    let (a, b) = (points[k - 1].axis, points[k].axis);
    let (ra, rb) = (a.x.hypot(a.y), b.x.hypot(b.y));
    let vertical = nc_geom::kinematics::VERTICAL_RHO;
    if ra.min(rb) >= NEAR_VERTICAL || ra.max(rb) < vertical {
        return false;
    }
    let ends = (ra < vertical, rb < vertical);
    let programmed = turn_about_vertical(|f| a + (b - a) * f, ends);
    let fitted = turn_about_vertical(|f| curve.eval(u0 + (u1 - u0) * f).1, ends);
    fitted > programmed + TURN_SLACK
}

/// The fitted cutter backs up along move k (points k - 1 .. k, at parameters `u0..u1`,
/// where it is at `ends` and at `middle`): its projection on the move's chord falls
/// somewhere between the two feet ([`ADVANCE_AT`]). A move shorter than the distance
/// tolerance is not checked (its direction may be the post's rounding). A post writes a
/// path that goes forward, and where the fitted cutter reverses it stands still for an
/// instant: a tool turning there turns without bound per millimetre of path. It did where
/// a move turned the tool 8.9 degrees in 0.09 mm and the next ones 0.06 degrees each: the
/// cutter left the run's start 4.8 um backwards, and the planner refused A's jerk (18x its
/// limit) even at its slowest feed, where the moves as posted ran.
fn backs_up(
    curve: &Fitted,
    (points, k, tol_mm): (&[Point], usize, f64),
    (u0, u1): (f64, f64),
    ends: (Vector3<f64>, Vector3<f64>),
    middle: Vector3<f64>,
) -> bool {
    let chord = points[k].p - points[k - 1].p;
    if chord.norm() <= tol_mm {
        return false;
    }
    let at = |f: f64| curve.eval(u0 + (u1 - u0) * f).0;
    let [a, b, c, d, e, f] = ADVANCE_AT.map(at);
    [ends.0, a, b, c, middle, d, e, f, ends.1]
        .windows(2)
        .any(|w| w[1].dot(&chord) < w[0].dot(&chord))
}

/// Fit `points` (at least degree + 1 of them) within `tol`. `None` if nothing moves, or no
/// curve with fewer control points than points meets the tolerance.
pub fn fit(points: &[Point], tol: Tolerance, degree: usize) -> Option<Fitted> {
    let p = degree.clamp(1, MAX_FIT_DEGREE);
    let m = points.len().checked_sub(1)?;
    if m < p {
        return None;
    }
    let mut u = parameters(points)?;
    // Start with one span per 32 moves, split at the data.
    let spans0 = 1 + m / 128;
    let mut interior: Vec<f64> = (1..spans0).map(|j| u[j * m / spans0]).collect();
    interior.dedup();
    interior.retain(|&x| x > 0.0 && x < 1.0);
    // Knots of multiplicity `p` on programmed points, each with its point: corners.
    let mut corners: Vec<(f64, usize)> = Vec::new();
    for _ in 0..MAX_ROUNDS {
        let mut knots = vec![0.0; p + 1];
        knots.extend_from_slice(&interior);
        for &(c, _) in &corners {
            knots.extend(std::iter::repeat_n(c, p));
        }
        knots[p + 1..].sort_unstable_by(f64::total_cmp);
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        let n = knots.len() - p - 1;
        if n > points.len() {
            return None;
        }
        let mut curve = solve(points, &u, &knots, p, &corners)?;
        // Parameter correction: each point's parameter moves to its foot on the curve, and
        // the curve is solved again (Hoschek), so the error measured is the distance.
        for _ in 0..CORRECTIONS {
            if !project(&curve, points, &mut u) {
                break;
            }
            // A corner's point stays on it.
            for &(c, k) in &corners {
                u[k] = c;
            }
            curve = solve(points, &u, &knots, p, &corners)?;
        }
        let (mut dev_mm, mut dev_rad) = (0.0f64, 0.0f64);
        let mut split: Vec<(usize, f64)> = Vec::new();
        let fail = |uu: f64, split: &mut Vec<(usize, f64)>| {
            let i = span(&knots, p, n, uu);
            if split.last().map(|x| x.0) != Some(i) {
                split.push((i, uu));
            }
        };
        // Measured at each point's foot on this curve, as the independent check measures
        // the written block (the nearest point and the tool axis there): the parameters
        // the last solve used are the feet on the curve before it, and the tool axis a
        // little along the curve from the foot can be over the angle tolerance where the
        // one at the foot is not (0.0166 deg against 0.01657 on a generated curve).
        let mut u = u.clone();
        project(&curve, points, &mut u);
        let mut foot = Vector3::zeros();
        for (k, pt) in points.iter().enumerate() {
            let (c, t) = curve.eval(u[k]);
            let last_foot = std::mem::replace(&mut foot, c);
            let e = (c - pt.p).norm();
            let a = t.angle(&pt.axis);
            dev_mm = dev_mm.max(e);
            dev_rad = dev_rad.max(a);
            if e > tol.mm || a > tol.rad || !e.is_finite() || !a.is_finite() {
                fail(u[k], &mut split);
            } else if k > 0 {
                let um = 0.5 * (u[k - 1] + u[k]);
                let (cm, _) = curve.eval(um);
                let chord = deviation::to_segment(&cm, &points[k - 1].p, &pt.p);
                if chord > bulge_allowance(points, k, tol.mm)
                    || turns_more_than_programmed(&curve, points, k, u[k - 1], u[k])
                    || backs_up(
                        &curve,
                        (points, k, tol.mm),
                        (u[k - 1], u[k]),
                        (last_foot, c),
                        cm,
                    )
                {
                    fail(um, &mut split);
                }
            }
        }
        if split.is_empty() {
            return Some(Fitted {
                dev_mm,
                dev_rad,
                ..curve
            });
        }
        split.sort_unstable_by_key(|x| x.0);
        split.dedup_by_key(|x| x.0);
        let mut changed = false;
        for (i, uu) in split {
            let (a, b) = (knots[i], knots[i + 1]);
            // The middle datum strictly inside the span, else the span's middle.
            let lo = u.partition_point(|&x| x <= a);
            let hi = u.partition_point(|&x| x < b);
            let at = if hi > lo {
                u[(lo + hi) / 2]
            } else {
                0.5 * (a + b)
            };
            // Knots closer than a quarter of the points' step there would let the curve
            // hook back (it did, 3.6 um over four knots within 5e-6, where a post's point
            // stood 3 um off its neighbours): the curve takes a corner on the point instead,
            // as the posted moves do.
            let gap = CLUSTER * local_step(&u, at);
            if at > a + gap && at < b - gap {
                interior.push(at);
                changed = true;
            } else {
                // The nearer of the two points about the failure that can take a corner: not
                // an end, nor within the gap of a corner (between them no point would hold
                // the curve).
                let free = |k: &usize| {
                    *k > 0 && *k < m && corners.iter().all(|&(x, _)| (x - u[*k]).abs() > gap)
                };
                if let Some(k) = about(&u, uu).into_iter().flatten().find(free) {
                    let c = u[k];
                    interior.retain(|&x| (x - c).abs() > gap);
                    corners.push((c, k));
                    changed = true;
                }
            }
        }
        if !changed {
            return None;
        }
        interior.sort_unstable_by(f64::total_cmp);
        interior.dedup();
    }
    None
}

/// The larger parameter step between the data on either side of `at`.
fn local_step(u: &[f64], at: f64) -> f64 {
    let last = u.len() - 1;
    let k = u.partition_point(|&x| x < at).min(last);
    (u[k] - u[k.saturating_sub(1)]).max(u[(k + 1).min(last)] - u[k])
}

/// The data on either side of `at`, the nearer first.
fn about(u: &[f64], at: f64) -> [Option<usize>; 2] {
    let last = u.len() - 1;
    let k = u.partition_point(|&x| x < at).min(last);
    match k.checked_sub(1) {
        Some(j) if at - u[j] < u[k] - at => [Some(j), Some(k)],
        j => [Some(k), j],
    }
}

/// Each interior point's parameter moved to the foot of the perpendicular from the point to
/// the curve (two Gauss-Newton steps), kept between its neighbours'. Whether any moved.
fn project(curve: &Fitted, points: &[Point], u: &mut [f64]) -> bool {
    const H: f64 = 1e-7;
    let mut moved = false;
    let m = u.len() - 1;
    for k in 1..m {
        let (lo, hi) = (u[k - 1], u[k + 1]);
        let mut x = u[k];
        for _ in 0..2 {
            let (c, _) = curve.eval(x);
            let d = (curve.eval((x + H).min(1.0)).0 - curve.eval((x - H).max(0.0)).0)
                / ((x + H).min(1.0) - (x - H).max(0.0));
            let dd = d.norm_squared();
            if dd.is_nan() || dd <= 1e-18 {
                break;
            }
            let step = (c - points[k].p).dot(&d) / dd;
            let margin = 1e-9 * (hi - lo);
            x = (x - step).clamp(lo + margin, hi - margin);
        }
        if x.is_finite() && (x - u[k]).abs() > 1e-13 {
            u[k] = x;
            moved = true;
        }
    }
    moved
}

/// Least squares with the end points and the corners' points fixed: the other control
/// points of the cutter curve and of the tool vectors, from one set of normal equations.
fn solve(
    points: &[Point],
    u: &[f64],
    knots: &[f64],
    p: usize,
    corners: &[(f64, usize)],
) -> Option<Fitted> {
    let n = knots.len() - p - 1;
    let row =
        |pt: &Point| -> [f64; 6] { [pt.p.x, pt.p.y, pt.p.z, pt.axis.x, pt.axis.y, pt.axis.z] };
    // The control points the curve passes through: the ends, and at a knot of multiplicity
    // p (first at index r) the point r - 1, a corner's programmed point.
    let mut fixed: Vec<Option<[f64; 6]>> = vec![None; n];
    fixed[0] = Some(row(points.first()?));
    fixed[n - 1] = Some(row(points.last()?));
    for &(c, k) in corners {
        let r = knots.partition_point(|&x| x < c);
        fixed[r.checked_sub(1)?] = Some(row(points.get(k)?));
    }
    // Each free control point's row in the equations.
    let mut unknown: Vec<Option<usize>> = vec![None; n];
    let mut free = 0;
    for (i, f) in fixed.iter().enumerate() {
        if f.is_none() {
            unknown[i] = Some(free);
            free += 1;
        }
    }
    let mut net: Vec<[f64; 6]> = fixed.iter().map(|f| f.unwrap_or([0.0; 6])).collect();
    if free > 0 {
        let mut a = Band::new(free, p.max(2));
        let mut rhs = vec![[0.0; 6]; free];
        let mut b = [0.0; MAX_FIT_DEGREE + 1];
        for (pt, &uk) in points.iter().zip(u) {
            let i = span(knots, p, n, uk);
            basis(knots, p, i, uk, &mut b);
            let mut r = row(pt);
            for (k, &w) in b[..=p].iter().enumerate() {
                if let Some(f) = &fixed[i - p + k] {
                    for c in 0..6 {
                        r[c] -= w * f[c];
                    }
                }
            }
            for (k1, &w1) in b[..=p].iter().enumerate() {
                let Some(j1) = unknown[i - p + k1] else {
                    continue;
                };
                if w1 == 0.0 {
                    continue;
                }
                for c in 0..6 {
                    rhs[j1][c] += w1 * r[c];
                }
                for (k2, &w2) in b[..=k1].iter().enumerate() {
                    if let Some(j2) = unknown[i - p + k2] {
                        a.add(j1, j2, w1 * w2);
                    }
                }
            }
        }
        // A whisper of smoothing (the second differences of the net about each free
        // control point) keeps spans without data solvable: there (as between corners on
        // neighbouring points) the control points line up between the fixed ones, and the
        // curve is their chord. None about a fixed one: it pulled the free point after a
        // corner onto the line from the point before it, and the curve between two
        // neighbouring corners went past the second and came back to it (2.5 um on a post).
        let scale = (0..free)
            .map(|i| a.get(i, i))
            .fold(0.0, f64::max)
            .max(1e-300);
        let lambda = 1e-12 * scale;
        for i in (1..n - 1).filter(|&i| fixed[i].is_none()) {
            let terms = [(i - 1, 1.0), (i, -2.0), (i + 1, 1.0)];
            for &(ia, ca) in &terms {
                let Some(ja) = unknown[ia] else {
                    continue;
                };
                for &(ib, cb) in &terms {
                    match (unknown[ib], &fixed[ib]) {
                        (Some(jb), _) if jb <= ja => a.add(ja, jb, lambda * ca * cb),
                        (None, Some(f)) => {
                            for c in 0..6 {
                                rhs[ja][c] -= lambda * ca * cb * f[c];
                            }
                        }
                        _ => {}
                    }
                }
            }
        }
        a.solve(&mut rhs)?;
        for (i, j) in unknown.iter().enumerate() {
            if let Some(j) = j {
                net[i] = rhs[*j];
            }
        }
    }
    Some(Fitted {
        degree: p,
        knots: knots.to_vec(),
        ctrl: net.iter().map(|r| [r[0], r[1], r[2]]).collect(),
        tool: net.iter().map(|r| [r[3], r[4], r[5]]).collect(),
        dev_mm: 0.0,
        dev_rad: 0.0,
    })
}

#[cfg(test)]
mod tests;
