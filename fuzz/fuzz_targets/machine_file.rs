//! Machine file bytes -> TOML -> validated machine -> the planner's set-up, as every
//! `dnurbs` command loads it; then, on every machine accepted, two programs planned as
//! `simulate` and `run` plan them (the paper's G06.5 block and a small 3-axis raster of
//! G01 moves with row-end corners) and interpolated by arc length, as `run` sends them.
//! A panic, an abort or a hang is a finding; so is an accepted plan one of whose setpoints
//! moves an axis faster than the machine file's velocity or acceleration, or outside its
//! travel, by finite differences at the period (`nc_plan::fixtures::axes_within`; the jerk
//! where the four setpoints lie in one block). A refusal is not: a machine file may be too
//! slow, too small or too coarse for a program. Plans of more than 200 000 periods are not
//! made, for the fuzzer's rate.
#![no_main]

use libfuzzer_sys::fuzz_target;

mod common;

const PAPER: &str = include_str!("../../tests/data/paper-example.nc");

/// Three rows of 0.5 mm G01 moves over a wave, 1 mm step-overs, F1200.
const RASTER: &str = "%\nG90 G21 G94\nG01 X0 Y0 Z0 F1200\n\
X0.5 Z0.1\nX1 Z0.15\nX1.5 Z0.1\nX2 Z0\nX2.5 Z-0.1\nX3 Z-0.15\nY1\n\
X2.5 Z-0.1\nX2 Z0\nX1.5 Z0.1\nX1 Z0.15\nX0.5 Z0.1\nX0 Z0\nY2\n\
X0.5 Z0.1\nX1 Z0.15\nX1.5 Z0.1\nX2 Z0\nX2.5 Z-0.1\nX3 Z-0.15\nM30\n%\n";

fn plan_within_limits(src: &str, s: &dnurbs_tools::setup::MachineSetup) {
    let program = nc_lang::parse(src).expect("the fixed programs parse");
    let Ok(path) = nc_geom::segment::build(&program, &s.kin, &s.build) else {
        return;
    };
    if !common::short_enough(&path, s) {
        return;
    }
    let Ok(profile) = nc_plan::plan::plan(&path, &s.kin, &s.plan) else {
        return;
    };
    let cfg = &s.plan;
    let sp = nc_plan::fixtures::interpolate(
        &path,
        &profile,
        s.kin,
        cfg,
        nc_plan::interp::Method::ArcLength,
        4_000_000,
    )
    .expect("an accepted plan ends");
    for w in sp.windows(4) {
        let jerk = w.iter().all(|x| x.block == w[0].block);
        if let Err(e) =
            nc_plan::fixtures::axes_within(cfg, cfg.period, [&w[0], &w[1], &w[2], &w[3]], jerk)
        {
            panic!("accepted plan over a limit: {e}");
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(m) = config::from_str(text, std::path::Path::new("fuzz.toml")) {
        let s = dnurbs_tools::setup::MachineSetup::new(&m);
        plan_within_limits(PAPER, &s);
        plan_within_limits(RASTER, &s);
    }
});
