//! Reference data shared by the unit tests, integration tests and benchmarks of this crate:
//! the paper's double-NURBS block (docs/paper.md) and a small 5-axis mill. Not part of
//! the interpolator; kept public so `tests/` and `benches/` use the same values.

use crate::config::PlanConfig;
use crate::interp::{Interpolator, Method};
use crate::profile::FeedProfile;
use nalgebra::Vector3;
use nc_geom::kinematics::{MachineKinematics, RotaryLimits};
use nc_geom::limits::AxisLimit;
use nc_geom::segment::{BuildLimits, Geometry, Path};
use nc_geom::setpoint::Setpoint;

/// The programs of `tests/data` the planner's tests plan on the small mill: the test
/// programs and the classics it accepts.
pub const TEST_PROGRAMS: [&str; 13] = [
    "g01-5axis.nc",
    "g062-example.nc",
    "helix-ramp.nc",
    "paper-example.nc",
    "tight-curvature.nc",
    "two-blocks-g2.nc",
    "vertical-turns.nc",
    "classics/butterfly.nc",
    "classics/dual-spline.nc",
    "classics/fan-5axis.nc",
    "classics/figure-eight-circles.nc",
    "classics/figure-eight-weights.nc",
    "classics/star.nc",
];

/// The text of `tests/data/<rel>` (for the tests; panics with the path if unreadable).
pub fn test_program(rel: &str) -> String {
    let p = format!("{}/../../tests/data/{rel}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e}"))
}

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

/// The machine of the generated-program suite (`nc/tests/adversarial.rs`): the small mill
/// with A within +-95 degrees, C endless, and X Y Z travel +-300, +-250, +-200 mm.
pub fn adversarial_mill(period: f64) -> (PlanConfig, BuildLimits) {
    let (mut cfg, mut bl) = small_mill(period);
    let rotary = RotaryLimits {
        tilt: ((-95f64).to_radians(), 95f64.to_radians()),
        c: (f64::NEG_INFINITY, f64::INFINITY),
    };
    cfg.rotary = rotary;
    bl.rotary = rotary;
    cfg.travel = [
        (-300.0, 300.0),
        (-250.0, 250.0),
        (-200.0, 200.0),
        rotary.tilt,
        rotary.c,
    ];
    (cfg, bl)
}

/// A G01 program through `points` (cutter, tool axis), written as a post-processor writes
/// it: four decimals for positions, six for the unit axis; the first point is the start.
pub fn g01_program(points: &[(Vector3<f64>, Vector3<f64>)], feed_mm_min: f64) -> String {
    use std::fmt::Write;
    let mut s = String::from("%\nG90 G21 G94\n");
    for (k, (p, a)) in points.iter().enumerate() {
        let a = a.normalize();
        let g = if k < 2 { "G01 " } else { "" };
        let f = if k == 0 {
            format!(" F{feed_mm_min}")
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "N{} {g}X{:.4} Y{:.4} Z{:.4} I{:.6} J{:.6} K{:.6}{f}",
            10 * (k + 1),
            p.x,
            p.y,
            p.z,
            a.x,
            a.y,
            a.z
        );
    }
    s.push_str("M30\n%\n");
    s
}

/// `n + 1` points along `f` (t in 0..=t_max) at equal steps of cutter path length: `step`
/// mm, or the whole length in `n` steps if `step` is 0. By a table of 200 000 chords.
pub fn resample(
    f: impl Fn(f64) -> (Vector3<f64>, Vector3<f64>),
    t_max: f64,
    n: usize,
    step: f64,
) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let dense = 200_000;
    let mut table = vec![(0.0, 0.0)];
    let mut prev = f(0.0).0;
    for j in 1..=dense {
        let t = t_max * j as f64 / dense as f64;
        let p = f(t).0;
        let s = table.last().map_or(0.0, |x| x.1) + (p - prev).norm();
        table.push((t, s));
        prev = p;
    }
    let total = table.last().map_or(0.0, |x| x.1);
    let step = if step > 0.0 { step } else { total / n as f64 };
    (0..=n)
        .map(|k| {
            let s = (k as f64 * step).min(total);
            let j = table.partition_point(|x| x.1 < s).clamp(1, dense);
            let ((t0, s0), (t1, s1)) = (table[j - 1], table[j]);
            let t = t0 + (t1 - t0) * (s - s0) / (s1 - s0).max(1e-300);
            f(t)
        })
        .collect()
}

