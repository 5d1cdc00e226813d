//! `dnurbs demo`: the paper's example on the paper's machine, its five drives simulated in
//! a thread on the other end of an in-process link, in real time.

use crate::feed::Input;
use crate::run::{run_input, RunOptions, RunResult};
use config::Machine;
use drives::link::{CanLink, MemLink, SocketLink};

/// The demo's machine: the paper's machine (its drives on an in-process bus).
pub const DEMO_MACHINE: &str = include_str!("../../config/machines/paper-ac-table.toml");
/// The demo machine's tool table (its `[program] tool_table`).
pub const DEMO_TOOLS: &str = include_str!("../../config/machines/mill.tbl");
/// Where the demo's machine file says it is.
pub const DEMO_MACHINE_PATH: &str = "config/machines/paper-ac-table.toml";
/// The demo's program: the paper's example.
pub const DEMO_PROGRAM: &str = include_str!("../../tests/data/paper-example.nc");

/// The in-process bus of `dnurbs demo` (`--link`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DemoLink {
    /// Lock-free queues in memory (`MemLink`): the cycle makes no system call for the bus.
    Memory,
    /// A kernel socketpair (`SocketLink::pair`) carrying `can_frame` structs through the
    /// same system calls as a CAN interface (`sendmmsg`/`recvmmsg` per cycle).
    Socketpair,
}

/// Frames each direction of the demo's memory bus holds (a few hundred periods' worth).
pub const DEMO_QUEUE_FRAMES: usize = 1024;

/// `dnurbs demo`: the paper's example on the paper's machine, its five drives simulated in a
/// thread on the other end of an in-process link.
pub fn demo(
    opts: &RunOptions,
    link: DemoLink,
    input: Input,
) -> anyhow::Result<(RunResult, Vec<drives::sim::Record>)> {
    let machine = demo_machine()?;
    match link {
        DemoLink::Memory => demo_on(&machine, opts, input, || {
            Ok(MemLink::pair(DEMO_QUEUE_FRAMES))
        }),
        DemoLink::Socketpair => demo_on(&machine, opts, input, SocketLink::pair),
    }
}

/// The demo's machine file, read with its built-in tool table.
pub fn demo_machine() -> Result<Machine, config::ConfigError> {
    config::from_str_with_files(
        DEMO_MACHINE,
        std::path::Path::new(DEMO_MACHINE_PATH),
        &|path| {
            if path == std::path::Path::new("config/machines/mill.tbl") {
                Ok(DEMO_TOOLS.to_owned())
            } else {
                std::fs::read_to_string(path)
            }
        },
    )
}

fn demo_on<L: CanLink + Send + 'static>(
    machine: &Machine,
    opts: &RunOptions,
    input: Input,
    pair: impl Fn() -> std::io::Result<(L, L)>,
) -> anyhow::Result<(RunResult, Vec<drives::sim::Record>)> {
    let (links, sims) =
        crate::simdrives::sim_threads(machine, &Default::default(), opts.rt.priority, pair)?;
    let result = run_input(input, machine, move || Ok(links), opts);
    let records = sims.into_iter().flat_map(|s| s.finish()).collect();
    Ok((result?, records))
}
