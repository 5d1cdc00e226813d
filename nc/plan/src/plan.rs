//! Feed planning outside the real-time thread, in windows of bounded look-ahead
//! ([`window`]: each window runs the steps below over its own stretch of path).
//!
//! 1. **Stations.** Each segment is sampled at stations about one period of travel apart
//!    (16..=4096 per segment; 2 or more along a line with a fixed tool axis, whose joints
//!    move at constant rates; eight times as many, up to 4096, where a rotary axis's rate
//!    changes 8x from one interval to the next). At each station the machine joints q(s)
//!    are computed through the kinematics (with rotary continuity), and dq/ds, d2q/ds2,
//!    d3q/ds3 by finite differences (at a joint of two segments, each side's).
//! 2. **Velocity ceiling** at each station, the least of: the programmed feed; the chord-error
//!    limit `2 sqrt(2 rho delta - delta^2) / Ts` (rho = 1/curvature, delta = tolerance); the
//!    centripetal limit `sqrt(A / curvature)`; for every axis j `vmax_j / |dq_j/ds|` and
//!    `sqrt(amax_j / (2 |d2q_j/ds2|))` (at least half the axis acceleration is left for the
//!    path acceleration, see 4). Near the vertical tool dC/ds grows like 1/sin(A), so this is what
//!    slows the path and keeps the C axis within its limits.
//! 3. **Corners.** Where segments meet with a kink in some axis (dq/ds jumps by d_j), the
//!    joint is passed at `min_j amax_j Ts / d_j`: each axis's velocity then changes by at
//!    most one period's worth of its acceleration. A G2-continuous joint has d = 0 and is
//!    passed at speed. Where the cutter path turns by phi there, also at most
//!    `2 tol / (Ts sin(phi / 2))`: the chord that straddles the corner then keeps the
//!    tolerance whatever the sampling phase (after a hold, too). The path starts and ends
//!    at rest, and rests where a move waits (a dwell, the operator, the spindle).
//! 4. **S-curves between critical points.** Critical points are the start, the end, the
//!    joints, the local minima of the ceiling, and the stations next to where the rates
//!    jump (the path acceleration they allow falls or rises 8x from what it was on the
//!    stretch leaving the last critical point: a tool arriving at the vertical, or leaving
//!    it), which would otherwise hold the ramps beside them.
//!    Backward and forward passes make each point's speed reachable from its neighbours;
//!    then each section gets a jerk-limited accelerate / cruise / decelerate profile with
//!    the highest cruise speed that fits. Its two ramps' path acceleration and jerk are
//!    what each axis's share (90 %) leaves after the curvature terms, over the stretch each
//!    ramp can cover and at the speeds it can have there, and never less than half the
//!    axis's ([`limits`]). Wherever a section's speed exceeds the ceiling at a station,
//!    that station becomes a critical point and the plan is redone.
//! 5. **The setpoint check** measures every axis's velocity, acceleration and jerk by finite
//!    differences at the period ([`crate::verify`]); where one is over its limit the
//!    ceilings there are lowered (and for jerk the path's share, to half) and the window is
//!    planned again. Where the caps stop changing the plan, they go to the stations on
//!    either side, unless that would make the path crawl to them: then the path's share is
//!    lowered, or the ceilings the violation holds go on down from where they are, and the
//!    window falls back to the widened caps if that ends in a refusal ([`remedy`]). No cap
//!    goes below the floor speed [`V_FLOOR`] but a joint's, down to [`V_JOINT_FLOOR`].
//!
//! The result is a [`FeedProfile`]: constant-jerk phases over the whole path, evaluated per
//! period without allocation.

use crate::config::PlanConfig;
use crate::profile::FeedProfile;
use nc_geom::kinematics::{Joints, MachineKinematics};
use nc_geom::program::SrcPos;
use nc_geom::scurve::Phase;
use nc_geom::segment::{Path, Segment};

mod error;
mod limits;
mod remedy;
mod rounds;
mod schedule;
mod stations;
mod window;

use stations::Station;

pub use error::{PlanError, PlanErrorKind, ProgramError};
pub use window::{Finished, Planner, Sink};

/// Slowest speed a joint is passed at where an axis's rate jumps there by more than the
/// floor speed allows (path units/s): the jump is taken in one period at that speed.
pub const V_JOINT_FLOOR: f64 = 1e-7;
/// Likewise for a section's path acceleration and jerk.
const A_FLOOR: f64 = 1e-3;
/// Replanning rounds before every violating station is made critical at once.
const ROUNDS_WORST_ONLY: usize = 60;
const ROUNDS_MAX: usize = 400;

/// Planning rounds with the setpoint check before the program is refused.
const VERIFY_ROUNDS: usize = 40;
/// A lowered ceiling aims this far below what the measured violation needs.
const CAP_MARGIN: f64 = 0.97;

/// Plan the feed over the whole path: stations, ceilings and S-curves, then the check of the
/// setpoints at the period ([`crate::verify::check`]). Where a limit is broken the ceiling
/// there drops by the factor the measurement asks for and the plan is made again; a limit
/// that slowing cannot bring within its bound (travel, a step at rest, a violation at the
/// slowest feed) refuses the program with the position of its block. The path is planned
/// in windows of bounded length ([`window`]), each checked as it is planned, by the
/// [`Planner`] a streamed program goes through, fed the whole path.
pub fn plan(
    path: &Path,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
) -> Result<FeedProfile, PlanError> {
    plan_whole(path, Planner::new(start_of(path), kin, cfg))
}

