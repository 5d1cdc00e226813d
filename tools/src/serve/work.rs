//! What the controller prepares outside the real-time thread: an MDI line or a loaded
//! program planned from where the machine stands, cut into chunks for the life's queues;
//! the axes' drives, jog limits and homing requests from the machine file.

use crate::run::home_request;
use crate::setup::MachineSetup;
use config::bus::HomeMethod;
use config::Machine;
use drives::master::HomeRequest;
use nc_follow::jog::JogLimits;
use nc_follow::{Chunk, Start};
use nc_geom::program::{Block, Program};
use nc_lang::restart::Standing;
use nc_lang::Entry;

/// Programs larger than this are refused by `load` (serve plans a program whole before it
/// moves; `dnurbs run` streams larger ones).
pub const MAX_PROGRAM_BYTES: u64 = crate::feed::CHECK_WHOLE_BYTES;

/// A program or MDI line planned and cut, ready to hand over.
pub struct Planned {
    pub start: Start,
    #[allow(clippy::vec_box)] // the boxes travel through the queues as pointers
    pub chunks: Vec<Box<Chunk>>,
    /// The tool length its last block leaves on the machine's Z (mm).
    pub tool_length: f64,
    /// It moves (a line of modes alone does not).
    pub moves: bool,
}

/// Build, plan and cut `program` on the machine.
pub fn plan(program: &Program, setup: &MachineSetup, depth: usize) -> Result<Planned, String> {
    let path =
        nc_geom::segment::build(program, &setup.kin, &setup.build).map_err(|e| e.to_string())?;
    let moves = !path.segments.is_empty();
    let profile = nc_plan::plan::plan(&path, &setup.kin, &setup.plan).map_err(|e| e.to_string())?;
    let tool_length = match program.blocks.last() {
        Some(Block::Linear(b)) => b.tooling.tool_length,
        Some(Block::Nurbs(b)) => b.tooling.tool_length,
        None => 0.0,
    };
    let (start, chunks) = nc_plan::stream::chunks(path, &profile, &setup.plan.hold(), depth);
    Ok(Planned {
        start,
        chunks,
        tool_length,
        moves,
    })
}

/// A whole program's entries as a program from where the machine stands (`standing`), as
/// an MDI line is ([`nc_lang::mdi::program`]).
pub fn from_here(
    entries: &[Entry],
    tilt_word: Option<(char, nc_geom::program::SrcPos)>,
    standing: &Standing,
    setup: &MachineSetup,
) -> Program {
    nc_lang::mdi::program(entries, tilt_word, standing, &setup.kin)
}

/// Single block: a stop before every block of `program` but its start and its first move
/// (an operator stop, as `M00` makes it), so that the path comes to rest at the end of each
/// block and waits. The lines of the stops, sorted.
pub fn stop_before_each_block(program: &mut Program) -> Vec<u32> {
    let mut lines = Vec::new();
    for b in program.blocks.iter_mut().skip(2) {
        let (pos, wait) = match b {
            Block::Linear(m) => (m.pos, &mut m.tooling.wait),
            Block::Nurbs(n) => (n.pos, &mut n.tooling.wait),
        };
        wait.operator.get_or_insert(pos);
        lines.push(pos.line);
    }
    lines.sort_unstable();
    lines.dedup();
    lines
}

/// One drive of an axis: its bus, its index in the master's node order, the drive.
#[derive(Clone, Debug)]
pub struct AxisDrive {
    pub bus: usize,
    pub index: usize,
    pub drive: config::bus::Drive,
}

/// Each joint's drives (X Y Z tilt C), from the machine file.
pub fn axis_drives(machine: &Machine) -> [Vec<AxisDrive>; 5] {
    let mut out: [Vec<AxisDrive>; 5] = Default::default();
    for bus in 0..machine.buses.len() {
        // The master's node order: the axes' drives first, in the file's order.
        for (index, d) in machine.drives.iter().filter(|d| d.bus == bus).enumerate() {
            if let Some(v) = out.get_mut(d.axis) {
                v.push(AxisDrive {
                    bus,
                    index,
                    drive: d.clone(),
                });
            }
        }
    }
    out
}

/// How a joint is homed.
#[derive(Clone, Debug, PartialEq)]
pub enum Homing {
    /// An absolute encoder: homed from the start.
    Absolute,
    /// No `[axes.*.home]`: homed where it stands when asked (LinuxCNC's
    /// `HOME_SEARCH_VEL = 0`).
    Here,
    /// CiA-402 homing of each of its drives, in sequence group `sequence`.
    Drive {
        sequence: u8,
        requests: Vec<(usize, usize, HomeRequest)>,
    },
}

/// The homing of joint `j`.
pub fn homing(machine: &Machine, drives: &[AxisDrive], limits: &config::AxisLimits) -> Homing {
    let Some(first) = drives.first() else {
        return Homing::Absolute;
    };
    match first.drive.home {
        None => Homing::Here,
        Some(h) if h.method == HomeMethod::Absolute => Homing::Absolute,
        Some(h) => Homing::Drive {
            sequence: h.sequence,
            requests: drives
                .iter()
                .filter_map(|d| {
                    home_request(&d.drive, limits, machine.period_s).map(|r| (d.bus, d.index, r))
                })
                .collect(),
        },
    }
}

/// Jog limits of joint `j` in its units: the axis's, with its travel once homed; before,
/// the range its drive's counts can hold (as in LinuxCNC, soft limits need a home).
pub fn jog_limits(
    limits: &config::AxisLimits,
    drive: &config::bus::Drive,
    homed: bool,
) -> JogLimits {
    let (min, max) = if homed {
        (limits.min, limits.max)
    } else {
        let a = drive.position(i32::MIN + 1);
        let b = drive.position(i32::MAX - 1);
        (a.min(b), a.max(b))
    };
    JogLimits {
        velocity: limits.velocity,
        acceleration: limits.acceleration,
        jerk: limits.jerk,
        min,
        max,
    }
}
