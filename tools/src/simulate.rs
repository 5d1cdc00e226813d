//! `dnurbs simulate`: the interpolator run offline, period by period, exactly as the
//! real-time thread will run it, and the measurements that judge the result.
//!
//! The measurements are made independently of the interpolator's own shortcuts: arc length
//! per period is integrated afresh between the two setpoints' parameters (Gauss-Legendre on
//! |C'(u)|, not the arc-length table), the chord error is measured against the curve itself,
//! and the tool axis is recovered from the machine angles through forward kinematics.

use crate::setup::MachineSetup;
use nc::arclen::GL8;
use nc::interp::{Interpolator, Method, Setpoint};
use nc::kinematics::Kinematics;
use nc::nurbs::DoubleNurbs;
use nc::plan::{plan, FeedProfile, ProgramError};
use nc::program::Program;
use nc::segment::{build, Path, Tooling};
use nc::verify::dist_to_chord;
pub use nc::verify::MAX_CYCLES;
use serde::Serialize;
use std::collections::HashMap;

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
/// than [`MAX_CYCLES`] is an error, not a truncated result.
pub fn interpolate(
    path: &Path,
    profile: &FeedProfile,
    setup: &MachineSetup,
    method: Method,
) -> Result<Vec<Setpoint>, ProgramError> {
    let creep = setup.plan.path_acc * setup.period;
    let mut setpoints = Vec::with_capacity((profile.duration / setup.period) as usize + 2);
    let mut ip = Interpolator::new(
        path,
        profile,
        setup.kin,
        setup.plan.rotary,
        method,
        setup.period,
        creep,
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
    /// Jerk as the planner's setpoint check measures it (`nc::verify`: inside blocks and
    /// across G2-continuous junctions, by third differences at the period).
    pub axis_jerk_fraction: AxisMap,
    pub axis_travel_ok: bool,
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
}

/// See [`Summary::spindle_waits`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpindleWaits {
    pub count: u32,
    pub ramp_s: f64,
}

impl SpindleWaits {
    /// The waits of a path on a machine whose spindle ramps at `acc_rpm_s`.
    pub fn of(path: &nc::segment::Path, acc_rpm_s: f64) -> SpindleWaits {
        let (mut count, mut ramp_s, mut rpm) = (0, 0.0, 0.0);
        for seg in &path.segments {
            if seg.wait.spindle {
                count += 1;
                ramp_s += (seg.aux.spindle_rpm - rpm).abs() / acc_rpm_s;
            }
            rpm = seg.aux.spindle_rpm;
        }
        SpindleWaits { count, ramp_s }
    }
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

/// What the summary needs to know about one block's segments, found in one pass so the
/// summary stays linear in the program (it searched every segment for every setpoint).
#[derive(Default)]
struct BlockSegs<'a> {
    /// The block has a straight move (a setpoint without u belongs to it).
    line: bool,
    /// The block has a turn at rest (the cutter stands while the tool turns).
    turns: bool,
    /// The block's curve pieces in parameter order (`nc::split`).
    pieces: Vec<&'a DoubleNurbs>,
}

impl<'a> BlockSegs<'a> {
    /// Indexed by block number (blocks are numbered from 1 in program order, so the
    /// setpoints walk it in order: no hashing, no cache miss per setpoint).
    fn index(path: &'a Path) -> Vec<BlockSegs<'a>> {
        let n = path.segments.iter().map(|s| s.block as usize + 1).max();
        let mut map: Vec<BlockSegs<'a>> = Vec::new();
        map.resize_with(n.unwrap_or(0), BlockSegs::default);
        for s in &path.segments {
            let Some(b) = map.get_mut(s.block as usize) else {
                continue;
            };
            match s.nurbs() {
                Some((c, _)) => b.pieces.push(c),
                None if s.rotary_only => b.turns = true,
                None => b.line = true,
            }
        }
        map
    }

    /// The piece that holds parameter `u`: the first whose range reaches it, else the last.
    fn piece_at(&self, u: f64) -> Option<&'a DoubleNurbs> {
        let i = self.pieces.partition_point(|c| c.range().1 < u);
        self.pieces
            .get(i.min(self.pieces.len().saturating_sub(1)))
            .copied()
    }

    /// Arc length of the block's curve between two parameters, over the pieces they span.
    fn arc(&self, lo: f64, hi: f64) -> f64 {
        let first = self.pieces.partition_point(|c| c.range().1 <= lo);
        self.pieces[first..]
            .iter()
            .take_while(|c| c.range().0 < hi)
            .map(|c| {
                let (r0, r1) = c.range();
                arc_between(c, lo.max(r0), hi.min(r1))
            })
            .sum()
    }
}