/// A blade-like 5-axis sweep at t (0..): the cutter along a twisted, cambered curve (about
/// 41 mm a unit of t), the tool leaning 5..25 degrees and swinging with it.
pub fn blade(t: f64) -> (Vector3<f64>, Vector3<f64>) {
    let p = Vector3::new(
        40.0 * t.cos() + 3.0 * (3.0 * t).cos(),
        40.0 * t.sin() + 2.0 * (2.0 * t).sin(),
        10.0 + 8.0 * t + 1.5 * (5.0 * t).sin(),
    );
    let lean = (15.0 + 10.0 * (2.0 * t).sin()).to_radians();
    let sw = t + 30f64.to_radians() * t.sin();
    let a = Vector3::new(lean.sin() * sw.cos(), lean.sin() * sw.sin(), lean.cos());
    (p, a)
}

/// Every setpoint of `path` planned as `profile`, interpolated offline by `method` at
/// `cfg.period`, up to the one that ends the program; `None` if it has not ended after
/// `max` periods.
pub fn interpolate(
    path: &Path,
    profile: &FeedProfile,
    kin: MachineKinematics,
    cfg: &PlanConfig,
    method: Method,
    max: usize,
) -> Option<Vec<Setpoint>> {
    let mut ip = Interpolator::new(path, profile, kin, cfg.rotary, method, cfg.period, 0.0);
    let mut out = Vec::new();
    while out.len() < max {
        let sp = ip.step();
        out.push(sp);
        if sp.done {
            return Some(out);
        }
    }
    None
}

/// Largest distance between the curve of NURBS segment `seg` and the chord of its setpoints
/// `a` and `b` (seven points between them): the chord error the generated-input suites
/// check, 0 on a line.
pub fn chord_error(path: &Path, seg: usize, a: &Setpoint, b: &Setpoint) -> f64 {
    let Some(Geometry::Nurbs { curve, .. }) = path.segments.get(seg).map(|s| &s.geometry) else {
        return 0.0;
    };
    let (Some(ua), Some(ub)) = (a.u, b.u) else {
        return 0.0;
    };
    let ab = b.p - a.p;
    (1..8)
        .map(|i| {
            let p = curve.cutter(ua + (ub - ua) * f64::from(i) / 8.0, 0).p;
            let f = if ab.norm_squared() > 0.0 {
                ((p - a.p).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p - (a.p + ab * f)).norm()
        })
        .fold(0.0, f64::max)
}

/// Every axis on the four setpoints `w` (oldest first), by finite differences at `period`:
/// velocity and acceleration on the newest, jerk too if `jerk`, and the travel, each within
/// `cfg`'s limit (to a relative 1e-6). What the generated-input suites check on every
/// window of setpoints; the error names the axis, the value, the limit and the time.
pub fn axes_within(
    cfg: &PlanConfig,
    period: f64,
    w: [&Setpoint; 4],
    jerk: bool,
) -> Result<(), String> {
    let slack = 1.0 + 1e-6;
    let t = w[3].t;
    for (j, ax) in cfg.axes.iter().enumerate() {
        let [q0, q1, q2, q3] = w.map(|x| x.joints[j]);
        if !q3.is_finite() {
            return Err(format!("NaN setpoint of axis {j} at t={t}"));
        }
        let v = ((q3 - q2) / period).abs();
        let a = ((q3 - 2.0 * q2 + q1) / period.powi(2)).abs();
        let jk = ((q3 - 3.0 * q2 + 3.0 * q1 - q0) / period.powi(3)).abs();
        let (lo, hi) = cfg.travel[j];
        if v > ax.velocity * slack {
            return Err(format!("axis {j} velocity {v} > {} at t={t}", ax.velocity));
        }
        if a > ax.acceleration * slack {
            return Err(format!(
                "axis {j} acceleration {a} > {} at t={t}",
                ax.acceleration
            ));
        }
        if jerk && jk > ax.jerk * slack {
            return Err(format!("axis {j} jerk {jk} > {} at t={t}", ax.jerk));
        }
        if q3 < lo - 1e-9 || q3 > hi + 1e-9 {
            return Err(format!("axis {j} at {q3} outside travel at t={t}"));
        }
    }
    Ok(())
}
