//! Machine kinematics: from a cutter point and tool axis in the workpiece frame to the five
//! machine axes (X, Y, Z, tilt, C) and back.
//!
//! Conventions (all three machines): the spindle points along machine +Z and moves in X Y Z;
//! the workpiece sits on a C rotary table carried by a tilting table (A about machine X, or B
//! about machine Y). At tilt = C = 0 the workpiece frame coincides with the machine frame.
//! The table rotation that takes workpiece vectors into the machine frame is
//! `M = R_tilt(tilt) * R_z(-C)`; the tool axis in the workpiece frame is `T = M^T e_z`:
//!
//! * A/C: `T = (-sin A sin C, sin A cos C, cos A)`, hence the paper's eq. 17:
//!   `A = arccos(Tz)`, `C = atan2(-Tx, Ty)`; eq. 18 (A = C = 0 for Tz = 1) is the singular case.
//! * B/C: `T = (-sin B cos C, -sin B sin C, cos B)`.
//!
//! Every tool axis off the vertical has two rotary solutions, `(t, C)` and `(-t, C + pi)`, and
//! C is defined modulo 2 pi. [`Kinematics::angles`] picks the one nearest the previous angles
//! (C unwrapped, never a 360-degree jump) that respects the axis limits, so a path straight
//! through the vertical keeps C still and lets the tilt change sign. Exactly at the vertical
//! (`rho = |(Tx, Ty)| < 1e-12`), C is held at its previous value. `rho` is computed from Tx and
//! Ty directly, never as `sqrt(1 - Tz^2)`, which loses all precision near the vertical.
//!
//! Positions: `paper` takes machine XYZ = workpiece XYZ, exactly as the paper assumes (no
//! tool-centre-point compensation). The `*-trt` machines apply full RTCP: the workpiece point
//! is carried through the C rotation about the C axis and the tilt rotation about the tilt
//! axis, and the spindle goes where the point now is.

use nalgebra::{Rotation3, Vector3};

/// Machine axis positions: X, Y, Z in mm, tilt (A or B) and C in radians.
pub type Joints = [f64; 5];

/// Which axis the tilting table turns about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tilt {
    /// A: about machine X.
    A,
    /// B: about machine Y.
    B,
}

/// Rotary limits in radians (C may be unlimited: infinite bounds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotaryLimits {
    pub tilt: (f64, f64),
    pub c: (f64, f64),
}

impl RotaryLimits {
    pub const UNLIMITED: RotaryLimits = RotaryLimits {
        tilt: (f64::NEG_INFINITY, f64::INFINITY),
        c: (f64::NEG_INFINITY, f64::INFINITY),
    };
}

/// Forward and inverse transforms of a 5-axis machine.
pub trait Kinematics {
    /// Unit tool axis in the workpiece frame for the rotary angles.
    fn tool_axis(&self, tilt: f64, c: f64) -> Vector3<f64>;
    /// Rotary angles for the unit tool axis `t`, nearest to `prev` and within `lim` if any
    /// solution is.
    fn angles(&self, t: &Vector3<f64>, prev: (f64, f64), lim: &RotaryLimits) -> (f64, f64);
    /// Machine X Y Z that bring the spindle onto workpiece point `p` at the given angles.
    fn place(&self, p: &Vector3<f64>, tilt: f64, c: f64) -> Vector3<f64>;
    /// Workpiece point under the spindle for machine X Y Z at the given angles.
    fn unplace(&self, m: &Vector3<f64>, tilt: f64, c: f64) -> Vector3<f64>;

    /// Inverse kinematics: joints for cutter point `p` and tool axis `t`.
    fn inverse(
        &self,
        p: &Vector3<f64>,
        t: &Vector3<f64>,
        prev: &Joints,
        lim: &RotaryLimits,
    ) -> Joints {
        let (tilt, c) = self.angles(t, (prev[3], prev[4]), lim);
        let m = self.place(p, tilt, c);
        [m.x, m.y, m.z, tilt, c]
    }

    /// Forward kinematics: cutter point and tool axis in the workpiece frame.
    fn forward(&self, j: &Joints) -> (Vector3<f64>, Vector3<f64>) {
        let m = Vector3::new(j[0], j[1], j[2]);
        (self.unplace(&m, j[3], j[4]), self.tool_axis(j[3], j[4]))
    }
}

