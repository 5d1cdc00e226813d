//! Jogging along a straight line of the machine's linear axes X Y Z, the rotary axes
//! standing still: the workpiece's X, Y or Z at whatever angles the table stands
//! ([`workpiece_direction`]), or the tool axis ([`tool_direction`]).
//!
//! With the rotary axes still, the workpiece frame is the machine frame turned and
//! shifted, so a straight line of the workpiece is a straight line of X Y Z. One jog runs
//! along it ([`Jog`], on the distance `s` along the line), with each axis's limits over its
//! share of the direction (`v_i / |d_i|`, and so on) and the travel where the line leaves
//! the first axis's. Each axis then moves as `origin_i + d_i s`: its velocity, acceleration
//! and jerk are `d_i` times the line's, within its limits by construction (the setpoints
//! too, by finite differences), and the tool tip moves straight in the workpiece with its
//! axis still (the tool centre point held). Sans-I/O and allocation-free, for the
//! real-time thread, as [`Jog`].

use crate::jog::{Jog, JogLimits, JogRefused};
use nalgebra::Vector3;
use nc_geom::kinematics::{Kinematics, MachineKinematics};

/// Why a jog along a line cannot start.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum LineRefused {
    #[error("the jog's direction {dir:?} is not a direction (zero or not finite)")]
    Direction { dir: [f64; 3] },
    #[error("the {axis} axis stands at {position}, outside its travel {min}..{max}: jog it alone back inside")]
    Outside {
        axis: char,
        position: f64,
        min: f64,
        max: f64,
    },
    #[error(transparent)]
    Jog(#[from] JogRefused),
}

/// A jog along one line of X Y Z.
#[derive(Clone, Copy, Debug)]
pub struct LineJog {
    jog: Jog,
    origin: [f64; 3],
    dir: [f64; 3],
    lim: JogLimits,
}

impl LineJog {
    /// At rest at `origin` (machine X Y Z), to jog along `dir` (any length; made a unit
    /// vector), within `axes`' limits and travels. A continuous jog goes on for
    /// `deadman_periods` periods after its last renewal.
    pub fn new(
        origin: [f64; 3],
        dir: [f64; 3],
        axes: &[JogLimits; 3],
        period: f64,
        deadman_periods: u32,
    ) -> Result<Self, LineRefused> {
        let n = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        if !(n.is_finite() && n > 0.0) {
            return Err(LineRefused::Direction { dir });
        }
        let d = [dir[0] / n, dir[1] / n, dir[2] / n];
        let mut lim = JogLimits {
            velocity: f64::INFINITY,
            acceleration: f64::INFINITY,
            jerk: f64::INFINITY,
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
        };
        for (i, (ax, (&o, &di))) in axes.iter().zip(origin.iter().zip(&d)).enumerate() {
            if !(o >= ax.min && o <= ax.max) {
                return Err(LineRefused::Outside {
                    axis: ['X', 'Y', 'Z'][i],
                    position: o,
                    min: ax.min,
                    max: ax.max,
                });
            }
            let share = di.abs();
            if share == 0.0 {
                continue;
            }
            lim.velocity = lim.velocity.min(ax.velocity / share);
            lim.acceleration = lim.acceleration.min(ax.acceleration / share);
            lim.jerk = lim.jerk.min(ax.jerk / share);
            let (a, b) = ((ax.min - o) / di, (ax.max - o) / di);
            lim.min = lim.min.max(a.min(b));
            lim.max = lim.max.min(a.max(b));
        }
        Ok(LineJog {
            jog: Jog::new(0.0, lim, period, deadman_periods),
            origin,
            dir: d,
            lim,
        })
    }

    /// The line's own limits: the speeds along it and how far it goes each way.
    pub fn limits(&self) -> JogLimits {
        self.lim
    }

    /// The unit direction.
    pub fn direction(&self) -> [f64; 3] {
        self.dir
    }

    /// Distance along the line from the origin, its velocity and acceleration.
    pub fn state(&self) -> (f64, f64, f64) {
        self.jog.state()
    }

    pub fn at_rest(&self) -> bool {
        self.jog.at_rest()
    }

    /// The last jog stopped short of the travel.
    pub fn limited(&self) -> bool {
        self.jog.limited()
    }

    /// Continuous jog at `velocity` along the line (signed), until a stop or the dead-man.
    pub fn velocity(&mut self, velocity: f64) -> Result<(), LineRefused> {
        Ok(self.jog.velocity(velocity)?)
    }

    pub fn renew(&mut self) {
        self.jog.renew();
    }

    pub fn stop(&mut self) {
        self.jog.stop();
    }

    /// Incremental jog to `distance` along the line from the origin, from rest.
    pub fn to(&mut self, distance: f64, speed: f64) -> Result<(), LineRefused> {
        Ok(self.jog.to(distance, speed)?)
    }

    /// The next period's X Y Z.
    pub fn step(&mut self) -> [f64; 3] {
        let s = self.jog.step();
        self.at(s)
    }

    /// X Y Z at distance `s` along the line.
    pub fn at(&self, s: f64) -> [f64; 3] {
        let (o, d) = (&self.origin, &self.dir);
        [o[0] + d[0] * s, o[1] + d[1] * s, o[2] + d[2] * s]
    }
}

/// The machine's X Y Z direction that moves the tool along the workpiece's `w` with the
/// rotary axes standing at `tilt` and `c` (radians).
pub fn workpiece_direction(kin: &MachineKinematics, w: [f64; 3], tilt: f64, c: f64) -> [f64; 3] {
    let zero = kin.place(&Vector3::zeros(), tilt, c);
    (kin.place(&Vector3::from(w), tilt, c) - zero).into()
}

/// The machine's X Y Z direction along the tool axis (away from the workpiece) at `tilt`
/// and `c`.
pub fn tool_direction(kin: &MachineKinematics, tilt: f64, c: f64) -> [f64; 3] {
    workpiece_direction(kin, kin.tool_axis(tilt, c).into(), tilt, c)
}
