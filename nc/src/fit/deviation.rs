//! The fitted program measured against the one it came from, independently of the fit:
//! both are built into paths by the segment builder (the geometry `simulate` and `run`
//! interpolate) and compared by dense sampling.
//!
//! * Every programmed point (each input segment's end) against the output path: the
//!   nearest sample's neighbourhood is searched for the exact nearest path position (a
//!   ternary search on the segment's own evaluation), where the tool axes are compared.
//! * Every output sample against the input path's samples (for `G01` moves those lie on the
//!   programmed chords): how far the output strays between the points.
//!
//! Both walk forward with the paths (a cursor that searches a reach of twice the step ahead),
//! so the cost is linear in the samples.

use crate::kinematics::MachineKinematics;
use crate::segment::Path;
use nalgebra::Vector3;

pub use crate::verify::dist_to_chord as to_segment;

/// The largest deviations found.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Deviation {
    /// Programmed points off the output path (mm) and their tool axes off the output's
    /// axis there (degrees).
    pub point_mm: f64,
    pub point_deg: f64,
    /// Source line (input) of the worst point by distance and by angle.
    pub point_mm_line: u32,
    pub point_deg_line: u32,
    /// Output samples off the input path (mm).
    pub path_mm: f64,
    /// Programmed points and output samples compared.
    pub points: usize,
    pub samples: usize,
}

struct Track {
    p: Vec<Vector3<f64>>,
    /// Segment and path position of each sample.
    at: Vec<(usize, f64)>,
    /// Distance along the samples.
    along: Vec<f64>,
}

/// Samples every `h` (mm, or degrees on rotary-only segments), at least 4 a segment.
fn sample(path: &Path, h: f64) -> Track {
    let mut t = Track {
        p: Vec::new(),
        at: Vec::new(),
        along: Vec::new(),
    };
    let push = |t: &mut Track, seg: usize, s: f64, p: Vector3<f64>| {
        let d = t.p.last().map_or(0.0, |q: &Vector3<f64>| (p - q).norm());
        let a = t.along.last().copied().unwrap_or(0.0) + d;
        t.p.push(p);
        t.at.push((seg, s));
        t.along.push(a);
    };
    push(&mut t, 0, 0.0, path.start.p);
    for (k, seg) in path.segments.iter().enumerate() {
        let n = ((seg.length / h).ceil() as usize).clamp(4, 10_000_000);
        for j in 1..=n {
            let s = seg.length * j as f64 / n as f64;
            push(&mut t, k, s, seg.pose(s).p);
        }
    }
    t
}

/// Nearest sample segment (j, j + 1) to `q`, searched from `from` over `reach` of path.
fn nearest(t: &Track, q: &Vector3<f64>, from: usize, reach: f64) -> (usize, f64) {
    let start = from.saturating_sub(2);
    let limit = t.along[from.min(t.p.len() - 1)] + reach;
    let mut best = (start, f64::INFINITY);
    let mut j = start;
    while j + 1 < t.p.len() {
        let d = to_segment(q, &t.p[j], &t.p[j + 1]);
        if d < best.1 {
            best = (j, d);
        }
        if t.along[j] > limit {
            break;
        }
        j += 1;
    }
    if t.p.len() == 1 {
        best = (0, (q - t.p[0]).norm());
    }
    best
}

/// The minimum of a unimodal `f` on lo..hi (golden-section search, to 1e-9 of the interval).
fn golden(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    const R: f64 = 0.618_033_988_749_894_8;
    let (mut x1, mut x2) = (hi - R * (hi - lo), lo + R * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..44 {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - R * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + R * (hi - lo);
            f2 = f(x2);
        }
    }
    if f1 <= f2 {
        x1
    } else {
        x2
    }
}

/// Measure `output` against `input` (both from the segment builder), sampling every `h`.
pub fn measure(input: &Path, output: &Path, kin: &MachineKinematics, h: f64) -> Deviation {
    let out = sample(output, h);
    let inp = sample(input, h);
    let mut dev = Deviation {
        samples: out.p.len(),
        ..Deviation::default()
    };
    // Programmed points: the start and every input segment's end.
    let mut points = vec![(input.start, input.start_src.line)];
    points.extend(
        input
            .segments
            .iter()
            .map(|s| (s.pose(s.length), s.src.line)),
    );
    let mut cursor = 0;
    let mut prev = input.start.p;
    for (pose, line) in points {
        let step = (pose.p - prev).norm();
        prev = pose.p;
        let (j, _) = nearest(&out, &pose.p, cursor, 2.0 * step + 0.5);
        cursor = j;
        // The exact nearest position around samples j - 1 .. j + 2, on their segments.
        let (mut best_d, mut best_axis) = (f64::INFINITY, Vector3::z());
        for k in j.saturating_sub(1)..(j + 1).min(out.p.len() - 1) {
            let ((sa, a), (sb, b)) = (out.at[k], out.at[k + 1]);
            let (seg, lo, hi) = if sa == sb { (sb, a, b) } else { (sb, 0.0, b) };
            let Some(segment) = output.segments.get(seg) else {
                continue;
            };
            let dist = |s: f64| (segment.pose(s).p - pose.p).norm();
            let s = golden(lo, hi, dist);
            let d = dist(s);
            if d < best_d {
                best_d = d;
                best_axis = segment.pose(s).axis(kin);
            }
        }
        if !best_d.is_finite() {
            best_d = (out.p[j] - pose.p).norm();
        }
        // Where the output stands still while the tool turns (the rotary axes alone move),
        // every sample of the turn is as near: the programmed axis is compared with the
        // nearest of their axes, and the next point is looked for from there.
        let target = pose.axis(kin);
        let mut deg = best_axis.angle(&target).to_degrees();
        // (Sample j may stand before the nearest position: the ties start at j or j + 1.)
        for k in j..out.p.len() {
            if (out.p[k] - pose.p).norm() > best_d + 1e-9 {
                if k > j {
                    break;
                }
                continue;
            }
            let (seg, s) = out.at[k];
            if let Some(segment) = output.segments.get(seg) {
                let a = segment.pose(s).axis(kin).angle(&target).to_degrees();
                if a < deg {
                    deg = a;
                    cursor = k;
                }
            }
        }
        if best_d > dev.point_mm {
            dev.point_mm = best_d;
            dev.point_mm_line = line;
        }
        if deg > dev.point_deg {
            dev.point_deg = deg;
            dev.point_deg_line = line;
        }
        dev.points += 1;
    }
    // Output samples against the input path.
    let mut cursor = 0;
    for j in 0..out.p.len() {
        let step = if j > 0 {
            out.along[j] - out.along[j - 1]
        } else {
            0.0
        };
        let (k, d) = nearest(&inp, &out.p[j], cursor, 2.0 * step + 0.5);
        cursor = k;
        dev.path_mm = dev.path_mm.max(d);
    }
    dev
}