/// The machines dnurbs knows, as one value (no trait objects in the real-time path).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MachineKinematics {
    /// Machine XYZ = workpiece XYZ, A/C angles from the tool axis (paper section 5.2).
    Paper,
    /// Tilting table (A about X or B about Y) through `tilt_point`, carrying a C table whose
    /// axis passes through `c_point` at tilt = 0. Points in mm, machine frame.
    Trt {
        tilt: Tilt,
        tilt_point: Vector3<f64>,
        c_point: Vector3<f64>,
    },
}

impl MachineKinematics {
    pub fn tilt_kind(&self) -> Tilt {
        match self {
            MachineKinematics::Paper => Tilt::A,
            MachineKinematics::Trt { tilt, .. } => *tilt,
        }
    }

    fn tilt_rotation(&self, angle: f64) -> Rotation3<f64> {
        match self.tilt_kind() {
            Tilt::A => Rotation3::from_axis_angle(&Vector3::x_axis(), angle),
            Tilt::B => Rotation3::from_axis_angle(&Vector3::y_axis(), angle),
        }
    }
}

const TWO_PI: f64 = 2.0 * core::f64::consts::PI;
/// Below this |(Tx, Ty)| the tool is vertical and C is left where it was.
pub const VERTICAL_RHO: f64 = 1e-12;

/// The unit tool axis `t` is within [`VERTICAL_RHO`] of the vertical, where a table's C is
/// undefined and [`Kinematics::angles`] keeps it.
pub fn is_vertical(t: &Vector3<f64>) -> bool {
    t.x.hypot(t.y) < VERTICAL_RHO
}

/// `c` shifted by whole turns to lie nearest `reference`.
pub fn unwrap_near(c: f64, reference: f64) -> f64 {
    c + TWO_PI * ((reference - c) / TWO_PI).round()
}

fn within(x: f64, (lo, hi): (f64, f64)) -> bool {
    x >= lo - 1e-12 && x <= hi + 1e-12
}

impl Kinematics for MachineKinematics {
    fn tool_axis(&self, tilt: f64, c: f64) -> Vector3<f64> {
        let (st, ct) = tilt.sin_cos();
        let (sc, cc) = c.sin_cos();
        match self.tilt_kind() {
            Tilt::A => Vector3::new(-st * sc, st * cc, ct),
            Tilt::B => Vector3::new(-st * cc, -st * sc, ct),
        }
    }

    fn angles(&self, t: &Vector3<f64>, prev: (f64, f64), lim: &RotaryLimits) -> (f64, f64) {
        let rho = t.x.hypot(t.y);
        let tilt = rho.atan2(t.z);
        if is_vertical(t) {
            // Vertical tool: any C is right; keep it, and keep the tilt's sign.
            return (if prev.0 < 0.0 { -tilt } else { tilt }, prev.1);
        }
        let c1 = match self.tilt_kind() {
            Tilt::A => (-t.x).atan2(t.y),
            Tilt::B => (-t.y).atan2(-t.x),
        };
        let mut best = (tilt, unwrap_near(c1, prev.1));
        let mut best_cost = f64::INFINITY;
        for (cand_tilt, cand_c) in [(tilt, c1), (-tilt, c1 + core::f64::consts::PI)] {
            // The C solutions nearest prev and one turn to either side, for limited C tables.
            let near = unwrap_near(cand_c, prev.1);
            for c in [near, near - TWO_PI, near + TWO_PI] {
                let mut cost = (cand_tilt - prev.0).abs() + (c - prev.1).abs();
                if !within(cand_tilt, lim.tilt) || !within(c, lim.c) {
                    cost += 1e6; // out of range: only if nothing else is possible
                }
                if cost < best_cost {
                    best_cost = cost;
                    best = (cand_tilt, c);
                }
            }
        }
        best
    }

    fn place(&self, p: &Vector3<f64>, tilt: f64, c: f64) -> Vector3<f64> {
        match self {
            MachineKinematics::Paper => *p,
            MachineKinematics::Trt {
                tilt_point,
                c_point,
                ..
            } => {
                let rc = Rotation3::from_axis_angle(&Vector3::z_axis(), -c);
                let on_tilt = c_point + rc * (p - c_point) - tilt_point;
                tilt_point + self.tilt_rotation(tilt) * on_tilt
            }
        }
    }

