//! The planner's configuration: the machine's period, tolerances and limits as the planner
//! reads them (built from the machine file by the command line).

use nc_follow::HoldConfig;
use nc_geom::kinematics::RotaryLimits;
use nc_geom::limits::AxisLimit;

/// What the planner plans for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanConfig {
    /// Interpolation period, s.
    pub period: f64,
    /// Chord tolerance, mm.
    pub chord_tol: f64,
    /// Path acceleration and jerk, mm/s^2 and mm/s^3.
    pub path_acc: f64,
    pub path_jerk: f64,
    /// X, Y, Z, tilt, C.
    pub axes: [AxisLimit; 5],
    pub rotary: RotaryLimits,
    /// Travel of each axis (mm, radians): every setpoint stays within it, or the program
    /// is refused. Infinite for a continuous C table.
    pub travel: [(f64, f64); 5],
}

impl PlanConfig {
    /// The feed hold's limits: half the path's acceleration and jerk, every axis's limits.
    pub fn hold(&self) -> HoldConfig {
        HoldConfig {
            period: self.period,
            acc: self.path_acc / 2.0,
            jerk: self.path_jerk / 2.0,
            axes: self.axes,
        }
    }
}
