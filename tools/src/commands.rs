//! The subcommands' bodies. Each returns the [`Outcome`] of what it ran, or an error whose
//! kind picks the exit code ([`crate::exit`]).
//!
//! * [`offline`]: `simulate`, `compare`, `busload` (no bus, no real time);
//! * [`check`]: `check` (the pre-pass alone);
//! * [`fit`]: `fit` (G01 runs into G06.5 blocks);
//! * [`machine`]: `run` and `demo` (drives, real-time thread, report);
//! * [`latency`]: `latency` (the real-time loop alone);
//! * [`ctl`]: `ctl` (the client of a run's control socket).

pub mod check;
pub mod ctl;
pub mod fit;
pub mod latency;
pub mod machine;
pub mod offline;
pub mod operator;

use crate::cli::{Command, MethodArg};
use crate::exit::Outcome;
use crate::simdrives;

/// Run one subcommand.
pub fn dispatch(command: Command) -> anyhow::Result<Outcome> {
    match command {
        Command::Demo {
            report,
            no_rt,
            link,
            cpu,
            lead,
            control,
            program,
            trace,
        } => machine::demo(
            machine::Written { report, trace },
            link,
            cpu.settings((!no_rt).then_some(80)),
            lead,
            control,
            program,
        ),
        Command::Run {
            program,
            machine,
            report,
            approach,
            no_rt,
            control,
            trace,
            shop,
        } => machine::run(
            &program,
            &machine,
            machine::Written { report, trace },
            approach,
            no_rt,
            control,
            &shop,
        ),
        Command::Ctl { socket, command } => ctl::ctl(&socket, command),
        Command::Serve(args) => {
            crate::serve::process::serve(args.options()?)?;
            Ok(crate::exit::Outcome::Completed)
        }
        Command::Simulate {
            program,
            machine,
            method: _,
            trace,
            json,
            operator: Some(script),
            shop,
            ..
        } => operator::simulate_operator(&program, &machine, &script, trace, json, &shop),
        Command::Simulate {
            program,
            machine,
            method,
            trace,
            json,
            operator: None,
            from_line,
            clearance,
            shop,
        } => offline::simulate(
            &program,
            &machine,
            method.map(method_of),
            trace,
            json,
            from_line.map(|line| (line, clearance)),
            &shop,
        ),
        Command::Check {
            program,
            machine,
            json,
            shop,
        } => check::check(&program, &machine, json, &shop),
        Command::Compare {
            programs,
            machine,
            shop,
        } => offline::compare(&programs, &machine, &shop),
        Command::Busload { machine } => offline::busload(&machine),
        Command::Fit {
            program,
            machine,
            output,
            tol_mm,
            tol_deg,
            corner_deg,
            json,
            tools,
        } => fit::fit(
            &program,
            &machine,
            output.as_deref(),
            fit::Tolerances {
                mm: tol_mm,
                deg: tol_deg,
                corner_deg,
            },
            json,
            tools,
        ),
        Command::Latency {
            period,
            duration,
            priority,
            cpu,
            no_rt,
            report,
        } => latency::latency(
            period,
            duration,
            cpu.settings((!no_rt).then_some(priority)),
            report,
        ),
        Command::SimDrives {
            iface,
            machine,
            record,
            lag,
            duration,
            fault_at,
            heartbeat_stops,
            never_boots,
            drop_every,
            silent_from,
            no_home_switch,
        } => {
            let machine = crate::load_machine(&machine)?;
            simdrives::run(simdrives::SimArgs {
                iface,
                machine,
                record,
                lag_ns: lag,
                duration_ns: duration,
                faults: simdrives::FaultArgs {
                    fault_at,
                    heartbeat_stops,
                    never_boots,
                    drop_every,
                    silent_from,
                    no_home_switch,
                },
            })?;
            Ok(Outcome::Completed)
        }
    }
}

fn method_of(m: MethodArg) -> nc_plan::interp::Method {
    match m {
        MethodArg::Arclength => nc_plan::interp::Method::ArcLength,
        MethodArg::Taylor1 => nc_plan::interp::Method::Taylor1,
        MethodArg::Taylor2 => nc_plan::interp::Method::Taylor2,
    }
}

/// With a real-time CPU: this thread, and every thread it starts from now on, stays off it.
fn keep_off_rt_cpu(rt: rt_loop::thread::RtSettings) -> anyhow::Result<()> {
    if let Some(cpu) = rt.cpu {
        rt_loop::os::avoid_cpu(cpu)?;
    }
    Ok(())
}

/// ", real-time thread on CPU n (idle polled)" or nothing.
fn cpu_text(rt: rt_loop::thread::RtSettings) -> String {
    match rt.cpu {
        Some(c) if rt.idle_poll => format!(", real-time thread on CPU {c} (idle polled)"),
        Some(c) => format!(", real-time thread on CPU {c}"),
        None => String::new(),
    }
}

/// Create the report directory.
fn report_dir(dir: &Option<std::path::PathBuf>) -> anyhow::Result<()> {
    use anyhow::Context;
    if let Some(d) = dir {
        std::fs::create_dir_all(d).with_context(|| format!("{}: cannot create", d.display()))?;
    }
    Ok(())
}
