//! A setpoint with what the check needs beside it ([`Sample`]), and what every check
//! measures against ([`Ctx`]).

use crate::config::PlanConfig;
use crate::profile::FeedProfile;
use nalgebra::Vector3;
use nc_geom::kinematics::{Joints, MachineKinematics};
use nc_geom::segment::Path;
use nc_geom::setpoint::Setpoint;

/// A setpoint with what the check needs beside it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sample {
    pub(super) q: Joints,
    pub(super) p: Vector3<f64>,
    pub(super) u: Option<f64>,
    pub(super) seg: usize,
    pub(super) s: f64,
    pub(super) v: f64,
    pub(super) cycle: u64,
    pub(super) t: f64,
}

pub(super) fn sample(
    sp: &Setpoint,
    seg: usize,
    profile: &FeedProfile,
    cursor: &mut usize,
) -> Sample {
    let m = profile.at(sp.t, cursor);
    Sample {
        q: sp.joints,
        p: sp.p,
        u: sp.u,
        seg,
        s: m.s,
        v: m.v,
        cycle: sp.cycle,
        t: sp.t,
    }
}

/// What a check measures against: the path, its plan, the machine, and which junctions
/// are G2-continuous.
pub(super) struct Ctx<'a> {
    pub(super) path: &'a Path,
    pub(super) profile: &'a FeedProfile,
    pub(super) kin: &'a MachineKinematics,
    pub(super) cfg: &'a PlanConfig,
    pub(super) smooth: &'a [bool],
}

/// Does the stencil `w` cross a junction that is not G2-continuous?
pub(super) fn crosses_corner(w: &[Sample], smooth: &[bool]) -> bool {
    corner_among(w[0].seg, w[w.len() - 1].seg, smooth, None)
}

/// Is a junction that is not G2-continuous among those between segments `a` and `b`
/// (the starts of the segments after the first up to the last), other than `except`?
pub(super) fn corner_among(a: usize, b: usize, smooth: &[bool], except: Option<usize>) -> bool {
    (a.min(b) + 1..=a.max(b))
        .filter(|&k| Some(k) != except)
        .any(|k| !smooth.get(k).copied().unwrap_or(false))
}

/// The segment path position `s` lies on: a junction counts with the segment it starts,
/// the path's end (where the drives hold the last pose) with the last segment.
pub(super) fn segment_at(ctx: &Ctx, s: f64) -> usize {
    let n = ctx.path.segments.len().saturating_sub(1);
    let k = ctx.profile.seg_start.partition_point(|&x| x <= s);
    k.saturating_sub(1).min(n)
}
