//! What the NC fuzz targets share: the paper's machine, the input bound and parse, and the
//! plan of a built path with its setpoint check.

/// The shipped paper machine, set up as `simulate` and `run` set it up.
pub fn paper_machine() -> dnurbs_tools::setup::MachineSetup {
    let text = include_str!("../../config/machines/paper-ac-table.toml");
    let m = config::from_str(text, std::path::Path::new("paper-ac-table.toml"))
        .expect("the shipped machine file is valid");
    dnurbs_tools::setup::MachineSetup::new(&m)
}

/// The program in `data` (up to 4 KB), if its text parses.
pub fn program(data: &[u8]) -> Option<nc::program::Program> {
    if data.len() > 4096 {
        return None;
    }
    let text = dnurbs_tools::program_text(data).ok()?;
    nc::parse::parse(text).ok()
}

/// Plan `path` as `simulate` and `run` do, unless its plan would take more than 200 000
/// periods (400 s; kept out for the fuzzer's rate, the generated-input suite covers long
/// plans); an accepted plan whose own check measured a limit above 100 % is a finding.
pub fn plan_within_limits(path: &nc::segment::Path, s: &dnurbs_tools::setup::MachineSetup) {
    let periods: f64 = path
        .segments
        .iter()
        .map(|seg| seg.length / seg.feed.max(1e-3) / s.period)
        .sum();
    if !(periods <= 200_000.0) {
        return;
    }
    if let Ok(profile) = nc::plan::plan(path, &s.kin, &s.plan) {
        let m = profile.margins;
        let worst = (0..5)
            .map(|j| m.velocity[j].max(m.acceleration[j]).max(m.jerk[j]))
            .fold(m.chord, f64::max);
        assert!(worst <= 1.0 + 1e-9, "accepted plan at {worst}x a limit");
    }
}
