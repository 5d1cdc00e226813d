//! Planning in windows of bounded length, the planner's look-ahead, over a program that
//! arrives a segment at a time ([`Planner`]).
//!
//! A window runs from a joint where the plan so far arrives (its speed there, no
//! acceleration) over [`COMMIT_STOPS`] + 1 stopping distances of the path's top speed so far,
//! and ends at rest: whatever lies beyond it, the window's plan is one the machine can
//! follow to a stop. The window is scheduled and checked at the period (`crate::verify`,
//! resuming at the committed plan's last mark), and capped and planned again where a limit
//! breaks. Then the plan up to the first joint past [`COMMIT_STOPS`] stopping distances is
//! final, and the next window starts there. Since the next window reaches at least as far
//! ahead as this one did, it can always keep that speed in principle; where its check or
//! its stations say otherwise (a cap that needs a slower start), the previous window's own
//! plan, already checked to its stop, is taken as it is and the next window starts from
//! rest there: a stop the program did not ask for, but never a limit broken. A window that
//! starts at rest and cannot hold a limit refuses the program.
//!
//! **Streaming.** A window is planned as soon as the segments that have arrived reach its
//! end (a joint found from the path alone, never from how much of it has arrived), so the
//! plan is the same however the program is fed. What the plan has committed goes to a
//! [`Sink`] (the phases at once; each segment once nothing reads it any more), and the
//! buffers keep only what the next window's check reads: from the oldest mark of the last
//! check on (it resumes there), and the path of a few periods before it, for a corner's
//! stencil.
//! Every index into them is counted from the buffers' front, and moved when it drops. So
//! the memory is that of a window or two, whatever the program's length, and the time is
//! linear in the program.

use super::error::refuse;
use super::limits::section_limits;
use super::rounds::{Start, WindowPlan, Windows};
use super::stations::Sampler;
use super::{PlanError, Station};
use crate::config::PlanConfig;
use crate::profile::FeedProfile;
use crate::verify::{check_from, g2};
use nc_geom::kinematics::{Joints, MachineKinematics};
use nc_geom::limits::Margins;
use nc_geom::program::SrcPos;
use nc_geom::scurve::{change_dist, reachable, Phase};
use nc_geom::segment::{Path, Pose, Segment};

/// Stopping distances from the top speed that a window commits; one more lies ahead of
/// what it commits.
const COMMIT_STOPS: f64 = 3.0;
/// Periods of the plan kept before the oldest sample the next check reads: a corner's
/// stencil reads the plan up to four periods before the setpoints it measures.
const KEEP_PERIODS: f64 = 8.0;

/// Where the plan goes as it becomes final.
pub trait Sink {
    /// The next segment of the path, once nothing in the planner reads it any more (the
    /// plan over it is final then, and was sent).
    fn segment(&mut self, seg: Segment);
    /// The next phases of the plan, final.
    fn phases(&mut self, phases: &[Phase]);
}

/// What the whole plan came to ([`Planner::finish`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Finished {
    /// The path's length and the plan's duration.
    pub length: f64,
    pub duration: f64,
    /// The largest fractions of the limits the setpoints reach, over the whole plan.
    pub margins: Margins,
}

/// The highest ceiling and the largest linear-axis rates of the stations so far, for the
/// look-ahead distance.
#[derive(Default)]
struct Top {
    v: f64,
    dq: [f64; 3],
    /// Stations before this one are counted.
    scanned: usize,
}

impl Top {
    fn count(&mut self, st: &[Station], upto: usize) {
        for s in st.get(self.scanned..upto).unwrap_or(&[]) {
            self.v = self.v.max(s.vlim);
            for k in 0..3 {
                self.dq[k] = self.dq[k].max(s.d1(k));
            }
        }
        self.scanned = self.scanned.max(upto);
    }

    /// The look-ahead distance: a stop from the highest ceiling, at the path's acceleration
    /// and jerk shared as the sections share them (`super::section_limits`).
    fn reach(&self, cfg: &PlanConfig) -> f64 {
        let (mut a, mut j) = (cfg.path_acc, cfg.path_jerk);
        for (k, ax) in cfg.axes.iter().enumerate().take(3) {
            let dq = self.dq[k];
            if dq > 1e-15 {
                a = a.min(ax.acceleration / (2.0 * dq));
                j = j.min(ax.planned_jerk(cfg.period) / (2.0 * dq));
            }
        }
        change_dist(self.v, 0.0, a.max(1e-3), j.max(1e-3))
    }
}

