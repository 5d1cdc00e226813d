//! `simulate`, `compare` and `busload`: the machine file and programs, no bus, no real time.

use crate::exit::{InputError, Outcome};
use crate::setup::MachineSetup;
use crate::shop::{parse_setup, ShopArgs};
use crate::simulate::{
    roll, run, summarize, write_trace_header, write_trace_row, Rolled, Summarizer,
};
use crate::words::Noted;
use crate::{load_machine, load_program};
use anyhow::Context;
use nc_geom::setpoint::Setpoint;
use nc_lang::{Entries, ReadLines};
use nc_plan::interp::Method;
use nc_plan::plan::ProgramError;
use nc_plan::rolling::{Unrolled, Window};
use nc_plan::stream::ProgramEntries;
use std::io::Write;
use std::path::{Path, PathBuf};

pub fn simulate(
    program: &Path,
    machine: &Path,
    method: Option<Method>,
    trace: Option<PathBuf>,
    json: bool,
    from_line: Option<(u32, f64)>,
    shop: &ShopArgs,
) -> anyhow::Result<Outcome> {
    let machine = load_machine(machine)?;
    if let Err(e) = machine.check_bus_load() {
        eprintln!("dnurbs simulate: warning (simulate uses no bus; run would refuse): {e}");
    }
    let shop = shop.load()?;
    let parse = parse_setup(&machine, &shop)?;
    let setup = MachineSetup::new(&machine).with_compress(shop.compress);
    let method = method.unwrap_or(setup.method);
    let name = program.display().to_string();
    // The setpoints go to the summary (and the trace) as they are made: none is kept.
    let trace_file = trace.clone();
    let mut trace = match &trace {
        Some(file) => {
            let f = std::fs::File::create(file)
                .with_context(|| format!("{}: cannot create the trace", file.display()))?;
            let mut w = std::io::BufWriter::new(f);
            write_trace_header(&mut w)
                .with_context(|| format!("{}: cannot write the trace", file.display()))?;
            Some((file, w, Ok(())))
        }
        None => None,
    };
    let mut summarizer = Summarizer::new(&setup);
    let take = |sp: &Setpoint, w: Window| {
        summarizer.push(sp, w);
        if let Some((_, w, result @ Ok(()))) = &mut trace {
            *result = write_trace_row(w, sp);
        }
    };
    let step = crate::simulate::stepping(&setup, method);
    // A refused program leaves no trace: what was simulated before the error is not the
    // program's (nothing is silently cut short).
    let discard = || {
        if let Some(file) = &trace_file {
            let _ = std::fs::remove_file(file);
        }
    };
    let refused = |e: Unrolled| {
        discard();
        match e {
            Unrolled::Stream(e) => InputError::stream(&name, e),
            Unrolled::Unfinished(n) => InputError::program(program, ProgramError::Unfinished(n)),
        }
    };
    // A program of at most CHECK_WHOLE_BYTES is parsed whole first, so that every syntax
    // error in it is listed; a longer one is read a line at a time. Either way it is
    // compressed (when that is on), built, planned and interpolated as it is read.
    let size = std::fs::metadata(program).map_or(0, |m| m.len());
    let mut restarted = None;
    let (rolled, words) = if let Some((line, clearance)) = from_line {
        // A restart reads the whole program first, whatever its length.
        let prog = load_program(program, &parse).inspect_err(|_| discard())?;
        let (prog, note) =
            crate::simulate::restart::restart(&prog, program, line, clearance, &setup)
                .inspect_err(|_| discard())?;
        restarted = Some(note);
        let words = crate::words::describe(&prog);
        let rolled = roll(ProgramEntries::new(prog), &setup, step, take).map_err(refused)?;
        (rolled, words)
    } else if size <= crate::feed::CHECK_WHOLE_BYTES {
        let prog = load_program(program, &parse).inspect_err(|_| discard())?;
        let words = crate::words::describe(&prog);
        let rolled = roll(ProgramEntries::new(prog), &setup, step, take).map_err(refused)?;
        (rolled, words)
    } else {
        let f = std::fs::File::open(program).map_err(|error| {
            discard();
            InputError::ReadProgram {
                file: name.clone(),
                error,
            }
        })?;
        let lines = ReadLines::new(std::io::BufReader::with_capacity(1 << 16, f));
        let mut words = Vec::new();
        let entries = Noted::new(Entries::new(lines, &parse), &mut words);
        let rolled = roll(entries, &setup, step, take).map_err(refused)?;
        (rolled, words)
    };
    if let Some((file, mut w, result)) = trace {
        result
            .and_then(|_| w.flush())
            .with_context(|| format!("{}: cannot write the trace", file.display()))?;
    }
    let Rolled {
        rolling,
        plan,
        blocks,
        compressed,
    } = rolled;
    let spindle_waits = machine
        .spindle
        .as_ref()
        .map(|s| summarizer.spindle_waits(s.acceleration_rpm_s));
    let mut summary = summarizer.finish(&plan, rolling.last_segment(), method, blocks);
    summary.program_words = words;
    summary.compressed = compressed.map(crate::simulate::Compression::from);
    summary.spindle_waits = spindle_waits;
    summary.restart = restarted;
    if json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print!("{}", summary.text());
    }
    if summary.limits_exceeded.is_empty() {
        return Ok(Outcome::Completed);
    }
    // Never reported as a success: the plan is checked on the arclength setpoints.
    if method == Method::ArcLength {
        anyhow::bail!(
            "{name}: the arclength setpoints exceed an axis limit the plan was checked against: a planner fault, please report it"
        );
    }
    eprintln!(
        "dnurbs simulate: {name}: the {} setpoints exceed an axis limit ({}): the Taylor methods are comparisons and hold no limit; `run` sends the arclength setpoints (--method arclength, or the machine file's method = \"arclength\")",
        method.name(),
        summary.limits_brief()
    );
    Ok(Outcome::OverLimits)
}

