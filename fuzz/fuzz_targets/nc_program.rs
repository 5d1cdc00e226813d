//! NC program bytes -> text (UTF-8, BOM) -> parse -> segments -> plan with its setpoint
//! check, on the paper's machine, exactly as `dnurbs simulate` and `dnurbs run` do. A panic,
//! an abort or a hang is a finding; so is an accepted plan whose own check measured a limit
//! above 100 %. Programs whose plan would take more than 200 000 periods (400 s) are parsed
//! and built but not planned, to keep the fuzzer's throughput (counted by nothing: the
//! generated-input suite covers long plans).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

fn setup() -> &'static dnurbs_tools::setup::MachineSetup {
    static SETUP: OnceLock<dnurbs_tools::setup::MachineSetup> = OnceLock::new();
    SETUP.get_or_init(|| {
        let text = include_str!("../../config/machines/paper-ac-table.toml");
        let m = config::from_str(text, std::path::Path::new("paper-ac-table.toml"))
            .expect("the shipped machine file is valid");
        dnurbs_tools::setup::MachineSetup::new(&m)
    })
}

fuzz_target!(|data: &[u8]| {
    if data.len() > 4096 {
        return;
    }
    let Ok(text) = dnurbs_tools::program_text(data) else {
        return;
    };
    let Ok(program) = nc::parse::parse(text) else {
        return;
    };
    let s = setup();
    let Ok(path) = nc::segment::build(&program, &s.kin, &s.build) else {
        return;
    };
    let periods: f64 = path
        .segments
        .iter()
        .map(|seg| seg.length / seg.feed.max(1e-3) / s.period)
        .sum();
    if !(periods <= 200_000.0) {
        return;
    }
    if let Ok(profile) = nc::plan::plan(&path, &s.kin, &s.plan) {
        let m = profile.margins;
        let worst = (0..5)
            .map(|j| m.velocity[j].max(m.acceleration[j]).max(m.jerk[j]))
            .fold(m.chord, f64::max);
        assert!(worst <= 1.0 + 1e-9, "accepted plan at {worst}x a limit");
    }
});