/// The first joint after joint `starts[kc]` far enough ahead that a stop there does not
/// slow the plan at `starts[kc]`: going back from it at rest (the backward pass, over the
/// joints), the speed reaches a joint's own ceiling before `starts[kc]`. Looked for at
/// `reach`, twice that, and so on; None if the stations run out first.
fn window_end(
    st: &[Station],
    starts: &[usize],
    cfg: &PlanConfig,
    kc: usize,
    reach: f64,
    fixed: bool,
) -> Option<usize> {
    let c = starts[kc];
    let mut reach = reach.max(1e-9);
    loop {
        let ke = kc + 1 + starts[kc + 1..].partition_point(|&i| st[i].s < st[c].s + reach);
        let end = *starts.get(ke)?;
        if fixed {
            return Some(end);
        }
        let mut v = 0.0;
        for k in (kc..ke).rev() {
            let (a, b) = (starts[k], starts[k + 1]);
            let (acc, jerk) = section_limits(st, a, b, cfg);
            v = reachable(v, st[b].s - st[a].s, acc, jerk);
            if v >= st[a].vlim {
                return Some(end);
            }
        }
        reach *= 2.0;
    }
}

/// Plans a path given a segment at a time ([`Planner::push`], then [`Planner::finish`]).
pub struct Planner<'a> {
    kin: &'a MachineKinematics,
    cfg: &'a PlanConfig,
    /// Every window looks ahead just this far (the tests' short windows).
    fixed_reach: Option<f64>,
    /// Keep every segment, station and phase (the tests compare the plan with and without).
    keep_all: bool,
    /// The buffered segments (the path's start pose is the program's).
    path: Path,
    /// The buffered phases, and the start of each buffered segment and the buffer's end.
    profile: FeedProfile,
    st: Vec<Station>,
    starts: Vec<usize>,
    smooth: Vec<bool>,
    sampler: Sampler,
    top: Top,
    /// The look-ahead the last window found (none before the first).
    ahead: Option<f64>,
    from: Start,
    /// Phases before this index are final; those before `sent` went to the sink.
    committed: usize,
    sent: usize,
    /// The last window's checked plan, which covers the committed phases and goes on to a
    /// stop at `stop`.
    before: Option<WindowPlan>,
    stop: Start,
    /// No window is tried before the buffered path reaches this far (path units).
    wait_for: f64,
    pushed: usize,
    most_buffered: usize,
    done: bool,
}

impl<'a> Planner<'a> {
    /// A planner for the path that starts at `start` (pose, where it was programmed, joints).
    pub fn new(
        (start, start_src, start_joints): (Pose, SrcPos, Joints),
        kin: &'a MachineKinematics,
        cfg: &'a PlanConfig,
    ) -> Self {
        Planner {
            kin,
            cfg,
            fixed_reach: None,
            keep_all: false,
            path: Path {
                start,
                start_src,
                start_joints,
                segments: Vec::new(),
            },
            profile: FeedProfile {
                phases: Vec::new(),
                seg_start: vec![0.0],
                length: 0.0,
                duration: 0.0,
                margins: Margins::default(),
            },
            st: Vec::new(),
            starts: Vec::new(),
            smooth: Vec::new(),
            sampler: Sampler::new(start_joints),
            top: Top::default(),
            ahead: None,
            from: Start {
                station: 0,
                t: 0.0,
                v: 0.0,
            },
            committed: 0,
            sent: 0,
            before: None,
            stop: Start {
                station: 0,
                t: 0.0,
                v: 0.0,
            },
            wait_for: 0.0,
            pushed: 0,
            most_buffered: 0,
            done: false,
        }
    }

    /// Every window looks ahead just `reach` (path units) past what it commits, however
    /// much the stop at its end slows the plan (for the tests).
    pub fn looking_ahead(mut self, reach: f64) -> Self {
        self.fixed_reach = Some(reach);
        self
    }

    /// Drop nothing: the same plan from buffers that hold the whole path (for the tests).
    pub fn keeping_everything(mut self) -> Self {
        self.keep_all = true;
        self
    }

