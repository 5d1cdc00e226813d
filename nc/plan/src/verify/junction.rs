//! Which junctions between segments are G2-continuous in the joints: across them the check
//! measures the jerk, at the others (corners) it does not.

use crate::config::PlanConfig;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::{Path, Segment};

/// One-sided step used to compare the joint derivatives on both sides of a junction, mm.
pub(super) const JUNCTION_STEP: f64 = 1e-4;

/// For every segment, whether the junction at its start is G2-continuous in the machine
/// joints: equal first and second derivatives dq/ds, d2q/ds2 from both sides (one-sided
/// finite differences), and no change between mm and degrees of path. Segment 0 (the
/// program start, from rest) counts as smooth.
pub fn smooth_junctions(path: &Path, kin: &MachineKinematics, cfg: &PlanConfig) -> Vec<bool> {
    let mut out = Vec::with_capacity(path.segments.len());
    out.push(true);
    for w in path.segments.windows(2) {
        out.push(g2(&w[0], &w[1], kin, cfg));
    }
    out
}

pub(crate) fn g2(a: &Segment, b: &Segment, kin: &MachineKinematics, cfg: &PlanConfig) -> bool {
    if a.rotary_only || b.rotary_only {
        return false;
    }
    let h = JUNCTION_STEP.min(a.length / 4.0).min(b.length / 4.0);
    if h <= 0.0 {
        return false;
    }
    let lim = &cfg.rotary;
    // Joints along a, then on into b, following one rotary branch.
    let mut prev = a.pose(a.length - 3.0 * h).joints(kin, &[0.0; 5], lim);
    let mut qa = [[0.0; 5]; 3];
    for (i, q) in qa.iter_mut().enumerate() {
        prev = a
            .pose(a.length - (2 - i) as f64 * h)
            .joints(kin, &prev, lim);
        *q = prev;
    }
    let mut qb = [[0.0; 5]; 3];
    for (i, q) in qb.iter_mut().enumerate() {
        prev = b.pose(i as f64 * h).joints(kin, &prev, lim);
        *q = prev;
    }
    (0..5).all(|j| {
        let d1a = (qa[2][j] - qa[1][j]) / h;
        let d1b = (qb[1][j] - qb[0][j]) / h;
        let d2a = (qa[2][j] - 2.0 * qa[1][j] + qa[0][j]) / (h * h);
        let d2b = (qb[2][j] - 2.0 * qb[1][j] + qb[0][j]) / (h * h);
        let scale = d2a.abs().max(d2b.abs()).max(1.0);
        (qa[2][j] - qb[0][j]).abs() < 1e-9
            && (d1a - d1b).abs() < 1e-3 * d1a.abs().max(d1b.abs()).max(1.0) + 4.0 * h * scale
            && (d2a - d2b).abs() < 1e-2 * scale
    })
}
