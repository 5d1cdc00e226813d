//! NC program bytes -> the interpreter and the modal state machine (`nc_lang::parse_with`),
//! with the reference position set so that programs without a full first pose run too. A
//! panic, an abort, a hang or unbounded memory is a finding: parameters, expressions nested
//! deep or long, loops that never end (refused at the budget of lines run again, here 10 000),
//! recursion (refused at 9 calls deep), subroutines read ahead to, `%` and the end.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

fn setup() -> &'static nc_lang::Setup {
    static SETUP: OnceLock<nc_lang::Setup> = OnceLock::new();
    SETUP.get_or_init(|| nc_lang::Setup {
        reference: Some([0.0, 0.0, 100.0]),
        max_loop_lines: 10_000,
        ..nc_lang::Setup::default()
    })
}

fuzz_target!(|data: &[u8]| {
    if data.len() > 4096 {
        return;
    }
    let Ok(text) = dnurbs_tools::program_text(data) else {
        return;
    };
    let _ = nc_lang::parse_with(text, setup());
});
