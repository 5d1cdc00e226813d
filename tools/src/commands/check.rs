//! `check`: the pre-pass alone ([`nc_plan::prepass`]): the program read as a stream, in the
//! memory of one line, checked for syntax, geometry and the travel at every programmed
//! point; nothing planned, nothing moved.

use crate::exit::{InputError, Outcome};
use crate::load_machine;
use crate::setup::MachineSetup;
use crate::shop::{parse_setup, ShopArgs};
use nc_lang::ReadLines;
use nc_plan::prepass::Refused;
use std::path::Path;

pub fn check(
    program: &Path,
    machine: &Path,
    json: bool,
    shop: &ShopArgs,
) -> anyhow::Result<Outcome> {
    let machine = load_machine(machine)?;
    let shop = shop.load()?;
    let parse = parse_setup(&machine, &shop)?;
    let setup = MachineSetup::new(&machine);
    let file = program.display().to_string();
    let reader = std::fs::File::open(program).map_err(|error| InputError::ReadProgram {
        file: file.clone(),
        error,
    })?;
    let clock = std::time::Instant::now();
    let lines = ReadLines::new(std::io::BufReader::with_capacity(1 << 16, reader));
    let passed =
        nc_plan::prepass::check(lines, &parse, &setup.kin, &setup.build, &setup.plan.travel)
            .map_err(|e| match e {
                Refused::Parse(errors) => InputError::Parse {
                    file: file.clone(),
                    errors,
                },
                other => InputError::Checked {
                    file: file.clone(),
                    error: other,
                },
            })?;
    let secs = clock.elapsed().as_secs_f64();
    let rate = f64::from(passed.lines) / secs.max(1e-9);
    if json {
        let out = serde_json::json!({
            "program": file,
            "machine": setup.name,
            "lines": passed.lines,
            "blocks": passed.blocks,
            "segments": passed.segments,
            "path_length": passed.length,
            "seconds": secs,
            "lines_per_s": rate,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!(
            "{file}: {} lines, {} motion blocks, {} segments, path {:.3} mm on {}",
            passed.lines, passed.blocks, passed.segments, passed.length, setup.name
        );
        println!("syntax, geometry and the travel at every programmed point: ok");
        println!("not checked here: feeds, and the path between programmed points, against the axis limits (`dnurbs simulate` plans them)");
        println!("read in {secs:.3} s: {rate:.0} lines/s");
    }
    Ok(Outcome::Completed)
}
