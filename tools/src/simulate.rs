//! `dnurbs simulate`: the interpolator run offline, period by period, exactly as the
//! real-time thread will run it, and the measurements that judge the result.
//!
//! The measurements are made independently of the interpolator's own shortcuts: arc length
//! per period is integrated afresh between the two setpoints' parameters (Gauss-Legendre on
//! |C'(u)|, not the arc-length table), the chord error is measured against the curve itself,
//! and the tool axis is recovered from the machine angles through forward kinematics.

use crate::setup::MachineSetup;
use nc_fit::online::Compressing;
use nc_geom::arclen::GL8;
use nc_geom::nurbs::DoubleNurbs;
use nc_geom::program::Program;
use nc_geom::segment::{build, Path};
use nc_geom::setpoint::Setpoint;
use nc_plan::interp::{Interpolator, Method};
use nc_plan::plan::{plan, Finished, ProgramError};
use nc_plan::profile::FeedProfile;
use nc_plan::rolling::{Rolling, Stepping, Unrolled, Window};
use nc_plan::stream::{ProgramSource, Stages};
pub use nc_plan::verify::MAX_CYCLES;
use serde::Serialize;

pub mod operator;
pub mod restart;
pub mod script;
mod summary;
pub use summary::Summarizer;

/// A finished offline run.
pub struct Run {
    pub path: Path,
    pub profile: FeedProfile,
    pub setpoints: Vec<Setpoint>,
    pub method: Method,
}

/// Plan and interpolate a whole program.
pub fn run(program: &Program, setup: &MachineSetup, method: Method) -> Result<Run, ProgramError> {
    let path = build(program, &setup.kin, &setup.build)?;
    let profile = plan(&path, &setup.kin, &setup.plan)?;
    let setpoints = interpolate(&path, &profile, setup, method)?;
    Ok(Run {
        path,
        profile,
        setpoints,
        method,
    })
}

/// Every setpoint of a planned path, period by period, to the last (`done`); a run longer
/// than [`MAX_CYCLES`] is an error, not a truncated result. (`simulate` streams instead,
/// [`roll`]; this keeps the whole run, for `compare` and the tests.)
pub fn interpolate(
    path: &Path,
    profile: &FeedProfile,
    setup: &MachineSetup,
    method: Method,
) -> Result<Vec<Setpoint>, ProgramError> {
    let mut setpoints = Vec::with_capacity((profile.duration / setup.period) as usize + 2);
    let step = stepping(setup, method);
    let mut ip = Interpolator::new(
        path,
        profile,
        step.kin,
        step.lim,
        method,
        step.period,
        step.creep,
    );
    loop {
        let sp = ip.step();
        setpoints.push(sp);
        if sp.done || path.segments.is_empty() {
            return Ok(setpoints);
        }
        if sp.cycle >= MAX_CYCLES {
            return Err(ProgramError::Unfinished(MAX_CYCLES));
        }
    }
}

/// The rolling interpolator's stepping on `setup`'s machine with `method`.
pub fn stepping(setup: &MachineSetup, method: Method) -> Stepping {
    Stepping {
        kin: setup.kin,
        lim: setup.plan.rotary,
        method,
        period: setup.period,
        creep: setup.plan.path_acc * setup.period,
        speed_cap: setup.build.speed_cap(),
    }
}

/// A streamed simulation's end.
pub struct Rolled {
    pub rolling: Rolling,
    pub plan: Finished,
    /// Motion blocks planned (after compression).
    pub blocks: usize,
    pub compressed: Option<nc_fit::compress::Compressed>,
}

/// A program's entries through the compressor (when it is on), the stages and the rolling
/// interpolator.
pub fn roll<E: ProgramSource>(
    entries: E,
    setup: &MachineSetup,
    step: Stepping,
    take: impl FnMut(&Setpoint, Window),
) -> Result<Rolled, Unrolled> {
    let entries = Compressing::new(entries, &setup.kin, setup.compress);
    let mut stages = Stages::new(entries, setup.machine());
    let (rolling, plan) = nc_plan::rolling::interpolate(&mut stages, step, take)?;
    Ok(Rolled {
        rolling,
        plan,
        blocks: stages.blocks(),
        compressed: stages.entries().compressed(),
    })
}

/// Per-axis values in machine order (X Y Z, tilt, C).
pub type AxisMap = serde_json::Map<String, serde_json::Value>;

fn axis_map(names: &[&str; 5], values: [f64; 5]) -> AxisMap {
    names
        .iter()
        .zip(values)
        .map(|(n, v)| (n.to_string(), v.into()))
        .collect()
}