pub fn summarize(run: &Run, setup: &MachineSetup, blocks: usize) -> Summary {
    let sps = &run.setpoints;
    let ts = setup.period;
    // A block may be several segments: pieces of a large or kinked curve (`nc::split`), a
    // turn at rest before it. A setpoint's u says which piece holds it; a line's setpoints
    // (no u) belong to the block's straight move.
    let index = BlockSegs::index(&run.path);
    let none = BlockSegs::default();
    let seg_of = |block: u32| index.get(block as usize).unwrap_or(&none);
    let (mut fmax, mut fsq, mut fn_) = (0.0f64, 0.0f64, 0u64);
    let mut chord = 0.0f64;
    for w in sps.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if a.block != b.block || b.done {
            continue;
        }
        let segs = seg_of(b.block);
        let ds = match (a.u, b.u) {
            (Some(ua), Some(ub)) => {
                for f in [0.25, 0.5, 0.75] {
                    let u = ua + (ub - ua) * f;
                    if let Some(curve) = segs.piece_at(u) {
                        let p = curve.cutter(u, 0).p;
                        chord = chord.max(dist_to_chord(&p, &a.p, &b.p));
                    }
                }
                segs.arc(ua.min(ub), ua.max(ub))
            }
            // A turn at rest in the block (the cutter stands, the tool turns) is no feed.
            (None, None) if segs.line && !(a.p == b.p && segs.turns) => (b.p - a.p).norm(),
            _ => continue,
        };
        if a.feed == b.feed && b.feed > 0.0 {
            let want = b.feed * ts;
            let f = (ds - want).abs() / want;
            fmax = fmax.max(f);
            fsq += f * f;
            fn_ += 1;
        }
    }
    // Axis velocity and acceleration by finite differences (rotary in degrees).
    let unit = |j: usize, x: f64| if j >= 3 { x.to_degrees() } else { x };
    let mut vfrac = [0.0f64; 5];
    let mut afrac = [0.0f64; 5];
    let mut travel_ok = true;
    for (k, sp) in sps.iter().enumerate() {
        for j in 0..5 {
            let q = unit(j, sp.joints[j]);
            let l = &setup.limits[j];
            travel_ok &= q >= l.min - 1e-9 && q <= l.max + 1e-9;
            if k >= 1 {
                let v = unit(j, sp.joints[j] - sps[k - 1].joints[j]) / ts;
                vfrac[j] = vfrac[j].max(v.abs() / l.velocity);
            }
            if k >= 2 {
                let a = unit(
                    j,
                    sp.joints[j] - 2.0 * sps[k - 1].joints[j] + sps[k - 2].joints[j],
                ) / (ts * ts);
                afrac[j] = afrac[j].max(a.abs() / l.acceleration);
            }
        }
    }
    // Tool axis at the knots: machine angles interpolated between the bracketing setpoints,
    // through forward kinematics, against the program's own CT(u) - C(u).
    let mut with_u: HashMap<u32, Vec<&Setpoint>> = HashMap::new();
    for sp in sps.iter().filter(|s| s.u.is_some()) {
        with_u.entry(sp.block).or_default().push(sp);
    }
    let mut tool_dev = 0.0f64;
    for seg in &run.path.segments {
        let (Some((curve, _)), Tooling::Curve) = (seg.nurbs(), &seg.tooling) else {
            continue;
        };
        let Some(mine) = with_u.get(&seg.block) else {
            continue;
        };
        let u = |s: &Setpoint| s.u.unwrap_or(0.0);
        let rising = mine.windows(2).all(|w| u(w[0]) <= u(w[1]));
        let mut knots: Vec<f64> = curve.knots().to_vec();
        knots.dedup();
        for &k in &knots {
            // The first pair of setpoints that brackets the knot (a binary search where u
            // only rises, as it does without holds).
            let w = if rising {
                let i = mine.partition_point(|s| u(s) < k).max(1) - 1;
                mine.get(i..i + 2).filter(|w| u(w[0]) <= k && k <= u(w[1]))
            } else {
                mine.windows(2).find(|w| u(w[0]) <= k && k <= u(w[1]))
            };
            let Some(w) = w else {
                continue;
            };
            let (ua, ub) = (u(w[0]), u(w[1]));
            let f = if ub > ua { (k - ua) / (ub - ua) } else { 0.0 };
            let j: [f64; 5] =
                core::array::from_fn(|i| w[0].joints[i] + (w[1].joints[i] - w[0].joints[i]) * f);
            let got = setup.kin.tool_axis(j[3], j[4]);
            let (_, d) = curve.cutter_and_tool(k, 0);
            let want = d.p.normalize();
            tool_dev = tool_dev.max(got.cross(&want).norm().atan2(got.dot(&want)).to_degrees());
        }
    }
    let end_err = match (sps.last(), run.path.segments.last()) {
        (Some(sp), Some(seg)) => (sp.p - seg.pose(seg.length).p).norm(),
        _ => 0.0,
    };
    let names = setup.axis_names;
    Summary {
        machine: setup.name.clone(),
        method: run.method.name(),
        blocks,
        cycles: sps.len() as u64,
        period_s: ts,
        machining_time_s: sps.last().map_or(0.0, |s| s.t),
        path_length: run.profile.length,
        feed_fluctuation_max: fmax,
        feed_fluctuation_rms: if fn_ > 0 {
            (fsq / fn_ as f64).sqrt()
        } else {
            0.0
        },
        feed_fluctuation_periods: fn_,
        chord_error_max_mm: chord,
        chord_tolerance_mm: setup.plan.chord_tol,
        axis_velocity_fraction: axis_map(&names, vfrac),
        axis_acceleration_fraction: axis_map(&names, afrac),
        axis_jerk_fraction: axis_map(&names, run.profile.margins.jerk),
        axis_travel_ok: travel_ok,
        tool_axis_deviation_max_deg: tool_dev,
        end_position_error_mm: end_err,
        program_words: Vec::new(),
        spindle_waits: None,
        compressed: None,
    }
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
            self.tool_axis_deviation_max_deg,
            self.end_position_error_mm,
        ) + &self
            .spindle_waits
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
            + &crate::words::text(&self.program_words)
    }
}

/// [`nc::fit::compress::Compressed`] for the summary.
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

impl From<nc::fit::compress::Compressed> for Compression {
    fn from(c: nc::fit::compress::Compressed) -> Self {
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

/// Write the trace CSV (header documented in the README).
pub fn write_trace(w: &mut impl std::io::Write, sps: &[Setpoint]) -> std::io::Result<()> {
    writeln!(w, "cycle,t,block,u,x,y,z,i,j,k,feed,X,Y,Z,A,C")?;
    for s in sps {
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
        )?;
    }
    Ok(())
}