    /// The most segments the buffers held at once so far.
    pub fn most_buffered(&self) -> usize {
        self.most_buffered
    }

    /// The next segment of the path. Plans every window the path now reaches; what they
    /// commit goes to `sink`. An error refuses the program (the position of its block).
    pub fn push(&mut self, seg: Segment, sink: &mut impl Sink) -> Result<(), PlanError> {
        let (kin, cfg) = (self.kin, self.cfg);
        let smooth = self
            .path
            .segments
            .last()
            .is_none_or(|p| g2(p, &seg, kin, cfg));
        self.smooth.push(smooth);
        self.sampler
            .push(&seg, smooth, kin, cfg, &mut self.st, &mut self.starts);
        let s0 = self.profile.seg_start.last().copied().unwrap_or(0.0);
        self.profile.seg_start.push(s0 + seg.length);
        self.path.segments.push(seg);
        self.pushed += 1;
        self.most_buffered = self.most_buffered.max(self.path.segments.len());
        if s0 + self.path.segments.last().map_or(0.0, |s| s.length) < self.wait_for {
            return Ok(());
        }
        self.plan_ready(sink, false)
    }

    /// The path is complete: plan it to its end, send the rest to `sink`.
    pub fn finish(mut self, sink: &mut impl Sink) -> Result<Finished, PlanError> {
        let (kin, cfg) = (self.kin, self.cfg);
        if self.pushed == 0 {
            // Nothing to plan; the start pose itself is checked (its travel).
            let (checked, _) = check_from(&self.path, &self.profile, kin, cfg, &[], None);
            return match checked.violations.first() {
                None => Ok(Finished {
                    length: 0.0,
                    duration: 0.0,
                    margins: checked.margins,
                }),
                Some(v) => Err(refuse(&self.path, kin, cfg, v)),
            };
        }
        self.plan_ready(sink, true)?;
        self.committed = self.profile.phases.len();
        self.send(sink);
        for seg in self.path.segments.drain(..) {
            sink.segment(seg);
        }
        Ok(Finished {
            length: self.profile.length,
            duration: self.profile.duration,
            margins: self.profile.margins,
        })
    }

    /// Plan the windows the buffered path reaches (all of them once it is `complete`).
    fn plan_ready(&mut self, sink: &mut impl Sink, complete: bool) -> Result<(), PlanError> {
        let cfg = self.cfg;
        while !self.done {
            let last = self.st.len() - 1;
            // The last station is a joint still to be met by the next segment.
            self.top
                .count(&self.st, if complete { self.st.len() } else { last });
            let reach_min = self.fixed_reach.unwrap_or_else(|| self.top.reach(cfg));
            let ahead = *self.ahead.get_or_insert(reach_min);
            let (st, starts) = (&self.st, &self.starts);
            let s0 = st[self.from.station].s;
            // Joints after the start; the commit point and the window's end are joints.
            let k0 = starts.partition_point(|&i| i <= self.from.station);
            let kc = k0 + starts[k0..].partition_point(|&i| st[i].s < s0 + COMMIT_STOPS * ahead);
            let found = starts.get(kc).map(|&c| {
                // Looked for from half the last window's look-ahead: the path ahead is
                // likely much like the path behind.
                let from_reach = match self.fixed_reach {
                    Some(r) => r,
                    None => (0.5 * ahead).max(reach_min),
                };
                let end = window_end(st, starts, cfg, kc, from_reach, self.fixed_reach.is_some());
                (c, end)
            });
            let (c, end) = match found {
                Some((c, Some(end))) => (c, end),
                Some((c, None)) if complete => (c, last),
                None if complete => (last, last),
                _ => {
                    // Wait until the path ahead of the window's start has doubled: a
                    // window is tried a few times, not once a segment.
                    self.wait_for = st[last].s + (st[last].s - s0);
                    return Ok(());
                }
            };
            if found.is_some() {
                // The next window commits in proportion to what this one looked ahead.
                self.ahead = Some((st[end].s - st[c].s).max(reach_min));
            }
            self.window_to(c, end, sink)?;
        }
        Ok(())
    }