/// The summary `dnurbs simulate` prints (JSON keys documented in the README).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub machine: String,
    pub method: &'static str,
    pub blocks: usize,
    pub cycles: u64,
    pub period_s: f64,
    pub machining_time_s: f64,
    pub path_length: f64,
    pub feed_fluctuation_max: f64,
    pub feed_fluctuation_rms: f64,
    pub feed_fluctuation_periods: u64,
    pub chord_error_max_mm: f64,
    pub chord_tolerance_mm: f64,
    pub axis_velocity_fraction: AxisMap,
    pub axis_acceleration_fraction: AxisMap,
    /// Jerk as the planner's setpoint check measures it (`nc_plan::verify`: inside blocks and
    /// across G2-continuous junctions, by third differences at the period).
    pub axis_jerk_fraction: AxisMap,
    pub axis_travel_ok: bool,
    /// Each axis velocity and acceleration over its limit on these setpoints, at its
    /// largest. Empty when every one is within its limit: the plan is checked on the
    /// `arclength` setpoints, so only the Taylor methods (which drift from it) can fill it.
    pub limits_exceeded: Vec<Exceeded>,
    pub tool_axis_deviation_max_deg: f64,
    pub end_position_error_mm: f64,
    /// Spindle, coolant, tool, stop and dwell words, one line each (`crate::words`).
    pub program_words: Vec<String>,
    /// Feed moves that wait for the spindle's speed, and the time its ramps take there, s
    /// (from the commanded speeds and `[spindle] acceleration_rpm_s`; the drive's own
    /// settling adds to it). Not in `machining_time_s`. Absent without a `[spindle]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spindle_waits: Option<SpindleWaits>,
    /// What on-line compression did, when it was on.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compressed: Option<Compression>,
    /// `--from-line`: what the restart restored and its approach.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub restart: Option<restart::RestartNote>,
}

/// An axis over its velocity or acceleration limit ([`Summary::limits_exceeded`]): the
/// largest fraction of the limit, and the first setpoint that reaches it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Exceeded {
    pub axis: String,
    /// `velocity` or `acceleration`.
    pub quantity: &'static str,
    pub fraction: f64,
    /// The setpoint's time, its NC block (1-based) and the program line the block starts on.
    pub t_s: f64,
    pub block: u32,
    pub line: u32,
}

