//! The chord error: how far the path strays from the chord between two setpoints.

use super::sample::Sample;
use nalgebra::Vector3;
use nc_geom::segment::{Geometry, Path};

/// Distance from `p` to the segment a..b.
pub fn dist_to_chord(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    chord_foot(p, a, b).1
}

/// The foot of `p` on the segment a..b, as the fraction of the way from `a`, and the
/// distance from `p` to it.
pub fn chord_foot(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> (f64, f64) {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let f = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (f, (p - (a + ab * f)).norm())
}

/// Largest distance of the cutter path between setpoints `a` and `b` from their chord.
pub(super) fn chord_error(a: &Sample, b: &Sample, path: &Path) -> f64 {
    let mut e = 0.0f64;
    if a.seg == b.seg {
        let Some(seg) = path.segments.get(a.seg) else {
            return e;
        };
        if let (Geometry::Nurbs { curve, .. }, Some(ua), Some(ub)) = (&seg.geometry, a.u, b.u) {
            for f in [0.25, 0.5, 0.75] {
                let p = curve.cutter(ua + (ub - ua) * f, 0).p;
                e = e.max(dist_to_chord(&p, &a.p, &b.p));
            }
        }
        return e;
    }
    // The chord spans junctions: every segment end between them is a point of the path.
    for seg in path.segments.get(a.seg..b.seg).unwrap_or(&[]) {
        if !seg.rotary_only {
            e = e.max(dist_to_chord(&seg.pose(seg.length).p, &a.p, &b.p));
        }
    }
    e
}
