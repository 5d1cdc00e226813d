//! The jerk between the plan's phases. The check measures each axis's jerk on the
//! setpoints the plan gives, one phase of the period. A hold, an override or a wait for
//! data shifts the phase at which the drives' setpoints meet the path, and where the
//! joints' motion changes within a period (a sharp feature inside a segment, a curvature
//! peak passed slowly) the jerk at another phase can be well over what the plan's phase
//! shows: the third difference weighs the motion of three periods by a kernel that peaks
//! between setpoints. Where an axis's jerk changes by more than [`JERK_STEP`] of its
//! planned jerk from one stencil to the next, or peaks between them, the stencil is also
//! measured at [`SUBPHASES`] - 1 phases between each two of the last three ([`measure`]);
//! a stencil over a corner up to the corner, and the first after a corner where their jerk
//! is large; elsewhere the jerk varies little within a period, and the phase changes it
//! little. Found by the generated-input suite through holds: a curvature peak inside a
//! NURBS segment passed at 0.2 mm/s showed 0.56 of the limit at the plan's phases and 1.13x
//! at another; one right after a corner between two G06.2 segments, 1.07x.

use super::corner::joints_at;
use super::sample::{corner_among, crosses_corner, segment_at, Ctx, Sample};
use nc_geom::kinematics::Joints;

/// Change of an axis's jerk between two consecutive stencils, as a share of its planned
/// jerk, above which the stencil is measured between the plan's phases.
pub(super) const JERK_STEP: f64 = 0.25;

/// Phases a period is cut into for the measurement between phases.
pub(super) const SUBPHASES: usize = 8;

/// Each axis's largest |jerk| between the plan's phases about the stencil `w` (`older`
/// the two setpoints before it), where the jerk changes fast or peaks between the last
/// stencils ([`JERK_STEP`]); `None` where it does not. Where a corner lies among the last
/// stencils, what lies on one side of it: a stencil over the corner is measured up to it
/// (the shifted stencils that end before it) where the jerk changed fast before it, and
/// the first stencils after a corner where their jerk is a good part of the limit (no
/// stencil before them to compare with: a curvature peak right after the corner).
pub(super) fn measure(w: &[Sample; 4], older: &[Sample; 2], ctx: &Ctx) -> Option<[f64; 5]> {
    let x = [&older[0], &older[1], &w[0], &w[1], &w[2], &w[3]];
    let ts = ctx.cfg.period;
    let jerk = |i: usize, j: usize| {
        (x[i + 3].q[j] - 3.0 * x[i + 2].q[j] + 3.0 * x[i + 1].q[j] - x[i].q[j]) / ts.powi(3)
    };
    let step = |j: usize| JERK_STEP * ctx.cfg.axes[j].planned_jerk(ts);
    let behind = crosses_corner(&[older[0], w[2]], ctx.smooth);
    let over = crosses_corner(&[w[0], w[3]], ctx.smooth);
    let steps = match (behind, over) {
        // All three stencils on one stretch: a fast change, or a peak between them.
        (false, false) => (0..5).any(|j| {
            let (j0, j1, j2) = (jerk(0, j), jerk(1, j), jerk(2, j));
            (j2 - j1).abs() > step(j) || (j2 - 2.0 * j1 + j0).abs() > step(j)
        }),
        // Over a corner, the two before it on one stretch.
        (false, true) => (0..5).any(|j| (jerk(1, j) - jerk(0, j)).abs() > step(j)),
        // Just after a corner.
        (true, false) => (0..5).any(|j| jerk(2, j).abs() > step(j)),
        (true, true) => false,
    };
    if steps {
        between(w, ctx)
    } else {
        None
    }
}

/// Each axis's largest |jerk| over the stencil `w` shifted back by 1/8 to 15/8 of a
/// period, those inside one G2-continuous stretch: the setpoints a hold might give between
/// the stencil two before `w` and `w`. `None` where a joint cannot be computed.
fn between(w: &[Sample; 4], ctx: &Ctx) -> Option<[f64; 5]> {
    let ts = ctx.cfg.period;
    let near = ctx.profile.near(w[0].t - 3.0 * ts, w[3].t + ts);
    let mut worst = [0.0f64; 5];
    for m in (1..2 * SUBPHASES).filter(|m| m % SUBPHASES != 0) {
        let shift = ts * m as f64 / SUBPHASES as f64;
        let s = [0, 1, 2, 3].map(|i| near.motion_at(w[i].t - shift).s);
        if corner_among(
            segment_at(ctx, s[0]),
            segment_at(ctx, s[3]),
            ctx.smooth,
            None,
        ) {
            continue;
        }
        let mut q: [Joints; 4] = [[0.0; 5]; 4];
        for (i, x) in q.iter_mut().enumerate() {
            *x = joints_at(ctx, s[i], &w[i].q)?;
        }
        for (j, worst) in worst.iter_mut().enumerate() {
            let jerk = (q[3][j] - 3.0 * q[2][j] + 3.0 * q[1][j] - q[0][j]) / (ts * ts * ts);
            *worst = worst.max(jerk.abs());
        }
    }
    Some(worst)
}
