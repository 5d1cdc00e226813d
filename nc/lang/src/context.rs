//! `M70`..`M73`: the modal state saved and restored, as LinuxCNC does it. `M70` saves it,
//! `M72` restores it (and forgets it), `M71` forgets it; `M73` in a subroutine saves it and
//! the return restores it. What is saved: units, plane, distance and arc-centre modes, feed
//! mode and feed, the work offset, path control, the cycles' return level, the spindle's
//! direction and speed and the coolant (a restore that changes these is an action, as the
//! words would be). Not saved: the position, the tool and its length, the motion mode.

use super::codes::{Code, ContextCode};
use super::error::{ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use crate::saved::Saved;
use nc_geom::program::{ActionKind, Coolant, Spindle, SrcPos};

impl Parser<'_> {
    fn snapshot(&self, pos: SrcPos) -> Saved {
        let m = &self.modal;
        Saved {
            plane: m.plane,
            inch: m.inch,
            incremental: m.incremental,
            inverse_time: m.inverse_time,
            per_rev: m.per_rev,
            feed_per_rev: self.feed_per_rev,
            arc_absolute: m.arc_absolute,
            path: m.path,
            retract_to_r: m.cycle.retract_to_r,
            work: m.work,
            feed: self.feed,
            spindle: m.spindle,
            rpm: m.rpm,
            mist: m.mist,
            flood: m.flood,
            pos,
        }
    }

    /// The line's `M70`..`M73`, if any.
    pub(super) fn context(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let Some((Code::Context(code), pos)) = line.code_of_group(18) else {
            return Ok(());
        };
        match code {
            ContextCode::Save => self.saved.m70 = Some(self.snapshot(pos)),
            ContextCode::Invalidate => self.saved.m70 = None,
            ContextCode::Restore => {
                let saved = self
                    .saved
                    .m70
                    .take()
                    .ok_or(ParseErrorKind::NothingSaved.at(pos))?;
                self.restore(&saved, pos);
            }
            ContextCode::AutoRestore => {
                let level = self.level;
                let saved = self.snapshot(pos);
                self.saved.m73.retain(|(l, _)| *l != level);
                self.saved.m73.push((level, saved));
            }
        }
        Ok(())
    }

    /// The modal state as `saved` has it; actions for the path-control mode, the spindle and
    /// the coolant it changes.
    fn restore(&mut self, saved: &Saved, pos: SrcPos) {
        let m = &mut self.modal;
        m.plane = saved.plane;
        m.inch = saved.inch;
        m.incremental = saved.incremental;
        m.inverse_time = saved.inverse_time;
        m.per_rev = saved.per_rev;
        m.arc_absolute = saved.arc_absolute;
        if m.path != saved.path {
            m.path = saved.path;
            self.act(pos, ActionKind::PathMode(saved.path));
        }
        let m = &mut self.modal;
        m.cycle.retract_to_r = saved.retract_to_r;
        if m.work != saved.work {
            // The offset it was saved with is defined (it was selected then).
            let work = self
                .work_offsets
                .get(usize::from(saved.work))
                .copied()
                .flatten()
                .unwrap_or([0.0; 3]);
            m.offset = std::array::from_fn(|k| work[k] + m.g92[k]);
            m.work = saved.work;
        }
        self.feed = saved.feed;
        self.feed_per_rev = saved.feed_per_rev;
        let (spindle, rpm) = (self.modal.spindle, self.modal.rpm);
        self.modal.spindle = saved.spindle;
        self.modal.rpm = saved.rpm;
        if spindle != saved.spindle || (saved.spindle != Spindle::Off && rpm != saved.rpm) {
            let kind = ActionKind::Spindle {
                dir: saved.spindle,
                rpm: saved.rpm,
            };
            self.act(pos, kind);
        } else if rpm != saved.rpm {
            self.act(pos, ActionKind::Speed { rpm: saved.rpm });
        }
        let (mist, flood) = (self.modal.mist, self.modal.flood);
        if (mist && !saved.mist) || (flood && !saved.flood) {
            self.act(pos, ActionKind::Coolant(Coolant::Off));
            (self.modal.mist, self.modal.flood) = (false, false);
        }
        if saved.mist && !self.modal.mist {
            self.act(pos, ActionKind::Coolant(Coolant::Mist));
        }
        if saved.flood && !self.modal.flood {
            self.act(pos, ActionKind::Coolant(Coolant::Flood));
        }
        (self.modal.mist, self.modal.flood) = (saved.mist, saved.flood);
    }

    /// The interpreter is at call level `level` now: a return from a level an `M73` saved
    /// at restores what it saved.
    pub(super) fn at_level(&mut self, level: usize) {
        self.level = level;
        let mut restore = None;
        self.saved.m73.retain(|(l, s)| {
            if *l > level {
                // The outermost one a return passes is the one that applies.
                if restore.is_none_or(|(rl, _): (usize, Saved)| *l < rl) {
                    restore = Some((*l, *s));
                }
                false
            } else {
                true
            }
        });
        if let Some((_, saved)) = restore {
            self.restore(&saved, saved.pos);
        }
    }
}
