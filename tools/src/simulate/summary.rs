//! The measurements of a run, taken a setpoint at a time: [`Summarizer::push`] keeps only
//! the last two setpoints and running maxima, so `dnurbs simulate` needs no memory for the
//! setpoints however long the program (at 10^6 G01 moves they were 2.4 M, the run's largest
//! allocation).

use super::{arc_between, axis_map, Exceeded, SpindleWaits, Summary};
use crate::setup::MachineSetup;
use nc_geom::kinematics::Kinematics;
use nc_geom::nurbs::DoubleNurbs;
use nc_geom::segment::{Segment, Tooling};
use nc_geom::setpoint::Setpoint;
use nc_plan::interp::Method;
use nc_plan::plan::Finished;
use nc_plan::rolling::Window;
use nc_plan::verify::dist_to_chord;

/// What the summary needs to know about the block the setpoints are in, loaded when they
/// enter it: the setpoints walk the blocks in order, so a cursor over the segments finds
/// each block's once. The block's curve pieces are copied out of the path (the window of it
/// that a streamed run holds may let go of them before the block ends), and nothing is kept
/// per block of the program.
#[derive(Default)]
struct BlockSegs {
    /// Block number (0 before the first is loaded).
    number: u32,
    /// The program line the block starts on.
    src_line: u32,
    /// Every segment of the block has been seen (a later block's came after them).
    complete: bool,
    /// The block has a straight move (a setpoint without u belongs to it).
    line: bool,
    /// The block has a turn at rest (the cutter stands while the tool turns).
    turns: bool,
    /// The block's curve pieces in parameter order (`nc_geom::split`).
    pieces: Vec<DoubleNurbs>,
    /// The distinct knots of each piece whose tool axis is its orientation curve, with
    /// the piece's index and whether the tool axis has been measured there, sorted by knot.
    knots: Vec<(f64, usize, bool)>,
}

/// Spindle waits counted over the segments as they pass ([`SpindleWaits`]).
#[derive(Clone, Copy, Default)]
struct SpindleTally {
    count: u32,
    /// Sum of the speed changes at the waits, rpm.
    steps_rpm: f64,
    /// The speed the spindle last reached: at the last wait, or 0 once stopped. (Rapids
    /// after a start do not wait, so the speed they carry is not yet reached.)
    rpm: f64,
}

impl SpindleTally {
    fn add(&mut self, seg: &Segment) {
        if seg.wait.spindle {
            self.count += 1;
            self.steps_rpm += (seg.aux.spindle_rpm - self.rpm).abs();
            self.rpm = seg.aux.spindle_rpm;
        } else if seg.aux.spindle_rpm == 0.0 {
            self.rpm = 0.0;
        }
    }
}

impl BlockSegs {
    /// Make this block `number`'s (or go on loading it), from the segments at `*cursor` on
    /// (an index into the whole path; `window` holds its segments from `window.first`); the
    /// cursor is left at the first segment not yet seen. Every segment passed is tallied.
    fn load(&mut self, window: Window, cursor: &mut usize, number: u32, tally: &mut SpindleTally) {
        let seg_at = |i: usize| {
            i.checked_sub(window.first)
                .and_then(|k| window.segments.get(k))
        };
        // Segments behind the window are those of blocks already left.
        *cursor = (*cursor).max(window.first);
        while let Some(s) = seg_at(*cursor).filter(|s| s.block < number) {
            tally.add(s);
            *cursor += 1;
        }
        if number != self.number {
            self.number = number;
            self.src_line = seg_at(*cursor)
                .filter(|s| s.block == number)
                .map_or(0, |s| s.src.line);
            self.complete = false;
            self.line = false;
            self.turns = false;
            self.pieces.clear();
            self.knots.clear();
        }
        let seen = *cursor;
        while let Some(s) = seg_at(*cursor).filter(|s| s.block == number) {
            tally.add(s);
            *cursor += 1;
            match s.nurbs() {
                Some((c, _)) => {
                    if matches!(s.tooling, Tooling::Curve) {
                        let mut knots = c.knots().to_vec();
                        knots.dedup();
                        let piece = self.pieces.len();
                        self.knots
                            .extend(knots.into_iter().map(|k| (k, piece, false)));
                    }
                    self.pieces.push(c.clone());
                }
                None if s.rotary_only => self.turns = true,
                None => self.line = true,
            }
        }
        self.complete = seg_at(*cursor).is_some();
        if *cursor > seen {
            self.knots.sort_by(|x, y| x.0.total_cmp(&y.0));
        }
    }

