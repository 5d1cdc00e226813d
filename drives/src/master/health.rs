//! The bus's own health, beside the drives': what the CAN controller reports in error frames
//! and what a full transmit queue costs, turned each period into a condition and the
//! reaction it calls for. Sans-I/O and allocation-free: [`BusHealth::update`] takes the
//! link's counts and the frames the period's send dropped.
//!
//! | condition | reaction |
//! |---|---|
//! | error warning, controller overflow, protocol or bus errors, no ACK, one period's dropped frames | [`Reaction::Warn`]: counted, in the report |
//! | error passive; lost arbitration in [`ARBITRATION_STORM_PERIODS`] periods in a row | [`Reaction::Hold`]: feed hold along the path; the operator resumes |
//! | TX timeout; frames dropped in [`TX_FULL_PERIODS`] periods in a row (`ENOBUFS`) | [`Reaction::Stop`]: controlled stop along the path, drives disabled |
//! | bus-off; controller restarted; the interface down (`ENETDOWN`, `ENODEV`) | [`Reaction::QuickStop`]: the master's fault, every drive's quick stop (0x605A), then disabled |
//!
//! An error-passive controller still reaches the drives, but its next errors take it off
//! the bus: the path is brought to rest while frames still arrive. A frame that stays
//! unsent (TX timeout) or a transmit queue that stays full means targets are missing at the
//! drives: the path stops along itself while it still can. After bus-off or a restart (its
//! queued frames lost) the master cannot command a path; each drive stops by its own ramp,
//! and by its own protections (following error 0x6065/0x6066, fault reaction 0x605E) if
//! nothing reaches it at all.

use crate::link::BusErrors;

/// Periods in a row with lost arbitration that make a storm (a node flooding the bus with
/// ids below the master's).
pub const ARBITRATION_STORM_PERIODS: u32 = 10;
/// Periods in a row with dropped frames (a full transmit queue) before the path stops.
pub const TX_FULL_PERIODS: u32 = 3;

/// What the controller does about a bus condition, mildest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Reaction {
    /// Counted and named in the report; the run goes on.
    Warn,
    /// Feed hold: the path decelerates to rest along itself, the drives stay enabled; the
    /// operator resumes (`dnurbs ctl resume`) once the bus is sound.
    Hold,
    /// Controlled stop: along the path to rest, then the drives are disabled.
    Stop,
    /// Quick stop: every drive by its quick-stop ramp, then disabled (the master's fault).
    QuickStop,
}

impl Reaction {
    /// Its name in reports and docs.
    pub fn name(self) -> &'static str {
        match self {
            Reaction::Warn => "warning",
            Reaction::Hold => "feed hold",
            Reaction::Stop => "controlled stop",
            Reaction::QuickStop => "quick stop",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// A bus condition met in one period.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BusCondition {
    #[error("CAN controller at error warning level")]
    Warning,
    #[error("CAN controller overflow (frames lost in the controller)")]
    Overflow,
    #[error("CAN protocol or bus errors")]
    Protocol,
    #[error("{0} frames dropped: transmit queue full (ENOBUFS)")]
    TxDropped(u32),
    #[error("CAN controller error passive")]
    Passive,
    #[error("lost arbitration in {0} periods in a row (a node floods the bus)")]
    ArbitrationStorm(u32),
    #[error("TX timeout: a frame was not sent in time")]
    TxTimeout,
    #[error("transmit queue full in {0} periods in a row (ENOBUFS): targets missing")]
    TxFull(u32),
    #[error("bus-off: the CAN controller has left the bus")]
    BusOff,
    #[error("CAN controller restarted: frames in flight lost")]
    Restarted,
}

impl BusCondition {
    pub fn reaction(&self) -> Reaction {
        match self {
            BusCondition::Warning
            | BusCondition::Overflow
            | BusCondition::Protocol
            | BusCondition::TxDropped(_) => Reaction::Warn,
            BusCondition::Passive | BusCondition::ArbitrationStorm(_) => Reaction::Hold,
            BusCondition::TxTimeout | BusCondition::TxFull(_) => Reaction::Stop,
            BusCondition::BusOff | BusCondition::Restarted => Reaction::QuickStop,
        }
    }
}

/// What the master has seen of the bus.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BusHealth {
    /// The link's counts at the last update.
    seen: BusErrors,
    drops_in_a_row: u32,
    arbitration_in_a_row: u32,
    /// Periods whose worst condition called for each reaction, mildest first.
    reactions: [u64; 4],
    /// The worst condition so far.
    worst: Option<BusCondition>,
}

