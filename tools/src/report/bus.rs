//! What each CAN bus went through during a run: error frames by kind, frames the transmit
//! queue dropped, and the reactions they called for (`drives::master::health`).

use drives::master::{BusHealth, Reaction};
use serde::Serialize;
use std::collections::BTreeMap;

/// One bus, for the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BusNotes {
    /// The SocketCAN interface (the machine file's `[[bus]] interface`).
    pub interface: String,
    /// Error frames received, by kind; only the kinds seen.
    pub error_frames: BTreeMap<&'static str, u32>,
    /// Frames not sent: the transmit queue was full (`ENOBUFS`).
    pub dropped_frames: u64,
    /// Periods whose worst bus condition called for each reaction; only those that came.
    pub reactions: BTreeMap<&'static str, u64>,
    /// The most severe condition met, with its reaction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst: Option<String>,
}

impl BusNotes {
    pub fn new(interface: &str, h: &BusHealth, dropped_frames: u64) -> Self {
        let error_frames = h
            .errors()
            .named()
            .into_iter()
            .filter(|&(_, n)| n > 0)
            .collect();
        let reactions = [
            Reaction::Warn,
            Reaction::Hold,
            Reaction::Stop,
            Reaction::QuickStop,
        ]
        .into_iter()
        .map(|r| (r.name(), h.periods(r)))
        .filter(|&(_, n)| n > 0)
        .collect();
        BusNotes {
            interface: interface.to_owned(),
            error_frames,
            dropped_frames,
            reactions,
            worst: h.worst().map(|c| format!("{c} ({})", c.reaction().name())),
        }
    }

    /// One line of `summary.txt`.
    pub fn line(&self) -> String {
        let mut s = format!("bus {}: ", self.interface);
        if self.error_frames.is_empty() {
            s.push_str("no error frames");
        } else {
            s.push_str(&format!("error frames: {}", list(&self.error_frames)));
        }
        match self.dropped_frames {
            0 => s.push_str(", no frame dropped"),
            n => s.push_str(&format!(", {n} frames dropped (transmit queue full)")),
        }
        if !self.reactions.is_empty() {
            s.push_str(&format!(
                "; periods with a reaction: {}",
                list(&self.reactions)
            ));
        }
        if let Some(w) = &self.worst {
            s.push_str(&format!("; the worst: {w}"));
        }
        s.push('\n');
        s
    }
}

/// `n key, n key` in the map's order.
fn list<N: std::fmt::Display>(m: &BTreeMap<&str, N>) -> String {
    m.iter()
        .map(|(k, n)| format!("{n} {k}"))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use drives::link::BusErrors;

    #[test]
    fn a_clean_bus_and_a_troubled_one_read_plainly() {
        let h = BusHealth::default();
        assert_eq!(
            BusNotes::new("can0", &h, 0).line(),
            "bus can0: no error frames, no frame dropped\n"
        );
        let mut h = BusHealth::default();
        h.update(BusErrors::default(), 2);
        h.update(
            BusErrors {
                passive: 1,
                warning: 1,
                ..BusErrors::default()
            },
            0,
        );
        let notes = BusNotes::new("vcan0", &h, 2);
        assert_eq!(
            notes.line(),
            "bus vcan0: error frames: 1 error passive, 1 error warning, 2 frames dropped \
             (transmit queue full); periods with a reaction: 1 feed hold, 1 warning; the worst: \
             CAN controller error passive (feed hold)\n"
        );
    }
}