    fn unplace(&self, m: &Vector3<f64>, tilt: f64, c: f64) -> Vector3<f64> {
        match self {
            MachineKinematics::Paper => *m,
            MachineKinematics::Trt {
                tilt_point,
                c_point,
                ..
            } => {
                let rc = Rotation3::from_axis_angle(&Vector3::z_axis(), c);
                let untilted = self.tilt_rotation(-tilt) * (m - tilt_point) + tilt_point;
                c_point + rc * (untilted - c_point)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn trt(tilt: Tilt) -> MachineKinematics {
        MachineKinematics::Trt {
            tilt,
            tilt_point: Vector3::new(3.0, -20.0, -50.0),
            c_point: Vector3::new(5.0, 7.0, 0.0),
        }
    }

    #[test]
    fn paper_eq17_for_a_positive_tilt() {
        let k = MachineKinematics::Paper;
        let t = Vector3::new(0.3, 0.5, 0.8).normalize();
        let (a, c) = k.angles(&t, (0.1, 0.0), &RotaryLimits::UNLIMITED);
        assert!((a - t.z.acos()).abs() < 1e-12);
        // C = arctan(-Tx/Ty) (the quadrant follows from Ty > 0 here).
        assert!((c - (-t.x / t.y).atan()).abs() < 1e-12);
        assert!((k.tool_axis(a, c) - t).norm() < 1e-12);
        // Vertical tool: eq. 18.
        assert_eq!(
            k.angles(&Vector3::z(), (0.0, 0.0), &RotaryLimits::UNLIMITED),
            (0.0, 0.0)
        );
    }

    #[test]
    fn table_rotation_brings_the_tool_axis_onto_machine_z() {
        for k in [trt(Tilt::A), trt(Tilt::B)] {
            let t = k.tool_axis(0.7, -2.1);
            let m = k.tilt_rotation(0.7) * Rotation3::from_axis_angle(&Vector3::z_axis(), 2.1);
            assert!((m * t - Vector3::z()).norm() < 1e-12);
        }
    }

    #[test]
    fn straight_through_the_vertical_keeps_c_still() {
        let k = MachineKinematics::Paper;
        let mut prev = (0.0, 0.4);
        let mut cs = vec![];
        // The tool axis swings in the plane of C = 0.4 from one side of vertical to the other.
        for i in -50..=50 {
            let a = i as f64 * 0.002;
            let t = k.tool_axis(a, 0.4);
            prev = k.angles(&t, prev, &RotaryLimits::UNLIMITED);
            cs.push(prev.1);
            assert!((k.tool_axis(prev.0, prev.1) - t).norm() < 1e-12);
        }
        assert!(cs.iter().all(|&c| (c - 0.4).abs() < 1e-12), "{cs:?}");
    }

    #[test]
    fn c_is_unwrapped_over_many_turns() {
        let k = trt(Tilt::A);
        let mut prev = (0.5, 0.0);
        for i in 0..2000 {
            let c = i as f64 * 0.01; // about three turns
            let t = k.tool_axis(0.5, c);
            prev = k.angles(&t, prev, &RotaryLimits::UNLIMITED);
            assert!((prev.1 - c).abs() < 1e-9, "i={i} {prev:?}");
        }
    }

    #[test]
    fn tilt_limits_choose_the_other_branch() {
        let k = MachineKinematics::Paper;
        let lim = RotaryLimits {
            tilt: (-0.1, 1.6),
            c: (f64::NEG_INFINITY, f64::INFINITY),
        };
        // Nearest by angle would be the negative tilt, but the table cannot go there.
        let t = k.tool_axis(-0.5, 0.0);
        let (a, c) = k.angles(&t, (-0.05, 0.0), &lim);
        assert!((a - 0.5).abs() < 1e-12);
        assert!((k.tool_axis(a, c) - t).norm() < 1e-12);
    }

    proptest! {
        #[test]
        fn forward_inverse_round_trip(
            x in -200.0..200.0f64, y in -200.0..200.0f64, z in -100.0..100.0f64,
            theta in 0.001..1.5f64, phi in -3.1..3.1f64, kind in 0..3usize,
            prev_a in -1.0..1.0f64, prev_c in -10.0..10.0f64,
        ) {
            let k = [MachineKinematics::Paper, trt(Tilt::A), trt(Tilt::B)][kind];
            let p = Vector3::new(x, y, z);
            let t = Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            let j = k.inverse(&p, &t, &[0.0, 0.0, 0.0, prev_a, prev_c], &RotaryLimits::UNLIMITED);
            let (p2, t2) = k.forward(&j);
            prop_assert!((p2 - p).norm() < 1e-9, "{p} -> {j:?} -> {p2}");
            prop_assert!((t2 - t).norm() < 1e-9);
            // And the other way: joints -> pose -> the same joints (C near its start).
            let (p3, t3) = k.forward(&j);
            let j2 = k.inverse(&p3, &t3, &j, &RotaryLimits::UNLIMITED);
            for i in 0..5 { prop_assert!((j2[i] - j[i]).abs() < 1e-9); }
        }
    }
}