impl BusHealth {
    /// One period: the link's error counts now and the frames the last send dropped.
    /// Returns the period's most severe condition, if it has one. A storm and a full queue
    /// are reported on the period they begin, not on every period they last.
    pub fn update(&mut self, now: BusErrors, dropped: usize) -> Option<BusCondition> {
        let d = now.since(&self.seen);
        self.seen = now;
        let dropped = u32::try_from(dropped).unwrap_or(u32::MAX);
        self.drops_in_a_row = if dropped > 0 {
            self.drops_in_a_row.saturating_add(1)
        } else {
            0
        };
        self.arbitration_in_a_row = if d.lost_arbitration > 0 {
            self.arbitration_in_a_row.saturating_add(1)
        } else {
            0
        };
        let candidates = [
            (d.warning > 0).then_some(BusCondition::Warning),
            (d.overflow > 0).then_some(BusCondition::Overflow),
            (d.protocol > 0).then_some(BusCondition::Protocol),
            (dropped > 0).then_some(BusCondition::TxDropped(dropped)),
            (d.passive > 0).then_some(BusCondition::Passive),
            (self.arbitration_in_a_row == ARBITRATION_STORM_PERIODS)
                .then_some(BusCondition::ArbitrationStorm(ARBITRATION_STORM_PERIODS)),
            (d.tx_timeout > 0).then_some(BusCondition::TxTimeout),
            (self.drops_in_a_row == TX_FULL_PERIODS)
                .then_some(BusCondition::TxFull(TX_FULL_PERIODS)),
            (d.bus_off > 0).then_some(BusCondition::BusOff),
            (d.restarted > 0).then_some(BusCondition::Restarted),
        ];
        // The last of the most severe: the list is in order of severity.
        let cond = candidates
            .into_iter()
            .flatten()
            .max_by_key(BusCondition::reaction)?;
        self.reactions[cond.reaction().index()] += 1;
        if self.worst.is_none_or(|w| cond.reaction() > w.reaction()) {
            self.worst = Some(cond);
        }
        Some(cond)
    }

    /// The link's error frames by kind, as last seen.
    pub fn errors(&self) -> BusErrors {
        self.seen
    }

    /// Periods whose worst condition called for `r`.
    pub fn periods(&self, r: Reaction) -> u64 {
        self.reactions[r.index()]
    }

    /// The most severe condition met so far (the first of its severity).
    pub fn worst(&self) -> Option<BusCondition> {
        self.worst
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn errors(f: impl FnOnce(&mut BusErrors)) -> BusErrors {
        let mut e = BusErrors::default();
        f(&mut e);
        e
    }

    #[test]
    fn each_condition_has_its_reaction_and_the_worst_of_a_period_wins() {
        let mut h = BusHealth::default();
        assert_eq!(h.update(BusErrors::default(), 0), None);
        let w = errors(|e| e.warning = 1);
        assert_eq!(h.update(w, 0), Some(BusCondition::Warning));
        // Counts are cumulative: the same counts again are nothing new.
        assert_eq!(h.update(w, 0), None);
        let p = errors(|e| {
            e.warning = 2;
            e.passive = 1;
        });
        assert_eq!(h.update(p, 0), Some(BusCondition::Passive));
        assert_eq!(BusCondition::Passive.reaction(), Reaction::Hold);
        let off = errors(|e| {
            *e = p;
            e.bus_off = 1;
            e.tx_timeout = 1;
        });
        assert_eq!(h.update(off, 1), Some(BusCondition::BusOff));
        assert_eq!(h.worst(), Some(BusCondition::BusOff));
        assert_eq!(h.periods(Reaction::Warn), 1);
        assert_eq!(h.periods(Reaction::Hold), 1);
        assert_eq!(h.periods(Reaction::QuickStop), 1);
        assert_eq!(h.errors(), off);
        let t = errors(|e| {
            *e = off;
            e.tx_timeout = 2;
        });
        assert_eq!(h.update(t, 0), Some(BusCondition::TxTimeout));
        assert_eq!(BusCondition::TxTimeout.reaction(), Reaction::Stop);
    }

    #[test]
    fn a_full_queue_warns_then_stops_on_its_third_period_in_a_row() {
        let mut h = BusHealth::default();
        let none = BusErrors::default();
        assert_eq!(h.update(none, 2), Some(BusCondition::TxDropped(2)));
        assert_eq!(
            h.update(none, 0),
            None,
            "a period without drops starts again"
        );
        assert_eq!(h.update(none, 1), Some(BusCondition::TxDropped(1)));
        assert_eq!(h.update(none, 1), Some(BusCondition::TxDropped(1)));
        assert_eq!(
            h.update(none, 6),
            Some(BusCondition::TxFull(TX_FULL_PERIODS))
        );
        assert_eq!(h.update(none, 6), Some(BusCondition::TxDropped(6)));
    }

    #[test]
    fn lost_arbitration_is_a_storm_after_ten_periods_in_a_row() {
        let mut h = BusHealth::default();
        let mut e = BusErrors::default();
        for i in 1..=ARBITRATION_STORM_PERIODS {
            e.lost_arbitration += 3;
            let c = h.update(e, 0);
            if i < ARBITRATION_STORM_PERIODS {
                assert_eq!(c, None, "period {i}: lost arbitration alone is normal");
            } else {
                assert_eq!(c, Some(BusCondition::ArbitrationStorm(10)));
            }
        }
        e.lost_arbitration += 1;
        assert_eq!(h.update(e, 0), None, "reported once, when it begins");
    }
}
