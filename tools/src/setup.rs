//! The validated machine file turned into the nc crate's types, once, before anything runs.
//!
//! `config` stays free of motion code and `nc` free of file formats; this is the one place
//! where the two meet. Rotary quantities change units here: the machine file speaks degrees,
//! the interpolator radians.

use config::{Kinematics as KinConfig, Machine};
use nalgebra::Vector3;
use nc_geom::kinematics::{MachineKinematics, RotaryLimits, Tilt};
use nc_geom::limits::AxisLimit;
use nc_geom::segment::BuildLimits;
use nc_plan::config::PlanConfig;
use nc_plan::interp::Method;

/// Everything the interpolator needs from the machine file, in its own units.
#[derive(Clone, Debug)]
pub struct MachineSetup {
    pub name: String,
    pub period: f64,
    pub kin: MachineKinematics,
    pub plan: PlanConfig,
    pub build: BuildLimits,
    pub method: Method,
    /// Axis names in joint order: X Y Z, tilt (A or B), C.
    pub axis_names: [&'static str; 5],
    /// Axis limits as in the machine file (mm or degrees), joint order.
    pub limits: [config::AxisLimits; 5],
    /// On-line compression (`[interpolation] compress`, `--compress`, `--no-compress`, and
    /// the program's `G61`/`G64 P Q`): runs of G01 moves fitted into G06.5 blocks before
    /// the program is built and planned.
    pub compress: nc_fit::options::Policy,
}

pub fn method_of(m: config::Method) -> Method {
    match m {
        config::Method::Arclength => Method::ArcLength,
        config::Method::Taylor1 => Method::Taylor1,
        config::Method::Taylor2 => Method::Taylor2,
    }
}

impl MachineSetup {
    pub fn new(m: &Machine) -> MachineSetup {
        let kin = match &m.kinematics {
            // A 3-axis mill is the paper's kinematics with the tool kept vertical (the
            // parser refuses anything else), so its rotary axes stay at 0.
            KinConfig::Paper | KinConfig::Xyz => MachineKinematics::Paper,
            KinConfig::XyzacTrt {
                a_axis_point,
                c_axis_point,
            } => MachineKinematics::Trt {
                tilt: Tilt::A,
                tilt_point: Vector3::from(*a_axis_point),
                c_point: Vector3::from(*c_axis_point),
            },
            KinConfig::XyzbcTrt {
                b_axis_point,
                c_axis_point,
            } => MachineKinematics::Trt {
                tilt: Tilt::B,
                tilt_point: Vector3::from(*b_axis_point),
                c_point: Vector3::from(*c_axis_point),
            },
        };
        let all = m.axes.all();
        let limits = all.map(|(_, l)| l.clone());
        let axis_names = all.map(|(n, _)| n);
        let axes: [AxisLimit; 5] = core::array::from_fn(|j| {
            let l = &limits[j];
            let k = if j >= 3 { 1f64.to_radians() } else { 1.0 };
            AxisLimit {
                velocity: l.velocity * k,
                acceleration: l.acceleration * k,
                jerk: l.jerk * k,
            }
        });
        let rotary = RotaryLimits {
            tilt: (limits[3].min.to_radians(), limits[3].max.to_radians()),
            c: (limits[4].min.to_radians(), limits[4].max.to_radians()),
        };
        let travel: [(f64, f64); 5] = core::array::from_fn(|j| {
            let k = if j >= 3 { 1f64.to_radians() } else { 1.0 };
            (limits[j].min * k, limits[j].max * k)
        });
        let ip = &m.interpolation;
        let c = ip.compression;
        let compression = nc_fit::options::Options {
            tol: nc_fit::Tolerance {
                mm: c.tol_mm,
                rad: c.tol_deg.to_radians(),
            },
            corner_deg: c.corner_deg,
            ..nc_fit::options::Options::default()
        };
        MachineSetup {
            name: m.name.clone(),
            period: m.period_s,
            kin,
            plan: PlanConfig {
                period: m.period_s,
                chord_tol: ip.chord_tolerance_mm,
                path_acc: ip.path_acceleration,
                path_jerk: ip.path_jerk,
                axes,
                rotary,
                travel,
            },
            build: BuildLimits {
                rapid_mm_s: ip.rapid_feed_mm_min / 60.0,
                max_feed_mm_s: ip.max_feed_mm_min / 60.0,
                rotary,
            },
            method: method_of(ip.method),
            axis_names,
            limits,
            compress: nc_fit::options::Policy {
                on: ip.compress,
                ..nc_fit::options::Policy::on(compression)
            },
        }
    }

    /// The machine a streamed program is planned for (`nc_plan::stream::Stages`, `Source`).
    pub fn machine(&self) -> nc_plan::stream::Machine<'_> {
        nc_plan::stream::Machine {
            kin: &self.kin,
            build: &self.build,
            plan: &self.plan,
        }
    }

    /// `--compress` (`Some(true)`: on where the program says nothing) or `--no-compress`
    /// (`Some(false)`: never, whatever the program permits) over the machine file.
    pub fn with_compress(mut self, over: Option<bool>) -> MachineSetup {
        let opts = self.compress.opts;
        match over {
            Some(true) => self.compress = nc_fit::options::Policy::on(opts),
            Some(false) => self.compress = nc_fit::options::Policy::off(opts),
            None => {}
        }
        self
    }

    /// The program the planner plans: compressed when compression is on, with what the
    /// compressor did.
    pub fn prepare(
        &self,
        program: nc_geom::program::Program,
    ) -> (
        nc_geom::program::Program,
        Option<nc_fit::compress::Compressed>,
    ) {
        if !self.compress.may_compress() {
            return (program, None);
        }
        nc_fit::compress::compress(&program, &self.kin, &self.compress)
    }
}
