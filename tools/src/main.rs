//! `dnurbs`: real-time 5-axis double-NURBS interpolation.

use clap::{Parser, Subcommand, ValueEnum};
use dnurbs_tools::run::DemoLink;
use dnurbs_tools::simdrives;
use dnurbs_tools::simulate::{run, summarize, write_trace};
use dnurbs_tools::{load_machine, load_program, setup::MachineSetup, InputError};
use nc::interp::Method;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "dnurbs",
    version,
    about = "Real-time 5-axis double-NURBS interpolation (Wang et al. 2007)",
    long_about = "Real-time 5-axis double-NURBS interpolation (Wang et al. 2007).\n\n\
        An NC program (G01 5-axis lines, G06.2 NURBS, G06.5 double NURBS) is parsed, planned \
        with jerk-limited look-ahead and interpolated period by period into X Y Z A C setpoints.\n\n\
        Exit codes: 0 success, 1 failure writing output, 2 bad program or machine file."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum MethodArg {
    /// Advance the cutter by the commanded arc length each period (arc-length table + Newton).
    Arclength,
    /// Paper eq. 9: first-order Taylor update of u.
    Taylor1,
    /// Paper eq. 10 with the feed-acceleration term: second-order Taylor update of u.
    Taylor2,
}

#[derive(Subcommand)]
enum Command {
    /// The main job on built-in defaults: the paper's example program on the paper's machine,
    /// its five CiA-402 drives simulated on an in-process CAN link (no hardware, no root).
    /// The real-time thread runs with SCHED_FIFO and locked memory when the privileges allow,
    /// without them otherwise (said in the output). Prints the latency report.
    Demo {
        /// Write summary.txt, summary.json, latency.hlog and latency.svg into this directory.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
        /// Do not even try SCHED_FIFO and mlockall.
        #[arg(long)]
        no_rt: bool,
        /// The in-process bus between the master and the simulated drives: `memory` (lock-free
        /// queues, no system call per frame) or `socketpair` (a kernel socket carrying
        /// can_frame structs through the same socketcan calls as a CAN interface).
        #[arg(long, value_enum, default_value_t = DemoLink::Memory)]
        link: DemoLink,
        #[command(flatten)]
        cpu: CpuArgs,
        /// Wake this long before each 2 ms deadline: rehearse the interpolation step (warm
        /// caches), compute it in a quiet moment, wait on the clock and send the frames at the
        /// deadline. Costs the lead in CPU time per period. 0 sleeps to the deadline and
        /// computes after it. At most 1ms.
        #[arg(long, default_value = "60us", value_parser = parse_lead_ns)]
        lead: u64,
    },
    /// Run a program on the machine: set up the drives on the machine file's CAN interfaces
    /// (SDO, PDO mapping, NMT start), enable them (CiA-402), interpolate in the real-time
    /// thread while a planner thread streams planned segments, disable, print the latency
    /// report.
    ///
    /// The axes must be at the program's start pose (its first block) unless --approach is
    /// given. SIGINT (Ctrl-C) or SIGTERM stops along the path, then disables the drives.
    /// A drive fault quick-stops and disables every drive and names the node and the cause.
    /// Real-time settings come from the machine file's [realtime] section.
    ///
    /// Exit codes: 0 program completed, 1 stopped early or failed, 2 bad program or machine.
    Run {
        /// NC program.
        program: PathBuf,
        /// Machine file (TOML) with [[bus]] and [axes.*.drive].
        #[arg(long, short)]
        machine: PathBuf,
        /// Write summary.txt, summary.json, latency.hlog and latency.svg into this directory.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
        /// Before the program, move all axes from where the drives are to the program's start
        /// in one jerk-limited straight move in axis space (mind the fixtures).
        #[arg(long)]
        approach: bool,
        /// Run without mlockall and SCHED_FIFO (development machines; timing not guaranteed).
        #[arg(long)]
        no_rt: bool,
    },
    /// Run the interpolator offline, period by period, exactly as the real-time thread does,
    /// and report feed fluctuation, chord error and axis loads.
    Simulate {
        /// NC program (G-code with G01 / G06.2 / G06.5 blocks).
        program: PathBuf,
        /// Machine file (TOML), e.g. config/machines/paper-ac-table.toml.
        #[arg(long, short)]
        machine: PathBuf,
        /// Parameter update method [default: the machine file's, else arclength].
        #[arg(long, value_enum)]
        method: Option<MethodArg>,
        /// Write one CSV row per period:
        /// cycle,t,block,u,x,y,z,i,j,k,feed,X,Y,Z,A,C (mm, mm/min, degrees).
        #[arg(long, value_name = "OUT.csv")]
        trace: Option<PathBuf>,
        /// Print the summary as one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Play every drive of the machine's bus on a CAN interface: boot-up, NMT slave, SDO
    /// server, PDO mapping, CiA-402 state machine, CSP motor model, heartbeats. For tests
    /// and demonstrations without hardware; stop it with Ctrl-C.
    SimDrives {
        /// CAN interface, e.g. vcan0 (`ip link add dev vcan0 type vcan`).
        #[arg(long)]
        iface: String,
        /// Machine file whose [[bus]] on this interface (or only bus) lists the drives.
        #[arg(long, short)]
        machine: PathBuf,
        /// Write every target received: CSV sync,node,target_counts,actual_counts,statusword.
        #[arg(long, value_name = "FILE.csv")]
        record: Option<PathBuf>,
        /// Motor lag: time constant of the actual position following the target, ms.
        #[arg(long, default_value_t = 0.0)]
        lag_ms: f64,
        /// Exit after this many seconds (default: run until stopped).
        #[arg(long)]
        duration: Option<f64>,
        /// Drive fault (EMCY 0x8611, statusword Fault) on NODE at SYNC count N.
        #[arg(long, value_name = "NODE:N", value_parser = simdrives::node_value::<u64>)]
        fault_at: Vec<(u8, u64)>,
        /// NODE stops sending heartbeats after SYNC count N.
        #[arg(long, value_name = "NODE:N", value_parser = simdrives::node_value::<u64>)]
        heartbeat_stops: Vec<(u8, u64)>,
        /// NODE never boots: silent from power-on.
        #[arg(long, value_name = "NODE")]
        never_boots: Vec<u8>,
        /// NODE drops every N-th frame it sends.
        #[arg(long, value_name = "NODE:N", value_parser = simdrives::node_value::<u32>)]
        drop_every: Vec<(u8, u32)>,
        /// NODE sends nothing from SYNC count N on (a broken cable).
        #[arg(long, value_name = "NODE:N", value_parser = simdrives::node_value::<u64>)]
        silent_from: Vec<(u8, u64)>,
    },
    /// Measure this computer's real-time wake-up latency: the real-time loop with nothing
    /// to do (like cyclictest), same set-up and report as `dnurbs run`. Run it on a
    /// controller PC before deploying.
    Latency {
        /// Period, e.g. 1ms, 500us, 2ms.
        #[arg(long, default_value = "1ms", value_parser = parse_duration_ns)]
        period: u64,
        /// How long to measure, e.g. 10s, 5min.
        #[arg(long, default_value = "10s", value_parser = parse_duration_ns)]
        duration: u64,
        /// SCHED_FIFO priority of the loop thread (1..=99).
        #[arg(long, default_value_t = 80, value_parser = clap::value_parser!(i32).range(1..=99))]
        priority: i32,
        #[command(flatten)]
        cpu: CpuArgs,
        /// Run the same loop without mlockall and SCHED_FIFO (development machines).
        #[arg(long)]
        no_rt: bool,
        /// Write summary.txt, summary.json, latency.hlog (HdrHistogram interval log) and
        /// latency.svg (percentile plot) into this directory.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
    },
    /// Print the worst-case CAN bus load of a machine file, per bus: SYNC plus one 6-byte
    /// RPDO and TPDO per drive each cycle, at 55 + 10 n bits per frame (stuffing and
    /// interframe space included). vcan has no bit timing, so this is computed, not measured.
    Busload {
        /// Machine file (TOML) with [[bus]] tables and [axes.*.drive] mappings.
        #[arg(long, short)]
        machine: PathBuf,
    },
    /// Simulate programs with each parameter update method (taylor1, taylor2, arclength)
    /// and print a Markdown table of feed fluctuation and chord error.
    Compare {
        /// NC programs to compare on.
        #[arg(required = true)]
        programs: Vec<PathBuf>,
        /// Machine file (TOML).
        #[arg(long, short)]
        machine: PathBuf,
    },
}

/// `--cpu N [--idle-poll]` of `demo` and `latency`.
#[derive(clap::Args)]
struct CpuArgs {
    /// Pin the real-time thread to this CPU (pair with isolcpus= on the kernel command
    /// line) and keep dnurbs's other threads off it.
    #[arg(long)]
    cpu: Option<usize>,
    /// Keep the --cpu CPU busy between periods with a SCHED_IDLE polling thread, so it
    /// never halts (a user-space idle=poll for that CPU). Helps on virtual machines and PCs
    /// without a cpuidle driver; costs that CPU's power. Needs --cpu.
    #[arg(long, requires = "cpu")]
    idle_poll: bool,
}

impl CpuArgs {
    fn settings(&self, priority: Option<i32>) -> rt_loop::latency::RtSettings {
        rt_loop::latency::RtSettings {
            priority,
            cpu: self.cpu,
            idle_poll: self.idle_poll,
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Demo {
            report,
            no_rt,
            link,
            cpu,
            lead,
        } => demo(report, link, cpu.settings((!no_rt).then_some(80)), lead),
        Command::Run {
            program,
            machine,
            report,
            approach,
            no_rt,
        } => run_cmd(program, machine, report, approach, no_rt),
        Command::Simulate {
            program,
            machine,
            method,
            trace,
            json,
        } => simulate(program, machine, method, trace, json),
        Command::Compare { programs, machine } => compare(programs, machine),
        Command::Busload { machine } => busload(machine),
        Command::Latency {
            period,
            duration,
            priority,
            cpu,
            no_rt,
            report,
        } => latency(
            period,
            duration,
            cpu.settings((!no_rt).then_some(priority)),
            report,
        ),
        Command::SimDrives {
            iface,
            machine,
            record,
            lag_ms,
            duration,
            fault_at,
            heartbeat_stops,
            never_boots,
            drop_every,
            silent_from,
        } => load_machine(&machine)
            .map_err(anyhow::Error::from)
            .and_then(|machine| {
                simdrives::run(simdrives::SimArgs {
                    iface,
                    machine,
                    record,
                    lag_ms,
                    duration_s: duration,
                    faults: simdrives::FaultArgs {
                        fault_at,
                        heartbeat_stops,
                        never_boots,
                        drop_every,
                        silent_from,
                    },
                })
            }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("dnurbs: {e:#}");
            if e.downcast_ref::<InputError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

fn simulate(
    program: PathBuf,
    machine: PathBuf,
    method: Option<MethodArg>,
    trace: Option<PathBuf>,
    json: bool,
) -> anyhow::Result<()> {
    let machine = load_machine(&machine)?;
    let prog = load_program(&program)?;
    let setup = MachineSetup::new(&machine);
    let method = match method {
        Some(MethodArg::Arclength) => Method::ArcLength,
        Some(MethodArg::Taylor1) => Method::Taylor1,
        Some(MethodArg::Taylor2) => Method::Taylor2,
        None => setup.method,
    };
    let result =
        run(&prog, &setup, method).map_err(|e| InputError(format!("{}:{e}", program.display())))?;
    if let Some(path) = &trace {
        let file = std::fs::File::create(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot create the trace: {e}", path.display()))?;
        let mut w = std::io::BufWriter::new(file);
        write_trace(&mut w, &result.setpoints)
            .and_then(|_| w.flush())
            .map_err(|e| anyhow::anyhow!("{}: cannot write the trace: {e}", path.display()))?;
    }
    let summary = summarize(&result, &setup, prog.blocks.len());
    if json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print!("{}", summary.text());
    }
    Ok(())
}

fn compare(programs: Vec<PathBuf>, machine: PathBuf) -> anyhow::Result<()> {
    let setup = MachineSetup::new(&load_machine(&machine)?);
    println!(
        "| program | method | feed fluctuation max | feed fluctuation rms | chord error max (mm) | cycles |"
    );
    println!("|---|---|---|---|---|---|");
    for program in &programs {
        let prog = load_program(program)?;
        let name = program.file_name().map_or_else(
            || program.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        for method in [Method::Taylor1, Method::Taylor2, Method::ArcLength] {
            let result = run(&prog, &setup, method)
                .map_err(|e| InputError(format!("{}:{e}", program.display())))?;
            let s = summarize(&result, &setup, prog.blocks.len());
            println!(
                "| {name} | {} | {:.2e} | {:.2e} | {:.2e} | {} |",
                s.method,
                s.feed_fluctuation_max,
                s.feed_fluctuation_rms,
                s.chord_error_max_mm,
                s.cycles
            );
        }
    }
    Ok(())
}

fn busload(machine: PathBuf) -> anyhow::Result<()> {
    // Loading already refuses a bus over its max_load; this prints the numbers.
    let m = load_machine(&machine)?;
    if m.buses.is_empty() {
        println!(
            "{}: no [[bus]] tables: the machine has no drives",
            machine.display()
        );
        return Ok(());
    }
    println!("period {} ms", m.period_s * 1e3);
    for (i, b) in m.buses.iter().enumerate() {
        let drives: Vec<String> = m
            .drives
            .iter()
            .filter(|d| d.bus == i)
            .map(|d| format!("{}=node {}", m.axes.all()[d.axis].0, d.node))
            .collect();
        let n = drives.len() as u32;
        println!(
            "bus {} ({}, {} bit/s): {} drives [{}]: {} bits per cycle, load {:.2} % (max {:.0} %)",
            b.name,
            b.interface,
            b.bitrate,
            n,
            drives.join(", "),
            config::bus::cycle_bits(n),
            config::bus::load(n, b.bitrate, m.period_s) * 100.0,
            b.max_load * 100.0
        );
    }
    Ok(())
}

/// Parse `500us`, `1ms`, `1.5ms`, `2s`, `5min` into nanoseconds.
fn parse_duration_ns(s: &str) -> Result<u64, String> {
    let split = s
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(s.len());
    let (num, unit) = s.split_at(split);
    let value: f64 = num
        .parse()
        .map_err(|_| format!("{s:?}: expected a number with a unit, like 1ms"))?;
    let scale = match unit {
        "ns" => 1.0,
        "us" | "µs" => 1e3,
        "ms" => 1e6,
        "s" => 1e9,
        "min" => 60e9,
        _ => return Err(format!("{s:?}: unit must be ns, us, ms, s or min")),
    };
    let ns = value * scale;
    if !(1.0..1e15).contains(&ns) {
        return Err(format!("{s:?}: out of range"));
    }
    Ok(ns.round() as u64)
}

/// `--lead` of the demo: a duration up to half its 2 ms period, or 0.
fn parse_lead_ns(s: &str) -> Result<u64, String> {
    let ns = if s == "0" { 0 } else { parse_duration_ns(s)? };
    if ns > 1_000_000 {
        return Err(format!("{s:?}: at most 1ms (half the period)"));
    }
    Ok(ns)
}

fn write_report(
    dir: &std::path::Path,
    stats: &rt_loop::stats::Stats,
    title: &str,
) -> anyhow::Result<()> {
    let summary = stats.summary();
    let write = |name: &str, body: String| {
        let path = dir.join(name);
        std::fs::write(&path, body)
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))
    };
    write("summary.txt", summary.text())?;
    write("summary.json", serde_json::to_string_pretty(&summary)?)?;
    let svg = dir.join("latency.svg");
    rt_loop::report::write_svg(&svg, stats, title)
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", svg.display()))?;
    eprintln!("report: {}", dir.display());
    Ok(())
}

/// Print the report and outcome of a run; an early stop is an error (exit 1).
fn finish_run(
    r: &dnurbs_tools::run::RunResult,
    report: Option<PathBuf>,
    title: &str,
) -> anyhow::Result<()> {
    print!("{}", r.stats.summary().text());
    print!("{}", dnurbs_tools::run::outcome_text(r));
    if let Some(dir) = report {
        write_report(&dir, &r.stats, title)?;
    }
    match &r.reason {
        None => Ok(()),
        Some(why) => Err(anyhow::anyhow!("{why}")),
    }
}

fn demo(
    report: Option<PathBuf>,
    link: DemoLink,
    rt: rt_loop::latency::RtSettings,
    lead_ns: u64,
) -> anyhow::Result<()> {
    keep_off_rt_cpu(rt)?;
    let opts = dnurbs_tools::run::RunOptions {
        name: "paper-example.nc".into(),
        approach: true,
        rt,
        lead_ns,
        rt_fallback: true,
        report: report.clone(),
        progress: true,
    };
    let bus = match link {
        DemoLink::Memory => "an in-memory CAN link",
        DemoLink::Socketpair => "a socketpair CAN link",
    };
    eprintln!(
        "dnurbs demo: the paper's example on the paper's A/C table machine, 5 simulated \
         CiA-402 drives on {bus}, 2 ms period{}{}",
        lead_text(lead_ns),
        cpu_text(rt)
    );
    let (r, records) = dnurbs_tools::run::demo(&opts, link)?;
    println!("simulated drives received {} targets", records.len());
    finish_run(&r, report, "dnurbs demo: paper example, 2 ms")
}

fn run_cmd(
    program: PathBuf,
    machine: PathBuf,
    report: Option<PathBuf>,
    approach: bool,
    no_rt: bool,
) -> anyhow::Result<()> {
    let m = load_machine(&machine)?;
    let src = std::fs::read_to_string(&program).map_err(|e| {
        InputError(format!(
            "{}: cannot read the program: {e}",
            program.display()
        ))
    })?;
    let open_links = || -> anyhow::Result<Vec<drives::link::SocketLink>> {
        let mut links = Vec::new();
        for b in &m.buses {
            links.push(drives::link::SocketLink::open(&b.interface).map_err(|e| {
                anyhow::anyhow!(
                    "cannot open CAN interface {:?} (bus {:?}): {e}; is it up? \
                     `ip link set {} up type can bitrate {}`",
                    b.interface,
                    b.name,
                    b.interface,
                    b.bitrate
                )
            })?);
        }
        Ok(links)
    };
    let opts = dnurbs_tools::run::RunOptions {
        name: program.display().to_string(),
        approach,
        rt: rt_loop::latency::RtSettings {
            priority: (!no_rt).then_some(m.realtime.priority),
            cpu: m.realtime.cpu,
            idle_poll: m.realtime.idle_poll,
        },
        lead_ns: (m.realtime.lead_s * 1e9).round() as u64,
        rt_fallback: false,
        report: report.clone(),
        progress: true,
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
    let r = dnurbs_tools::run::run(&src, &m, open_links, &opts)?;
    let title = format!("dnurbs run: {} on {}", program.display(), m.name);
    finish_run(&r, report, &title)
}

/// With a real-time CPU: this thread, and every thread it starts from now on, stays off it.
fn keep_off_rt_cpu(rt: rt_loop::latency::RtSettings) -> anyhow::Result<()> {
    if let Some(cpu) = rt.cpu {
        rt_loop::os::avoid_cpu(cpu)?;
    }
    Ok(())
}

/// ", 60 µs lead" or nothing.
fn lead_text(lead_ns: u64) -> String {
    if lead_ns == 0 {
        return String::new();
    }
    format!(", {} µs lead", lead_ns as f64 / 1e3)
}

/// ", real-time thread on CPU n (idle polled)" or nothing.
fn cpu_text(rt: rt_loop::latency::RtSettings) -> String {
    match rt.cpu {
        Some(c) if rt.idle_poll => format!(", real-time thread on CPU {c} (idle polled)"),
        Some(c) => format!(", real-time thread on CPU {c}"),
        None => String::new(),
    }
}

fn latency(
    period: u64,
    duration: u64,
    rt: rt_loop::latency::RtSettings,
    report: Option<PathBuf>,
) -> anyhow::Result<()> {
    if period > duration {
        return Err(InputError(format!(
            "--period {period} ns is longer than --duration {duration} ns"
        ))
        .into());
    }
    keep_off_rt_cpu(rt)?;
    eprintln!(
        "dnurbs latency: {} periods of {} us{}{}",
        duration / period,
        period as f64 / 1000.0,
        if rt.priority.is_some() {
            ", SCHED_FIFO"
        } else {
            ", without real-time privileges (--no-rt)"
        },
        cpu_text(rt)
    );
    if let Some(dir) = &report {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
    }
    let hlog = report.as_ref().map(|d| d.join("latency.hlog"));
    let stats = rt_loop::latency::run(period, duration, rt, hlog.as_deref())?;
    let summary = stats.summary();
    print!("{}", summary.text());
    if let Some(dir) = report {
        let title = format!(
            "dnurbs latency: {} periods of {} us",
            summary.cycles,
            period as f64 / 1000.0
        );
        write_report(&dir, &stats, &title)?;
    }
    Ok(())
}
