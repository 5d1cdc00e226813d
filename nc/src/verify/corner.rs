//! A corner at its worst phase. Where the joint path has a kink (a junction that is not
//! G2-continuous), an axis's velocity jumps by `dv`, and the acceleration measured by finite
//! differences at the period depends on where the kink falls between two setpoints: it is
//! `dv (1 - theta) / Ts` with theta the kink's phase, largest (`dv / Ts`) when a setpoint
//! falls on the kink itself. The plan's own setpoints see one phase; a feed hold, a pause or
//! an override before the corner shifts the phase (`crate::stream`). So the check also
//! measures the stencil centred on the kink: the setpoints the interpolator would give one
//! period before the junction, on it, and one period after.

use super::{Ctx, Sample};
use crate::kinematics::Joints;

/// Joints at path position s, near `prev`.
fn joints_at(ctx: &Ctx, s: f64, prev: &Joints) -> Option<Joints> {
    let k = ctx
        .profile
        .seg_start
        .partition_point(|&x| x <= s)
        .saturating_sub(1)
        .min(ctx.path.segments.len().checked_sub(1)?);
    let seg = &ctx.path.segments[k];
    Some(
        seg.pose(s - ctx.profile.seg_start[k])
            .joints(ctx.kin, prev, &ctx.cfg.rotary),
    )
}

/// The stencil centred on a kink.
pub(super) struct Kink {
    /// Joints one period before the junction, on it, one period after.
    pub q: [Joints; 3],
    /// The junction's path position and the plan's speed there.
    pub s: f64,
    pub v: f64,
}

/// The stencil centred on the first kink between `w[1]` and `w[2]`, if there is one.
pub(super) fn stencil(w: &[Sample; 4], ctx: &Ctx) -> Option<Kink> {
    let (profile, smooth) = (ctx.profile, ctx.smooth);
    let (a, b) = (w[1].seg, w[2].seg);
    let k = (a + 1..=b).find(|&k| !smooth.get(k).copied().unwrap_or(false))?;
    let s_j = *profile.seg_start.get(k)?;
    // The time the plan reaches the junction: s(t) never decreases.
    let (mut lo, mut hi) = (w[1].t, w[2].t);
    if hi.partial_cmp(&lo) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if profile.motion_at(mid).s < s_j {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let ts = ctx.cfg.period;
    let before = joints_at(ctx, profile.motion_at(hi - ts).s, &w[1].q)?;
    let on = joints_at(ctx, s_j, &w[1].q)?;
    let after = joints_at(ctx, profile.motion_at(hi + ts).s, &w[2].q)?;
    Some(Kink {
        q: [before, on, after],
        s: s_j,
        v: profile.motion_at(hi).v,
    })
}
