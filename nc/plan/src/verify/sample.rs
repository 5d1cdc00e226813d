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
    let (a, b) = (w[0].seg, w[w.len() - 1].seg);
    (a + 1..=b).any(|k| !smooth.get(k).copied().unwrap_or(false))
}
