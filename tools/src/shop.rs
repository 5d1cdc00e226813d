//! The shop's side of a program: the tool table, the work offsets and the operator's
//! switches (`--tools`, `--offsets`, `--block-delete`, `--optional-stop`), merged with the
//! machine file's work offsets and reference position into the parser's
//! [`nc_lang::Setup`].

use crate::exit::InputError;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// `--tools`, `--offsets`, `--block-delete`, `--optional-stop` of `simulate`, `run` and
/// `compare`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct ShopArgs {
    /// Tool table in LinuxCNC's tool.tbl format (`T1 P1 Z+75.0 D6.0 ;comment`): the
    /// lengths `G43 H` / `G43.4 H` apply (Z, mm). Replaces the machine file's
    /// `[program] tool_table`.
    #[arg(long, value_name = "TOOL.TBL")]
    pub tools: Option<PathBuf>,
    /// Work offsets in LinuxCNC's parameter-file format (`linuxcnc.var`: `5221 120.5` is G54
    /// X): each of G54..G59 the file gives (parameters 5221..5223 + 20 per offset, mm)
    /// replaces the machine file's `[work_offsets]` entry.
    #[arg(long, value_name = "LINUXCNC.VAR")]
    pub offsets: Option<PathBuf>,
    /// Skip lines that start with `/` (block delete). Without it the `/` is ignored.
    #[arg(long)]
    pub block_delete: bool,
    /// Stop at M01 and wait for the operator (optional stop). Without it M01 is passed.
    #[arg(long)]
    pub optional_stop: bool,
    /// Fit runs of G01 moves into G06.5 blocks before planning (as `dnurbs fit` does, with
    /// the machine file's `compress_tol_mm`, `compress_tol_deg` and `compress_corner_deg`),
    /// whatever the machine file's `[interpolation] compress` says. The program's `G61`
    /// still turns it off and `G64 Q` sets its tolerance for the moves after them.
    #[arg(long, conflicts_with = "no_compress")]
    pub compress: bool,
    /// Plan the G01 moves as they are, whatever the machine file's `compress` and the
    /// program's `G64 Q` say.
    #[arg(long)]
    pub no_compress: bool,
}

/// The shop's options as values (tool lengths loaded).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShopOptions {
    /// Tool number -> length and diameter, mm, from `--tools` (else the machine file's
    /// table is used).
    pub tools: Option<BTreeMap<u32, config::Tool>>,
    /// G54..G59 from `--offsets`, over the machine file's.
    pub work_offsets: config::offsets::WorkOffsets,
    pub block_delete: bool,
    pub optional_stop: bool,
    /// `--compress` (Some(true)) or `--no-compress` (Some(false)) over the machine file.
    pub compress: Option<bool>,
}

impl ShopArgs {
    /// Loads the tool table, if one is given.
    pub fn load(&self) -> Result<ShopOptions, InputError> {
        let tools = match &self.tools {
            Some(path) => Some(config::tools::load_tools(path)?),
            None => None,
        };
        let work_offsets = match &self.offsets {
            Some(path) => config::offsets::load_offsets(path)?,
            None => [None; 6],
        };
        Ok(ShopOptions {
            tools,
            work_offsets,
            block_delete: self.block_delete,
            optional_stop: self.optional_stop,
            compress: match (self.compress, self.no_compress) {
                (true, _) => Some(true),
                (_, true) => Some(false),
                _ => None,
            },
        })
    }
}

/// The parser's setup for `machine` and the shop's options: the machine file's
/// `[program]` table (start-up modes, tool table, subroutine path, loop limit) with the
/// shop's `--tools` and `--offsets` over it.
pub fn parse_setup(
    machine: &config::Machine,
    shop: &ShopOptions,
) -> Result<nc_lang::Setup, InputError> {
    let program = &machine.program;
    let table = shop.tools.as_ref().unwrap_or(&program.tools);
    let tools = table.iter().map(|(n, t)| (*n, t.length_mm)).collect();
    let tool_diameters = table
        .iter()
        .filter_map(|(n, t)| t.diameter_mm.map(|d| (*n, d)))
        .collect();
    let mut setup = nc_lang::Setup {
        work_offsets: std::array::from_fn(|k| shop.work_offsets[k].or(machine.work_offsets[k])),
        reference: machine.reference,
        g30: machine.g30,
        tools,
        tool_diameters,
        rotary_axes: machine.kinematics.has_rotary_axes(),
        block_delete: shop.block_delete,
        optional_stop: shop.optional_stop,
        kinematics: Some(crate::setup::MachineSetup::new(machine).kin),
        max_rpm: machine.spindle.as_ref().map(|s| s.max_rpm),
        subroutine_dirs: program.subroutine_dirs.clone(),
        max_loop_lines: program.max_loop_lines,
        max_feed_mm_min: Some(machine.interpolation.max_feed_mm_min),
        io: nc_lang::Io {
            digital_outputs: program.io.digital_outputs,
            digital_inputs: program.io.digital_inputs,
            analog_outputs: program.io.analog_outputs,
            analog_inputs: program.io.analog_inputs,
        },
        user_mcodes: program
            .mcodes
            .iter()
            .map(|(&n, &a)| {
                use nc_geom::program::UserAction;
                let action = match a {
                    config::McodeAction::Ignore => UserAction::Ignore,
                    config::McodeAction::TcpOn => UserAction::TcpOn,
                    config::McodeAction::TcpOff => UserAction::TcpOff,
                    config::McodeAction::Stop => UserAction::Stop,
                    config::McodeAction::Output { output, on } => {
                        UserAction::Output { index: output, on }
                    }
                    config::McodeAction::Wait {
                        input,
                        level,
                        timeout_s,
                    } => UserAction::Wait {
                        input,
                        mode: match level {
                            config::Level::High => nc_geom::program::WaitMode::High,
                            config::Level::Low => nc_geom::program::WaitMode::Low,
                            config::Level::Rise => nc_geom::program::WaitMode::Rise,
                            config::Level::Fall => nc_geom::program::WaitMode::Fall,
                        },
                        timeout_s,
                    },
                };
                (n, action)
            })
            .collect(),
        ..nc_lang::Setup::default()
    };
    if !program.startup.is_empty() {
        // Checked when the machine file was read; the shop's offsets only add to it.
        setup.startup = nc_lang::Startup::parse(&program.startup, &setup).map_err(|e| {
            InputError::MachineUse(format!(
                "{}: [program] startup = {:?}: column {}: {}",
                machine.name, program.startup, e.col, e.message
            ))
        })?;
    }
    Ok(setup)
}
