//! `dnurbs serve`'s command line, and turning it into [`super::process::ServeOptions`].

use super::process::ServeOptions;
use crate::exit::InputError;
use crate::simdrives::{self, FaultArgs};
use std::path::PathBuf;

/// `dnurbs serve`'s options.
#[derive(clap::Args, Clone, Debug)]
pub struct ServeArgs {
    /// Machine file (TOML) with [[bus]] and [axes.*.drive] (and [axes.*.home] for homing).
    /// With --sim and without it: the demo's machine (the paper's; no home tables, so each
    /// axis homes where it stands).
    #[arg(long, short)]
    pub machine: Option<PathBuf>,
    /// Play the machine's CiA-402 drives in-process, on an in-memory bus (as `dnurbs demo`
    /// does): the whole controller without hardware.
    #[arg(long)]
    pub sim: bool,
    /// The control socket (mode 0660: its owner and group operate the machine). Default:
    /// the machine file's [control] socket.
    #[arg(long, value_name = "SOCKET")]
    pub control: Option<PathBuf>,
    /// Also serve a watch socket here (mode 0666): `status` only, for screens and metrics.
    #[arg(long, value_name = "SOCKET")]
    pub watch: Option<PathBuf>,
    /// With --sim: write every target the simulated drives took when serve ends (CSV
    /// sync,node,target_counts,actual_counts,statusword, as sim-drives --record).
    #[arg(long, value_name = "FILE.csv", requires = "sim")]
    pub record: Option<PathBuf>,
    /// With --sim: drive fault (EMCY 0x8611, statusword Fault) on NODE at SYNC count N.
    #[arg(long, value_name = "NODE:N", requires = "sim", value_parser = simdrives::node_value::<u64>)]
    pub fault_at: Vec<(u8, u64)>,
    /// With --sim: NODE's home switch is not wired: its homing search fails with the
    /// drive's homing error after a tenth of the axis's travel.
    #[arg(long, value_name = "NODE", requires = "sim")]
    pub no_home_switch: Vec<u8>,
    /// Run without mlockall and SCHED_FIFO (development machines; timing not guaranteed).
    #[arg(long)]
    pub no_rt: bool,
    #[command(flatten)]
    pub shop: crate::shop::ShopArgs,
}

impl ServeArgs {
    pub fn options(self) -> anyhow::Result<ServeOptions> {
        let machine = match (&self.machine, self.sim) {
            (Some(p), _) => crate::load_machine(p)?,
            (None, true) => crate::demo::demo_machine()?,
            (None, false) => {
                return Err(InputError::Usage(
                    "serve needs --machine FILE (or --sim for the demo's machine)".into(),
                )
                .into())
            }
        };
        let control = self
            .control
            .clone()
            .or_else(|| machine.control_socket.clone())
            .ok_or_else(|| {
                InputError::Usage(
                    "serve needs a control socket: --control SOCKET, or [control] socket in \
                     the machine file"
                        .into(),
                )
            })?;
        let shop = crate::shop::parse_setup(&machine, &self.shop.load()?)?;
        let rt = rt_loop::thread::RtSettings {
            priority: (!self.no_rt).then_some(machine.realtime.priority),
            cpu: machine.realtime.cpu,
            idle_poll: machine.realtime.idle_poll,
        };
        Ok(ServeOptions {
            shop,
            sim: self.sim,
            control,
            watch: self.watch,
            record: self.record,
            faults: FaultArgs {
                fault_at: self.fault_at,
                no_home_switch: self.no_home_switch,
                ..FaultArgs::default()
            },
            rt,
            machine,
        })
    }
}