    /// The piece that holds parameter `u`: the first whose range reaches it, else the last.
    fn piece_at(&self, u: f64) -> Option<&DoubleNurbs> {
        let i = self.pieces.partition_point(|c| c.range().1 < u);
        self.pieces.get(i.min(self.pieces.len().saturating_sub(1)))
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

/// The measurements of one run, fed its setpoints in order.
pub struct Summarizer<'a> {
    setup: &'a MachineSetup,
    /// The block of the newest setpoint, and the first segment not yet seen.
    block: BlockSegs,
    cursor: usize,
    spindle: SpindleTally,
    /// The last two setpoints, newest last.
    last: [Option<Setpoint>; 2],
    /// The newest setpoint with a curve parameter, and its block.
    last_u: Option<Setpoint>,
    cycles: u64,
    fmax: f64,
    fsq: f64,
    fn_: u64,
    chord: f64,
    /// Each axis's largest velocity and acceleration fraction, and where.
    vfrac: [Worst; 5],
    afrac: [Worst; 5],
    travel_ok: bool,
    tool_dev: f64,
}

impl<'a> Summarizer<'a> {
    pub fn new(setup: &'a MachineSetup) -> Summarizer<'a> {
        Summarizer {
            setup,
            block: BlockSegs::default(),
            cursor: 0,
            spindle: SpindleTally::default(),
            last: [None, None],
            last_u: None,
            cycles: 0,
            fmax: 0.0,
            fsq: 0.0,
            fn_: 0,
            chord: 0.0,
            vfrac: [Worst::default(); 5],
            afrac: [Worst::default(); 5],
            travel_ok: true,
            tool_dev: 0.0,
        }
    }

    /// Take the next setpoint; `window` holds the path's segments from the setpoint's (or
    /// an earlier one) on ([`nc_plan::rolling::Rolling`], or the whole path).
    pub fn push(&mut self, sp: &Setpoint, window: Window) {
        if sp.block != self.block.number || !self.block.complete {
            self.block
                .load(window, &mut self.cursor, sp.block, &mut self.spindle);
        }
        if let Some(a) = self.last[1] {
            self.feed_and_chord(&a, sp);
        }
        self.axes(sp);
        self.tool_at_knots(sp);
        self.last = [self.last[1], Some(*sp)];
        self.cycles += 1;
    }

    /// Feed fluctuation (arc length per period integrated afresh on the curve, not the
    /// table) and the chord error at three points between two setpoints.
    fn feed_and_chord(&mut self, a: &Setpoint, b: &Setpoint) {
        if a.block != b.block || b.done {
            return;
        }
        // A block may be several segments: pieces of a large or kinked curve
        // (`nc_geom::split`), a turn at rest before it. A setpoint's u says which piece holds
        // it; a line's setpoints (no u) belong to the block's straight move.
        let segs = &self.block;
        let ds = match (a.u, b.u) {
            (Some(ua), Some(ub)) => {
                for f in [0.25, 0.5, 0.75] {
                    let u = ua + (ub - ua) * f;
                    if let Some(curve) = segs.piece_at(u) {
                        let p = curve.cutter(u, 0).p;
                        self.chord = self.chord.max(dist_to_chord(&p, &a.p, &b.p));
                    }
                }
                segs.arc(ua.min(ub), ua.max(ub))
            }
            // A turn at rest in the block (the cutter stands, the tool turns) is no feed.
            (None, None) if segs.line && !(a.p == b.p && segs.turns) => (b.p - a.p).norm(),
            _ => return,
        };
        if a.feed == b.feed && b.feed > 0.0 {
            let want = b.feed * self.setup.period;
            let f = (ds - want).abs() / want;
            self.fmax = self.fmax.max(f);
            self.fsq += f * f;
            self.fn_ += 1;
        }
    }

    /// Axis velocity and acceleration by finite differences (rotary in degrees), and the
    /// travel.
    fn axes(&mut self, sp: &Setpoint) {
        let ts = self.setup.period;
        let unit = |j: usize, x: f64| if j >= 3 { x.to_degrees() } else { x };
        for j in 0..5 {
            let q = unit(j, sp.joints[j]);
            let l = &self.setup.limits[j];
            self.travel_ok &= q >= l.min - 1e-9 && q <= l.max + 1e-9;
            if let Some(p1) = &self.last[1] {
                let v = unit(j, sp.joints[j] - p1.joints[j]) / ts;
                self.vfrac[j].take(v.abs() / l.velocity, sp, self.block.src_line);
                if let Some(p2) = &self.last[0] {
                    let a = unit(j, sp.joints[j] - 2.0 * p1.joints[j] + p2.joints[j]) / (ts * ts);
                    self.afrac[j].take(a.abs() / l.acceleration, sp, self.block.src_line);
                }
            }
        }
    }

    /// Tool axis at the knots: machine angles interpolated between the first two
    /// consecutive setpoints of the block (with a curve parameter) whose parameters
    /// bracket the knot, through forward kinematics, against the program's own
    /// CT(u) - C(u).
    fn tool_at_knots(&mut self, sp: &Setpoint) {
        let Some(ub) = sp.u else {
            return;
        };
        let prev = self.last_u.replace(*sp).filter(|p| p.block == sp.block);
        let Some(a) = prev else {
            return;
        };
        let ua = a.u.unwrap_or(0.0);
        let (knots, pieces) = (&mut self.block.knots, &self.block.pieces);
        if ua > ub || knots.is_empty() {
            return; // a falling pair brackets nothing
        }
        let from = knots.partition_point(|&(k, _, _)| k < ua);
        for (k, piece, done) in knots[from..].iter_mut() {
            if *k > ub {
                break;
            }
            if *done {
                continue;
            }
            *done = true;
            let k = *k;
            let f = if ub > ua { (k - ua) / (ub - ua) } else { 0.0 };
            let j: [f64; 5] =
                core::array::from_fn(|i| a.joints[i] + (sp.joints[i] - a.joints[i]) * f);
            let got = self.setup.kin.tool_axis(j[3], j[4]);
            let (_, d) = pieces[*piece].cutter_and_tool(k, 0);
            let want = d.p.normalize();
            let dev = got.cross(&want).norm().atan2(got.dot(&want)).to_degrees();
            self.tool_dev = self.tool_dev.max(dev);
        }
    }

    /// The spindle waits of the segments the setpoints passed, its ramps at `acc_rpm_s`.
    pub fn spindle_waits(&self, acc_rpm_s: f64) -> SpindleWaits {
        SpindleWaits {
            count: self.spindle.count,
            ramp_s: self.spindle.steps_rpm / acc_rpm_s,
        }
    }

    /// The summary of the setpoints pushed, over a plan that came to `plan` on a path whose
    /// last segment is `last_seg`.
    pub fn finish(
        self,
        plan: &Finished,
        last_seg: Option<&Segment>,
        method: Method,
        blocks: usize,
    ) -> Summary {
        let last = self.last[1];
        let end_err = match (last, last_seg) {
            (Some(sp), Some(seg)) => (sp.p - seg.pose(seg.length).p).norm(),
            _ => 0.0,
        };
        let names = self.setup.axis_names;
        Summary {
            machine: self.setup.name.clone(),
            method: method.name(),
            blocks,
            cycles: self.cycles,
            period_s: self.setup.period,
            machining_time_s: last.map_or(0.0, |s| s.t),
            path_length: plan.length,
            feed_fluctuation_max: self.fmax,
            feed_fluctuation_rms: if self.fn_ > 0 {
                (self.fsq / self.fn_ as f64).sqrt()
            } else {
                0.0
            },
            feed_fluctuation_periods: self.fn_,
            chord_error_max_mm: self.chord,
            chord_tolerance_mm: self.setup.plan.chord_tol,
            axis_velocity_fraction: axis_map(&names, self.vfrac.map(|w| w.frac)),
            axis_acceleration_fraction: axis_map(&names, self.afrac.map(|w| w.frac)),
            limits_exceeded: exceeded(&names, &self.vfrac, &self.afrac),
            // The check measures the jerk against the planned jerk; the summary's fraction
            // is of the axis's limit, like the others.
            axis_jerk_fraction: axis_map(
                &names,
                core::array::from_fn(|j| {
                    let ax = &self.setup.plan.axes[j];
                    plan.margins.jerk[j] * ax.planned_jerk(self.setup.plan.period) / ax.jerk
                }),
            ),
            axis_travel_ok: self.travel_ok,
            tool_axis_deviation_max_deg: self.tool_dev,
            end_position_error_mm: end_err,
            program_words: Vec::new(),
            restart: None,
            spindle_waits: None,
            compressed: None,
        }
    }
}

/// The largest fraction of a limit one axis reaches, and the setpoint where it first does.
#[derive(Clone, Copy, Default)]
struct Worst {
    frac: f64,
    t: f64,
    block: u32,
    line: u32,
}

impl Worst {
    fn take(&mut self, frac: f64, sp: &Setpoint, line: u32) {
        if frac > self.frac {
            *self = Worst {
                frac,
                t: sp.t,
                block: sp.block,
                line,
            };
        }
    }
}

/// A fraction above this is over the limit (the rounding of the finite differences
/// themselves stays far below it).
const OVER: f64 = 1.0 + 1e-6;

/// The velocities and accelerations over their limits, velocity first, in axis order.
fn exceeded(names: &[&str; 5], v: &[Worst; 5], a: &[Worst; 5]) -> Vec<Exceeded> {
    let each = |quantity: &'static str, w: &[Worst; 5]| {
        names
            .iter()
            .zip(w)
            .filter(|(_, w)| w.frac > OVER)
            .map(|(axis, w)| Exceeded {
                axis: axis.to_string(),
                quantity,
                fraction: w.frac,
                t_s: w.t,
                block: w.block,
                line: w.line,
            })
            .collect::<Vec<_>>()
    };
    let mut out = each("velocity", v);
    out.extend(each("acceleration", a));
    out
}
