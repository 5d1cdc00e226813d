//! Reference data shared by the unit tests, integration tests and benchmarks of this crate:
//! the paper's double-NURBS block (docs/paper.md) and a small 5-axis mill. Not part of
//! the interpolator; kept public so `tests/` and `benches/` use the same values.

use crate::kinematics::RotaryLimits;
use crate::plan::{AxisLimit, PlanConfig};
use crate::segment::BuildLimits;

/// Degree of the paper's block (`G06.5 P3`).
pub const PAPER_DEGREE: usize = 3;
/// Cutter-centre control points X Y Z of the paper's block.
pub const PAPER_C: [[f64; 3]; 5] = [
    [47.7773, 71.0202, 58.8006],
    [44.3229, 75.6066, 54.4778],
    [37.2164, 84.6443, 44.5755],
    [28.7567, 101.5653, 29.7151],
    [-1.6963, 163.6796, 5.8369],
];
/// Orientation control points U V W of the paper's block.
pub const PAPER_T: [[f64; 3]; 5] = [
    [47.8066, 71.9791, 59.0828],
    [44.3651, 76.5494, 54.8138],
    [37.2554, 85.5421, 45.0342],
    [28.7081, 102.3535, 30.3361],
    [-1.8572, 163.9906, 6.7762],
];
/// Knots of the paper's block.
pub const PAPER_K: [f64; 9] = [0.0, 0.0, 0.0, 0.0, 0.5046, 1.0, 1.0, 1.0, 1.0];

/// A small 5-axis mill (the limits of `config/machines/paper-ac-table.toml`) at `period`
/// seconds, with unlimited rotary travel.
pub fn small_mill(period: f64) -> (PlanConfig, BuildLimits) {
    let lin = AxisLimit {
        velocity: 250.0,
        acceleration: 2500.0,
        jerk: 50000.0,
    };
    let rot = AxisLimit {
        velocity: 90f64.to_radians(),
        acceleration: 900f64.to_radians(),
        jerk: 20000f64.to_radians(),
    };
    let plan = PlanConfig {
        period,
        chord_tol: 0.001,
        path_acc: 1000.0,
        path_jerk: 20000.0,
        axes: [lin, lin, lin, rot, rot],
        rotary: RotaryLimits::UNLIMITED,
        travel: [(f64::NEG_INFINITY, f64::INFINITY); 5],
    };
    let build = BuildLimits {
        rapid_mm_s: 250.0,
        max_feed_mm_s: 10000.0 / 60.0,
        rotary: RotaryLimits::UNLIMITED,
    };
    (plan, build)
}
