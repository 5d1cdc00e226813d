//! NC program bytes -> text (UTF-8, BOM) -> parse -> segments -> plan with its setpoint
//! check, on the paper's machine, exactly as `dnurbs simulate` and `dnurbs run` do. A panic,
//! an abort or a hang is a finding; so is an accepted plan whose own check measured a limit
//! above 100 %. Programs whose plan would take more than 200 000 periods (400 s) are parsed
//! and built but not planned, to keep the fuzzer's throughput (counted by nothing: the
//! generated-input suite covers long plans).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

mod common;

fn setup() -> &'static dnurbs_tools::setup::MachineSetup {
    static SETUP: OnceLock<dnurbs_tools::setup::MachineSetup> = OnceLock::new();
    SETUP.get_or_init(common::paper_machine)
}

fuzz_target!(|data: &[u8]| {
    let Some(program) = common::program(data) else {
        return;
    };
    let s = setup();
    let Ok(path) = nc_geom::segment::build(&program, &s.kin, &s.build) else {
        return;
    };
    common::plan_within_limits(&path, s);
});
