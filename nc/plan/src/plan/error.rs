//! Why a program is refused: the plan's errors, their messages (which name the block, the
//! axis, the quantity, the value and both the limit a plan may use and the machine file's),
//! and the refusal built from the setpoint check's violation.

use crate::config::PlanConfig;
use crate::verify::{Quantity, Violation, MAX_CYCLES};
use nc_geom::kinematics::{MachineKinematics, Tilt};
use nc_geom::limits::{JERK_RESERVE, JERK_RISE, V_FLOOR};
use nc_geom::program::SrcPos;
use nc_geom::scurve::Phase;
use nc_geom::segment::Path;

/// A program the planner cannot run within the machine's limits.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{pos}: {kind}")]
pub struct PlanError {
    pub pos: SrcPos,
    pub kind: PlanErrorKind,
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanErrorKind {
    #[error("the program would take {hours:.1} h at the feeds the limits allow, more than the {max_cycles} periods dnurbs plans ({max_hours:.1} h at this period)")]
    TooLong {
        hours: f64,
        max_cycles: u64,
        max_hours: f64,
    },
    #[error("the {axis} axis would leave its travel: {value:.4} {unit} at t = {t:.3} s (travel {min} .. {max} {unit})")]
    Travel {
        axis: char,
        unit: &'static str,
        value: f64,
        min: f64,
        max: f64,
        t: f64,
    },
    #[error("the rotary axes would change solution in one period at t = {t:.3} s, for the same tool axis: {tilt} {from_tilt:.3} -> {to_tilt:.3} deg, C {from_c:.3} -> {to_c:.3} deg; following the tool axis on would leave the travel of {tilt} ({}) or C ({})", travel(*.tilt_min, *.tilt_max, "deg"), travel(*.c_min, *.c_max, "deg"))]
    Branch {
        tilt: char,
        from_tilt: f64,
        to_tilt: f64,
        from_c: f64,
        to_c: f64,
        t: f64,
        tilt_min: f64,
        tilt_max: f64,
        c_min: f64,
        c_max: f64,
    },
    #[error("the {} {} would reach {value:.4e} {unit} at t = {t:.3} s, {:.3}x {}, {}{hint}", subject(*.axis), .quantity.name(), .value / .limit, against(*.quantity, *.limit, *.machine, .unit), slowest(*.floor, *.v, .path_unit))]
    Limit {
        /// The axis, or `None` for the chord error of the cutter path.
        axis: Option<char>,
        quantity: Quantity,
        unit: &'static str,
        value: f64,
        /// What the plan's setpoints may reach: the machine file's limit, less the check's
        /// reserve ([`nc_geom::limits::reserve`]) or at the planned jerk
        /// ([`AxisLimit::planned_jerk`]).
        limit: f64,
        /// The machine file's limit.
        machine: f64,
        t: f64,
        v: f64,
        path_unit: &'static str,
        hint: &'static str,
        /// `v` is the slowest feed the planner schedules ([`V_FLOOR`]); else the planner
        /// got no slower there.
        floor: bool,
    },
}

/// How slow the planner went where it refuses: to its floor, or only as far as it got (its
/// rounds of slowing ran out, or a lower ceiling no longer changed its plan there): a slower
/// pass might hold, but the program is refused, not crawled through.
pub(super) fn slowest(floor: bool, v: f64, path_unit: &str) -> String {
    if floor {
        format!("even at the slowest feed the planner schedules there ({v:.3e} {path_unit}/s)")
    } else {
        format!("at {v:.3e} {path_unit}/s, the slowest the planner reached there")
    }
}

/// An axis's travel for a message: an axis without limits (a C that turns endlessly has
/// -inf .. inf) says so, not "-inf .. inf".
pub(super) fn travel(min: f64, max: f64, unit: &str) -> String {
    match (min.is_finite(), max.is_finite()) {
        (true, true) => format!("{min} .. {max} {unit}"),
        (true, false) => format!("from {min} {unit}, no upper limit"),
        (false, true) => format!("up to {max} {unit}, no lower limit"),
        (false, false) => "no travel limit".to_string(),
    }
}

/// The limit a refusal measures against. Where the plan may use less than the machine
/// file's limit, both are named: a refusal that said "its limit of 2.94e5 mm/s^3" of an
/// axis whose file says 1e9 read as a misparsed file.
pub(super) fn against(quantity: Quantity, limit: f64, machine: f64, unit: &str) -> String {
    if (limit - machine).abs() <= 1e-9 * machine.abs() {
        return format!("its limit of {limit:.4e} {unit}");
    }
    let kept = 100.0 * (1.0 - JERK_RESERVE);
    let rise = limit < machine * (1.0 - JERK_RESERVE) * (1.0 - 1e-9);
    let why = match quantity {
        Quantity::Jerk if rise => format!(
            "a plan's jerk is at most {JERK_RISE} x the acceleration per period, and \
             {kept:.1} % of that: the rest is kept for feed holds and overrides"
        ),
        _ => format!(
            "{:.1} %: the rest is kept for feed holds and overrides",
            100.0 * limit / machine
        ),
    };
    format!("the {limit:.4e} {unit} a plan may use of its limit of {machine:.4e} {unit} ({why})")
}

pub(super) fn subject(axis: Option<char>) -> String {
    axis.map_or_else(|| "cutter path".to_string(), |c| format!("{c} axis"))
}

pub(super) fn axis_name(kin: &MachineKinematics, j: usize) -> char {
    match (j, kin.tilt_kind()) {
        (0, _) => 'X',
        (1, _) => 'Y',
        (2, _) => 'Z',
        (3, Tilt::A) => 'A',
        (3, Tilt::B) => 'B',
        _ => 'C',
    }
}

pub(super) fn refuse(
    path: &Path,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    v: &Violation,
) -> PlanError {
    let pos = if v.cycle == 0 {
        path.start_src
    } else {
        path.segments
            .get(v.segment)
            .map_or(path.start_src, |s| s.src)
    };
    let rotary = (3..5).contains(&v.axis);
    let conv = |x: f64| if rotary { x.to_degrees() } else { x };
    let base = if v.axis == 5 {
        "mm"
    } else if rotary {
        "deg"
    } else {
        "mm"
    };
    let kind = match v.quantity {
        Quantity::Branch => PlanErrorKind::Branch {
            tilt: axis_name(kin, 3),
            from_tilt: v.rotary[0][0].to_degrees(),
            to_tilt: v.rotary[1][0].to_degrees(),
            from_c: v.rotary[0][1].to_degrees(),
            to_c: v.rotary[1][1].to_degrees(),
            t: v.t,
            tilt_min: cfg.travel[3].0.to_degrees(),
            tilt_max: cfg.travel[3].1.to_degrees(),
            c_min: cfg.travel[4].0.to_degrees(),
            c_max: cfg.travel[4].1.to_degrees(),
        },
        Quantity::Travel => PlanErrorKind::Travel {
            axis: axis_name(kin, v.axis),
            unit: base,
            value: conv(v.value),
            min: conv(cfg.travel[v.axis].0),
            max: conv(cfg.travel[v.axis].1),
            t: v.t,
        },
        q => {
            let unit = match (q, rotary) {
                (Quantity::Velocity, true) => "deg/s",
                (Quantity::Velocity, false) => "mm/s",
                (Quantity::Acceleration, true) => "deg/s^2",
                (Quantity::Acceleration, false) => "mm/s^2",
                (Quantity::Jerk, true) => "deg/s^3",
                (Quantity::Jerk, false) => "mm/s^3",
                _ => base,
            };
            let rotary_only = path.segments.get(v.segment).is_some_and(|s| s.rotary_only);
            PlanErrorKind::Limit {
                axis: (v.axis < 5).then(|| axis_name(kin, v.axis)),
                quantity: q,
                unit,
                value: conv(v.value),
                limit: conv(v.limit),
                machine: conv(match (q, cfg.axes.get(v.axis)) {
                    (Quantity::Velocity, Some(ax)) => ax.velocity,
                    (Quantity::Acceleration, Some(ax)) => ax.acceleration,
                    (Quantity::Jerk, Some(ax)) => ax.jerk,
                    _ => v.limit,
                }),
                t: v.t,
                v: v.v,
                path_unit: if rotary_only { "deg" } else { "mm" },
                floor: v.v <= V_FLOOR * 1.01,
                hint: if v.v <= 0.0 {
                    ": the axis steps while the path stands still (a jump of the rotary solution between blocks)"
                } else if rotary {
                    ": the tool axis passes too close to the vertical, where C turns by up to 180 degrees"
                } else {
                    ""
                },
            }
        }
    };
    PlanError { pos, kind }
}

pub(super) fn too_long(
    path: &Path,
    seg_start: &[f64],
    phases: &[Phase],
    duration: f64,
    ts: f64,
) -> PlanError {
    // Name the block the plan is in when the limit runs out.
    let t_max = MAX_CYCLES as f64 * ts;
    let i = phases.partition_point(|p| p.t0 <= t_max).saturating_sub(1);
    let s = phases.get(i).map_or(0.0, |p| p.at(t_max - p.t0).s);
    let k = seg_start.partition_point(|&x| x <= s).saturating_sub(1);
    PlanError {
        pos: path.segments.get(k).map_or(path.start_src, |seg| seg.src),
        kind: PlanErrorKind::TooLong {
            hours: duration / 3600.0,
            max_cycles: MAX_CYCLES,
            max_hours: t_max / 3600.0,
        },
    }
}

/// Why a parsed program cannot run on a machine: its geometry, or its plan.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProgramError {
    #[error(transparent)]
    Build(#[from] nc_geom::segment::BuildError),
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// The interpolation did not reach the program's end within [`MAX_CYCLES`] periods
    /// (a Taylor method creeping to the end): an error, never a silently short run.
    #[error("the interpolation did not reach the program's end within {0} periods")]
    Unfinished(u64),
}
