//! What one period of interpolation produces: the setpoint, offline (`nc_plan::interp`) and
//! in the real-time thread (`nc_follow`) alike.

use crate::kinematics::Joints;
use nalgebra::Vector3;

/// What one period produces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setpoint {
    pub cycle: u64,
    /// Time since the start of the program, s.
    pub t: f64,
    /// 1-based NC block index.
    pub block: u32,
    /// Curve parameter of a NURBS block.
    pub u: Option<f64>,
    /// Cutter centre, workpiece frame, mm.
    pub p: Vector3<f64>,
    /// Unit tool axis, workpiece frame.
    pub tool: Vector3<f64>,
    /// Commanded path feed, path units per second.
    pub feed: f64,
    /// Machine axes: X Y Z (mm), tilt and C (radians).
    pub joints: Joints,
    /// The program's end point has been reached; this is the last setpoint.
    pub done: bool,
    /// Spindle and coolant commanded in this period.
    pub aux: crate::program::Aux,
}
