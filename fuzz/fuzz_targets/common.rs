//! What the fuzz targets share: the paper's machine, the input bound and parse, the bound
//! on the plans made, and the plan of a built path with its setpoint check. (Each target
//! uses part of it.)
#![allow(dead_code)]

/// The shipped paper machine, set up as `simulate` and `run` set it up.
pub fn paper_machine() -> dnurbs_tools::setup::MachineSetup {
    let text = include_str!("../../config/machines/paper-ac-table.toml");
    let m = config::from_str(text, std::path::Path::new("paper-ac-table.toml"))
        .expect("the shipped machine file is valid");
    dnurbs_tools::setup::MachineSetup::new(&m)
}

/// The program in `data` (up to 4 KB), if its text parses.
pub fn program(data: &[u8]) -> Option<nc_geom::program::Program> {
    if data.len() > 4096 {
        return None;
    }
    let text = dnurbs_tools::program_text(data).ok()?;
    nc_lang::parse(text).ok()
}

/// Whether `path` is short enough to plan for the fuzzer's rate: at most 200 000 periods
/// (400 s at 2 ms) at its programmed feeds (the generated-input suite covers long plans).
pub fn short_enough(path: &nc_geom::segment::Path, s: &dnurbs_tools::setup::MachineSetup) -> bool {
    let periods: f64 = path
        .segments
        .iter()
        .map(|seg| seg.length / seg.feed.max(1e-3) / s.period)
        .sum();
    periods <= 200_000.0
}

/// Plan `path` as `simulate` and `run` do, if it is [`short_enough`]; an accepted plan
/// whose own check measured a limit above 100 % is a finding.
pub fn plan_within_limits(path: &nc_geom::segment::Path, s: &dnurbs_tools::setup::MachineSetup) {
    if !short_enough(path, s) {
        return;
    }
    if let Ok(profile) = nc_plan::plan::plan(path, &s.kin, &s.plan) {
        let m = profile.margins;
        let worst = (0..5)
            .map(|j| m.velocity[j].max(m.acceleration[j]).max(m.jerk[j]))
            .fold(m.chord, f64::max);
        assert!(worst <= 1.0 + 1e-9, "accepted plan at {worst}x a limit");
    }
}
