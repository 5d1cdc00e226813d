//! A corner at its worst phase. Where the joint path has a kink (a junction that is not
//! G2-continuous), an axis's velocity jumps by `dv`, and the acceleration measured by finite
//! differences at the period depends on where the kink falls between two setpoints: it is
//! `dv (1 - theta) / Ts` with theta the kink's phase, largest (`dv / Ts`) when a setpoint
//! falls on the kink itself. The plan's own setpoints see one phase; a feed hold, a pause or
//! an override before the corner shifts the phase (`crate::stream`). So the check also
//! measures the stencil centred on the kink: the setpoints the interpolator would give one
//! period before the junction, on it, and one period after.

use super::sample::{corner_among, segment_at, Ctx, Sample};
use nc_geom::kinematics::Joints;

/// Joints at path position s, near `prev`.
pub(super) fn joints_at(ctx: &Ctx, s: f64, prev: &Joints) -> Option<Joints> {
    let k = segment_at(ctx, s);
    let seg = ctx.path.segments.get(k)?;
    Some(
        seg.pose(s - ctx.profile.seg_start[k])
            .joints(ctx.kin, prev, &ctx.cfg.rotary),
    )
}

/// The stencil centred on a kink, and the two that end and start on it.
pub(super) struct Kink {
    /// Joints one period before the junction, on it, one period after.
    pub q: [Joints; 3],
    /// Joints three, two and one period before the junction and on it; on it and one, two
    /// and three periods after. Their jerk is the motion's on each side of the kink, which
    /// the windows that straddle it cannot measure: what the argument that covers every
    /// phase needs (see [`super::HOLD_RESERVE`]), and what shows a step of a joint at the
    /// junction, which no speed makes small. `None` where another kink is that close.
    pub sides: [Option<Side>; 2],
    /// The junction's path position and the plan's speed there.
    pub s: f64,
    pub v: f64,
}

/// Four setpoints on one side of a kink, one of them on it, oldest first; the path
/// positions they span and the plan's highest speed there.
pub(super) struct Side {
    pub q: [Joints; 4],
    pub s: (f64, f64),
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
    let ts = ctx.cfg.period;
    let near = profile.near(lo - 4.0 * ts, hi + 4.0 * ts);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if near.motion_at(mid).s < s_j {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let before = joints_at(ctx, near.motion_at(hi - ts).s, &w[1].q)?;
    let on = joints_at(ctx, s_j, &w[1].q)?;
    let after = joints_at(ctx, near.motion_at(hi + ts).s, &w[2].q)?;
    // A side is one-sided only if no other kink lies within its three periods.
    let kink_between =
        |s0: f64, s1: f64| corner_among(segment_at(ctx, s0), segment_at(ctx, s1), smooth, Some(k));
    let side = |dir: f64| -> Option<Side> {
        let s3 = near.motion_at(hi + dir * 3.0 * ts).s;
        if kink_between(s_j, s3) {
            return None;
        }
        let (mut prev, mut q, mut v) = (on, [on; 4], 0.0f64);
        for (i, x) in q.iter_mut().enumerate() {
            let m = near.motion_at(hi + dir * i as f64 * ts);
            v = v.max(m.v);
            if i > 0 {
                prev = joints_at(ctx, m.s, &prev)?;
                *x = prev;
            }
        }
        if dir < 0.0 {
            q.reverse();
        }
        Some(Side {
            q,
            s: (s_j.min(s3), s_j.max(s3)),
            v,
        })
    };
    Some(Kink {
        q: [before, on, after],
        sides: [side(-1.0), side(1.0)],
        s: s_j,
        v: near.motion_at(hi).v,
    })
}

#[cfg(test)]
mod tests {
    use crate::plan::{plan, PlanErrorKind};
    use crate::verify::Quantity;
    use nc_geom::kinematics::{Kinematics, MachineKinematics};
    use nc_geom::segment::{build, Tooling};

    /// The long run's seed 7 000 006 as the segment builder once built it: C turned, at
    /// rest, to where the tilt reached 1e-7, 5.6e-5 rad short of where the G06.5 block's
    /// tool leaves the vertical, so C stepped just after the junction (the plan was
    /// accepted, and a stop that shifted the phase put 1.12x on C). A step of a joint is
    /// measured at the junction's worst phase as an acceleration only while it is large;
    /// on the side after the junction any step is a jerk no speed brings within the limit.
    #[test]
    fn a_step_of_c_just_after_a_junction_is_refused() {
        let src =
            include_str!("../../../../tests/data/adversarial/stop-at-a-vertical-g065-start.nc");
        let (cfg, bl) = crate::fixtures::adversarial_mill(0.002);
        let kin = MachineKinematics::Paper;
        let program = nc_lang::parse(src).expect("parses");
        let mut path = build(&program, &kin, &bl).expect("builds");
        plan(&path, &kin, &cfg).expect("as built, C is continuous and the plan holds");
        // The old choice: C where the tilt first exceeds 1e-7, walking out in decades,
        // 5.6e-5 rad off.
        let k = path.segments.iter().position(|s| s.rotary_only);
        let k = k.expect("the path turns C at rest before the G06.5 block");
        let Tooling::Angles { from, .. } = path.segments[k].tooling else {
            panic!("a turn at rest is a move of the angles");
        };
        let seg = &path.segments[k + 1];
        let mut s = seg.length * 1e-9;
        let mut t = seg.pose(s).axis(&kin);
        while t.x.hypot(t.y) <= 1e-7 {
            s *= 10.0;
            t = seg.pose(s).axis(&kin);
        }
        let (_, c_old) = kin.angles(&t, from, &cfg.rotary);
        // A fifth of that step: at the plan's speed its acceleration at the worst phase
        // (1.1e-5 rad / Ts^2, 2.8 rad/s^2) is far below C's limit, and only the jerk after
        // the junction shows it.
        if let Tooling::Angles { to, .. } = &mut path.segments[k].tooling {
            assert!((to.1 - c_old).abs() > 5e-5, "{} {c_old}", to.1);
            to.1 += 0.2 * (c_old - to.1);
        }
        let err = plan(&path, &kin, &cfg).expect_err("a step of C is refused");
        assert!(
            matches!(
                err.kind,
                PlanErrorKind::Limit {
                    axis: Some('C'),
                    quantity: Quantity::Jerk,
                    ..
                }
            ),
            "{err}"
        );
    }
}
