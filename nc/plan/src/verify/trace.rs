//! Marks left along a check, so that the check of a later window resumes where the
//! committed plan's check left off instead of starting over ([`Trace`], [`Earlier`]).

use super::sample::Sample;
use super::Checked;
use crate::interp::Mark;
use nc_geom::limits::Margins;
use nc_geom::scurve::Phase;

/// Periods between two [`Trace`] marks.
pub(super) const MARK_EVERY: u64 = 256;

/// A check's state every [`MARK_EVERY`] periods, to start the next round's check where the
/// replanned profile first differs ([`check_from`]).
#[derive(Clone, Debug, Default)]
pub struct Trace {
    pub(super) marks: Vec<TraceMark>,
}

impl Trace {
    /// Forget the marks no later check will start from: all but the last before time `t`,
    /// when the plan before `t` is final (the planner's committed windows).
    pub fn forget_before(&mut self, t: f64) {
        let n = self.marks.partition_point(|m| m.win[3].t < t);
        self.marks.drain(..n.saturating_sub(1));
    }

    /// What a check resuming from the oldest mark reads behind it: the first segment its
    /// samples lie on, the first phase its cursors stand at, and the time of its oldest
    /// sample. None unless that mark's newest sample comes before time `until` (without
    /// one, a check starts from the program's start).
    pub fn oldest(&self, until: f64) -> Option<(usize, usize, f64)> {
        let m = self.marks.first().filter(|m| m.win[3].t < until)?;
        let seg = m.win.iter().chain(&m.older).map(|w| w.seg);
        let seg = seg.fold(m.ip.segment(), usize::min);
        Some((seg, m.cursor.min(m.ip.phase()), m.older[0].t))
    }

    /// The segments and phases before `segments` and `phases` are gone from the planner's
    /// buffers: every index the marks hold counts from there now. Nothing a mark points at
    /// may lie before them ([`Trace::oldest`]).
    pub fn rebase(&mut self, segments: usize, phases: usize) {
        for m in &mut self.marks {
            m.ip.rebase(segments, phases);
            m.cursor -= phases;
            for w in m.win.iter_mut().chain(&mut m.older) {
                w.seg -= segments;
            }
        }
    }
}

#[derive(Clone, Debug)]
pub(super) struct TraceMark {
    pub(super) ip: Mark,
    pub(super) win: [Sample; 4],
    /// The two samples before `win[0]`.
    pub(super) older: [Sample; 2],
    pub(super) cursor: usize,
    pub(super) margins: Margins,
    /// Violations recorded before the mark.
    pub(super) violations: usize,
}

/// A check of an earlier profile of the same path: its phases, result and trace.
pub struct Earlier<'a> {
    /// Phases before this index are the same in both profiles (the planner's committed
    /// windows), so the comparison starts there.
    pub offset: usize,
    /// The earlier profile's phases from `offset` on.
    pub phases: &'a [Phase],
    pub checked: &'a Checked,
    pub trace: &'a Trace,
}
