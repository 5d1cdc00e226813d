//! NC program bytes compressed on line, as `dnurbs simulate --compress` and `run --compress`
//! do on the paper's machine: text -> parse -> the compressor (runs of `G01` moves fitted
//! into G06.5 blocks) -> segments -> plan with its setpoint check. A panic, an abort or a
//! hang is a finding, and so is:
//! - a fitted block the compressor says is off its moves by more than the tolerances;
//! - a compressed program that the independent measurement of `dnurbs fit` (dense sampling
//!   of the output against the input polyline) finds off a programmed point by more than
//!   the tolerances, where the program as posted builds and runs up to 500 mm (sampled
//!   every 5 um);
//! - an accepted plan whose own check measured a limit above 100 %.
//!
//! Programs whose plan would take more than 200 000 periods are compressed and built but not
//! planned (as `nc_program`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

mod common;

fn setup() -> &'static dnurbs_tools::setup::MachineSetup {
    static SETUP: OnceLock<dnurbs_tools::setup::MachineSetup> = OnceLock::new();
    SETUP.get_or_init(|| common::paper_machine().with_compress(Some(true)))
}

fuzz_target!(|data: &[u8]| {
    let Some(posted) = common::program(data) else {
        return;
    };
    let s = setup();
    let opts = s.compress.as_ref().expect("compression is on");
    let (program, c) = s.prepare(posted.clone());
    let c = c.expect("compression is on");
    let tol_deg = opts.tol.rad.to_degrees();
    assert!(
        c.fit_mm <= opts.tol.mm && c.fit_deg <= tol_deg * (1.0 + 1e-9),
        "the fit claims {} mm and {} deg",
        c.fit_mm,
        c.fit_deg
    );
    let Ok(path) = nc_geom::segment::build(&program, &s.kin, &s.build) else {
        return;
    };
    if c.fitted_blocks > 0 {
        if let Ok(input) = nc_geom::segment::build(&posted, &s.kin, &s.build) {
            // Sampled every 5 um as `compressed_posts.rs` does, on paths up to 500 mm (100 000
            // samples). Not coarser over a longer path: at 3 mm a sample spans a pass that
            // goes back over itself, and a point was taken on the wrong visit (24 um and
            // 0.024 deg off, where 5 um samples find it on the path).
            let length: f64 = input.segments.iter().map(|x| x.length).sum();
            if length <= 500.0 {
                let h = 0.005;
                let dev = nc_fit::deviation::measure(&input, &path, &s.kin, h, opts.tol.mm);
                assert!(
                    dev.point_mm <= opts.tol.mm + 5e-7 && dev.point_deg <= tol_deg * (1.0 + 1e-3),
                    "measured off the posted program: {dev:?}"
                );
            }
        }
    }
    common::plan_within_limits(&path, s);
});
