//! `dnurbs simulate PROGRAM --machine FILE --operator SCRIPT`: the program through the
//! real-time thread's follower with the script's pauses, resumes, stops and overrides
//! (`crate::simulate::operator`), every setpoint checked against every axis's limits.

use crate::exit::{InputError, Outcome};
use crate::setup::MachineSetup;
use crate::shop::{parse_setup, ShopArgs};
use crate::simulate::operator::{replay, Replay};
use crate::simulate::script::{self, Act, When};
use crate::simulate::{write_trace_header, write_trace_row};
use crate::{load_machine, load_program};
use anyhow::Context;
use nc_plan::stream::ProgramEntries;
use std::io::Write;
use std::path::{Path, PathBuf};

pub fn simulate_operator(
    program: &Path,
    machine: &Path,
    script_file: &Path,
    trace: Option<PathBuf>,
    json: bool,
    shop: &ShopArgs,
) -> anyhow::Result<Outcome> {
    let text = std::fs::read_to_string(script_file)
        .with_context(|| format!("{}: cannot read the operator script", script_file.display()))?;
    let script = script::parse(&text)
        .map_err(|e| InputError::MachineUse(format!("{}: {e}", script_file.display())))?;
    let m = load_machine(machine)?;
    let shop = shop.load()?;
    let parse = parse_setup(&m, &shop)?;
    let setup = MachineSetup::new(&m).with_compress(shop.compress);
    let prog = load_program(program, &parse)?;
    let name = program.display().to_string();
    let mut w = match &trace {
        Some(file) => {
            let f = std::fs::File::create(file)
                .with_context(|| format!("{}: cannot create the trace", file.display()))?;
            let mut w = std::io::BufWriter::new(f);
            write_trace_header(&mut w)?;
            Some(w)
        }
        None => None,
    };
    let mut written = Ok(());
    let r = replay(
        ProgramEntries::new(prog),
        &setup,
        m.realtime.queue_depth,
        &script,
        |sp| {
            if let (Some(w), Ok(())) = (w.as_mut(), &written) {
                written = write_trace_row(w, sp);
            }
        },
    )
    .map_err(|e| InputError::stream(&name, e))?;
    if let (Some(file), Some(mut w)) = (&trace, w) {
        written
            .and_then(|_| w.flush())
            .with_context(|| format!("{}: cannot write the trace", file.display()))?;
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print!("{}", text_of(&r, &setup, script_file));
    }
    if !r.over.is_empty() || !r.outside_travel.is_empty() {
        eprintln!(
            "dnurbs simulate: {name}: setpoints over an axis limit under the operator's actions"
        );
        return Ok(Outcome::OverLimits);
    }
    if r.refusal.is_some() {
        return Ok(Outcome::StoppedByProgram);
    }
    Ok(Outcome::Completed)
}

fn text_of(r: &Replay, setup: &MachineSetup, script_file: &Path) -> String {
    let mut s = format!(
        "operator script    {}: {} actions taken, {} not reached\n",
        script_file.display(),
        r.taken.len(),
        r.not_taken
    );
    for t in &r.taken {
        let when = match t.action.when {
            When::At(at) => format!("at {at}s"),
            When::After(dt) => format!("after {dt}s"),
            When::Line(n) => format!("at line {n}"),
        };
        let act = match t.action.act {
            Act::Pause => "pause".to_owned(),
            Act::Resume => "resume".to_owned(),
            Act::Stop => "stop".to_owned(),
            Act::Override(p) => format!("override {p} %"),
        };
        s += &format!(
            "  {:>9.3} s  line {:<5} {act} (script line {}: {when})\n",
            t.t_s, t.at_line, t.action.line
        );
    }
    s += &format!(
        "machine            {}\nperiods            {} x {} ms = {:.3} s\n",
        setup.name,
        r.periods,
        setup.period * 1e3,
        r.time_s
    );
    let ending = match r.ending {
        "end" => "the program's end".to_owned(),
        "stopped" => format!("stopped along the path at line {}", r.line),
        "paused" => format!("paused at line {} (the script has nothing more)", r.line),
        "refused" => format!(
            "refused ahead of the tool, stopped along the path at line {}: {}",
            r.line,
            r.refusal.as_deref().unwrap_or("")
        ),
        other => other.to_owned(),
    };
    s += &format!("ended              {ending}\n");
    let fractions = |f: &[f64; 5]| -> String {
        (0..5)
            .map(|j| format!("{} {:.1}%", setup.axis_names[j], f[j] * 100.0))
            .collect::<Vec<_>>()
            .join("  ")
    };
    s += &format!(
        "axis velocity      {}  (of limit, from the setpoints)\n",
        fractions(&r.velocity_fraction)
    );
    s += &format!(
        "axis acceleration  {}  (of limit, from the setpoints)\n",
        fractions(&r.acceleration_fraction)
    );
    s += &format!(
        "axis jerk          {}  (of limit, from the setpoints, inside segments)\n",
        fractions(&r.jerk_fraction)
    );
    if r.outside_travel.is_empty() {
        s += "axis travel        within limits\n";
    } else {
        s += &format!(
            "axis travel        LEFT by {}\n",
            r.outside_travel.join(", ")
        );
    }
    if r.over.is_empty() {
        s += "limits             axis velocity, acceleration and jerk within limits, holds and overrides included\n";
    } else {
        let each: Vec<String> = r
            .over
            .iter()
            .map(|o| {
                format!(
                    "{} {} {:.1}% at {:.3} s (line {})",
                    o.axis,
                    o.quantity,
                    o.fraction * 100.0,
                    o.t_s,
                    o.line
                )
            })
            .collect();
        s += &format!("limits             EXCEEDED: {}\n", each.join("; "));
    }
    s
}
