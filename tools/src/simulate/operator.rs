//! `simulate --operator SCRIPT`: the program through the real-time thread's own follower
//! (`nc_follow::Follower`, fed chunk by chunk by the planner's `Source`, as `run` feeds it),
//! on simulated time, with the script's actions taken as the operator's commands would be:
//! pause, resume, stop, override. Every setpoint is checked by finite differences at the
//! period against every axis's velocity and acceleration limit and its travel, holds and
//! override changes included; the trace is `simulate --trace`'s.

use super::script::{Act, Action, When};
use crate::setup::MachineSetup;
use nc_follow::{Chunk, Follower, Queues};
use nc_geom::setpoint::Setpoint;
use nc_plan::stream::{ProgramSource, Source, StreamError};

/// Most periods a replay runs (a day at 1 ms): a script that holds the override near 0
/// ends there rather than never.
const MAX_PERIODS: u64 = 86_400_000;

/// An action taken, when and where.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Taken {
    pub action: Action,
    pub t_s: f64,
    /// The source line the tool was machining.
    pub at_line: u32,
}

/// An axis over a limit: the worst fraction, when and where.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Over {
    pub axis: &'static str,
    pub quantity: &'static str,
    pub fraction: f64,
    pub t_s: f64,
    pub line: u32,
}

/// How the replay ended, and what the setpoints did.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Replay {
    pub taken: Vec<Taken>,
    /// Actions never reached (the program ended, or stopped, first).
    pub not_taken: usize,
    pub periods: u64,
    pub time_s: f64,
    /// `end` (the program's end), `stopped` (a stop), `paused` (paused or at an operator
    /// stop when the script had nothing more to do), `refused` (an error met ahead of the
    /// tool: it stopped along the path), `too long`.
    pub ending: &'static str,
    /// The source line where it ended.
    pub line: u32,
    /// Largest fraction of each axis's velocity and acceleration limit, of its jerk limit
    /// inside a segment, and the travel.
    pub velocity_fraction: [f64; 5],
    pub acceleration_fraction: [f64; 5],
    pub jerk_fraction: [f64; 5],
    pub over: Vec<Over>,
    pub outside_travel: Vec<&'static str>,
    /// Why the program was refused, if it was.
    pub refusal: Option<String>,
}

/// The planner's chunks, the first one already cut; stops at the first error (kept).
struct Chunks<'s, 'm, E: ProgramSource> {
    first: Option<Box<Chunk>>,
    source: &'s mut Source<'m, E>,
    error: Option<StreamError>,
}

impl<E: ProgramSource> Iterator for Chunks<'_, '_, E> {
    type Item = Box<Chunk>;
    fn next(&mut self) -> Option<Box<Chunk>> {
        if let Some(c) = self.first.take() {
            return Some(c);
        }
        if self.error.is_some() {
            return None;
        }
        match self.source.next_chunk() {
            Ok(c) => c,
            Err(e) => {
                self.error = Some(e);
                None
            }
        }
    }
}

/// Replays `script` over `entries` on `setup`, `depth` chunks held (the machine file's
/// `queue_depth`); `take` sees every setpoint. `Err` when the program gives no motion.
pub fn replay<E: ProgramSource>(
    entries: E,
    setup: &MachineSetup,
    depth: usize,
    script: &[Action],
    mut take: impl FnMut(&Setpoint),
) -> Result<Replay, StreamError> {
    let mut source = Source::new(entries, setup.machine(), depth);
    let first = source.next_chunk()?;
    let Some(start) = source.start() else {
        let kind = nc_geom::segment::BuildErrorKind::NoStart;
        let pos = nc_geom::program::SrcPos::default();
        return Err(StreamError::Build(nc_geom::segment::BuildError {
            pos,
            kind,
        }));
    };
    let mut queues = Queues::new();
    let (mut feeder, inlet) = queues.split(depth);
    let (kin, rotary, hold) = (setup.kin, setup.plan.rotary, setup.plan.hold());
    let mut f = Follower::new(inlet, start, kin, rotary, hold);
    let mut chunks = Chunks {
        first,
        source: &mut source,
        error: None,
    };
    let ts = setup.period;
    let mut check = Check::new(setup);
    let (mut next, mut last_action_t, mut taken) = (0usize, 0.0f64, Vec::new());
    let mut ending = "too long";
    let mut periods = 0;
    while periods < MAX_PERIODS {
        feeder.feed(&mut chunks);
        if let Some(e) = &chunks.error {
            feeder.refuse(e.pos().line);
        }
        let t = periods as f64 * ts;
        // The next action, once its moment has come (one a period, in the script's order).
        if let Some(a) = script.get(next) {
            let due = match a.when {
                When::At(at) => t + 0.5 * ts >= at,
                When::After(dt) => t + 0.5 * ts >= last_action_t + dt,
                When::Line(n) => f.line() >= n,
            };
            if due {
                match a.act {
                    Act::Pause => f.pause(),
                    Act::Resume => f.resume(),
                    Act::Stop => f.request_stop(),
                    Act::Override(p) => f.set_override(f64::from(p) / 100.0),
                }
                taken.push(Taken {
                    action: *a,
                    t_s: t,
                    at_line: f.line(),
                });
                last_action_t = t;
                next += 1;
            }
        }
        let sp = f.step();
        take(&sp);
        check.push(&sp, f.line(), f.segment_start());
        periods += 1;
        if sp.done {
            ending = "end";
            break;
        }
        if f.is_stopped() {
            ending = if f.refused().is_some() {
                "refused"
            } else {
                "stopped"
            };
            break;
        }
        let waiting = f.is_paused() || f.awaiting().is_some();
        if waiting && next >= script.len() && check.at_rest() {
            ending = "paused";
            break;
        }
    }
    feeder.feed(&mut std::iter::empty());
    let refusal = chunks.error.map(|e| e.to_string());
    Ok(check.finish(Replay {
        not_taken: script.len() - next,
        taken,
        periods,
        time_s: periods as f64 * ts,
        ending,
        line: f.line(),
        velocity_fraction: [0.0; 5],
        acceleration_fraction: [0.0; 5],
        jerk_fraction: [0.0; 5],
        over: Vec::new(),
        outside_travel: Vec::new(),
        refusal,
    }))
}

