//! [`Cutter`]: chunks cut from a plan while it is made. It takes the planner's segments and
//! committed phases as they come ([`crate::plan::Sink`]) and gives a chunk once the phases
//! that cover it are final; [`super::cut`] runs it over a whole plan, so a streamed program
//! and a planned one are cut by the same code.

use crate::plan::Sink;
use nc_follow::{phase_vmax, Chunk, MAX_CHUNK_SEGMENTS, REST_V};
use nc_geom::scurve::Phase;
use nc_geom::segment::Segment;
use std::collections::VecDeque;

/// A run of consecutive segments no longer open to more: waiting for the phases over it.
struct Run {
    segments: Vec<Segment>,
    starts: Vec<f64>,
    s1: f64,
}

/// Cuts runs of consecutive segments at least `min_len` long (fewer if
/// [`MAX_CHUNK_SEGMENTS`] come first; a segment where the path waits for the operator or
/// the spindle starts one) and gives each the plan's phases over it.
pub struct Cutter {
    min_len: f64,
    /// The speed no chunk is planned above: every chunk's `vmax_ahead`.
    vmax_bound: f64,
    /// Source lines of the program (for each chunk's progress), if known.
    lines: Option<u32>,
    /// The run being filled, and where the next segment starts.
    open: Run,
    total: f64,
    closed: VecDeque<Run>,
    /// The phases received from the first that the next chunk can need.
    phases: VecDeque<Phase>,
    /// The last chunk cut, held until the next one's start says where the plan arrives.
    held: Option<Box<Chunk>>,
    ready: VecDeque<Box<Chunk>>,
    index: usize,
}

impl Cutter {
    /// `vmax_bound`: no planned speed is above it (`nc_geom::segment::BuildLimits::speed_cap`),
    /// which holds are scaled by before the plan is known ([`Chunk::vmax_ahead`]).
    pub fn new(min_len: f64, vmax_bound: f64) -> Self {
        Cutter {
            min_len,
            vmax_bound,
            lines: None,
            open: Run {
                segments: Vec::new(),
                starts: Vec::new(),
                s1: 0.0,
            },
            total: 0.0,
            closed: VecDeque::new(),
            phases: VecDeque::new(),
            held: None,
            ready: VecDeque::new(),
            index: 0,
        }
    }

    /// The program has `lines` source lines: each chunk's progress is the line of its
    /// first segment over it.
    pub fn set_lines(&mut self, lines: u32) {
        self.lines = Some(lines.max(1));
    }

    /// The next chunk cut, in order.
    pub fn next_chunk(&mut self) -> Option<Box<Chunk>> {
        self.ready.pop_front()
    }

    /// The plan is whole (it lasts `duration`): cut the rest; the last chunk says so.
    pub fn finish(&mut self, duration: f64) {
        self.close();
        while !self.closed.is_empty() {
            self.cut_front();
        }
        if let Some(mut c) = self.held.take() {
            c.t_end = c.t_end.min(duration);
            c.t_arrive = c.t_end;
            c.last = true;
            self.ready.push_back(c);
        }
    }

    fn close(&mut self) {
        if !self.open.segments.is_empty() {
            self.open.s1 = self.total;
            let run = core::mem::replace(
                &mut self.open,
                Run {
                    segments: Vec::new(),
                    starts: Vec::new(),
                    s1: 0.0,
                },
            );
            self.closed.push_back(run);
        }
    }

    /// Cut every closed run whose phases are all in: a phase that starts past its end has
    /// arrived.
    fn cut_ready(&mut self) {
        while let Some(run) = self.closed.front() {
            let eps = 1e-9 * run.s1.abs().max(1.0);
            if !self.phases.back().is_some_and(|p| p.s0 > run.s1 + eps) {
                break;
            }
            self.cut_front();
        }
    }

    /// The first closed run as a chunk, with the phases that cover it.
    fn cut_front(&mut self) {
        let Some(run) = self.closed.pop_front() else {
            return;
        };
        let s0 = run.starts.first().copied().unwrap_or(run.s1);
        let s1 = run.s1;
        let eps = 1e-9 * s1.abs().max(1.0);
        let ph = &mut self.phases;
        // Phases are in time order and s never decreases: skip those that end before s0.
        while ph.len() > 1 && ph[0].end().s < s0 - eps {
            ph.pop_front();
        }
        let mut last = 0;
        while last + 1 < ph.len() && ph[last + 1].s0 <= s1 + eps {
            last += 1;
        }
        let phases: Vec<Phase> = ph.range(..(last + 1).min(ph.len())).copied().collect();
        let t_end = phases.last().map_or(0.0, |p| p.t0 + p.dur);
        let vmax = phases.iter().map(phase_vmax).fold(0.0, f64::max);
        // The first phase that ends at or after s0, unless none does.
        let t_start = ph
            .front()
            .filter(|p| p.end().s >= s0 - eps)
            .map_or(0.0, |p| if p.s0 >= s0 - eps { p.t0 } else { p.t0 + p.dur });
        let progress = match (self.lines, run.segments.first()) {
            (Some(n), Some(seg)) => (f64::from(seg.src.line) / f64::from(n)).min(1.0),
            _ => 0.0,
        };
        let chunk = Box::new(Chunk {
            index: self.index,
            segments: run.segments,
            starts: run.starts,
            s0,
            s1,
            phases,
            t_end,
            t_start,
            vmax,
            vmax_ahead: self.vmax_bound.max(vmax),
            t_arrive: t_end,
            rests_at_end: false,
            last: false,
            progress,
        });
        self.index += 1;
        if let Some(mut prev) = self.held.replace(chunk) {
            let t = t_start;
            prev.t_arrive = t;
            prev.rests_at_end = prev
                .phases
                .iter()
                .find(|p| t <= p.t0 + p.dur)
                .is_some_and(|p| p.at((t - p.t0).clamp(0.0, p.dur)).v <= REST_V);
            self.ready.push_back(prev);
        }
    }
}

impl Sink for Cutter {
    fn segment(&mut self, seg: Segment) {
        let s = self.total;
        if let Some(&a) = self.open.starts.first() {
            let waits = seg.wait.operator.is_some() || seg.wait.spindle || seg.inputs[0].is_some();
            let long = s - a >= self.min_len;
            if waits || long || self.open.segments.len() >= MAX_CHUNK_SEGMENTS {
                self.close();
            }
        }
        self.total += seg.length;
        self.open.starts.push(s);
        self.open.segments.push(seg);
        self.cut_ready();
    }

    fn phases(&mut self, phases: &[Phase]) {
        self.phases.extend(phases.iter().copied());
        self.cut_ready();
    }
}
