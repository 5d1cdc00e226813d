//! `run` and `demo`: the drives, the real-time thread, the report.

use super::{cpu_text, keep_off_rt_cpu, report_dir};
use crate::demo::DemoLink;
use crate::exit::{InputError, Outcome};
use crate::run::{RunOptions, RunResult};
use anyhow::Context;
use std::path::{Path, PathBuf};

/// Print the report of a run (and write it with `--report`); its outcome.
fn finish(
    r: &RunResult,
    report: Option<PathBuf>,
    program: &str,
    machine: &str,
    title: &str,
    period_ns: u64,
) -> anyhow::Result<Outcome> {
    let rep = r.report(program, machine);
    print!("{}", rep.text());
    if let Some(dir) = report {
        rep.write(&dir, &r.stats, title, period_ns)?;
        eprintln!("report: {}", dir.display());
    }
    Ok(crate::report::outcome(r.reason.as_ref(), r.stats.overruns))
}

/// The files a run writes: its report directory, its trace.
pub struct Written {
    pub report: Option<PathBuf>,
    pub trace: Option<PathBuf>,
}

pub fn demo(
    written: Written,
    link: DemoLink,
    rt: rt_loop::thread::RtSettings,
    lead_ns: u64,
    control: Option<PathBuf>,
    program: Option<PathBuf>,
) -> anyhow::Result<Outcome> {
    let Written { report, trace } = written;
    keep_off_rt_cpu(rt)?;
    report_dir(&report)?;
    let name = program
        .as_ref()
        .map_or("paper-example.nc".into(), |p| p.display().to_string());
    if let Some(p) = &program {
        std::fs::metadata(p).map_err(|error| InputError::ReadProgram {
            file: name.clone(),
            error,
        })?;
    }
    let opts = RunOptions {
        name: name.clone(),
        approach: true,
        rt,
        lead_ns,
        rt_fallback: true,
        report: report.clone(),
        progress: true,
        control,
        shop: Default::default(),
        trace,
    };
    let bus = match link {
        DemoLink::Memory => "an in-memory CAN link",
        DemoLink::Socketpair => "a socketpair CAN link",
    };
    let what = match &program {
        Some(_) => name.clone(),
        None => "the paper's example".into(),
    };
    eprintln!(
        "dnurbs demo: {what} on the paper's A/C table machine, 5 simulated \
         CiA-402 drives on {bus}, 2 ms period{}{}",
        lead_text(lead_ns),
        cpu_text(rt)
    );
    let input = match program {
        Some(p) => crate::feed::Input::File(p),
        None => crate::feed::Input::Text(crate::demo::DEMO_PROGRAM.as_bytes().into()),
    };
    let (r, records) = crate::demo::demo(&opts, link, input)?;
    println!("simulated drives received {} targets", records.len());
    let title = if name == "paper-example.nc" {
        "dnurbs demo: paper example, 2 ms".to_string()
    } else {
        format!("dnurbs demo: {name}, 2 ms")
    };
    finish(&r, report, &name, "paper-ac-table", &title, 2_000_000)
}

pub fn run(
    program: &Path,
    machine: &Path,
    written: Written,
    approach: bool,
    no_rt: bool,
    control: Option<PathBuf>,
    shop: &crate::shop::ShopArgs,
) -> anyhow::Result<Outcome> {
    let Written { report, trace } = written;
    let m = crate::load_machine(machine)?;
    if m.interpolation.method != config::Method::Arclength {
        eprintln!(
            "dnurbs run: note: the machine file's method = \"{}\" is for simulate's comparisons; run sends the arclength setpoints, the ones the plan is checked on",
            m.interpolation.method.name()
        );
    }
    // Read a line at a time as it runs (the planner thread opens it; a FIFO is read once):
    // a program that is not there is exit 2 before anything else.
    std::fs::metadata(program).map_err(|error| InputError::ReadProgram {
        file: program.display().to_string(),
        error,
    })?;
    let open_links = || -> anyhow::Result<Vec<drives::link::SocketLink>> {
        let mut links = Vec::new();
        for b in &m.buses {
            links.push(
                drives::link::SocketLink::open(&b.interface).with_context(|| {
                    format!(
                        "cannot open CAN interface {:?} (bus {:?}); is it up? \
                         `ip link set {} up type can bitrate {}`",
                        b.interface, b.name, b.interface, b.bitrate
                    )
                })?,
            );
        }
        Ok(links)
    };
    let opts = RunOptions {
        name: program.display().to_string(),
        approach,
        rt: rt_loop::thread::RtSettings {
            priority: (!no_rt).then_some(m.realtime.priority),
            cpu: m.realtime.cpu,
            idle_poll: m.realtime.idle_poll,
        },
        lead_ns: (m.realtime.lead_s * 1e9).round() as u64,
        rt_fallback: false,
        report: report.clone(),
        progress: true,
        control: control.or_else(|| m.control_socket.clone()),
        shop: shop.load()?,
        trace,
    };
    keep_off_rt_cpu(opts.rt)?;
    eprintln!(
        "dnurbs run: {} on {} ({} drives, {} ms period{}{})",
        program.display(),
        m.name,
        m.drives.len(),
        m.period_s * 1000.0,
        lead_text(opts.lead_ns),
        cpu_text(opts.rt)
    );
    if m.interpolation.method != config::Method::Arclength {
        eprintln!(
            "dnurbs run: note: the real-time interpolator uses the arclength method; \
             [interpolation] method = \"{}\" applies to simulate and compare",
            m.interpolation.method
        );
    }
    report_dir(&report)?;
    let input = crate::feed::Input::File(program.to_path_buf());
    let r = crate::run::run_input(input, &m, open_links, &opts)?;
    let name = program.display().to_string();
    let title = format!("dnurbs run: {name} on {}", m.name);
    finish(
        &r,
        report,
        &name,
        &m.name,
        &title,
        (m.period_s * 1e9).round() as u64,
    )
}

/// ", 60 µs lead" or nothing.
fn lead_text(lead_ns: u64) -> String {
    if lead_ns == 0 {
        return String::new();
    }
    format!(", {} µs lead", lead_ns as f64 / 1e3)
}