/// The worst (fraction, t, line) of each axis's velocity, acceleration and jerk over its
/// limit.
type Worst = [[Option<(f64, f64, u32)>; 3]; 5];

/// The setpoints' finite differences against the axes' limits, as they come.
struct Check {
    names: [&'static str; 5],
    limits: [config::AxisLimits; 5],
    ts: f64,
    /// The last three positions (mm, degrees), oldest first, and where the segment of each
    /// starts ([`Follower::segment_start`]).
    q: [Option<[f64; 5]>; 3],
    seg: [f64; 3],
    vfrac: [f64; 5],
    afrac: [f64; 5],
    jfrac: [f64; 5],
    worst: Worst,
    outside: [bool; 5],
    still: u32,
}

impl Check {
    fn new(setup: &MachineSetup) -> Self {
        Check {
            names: setup.axis_names,
            limits: setup.limits.clone(),
            ts: setup.period,
            q: [None; 3],
            seg: [f64::NAN; 3],
            vfrac: [0.0; 5],
            afrac: [0.0; 5],
            jfrac: [0.0; 5],
            worst: [[None; 3]; 5],
            outside: [false; 5],
            still: 0,
        }
    }

    fn push(&mut self, sp: &Setpoint, line: u32, seg: f64) {
        let q: [f64; 5] = core::array::from_fn(|j| {
            if j >= 3 {
                sp.joints[j].to_degrees()
            } else {
                sp.joints[j]
            }
        });
        let t = sp.cycle as f64 * self.ts;
        // The jerk inside one segment (over a junction that is not G2-continuous the plan's
        // own jerk is not limited).
        let one_segment = self.seg.iter().all(|&s| s == seg);
        for j in 0..5 {
            let l = &self.limits[j];
            self.outside[j] |= q[j] < l.min - 1e-9 || q[j] > l.max + 1e-9;
            let note = |k: usize, frac: f64, worst: &mut Worst| {
                // A hair over 1 is the setpoints' rounding.
                if frac > 1.0 + 1e-6 && worst[j][k].is_none_or(|w| frac > w.0) {
                    worst[j][k] = Some((frac, t, line));
                }
            };
            let ts = self.ts;
            if let Some(p) = self.q[2] {
                let v = (q[j] - p[j]).abs() / ts / l.velocity;
                self.vfrac[j] = self.vfrac[j].max(v);
                note(0, v, &mut self.worst);
                if let Some(pp) = self.q[1] {
                    let a = (q[j] - 2.0 * p[j] + pp[j]).abs() / (ts * ts) / l.acceleration;
                    self.afrac[j] = self.afrac[j].max(a);
                    note(1, a, &mut self.worst);
                    if let (Some(ppp), true) = (self.q[0], one_segment) {
                        let jk = (q[j] - 3.0 * p[j] + 3.0 * pp[j] - ppp[j]).abs() / ts.powi(3);
                        let jk = jk / l.jerk;
                        self.jfrac[j] = self.jfrac[j].max(jk);
                        note(2, jk, &mut self.worst);
                    }
                }
            }
        }
        self.still = if self.q[2] == Some(q) {
            self.still + 1
        } else {
            0
        };
        self.q = [self.q[1], self.q[2], Some(q)];
        self.seg = [self.seg[1], self.seg[2], seg];
    }

    /// Three periods without a move: at rest.
    fn at_rest(&self) -> bool {
        self.still >= 3
    }

    fn finish(self, mut r: Replay) -> Replay {
        r.velocity_fraction = self.vfrac;
        r.acceleration_fraction = self.afrac;
        r.jerk_fraction = self.jfrac;
        for (j, w) in self.worst.iter().enumerate() {
            for (k, quantity) in ["velocity", "acceleration", "jerk"].into_iter().enumerate() {
                if let Some((fraction, t_s, line)) = w[k] {
                    r.over.push(Over {
                        axis: self.names[j],
                        quantity,
                        fraction,
                        t_s,
                        line,
                    });
                }
            }
        }
        r.outside_travel = (0..5)
            .filter(|&j| self.outside[j])
            .map(|j| self.names[j])
            .collect();
        r
    }
}