/// [`plan`] with windows that look ahead just `reach` (path units) past what they commit,
/// however much the stop at their end slows the plan: short windows for the tests, which
/// stop and start more often, and must hold every limit all the same.
pub fn plan_looking_ahead(
    path: &Path,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    reach: f64,
) -> Result<FeedProfile, PlanError> {
    plan_whole(
        path,
        Planner::new(start_of(path), kin, cfg).looking_ahead(reach),
    )
}

/// A path's start, as [`Planner::new`] takes it.
pub fn start_of(path: &Path) -> (nc_geom::segment::Pose, SrcPos, Joints) {
    (path.start, path.start_src, path.start_joints)
}

/// The phases a [`Planner`] sends, collected; its segments let go.
#[derive(Default)]
pub struct Collect {
    pub phases: Vec<Phase>,
}

impl Sink for Collect {
    fn segment(&mut self, _: Segment) {}
    fn phases(&mut self, phases: &[Phase]) {
        self.phases.extend_from_slice(phases);
    }
}

/// Feed `planner` every segment of `path` and collect its plan as one profile.
pub fn plan_whole(path: &Path, mut planner: Planner) -> Result<FeedProfile, PlanError> {
    let mut sink = Collect::default();
    for seg in &path.segments {
        planner.push(seg.clone(), &mut sink)?;
    }
    let end = planner.finish(&mut sink)?;
    let mut seg_start = Vec::with_capacity(path.segments.len() + 1);
    let mut total = 0.0;
    for seg in &path.segments {
        seg_start.push(total);
        total += seg.length;
    }
    seg_start.push(total);
    Ok(FeedProfile {
        phases: sink.phases,
        seg_start,
        length: end.length,
        duration: end.duration,
        margins: end.margins,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verify::Quantity;
    use nc_geom::limits::AxisLimit;
    use nc_geom::limits::V_FLOOR;

    /// Only a refusal at the planner's floor says no slower feed is scheduled; one above it
    /// says how slow the planner got (a refusal at 5.9 mm/s once read as if no speed would
    /// do).
    #[test]
    fn a_refusal_says_whether_the_planner_reached_its_floor() {
        let limit = |v: f64, floor: bool| PlanErrorKind::Limit {
            axis: Some('Y'),
            quantity: Quantity::Jerk,
            unit: "mm/s^3",
            value: 50574.0,
            limit: 50000.0,
            machine: 50000.0,
            t: 4.066,
            v,
            path_unit: "mm",
            hint: "",
            floor,
        };
        let above = limit(5.924, false).to_string();
        assert!(
            above.contains("at 5.924e0 mm/s, the slowest the planner reached there")
                && !above.contains("even at the slowest feed"),
            "{above}"
        );
        let at = limit(V_FLOOR, true).to_string();
        assert!(at.contains("1.011x its limit of 5.0000e4 mm/s^3,"), "{at}");
        assert!(
            at.contains("even at the slowest feed the planner schedules there (1.000e-3 mm/s)"),
            "{at}"
        );
    }

    /// Where the plan may use less than the machine file says, a refusal names both: the
    /// mill with its jerks set to 1e9 is planned at 2.94e5 mm/s^3, and "its limit of
    /// 2.9400e5" read as if the file had been misread.
    #[test]
    fn a_refusal_names_the_planned_limit_beside_the_files() {
        let x = AxisLimit {
            velocity: 300.0,
            acceleration: 3000.0,
            jerk: 1e9,
        };
        let refusal = |quantity, unit, value, limit, machine| {
            PlanErrorKind::Limit {
                axis: Some('X'),
                quantity,
                unit,
                value,
                limit,
                machine,
                t: 1.0,
                v: 2.0,
                path_unit: "mm",
                hint: "",
                floor: false,
            }
            .to_string()
        };
        let msg = refusal(
            Quantity::Jerk,
            "mm/s^3",
            3.0e5,
            x.planned_jerk(1e-3),
            x.jerk,
        );
        assert!(
            msg.contains(
                "1.200x the 2.4990e5 mm/s^3 a plan may use of its limit of 1.0000e9 mm/s^3 \
                 (a plan's jerk is at most 0.098 x the acceleration per period, and 85.0 % of \
                 that: the rest is kept for feed holds and overrides)"
            ),
            "{msg}"
        );
        // A jerk within the rise: the plan keeps the reserve of the file's.
        let slow = AxisLimit { jerk: 5e4, ..x };
        let msg = refusal(
            Quantity::Jerk,
            "mm/s^3",
            6.0e4,
            slow.planned_jerk(1e-3),
            slow.jerk,
        );
        assert!(
            msg.contains(
                "the 4.2500e4 mm/s^3 a plan may use of its limit of 5.0000e4 mm/s^3 (85.0 %: \
                 the rest is kept for feed holds and overrides)"
            ),
            "{msg}"
        );
        let share = nc_geom::limits::reserve(&x, 1e-3).1;
        let msg = refusal(
            Quantity::Acceleration,
            "mm/s^2",
            2900.0,
            3000.0 * share,
            3000.0,
        );
        assert!(
            msg.contains(
                "of its limit of 3.0000e3 mm/s^2 (95.7 %: the rest is kept for feed holds and overrides)"
            ),
            "{msg}"
        );
    }
}
