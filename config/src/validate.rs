//! Stage 1 -> stage 2: checks every raw value and builds the [`Machine`].
//!
//! Each rule lives in exactly one place here, and its message states the allowed range with
//! the unit. The first violation is returned as [`ConfigError::Invalid`] with the key path,
//! the value as written and its line:col (looked up in [`Source`]).

use crate::check::Check;
use crate::error::ConfigError;
use crate::raw::RawFile;
use crate::source::Source;
use machine::bus;
use machine::Machine;

mod guard;
mod hardware;
mod home;
mod io;
mod motion;
mod program;
mod spindle;

/// Converts the raw file into a validated [`Machine`].
pub(crate) fn machine(
    raw: RawFile,
    src: &Source<'_>,
    read: &dyn Fn(&std::path::Path) -> std::io::Result<String>,
) -> Result<Machine, ConfigError> {
    let check = Check { src };
    let (name, period_s) = check.machine(&raw.machine)?;
    let kinematics = check.kinematics(&raw.kinematics)?;
    let axes = check.axes(&raw.axes, &kinematics)?;
    let interpolation = check.interpolation(&raw.interpolation.unwrap_or_default())?;
    let buses = check.buses(&raw.bus)?;
    if !kinematics.has_rotary_axes() && !buses.is_empty() {
        let rule = "runs in simulation only (no [[bus]]): dnurbs's bus machines have five \
                    axes, each with a drive; a 3-axis machine on a bus is not supported yet"
            .to_owned();
        return Err(check.invalid(&["kinematics", "kind"], Some("\"xyz\"".to_owned()), rule));
    }
    let drives = check.drives(&raw.axes, &axes, &buses)?;
    let spindle = match &raw.spindle {
        Some(r) => Some(spindle::spindle(&check, r, &buses, &drives)?),
        None => None,
    };
    let coolant = match &raw.coolant {
        Some(r) => Some(spindle::coolant(
            &check,
            r,
            &buses,
            &drives,
            spindle.as_ref(),
        )?),
        None => None,
    };
    let (io, bus_io) = io::io(
        &check,
        raw.io,
        &buses,
        &drives,
        spindle.as_ref(),
        coolant.as_ref(),
    )?;
    let nodes: Vec<bus::Nodes> = (0..buses.len())
        .map(|i| bus::Nodes {
            drives: (drives.iter().filter(|d| d.bus == i).count()
                + usize::from(spindle.as_ref().is_some_and(|s| s.on_bus(i).is_some())))
                as u32,
            io: u32::from(
                coolant.as_ref().is_some_and(|c| c.on_bus(i).is_some())
                    || bus_io.is_some_and(|b| b.on_bus(i)),
            ),
        })
        .collect();
    let bus_overload = check.bus_load(&buses, &nodes, period_s);
    let realtime = check.realtime(&raw.realtime.unwrap_or_default(), period_s)?;
    let control_socket = match raw.control.and_then(|c| c.socket) {
        Some(s) if s.trim().is_empty() || s.contains('\0') => {
            return Err(check.invalid(
                &["control", "socket"],
                Some(format!("{s:?}")),
                "must be a path (e.g. \"/run/dnurbs/control.sock\")".into(),
            ))
        }
        other => other.map(std::path::PathBuf::from),
    };
    let offsets = raw.work_offsets.unwrap_or_default();
    let mut work_offsets = [None; 6];
    for ((slot, name), value) in work_offsets
        .iter_mut()
        .zip(["G54", "G55", "G56", "G57", "G58", "G59"])
        .zip([
            offsets.g54,
            offsets.g55,
            offsets.g56,
            offsets.g57,
            offsets.g58,
            offsets.g59,
        ])
    {
        if let Some(v) = value {
            *slot = Some(check.point(&["work_offsets", name], v)?);
        }
    }
    let (reference, g30) = match raw.reference {
        Some(r) => (
            Some(check.point(&["reference", "position"], r.position)?),
            match r.g30 {
                Some(p) => Some(check.point(&["reference", "g30"], p)?),
                None => None,
            },
        ),
        None => (None, None),
    };
    let mut program =
        program::program(&check, raw.program.unwrap_or_default(), &work_offsets, read)?;
    program.io = io;
    program.mcodes = program::mcodes(&check, raw.mcodes.unwrap_or_default(), io)?;
    Ok(Machine {
        program,
        spindle,
        coolant,
        bus_io,
        work_offsets,
        reference,
        g30,
        name,
        period_s,
        kinematics,
        axes,
        interpolation,
        buses,
        drives,
        realtime,
        bus_overload,
        control_socket,
    })
}