impl Summary {
    /// `within`, or each velocity and acceleration over its limit: `C acc 239.1% at 55.936 s`.
    pub fn limits_brief(&self) -> String {
        if self.limits_exceeded.is_empty() {
            return "within".into();
        }
        self.limits_exceeded
            .iter()
            .map(|e| {
                let q = if e.quantity == "velocity" {
                    "vel"
                } else {
                    "acc"
                };
                format!(
                    "{} {q} {:.1}% at {:.3} s",
                    e.axis,
                    e.fraction * 100.0,
                    e.t_s
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The summary's `limits` line: within, or each limit exceeded and where.
    fn limits_line(&self) -> String {
        if self.limits_exceeded.is_empty() {
            return "limits             axis velocity and acceleration within limits\n".into();
        }
        let each: Vec<String> = self
            .limits_exceeded
            .iter()
            .map(|e| {
                format!(
                    "{} {} {:.1}% at {:.3} s (block {}, line {})",
                    e.axis,
                    e.quantity,
                    e.fraction * 100.0,
                    e.t_s,
                    e.block,
                    e.line
                )
            })
            .collect();
        let why = if self.method == Method::ArcLength.name() {
            "the plan was checked on these setpoints: a planner fault, please report it".to_string()
        } else {
            format!(
                "the plan is checked on the arclength setpoints, which run sends; {} drifts from it",
                self.method
            )
        };
        format!(
            "limits             EXCEEDED by these {} setpoints: {}\n                   ({why})\n",
            self.method,
            each.join("; ")
        )
    }
}

/// See [`Summary::spindle_waits`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpindleWaits {
    pub count: u32,
    pub ramp_s: f64,
}

/// Arc length of the cutter curve between two parameters, integrated directly.
pub fn arc_between(curve: &DoubleNurbs, a: f64, b: f64) -> f64 {
    // Split at the knots so each piece is smooth, then 8-point Gauss-Legendre per piece.
    let (lo, hi) = (a.min(b), a.max(b));
    let mut cuts = vec![lo];
    cuts.extend(curve.knots().iter().copied().filter(|&k| k > lo && k < hi));
    cuts.push(hi);
    cuts.dedup();
    cuts.windows(2)
        .map(|w| {
            let (m, h) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
            GL8.iter()
                .map(|&(x, wt)| wt * curve.speed(m + h * x))
                .sum::<f64>()
                * h
        })
        .sum()
}

/// The measurements of a finished run (see [`Summarizer`], which takes them as the
/// setpoints come, without keeping them).
pub fn summarize(run: &Run, setup: &MachineSetup, blocks: usize) -> Summary {
    let mut s = Summarizer::new(setup);
    let whole = Window {
        segments: &run.path.segments,
        first: 0,
    };
    for sp in &run.setpoints {
        s.push(sp, whole);
    }
    let plan = Finished {
        length: run.profile.length,
        duration: run.profile.duration,
        margins: run.profile.margins,
    };
    s.finish(&plan, run.path.segments.last(), run.method, blocks)
}

impl Summary {
    /// The human-readable form printed without `--json`.
    pub fn text(&self) -> String {
        let fr = |m: &AxisMap| {
            m.iter()
                .map(|(k, v)| format!("{k} {:.1}%", v.as_f64().unwrap_or(f64::NAN) * 100.0))
                .collect::<Vec<_>>()
                .join("  ")
        };
        format!(
            "machine            {}\n\
             method             {}\n\
             blocks             {}\n\
             cycles             {} x {} ms\n\
             machining time     {:.3} s\n\
             path length        {:.4}\n\
             feed fluctuation   max {:.3e}  rms {:.3e}  over {} constant-feed periods\n\
             chord error        max {:.3e} mm (tolerance {} mm)\n\
             axis velocity      {}  (of limit)\n\
             axis acceleration  {}  (of limit)\n\
             axis jerk          {}  (of limit; inside blocks and over G2 junctions)\n\
             axis travel        {}\n\
             {}\
             tool axis at knots max deviation {:.3e} deg\n\
             end position error {:.3e} mm\n",
            self.machine,
            self.method,
            self.blocks,
            self.cycles,
            self.period_s * 1e3,
            self.machining_time_s,
            self.path_length,
            self.feed_fluctuation_max,
            self.feed_fluctuation_rms,
            self.feed_fluctuation_periods,
            self.chord_error_max_mm,
            self.chord_tolerance_mm,
            fr(&self.axis_velocity_fraction),
            fr(&self.axis_acceleration_fraction),
            fr(&self.axis_jerk_fraction),
            if self.axis_travel_ok {
                "within limits"
            } else {
                "OUTSIDE LIMITS"
            },
            self.limits_line(),
            self.tool_axis_deviation_max_deg,
            self.end_position_error_mm,
        ) + &self
            .spindle_waits
            .filter(|w| w.count > 0)
            .map(|w| {
                format!(
                    "spindle waits      {} feed moves wait for the spindle's speed: about {:.3} s of ramps, not in the machining time\n",
                    w.count, w.ramp_s
                )
            })
            .unwrap_or_default()
            + &self
                .compressed
                .map(|c| c.line())
                .unwrap_or_default()
            + &self.restart.as_ref().map(|r| r.text()).unwrap_or_default()
            + &crate::words::text(&self.program_words)
    }
}

/// [`nc_fit::compress::Compressed`] for the summary.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Compression {
    pub moves_in: usize,
    pub moves_fitted: usize,
    pub fitted_blocks: usize,
    pub runs_kept: usize,
    pub blocks_in: usize,
    pub blocks_out: usize,
    pub fit_mm: f64,
    pub fit_deg: f64,
}

impl Compression {
    /// The summary's and the run report's line.
    pub fn line(&self) -> String {
        format!(
            "compressed         {} of {} G01 moves into {} G06.5 blocks ({} motion blocks in, {} planned; runs left as G01: {}; largest fit deviation {:.2e} mm, {:.2e} deg)\n",
            self.moves_fitted,
            self.moves_in,
            self.fitted_blocks,
            self.blocks_in,
            self.blocks_out,
            self.runs_kept,
            self.fit_mm,
            self.fit_deg
        )
    }
}

impl From<nc_fit::compress::Compressed> for Compression {
    fn from(c: nc_fit::compress::Compressed) -> Self {
        Compression {
            moves_in: c.moves_in,
            moves_fitted: c.moves_fitted,
            fitted_blocks: c.fitted_blocks,
            runs_kept: c.runs_kept,
            blocks_in: c.blocks_in,
            blocks_out: c.blocks_out,
            fit_mm: c.fit_mm,
            fit_deg: c.fit_deg,
        }
    }
}

/// The trace's CSV header (documented in the README).
pub fn write_trace_header(w: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(w, "cycle,t,block,u,x,y,z,i,j,k,feed,X,Y,Z,A,C")
}

/// One setpoint as a row of the trace.
pub fn write_trace_row(w: &mut impl std::io::Write, s: &Setpoint) -> std::io::Result<()> {
    let u = s.u.map(|u| u.to_string()).unwrap_or_default();
    let q = &s.joints;
    writeln!(
        w,
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
        s.cycle,
        s.t,
        s.block,
        u,
        s.p.x,
        s.p.y,
        s.p.z,
        s.tool.x,
        s.tool.y,
        s.tool.z,
        s.feed * 60.0,
        q[0],
        q[1],
        q[2],
        q[3].to_degrees(),
        q[4].to_degrees()
    )
}
