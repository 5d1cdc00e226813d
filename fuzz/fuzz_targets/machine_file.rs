//! Machine file bytes -> TOML -> validated machine -> the planner's set-up, as every
//! `dnurbs` command loads it. A panic, an abort or a hang is a finding.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(m) = config::from_str(text, std::path::Path::new("fuzz.toml")) {
        let _ = dnurbs_tools::setup::MachineSetup::new(&m);
    }
});