pub fn compare(programs: &[PathBuf], machine: &Path, shop: &ShopArgs) -> anyhow::Result<Outcome> {
    let machine = load_machine(machine)?;
    let shop = shop.load()?;
    let parse = parse_setup(&machine, &shop)?;
    let setup = MachineSetup::new(&machine).with_compress(shop.compress);
    println!(
        "| program | method | feed fluctuation max | feed fluctuation rms | chord error max (mm) | cycles | axis limits |"
    );
    println!("|---|---|---|---|---|---|---|");
    for program in programs {
        let (prog, _) = setup.prepare(load_program(program, &parse)?);
        let name = program.file_name().map_or_else(
            || program.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        for method in [Method::Taylor1, Method::Taylor2, Method::ArcLength] {
            let result = run(&prog, &setup, method).map_err(|e| InputError::program(program, e))?;
            let s = summarize(&result, &setup, prog.blocks.len());
            println!(
                "| {name} | {} | {:.2e} | {:.2e} | {:.2e} | {} | {} |",
                s.method,
                s.feed_fluctuation_max,
                s.feed_fluctuation_rms,
                s.chord_error_max_mm,
                s.cycles,
                s.limits_brief()
            );
        }
    }
    Ok(Outcome::Completed)
}

/// Print each bus's load; a bus over its max_load is then an input error (exit 2).
pub fn busload(machine: &Path) -> anyhow::Result<Outcome> {
    let m = load_machine(machine)?;
    if m.buses.is_empty() {
        println!(
            "{}: no [[bus]] tables: the machine has no drives",
            machine.display()
        );
        return Ok(Outcome::Completed);
    }
    println!("period {} ms", m.period_s * 1e3);
    for (i, b) in m.buses.iter().enumerate() {
        let drives: Vec<String> = m
            .drives
            .iter()
            .filter(|d| d.bus == i)
            .map(|d| format!("{}=node {}", m.axes.all()[d.axis].0, d.node))
            .collect();
        let mut drives = drives;
        if let Some(node) = m.spindle.as_ref().and_then(|s| s.on_bus(i)) {
            drives.push(format!("spindle=node {node}"));
        }
        if let Some(node) = m.coolant.as_ref().and_then(|c| c.on_bus(i)) {
            drives.push(format!("coolant I/O=node {node}"));
        }
        let n = m.bus_nodes(i);
        println!(
            "bus {} ({}, {} bit/s): {} drives{} [{}]: {} bits per cycle, load {:.2} % (max {:.0} %)",
            b.name,
            b.interface,
            b.bitrate,
            n.drives,
            if n.io > 0 { " + 1 I/O module" } else { "" },
            drives.join(", "),
            config::bus::cycle_bits(n),
            config::bus::load(n, b.bitrate, m.period_s) * 100.0,
            b.max_load * 100.0
        );
    }
    crate::check_bus_load(&m)?;
    Ok(Outcome::Completed)
}
