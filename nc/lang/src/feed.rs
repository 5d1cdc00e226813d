//! The feed: `F` in the mode in effect (`G94` mm/min, `G95` mm per revolution of the speed
//! in effect, `G93` inverse time on its own line), LinuxCNC's zero feed (`F0`, and `G94`/`G95`
//! without `F`), and the report of a feed above the machine's highest.

use super::error::{ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use crate::rules::MIN_FEED_MM_MIN;
use crate::vocab::Motion;
use nc_geom::program::{ActionKind, SrcPos};

impl Parser<'_> {
    /// `F`: mm/min (inch/min under G20); under G93 it belongs to its line only.
    pub(super) fn feed_word(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let Some(f) = line.get('F') else {
            return Ok(());
        };
        if f.value == 0.0 && !self.modal.inverse_time {
            // F0: no feed (LinuxCNC's feed rate 0; a feed move is refused).
            self.feed = None;
            self.feed_per_rev = None;
            return Ok(());
        }
        if f.value < MIN_FEED_MM_MIN {
            return Err(ParseErrorKind::BadFeed { value: f.value }.at(f.pos));
        }
        if self.modal.per_rev {
            // mm per revolution: the feed follows from the speed (see `rev_feed`).
            self.feed_per_rev = Some(f.value * self.modal.scale());
        } else if !self.modal.inverse_time {
            let feed = f.value * self.modal.scale();
            self.feed = Some(feed);
            self.report_clamp(feed, f.pos);
        }
        Ok(())
    }

    /// A feed above the machine's highest runs at it: said where it stands, once for each
    /// such feed (a post repeats its F).
    fn report_clamp(&mut self, feed: f64, pos: SrcPos) {
        if let Some(max) = self.setup.max_feed_mm_min.filter(|&m| feed > m) {
            if self.clamped != Some(feed) {
                self.clamped = Some(feed);
                let kind = ActionKind::FeedClamped {
                    programmed_mm_min: feed,
                    used_mm_min: max,
                };
                self.act(pos, kind);
            }
        }
    }

    /// Under `G95`: the feed, mm/min, from the feed per revolution and the spindle speed in
    /// effect (none while either is 0).
    pub(super) fn rev_feed(&mut self, pos: SrcPos) {
        if !self.modal.per_rev {
            return;
        }
        let rpm = self.modal.rpm;
        self.feed = self.feed_per_rev.filter(|_| rpm > 0.0).map(|f| f * rpm);
        if let Some(feed) = self.feed {
            self.report_clamp(feed, pos);
        }
    }

    /// The error of a feed move without a feed: under `G95`, a speed of 0 says so.
    pub(super) fn no_feed(&self, motion: Motion) -> ParseErrorKind {
        if self.modal.per_rev && self.feed_per_rev.is_some() {
            ParseErrorKind::PerRevWithoutSpeed { motion }
        } else {
            ParseErrorKind::NoFeed { motion }
        }
    }
}
