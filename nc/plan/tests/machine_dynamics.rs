//! Machine files the team did not write: axis limits drawn over the whole range a machine
//! builder might give, above all a jerk that is high against the acceleration (a linear
//! motor, or a jerk set huge to mean none, as LinuxCNC has none). The setpoint check keeps
//! a reserve of each axis's acceleration that grows with `J Ts / 2A`, and with the plan's
//! ramps at 90 % of the whole acceleration a plain raster was refused on such a machine
//! (`the X axis acceleration would reach 2.6949e3 mm/s^2 ... 1.797x its limit of 1.5000e3`
//! on the xyzac-trt-mill with every jerk 1e9); now the plan keeps to
//! [`nc_geom::limits::AxisLimit::planned_jerk`]. Every generated machine plans three programs (a
//! 3-axis raster with row-end corners, a 5-axis blade sweep of short G01 moves, the
//! paper's G06.5 block), none is refused, and every setpoint holds every axis's velocity,
//! acceleration and travel by finite differences at the period, and its jerk (the machine's,
//! not the planned) wherever the four setpoints lie in one block.
//!
//! `DYN_CASES` machines (default 24), drawn from `DYN_SEED` (default 0).

use nc_geom::kinematics::MachineKinematics;
use nc_geom::limits::AxisLimit;
use nc_plan::config::PlanConfig;
use nc_plan::interp::Method;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError};

/// Rows of 0.1 mm G01 moves over a wave, 1 mm step-overs and 90-degree row ends, F3000.
fn raster() -> String {
    let mut s = String::from("%\nG90 G21 G94\nG01 X0 Y0 Z0 F3000\n");
    for row in 0..3 {
        let y = f64::from(row);
        for k in 0..=80 {
            let x = if row % 2 == 0 { k } else { 80 - k } as f64 * 0.1;
            let z = 0.5 * (x / 1.5).sin() * (y / 2.0).cos();
            s += &format!("X{x:.4} Y{y:.4} Z{z:.4}\n");
        }
    }
    s + "M30\n%\n"
}

/// 200 moves of 0.1 mm along the blade-like sweep, the tool axis given as I J K.
fn blade() -> String {
    let points = nc_plan::fixtures::resample(nc_plan::fixtures::blade, 0.5, 200, 0.1);
    nc_plan::fixtures::g01_program(&points, 3000.0)
}

/// An axis's limits: velocity, acceleration, and a jerk `ratio` times the acceleration a
/// second, scaled by `unit` (1 for mm, the radian of a degree for the rotary axes).
fn axis(v: f64, a: f64, ratio: f64, unit: f64) -> AxisLimit {
    AxisLimit {
        velocity: v * unit,
        acceleration: a * unit,
        jerk: a * ratio * unit,
    }
}

/// A machine: the small mill's rotary and travel set-up with the limits drawn.
fn machine() -> impl Strategy<Value = PlanConfig> {
    let lin = (50.0..1000.0f64, 2.0..4.5f64, 1.0..7.5f64);
    let rot = (30.0..720.0f64, 2.0..4.5f64, 1.0..7.5f64);
    (
        prop_oneof![Just(0.001), Just(0.002), Just(0.004)],
        [lin.clone(), lin.clone(), lin],
        [rot.clone(), rot],
        (2.0..5.0f64, 3.0..11.0f64),
    )
        .prop_map(|(period, lin, rot, (pa, pj))| {
            let (mut cfg, _) = nc_plan::fixtures::small_mill(period);
            for (j, (v, a, r)) in lin.into_iter().enumerate() {
                cfg.axes[j] = axis(v, 10f64.powf(a), 10f64.powf(r), 1.0);
            }
            for (j, (v, a, r)) in rot.into_iter().enumerate() {
                cfg.axes[3 + j] = axis(v, 10f64.powf(a), 10f64.powf(r), 1f64.to_radians());
            }
            cfg.path_acc = 10f64.powf(pa);
            cfg.path_jerk = 10f64.powf(pj);
            cfg
        })
}

fn plan_within_limits(cfg: &PlanConfig, name: &str, src: &str) -> Result<(), TestCaseError> {
    let kin = MachineKinematics::Paper;
    let (_, bl) = nc_plan::fixtures::small_mill(cfg.period);
    let parsed = nc_lang::parse(src).expect("parses");
    let path = nc_geom::segment::build(&parsed, &kin, &bl).expect("builds");
    let profile = nc_plan::plan::plan(&path, &kin, cfg)
        .map_err(|e| TestCaseError::fail(format!("{name} refused on {cfg:?}: {e}")))?;
    let sp = nc_plan::fixtures::interpolate(&path, &profile, kin, cfg, Method::ArcLength, 1 << 24)
        .ok_or_else(|| TestCaseError::fail(format!("{name}: no end on {cfg:?}")))?;
    for w in sp.windows(4) {
        let jerk = w.iter().all(|x| x.block == w[0].block);
        nc_plan::fixtures::axes_within(cfg, cfg.period, [&w[0], &w[1], &w[2], &w[3]], jerk)
            .map_err(|e| TestCaseError::fail(format!("{name}: {e} on {cfg:?}")))?;
    }
    Ok(())
}

#[test]
fn every_machine_plans_these_programs_within_its_limits() {
    let cases = test_support::generated::env("DYN_CASES", 24) as u32;
    let seed = test_support::generated::env("DYN_SEED", 0);
    let programs = [
        ("raster", raster()),
        ("blade", blade()),
        ("paper", nc_plan::fixtures::test_program("paper-example.nc")),
    ];
    let mut runner = test_support::generated::seeded_runner(
        Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        },
        seed,
    );
    let result = runner.run(&machine(), |cfg| {
        for (name, src) in &programs {
            plan_within_limits(&cfg, name, src)?;
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
}