    /// Plan the window from the start to station `end`, and commit it up to station `c`.
    fn window_to(&mut self, c: usize, end: usize, sink: &mut impl Sink) -> Result<(), PlanError> {
        let w = Windows {
            path: &self.path,
            kin: self.kin,
            cfg: self.cfg,
            smooth: &self.smooth,
            starts: &self.starts,
        };
        let planned = w.window(
            &mut self.st,
            self.from,
            end,
            &mut self.profile,
            self.committed,
            self.before.as_ref(),
        )?;
        let profile = &mut self.profile;
        match planned {
            Some(mut done) => {
                if end == self.st.len() - 1 {
                    profile.margins = done.checked.margins;
                    self.done = true;
                    return Ok(());
                }
                // Commit up to the joint c; the window's stop is the fallback.
                let sc = self.st[c].s;
                let eps = 1e-9 * sc.abs().max(1.0);
                let split = done.phases.partition_point(|p| p.s0 < sc - eps);
                let next = done.phases[split];
                self.committed = done.offset + split;
                self.stop = Start {
                    station: end,
                    t: profile.duration,
                    v: 0.0,
                };
                self.from = Start {
                    station: c,
                    t: next.t0,
                    v: next.v0,
                };
                // A check resumes from a mark whose setpoints all come a period before
                // the change: the marks kept end two periods before the commit.
                done.trace.forget_before(next.t0 - 2.0 * self.cfg.period);
                self.before = Some(done);
                self.send(sink);
                if !self.keep_all {
                    self.drop_front(sink);
                }
            }
            None => {
                // The window cannot keep the committed speed: take the last window's plan
                // through its stop, and go on from rest there.
                let done = self
                    .before
                    .as_ref()
                    .expect("a window that starts moving follows a checked one");
                profile.phases.truncate(done.offset);
                profile.phases.extend_from_slice(&done.phases);
                profile.duration = self.stop.t;
                profile.length = self.st[self.stop.station].s;
                self.committed = profile.phases.len();
                self.from = self.stop;
                self.send(sink);
            }
        }
        Ok(())
    }

    fn send(&mut self, sink: &mut impl Sink) {
        if self.committed > self.sent {
            sink.phases(&self.profile.phases[self.sent..self.committed]);
            self.sent = self.committed;
        }
    }

    /// Drop what the next window's check no longer reads: the segments, stations and
    /// phases before the oldest mark of the last check (less a corner's stencil), the
    /// segments to the sink. Every index into the buffers moves with them.
    fn drop_front(&mut self, sink: &mut impl Sink) {
        let Some(before) = self.before.as_mut() else {
            return;
        };
        // Only a mark the next check can resume from (its setpoints all a period before
        // the first phase that can change) lets anything go.
        let usable_until = self.from.t - self.cfg.period;
        let Some((seg_mark, phase_mark, t_mark)) = before.trace.oldest(usable_until) else {
            return;
        };
        let t_keep = t_mark - KEEP_PERIODS * self.cfg.period;
        let phases = self
            .profile
            .phases
            .partition_point(|p| p.t0 <= t_keep)
            .saturating_sub(1)
            .min(phase_mark)
            .min(self.sent);
        // The segments from where the plan is at that time (no later than the first kept
        // phase's start): a corner's stencil reads the path there, and with segments
        // shorter than a period's travel that is several segments behind the mark's.
        let s_keep = self.profile.phases.get(phases).map_or(0.0, |p| p.s0);
        let at_keep = self
            .profile
            .seg_start
            .partition_point(|&x| x <= s_keep)
            .saturating_sub(1);
        let segs = seg_mark.min(at_keep).saturating_sub(1);
        let stations = self.starts[segs].min(self.from.station);
        if segs == 0 && phases == 0 && stations == 0 {
            return;
        }
        for seg in self.path.segments.drain(..segs) {
            sink.segment(seg);
        }
        self.smooth.drain(..segs);
        self.profile.seg_start.drain(..segs);
        self.starts.drain(..segs);
        for i in &mut self.starts {
            *i -= stations;
        }
        self.st.drain(..stations);
        self.profile.phases.drain(..phases);
        self.from.station -= stations;
        self.stop.station -= stations;
        self.top.scanned = self.top.scanned.saturating_sub(stations);
        self.committed -= phases;
        self.sent -= phases;
        before.trace.rebase(segs, phases);
        if before.offset >= phases {
            before.offset -= phases;
        } else {
            before.phases.drain(..phases - before.offset);
            before.offset = 0;
        }
    }
}
