//! The report of a run or a latency measurement: what happened, not only how fast.
//!
//! `summary.txt` (also printed at the end) and `summary.json` carry the outcome (completed,
//! or stopped with the reason, the node and the program line), the real-time mode, the
//! overruns and the longest run of them, feed holds and hard stops, each drive's final
//! target and actual position against the program's end, the program, the machine, the
//! dnurbs version and the start time, and the latency statistics. `latency.svg` plots the
//! histograms; `latency.hlog` is written while the run goes.

mod bus;

pub use bus::BusNotes;

use crate::exit::Outcome;
use serde::Serialize;
use std::path::{Path, PathBuf};

pub use rt_loop::thread::RtMode;

/// One drive at the end.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DriveEnd {
    pub axis: &'static str,
    pub node: u8,
    pub target_counts: i32,
    pub actual_counts: i32,
    /// The program's end point in this drive's counts (when the program was planned).
    pub program_end_counts: Option<i32>,
}

/// `summary.json`; [`Report::text`] is `summary.txt`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    pub dnurbs_version: &'static str,
    /// UTC, RFC 3339.
    pub started: String,
    /// What ran: the program file (or "latency").
    pub program: String,
    /// The machine's name (empty for `latency`).
    pub machine: String,
    pub outcome: &'static str,
    pub exit_code: u8,
    /// Why it stopped early, if it did.
    pub stop_reason: Option<String>,
    /// The drive that caused the stop, if one did.
    pub stop_node: Option<u8>,
    /// The program line being machined when the stop began.
    pub stop_line: Option<usize>,
    #[serde(with = "crate::rt_serde::RtModeDef")]
    pub realtime: RtMode,
    pub overruns: u64,
    pub max_consecutive_overruns: u64,
    /// Feed holds because the planner fell behind (planner underruns).
    pub feed_holds: u64,
    /// Periods where the path ran out before a hold had stopped the tool (should be 0).
    pub hard_stops: u64,
    /// `M66` waits that ended at their timeout (the path then went on, as LinuxCNC's does),
    /// and the line of the last.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input_timeouts: Option<InputTimeouts>,
    pub drives: Vec<DriveEnd>,
    /// Per bus: error frames, dropped frames, the reactions they called for.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub buses: Vec<BusNotes>,
    #[serde(with = "crate::rt_serde::SummaryDef")]
    pub latency: rt_loop::stats::Summary,
    /// Spindle, coolant, tool, stop and dwell words of the program, one line each.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub program_words: Vec<String>,
    /// What on-line compression did, when it was on.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compressed: Option<crate::simulate::Compression>,
    /// Why the program was refused ahead of the tool (`file:line:col: reason`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refusal: Option<String>,
    /// How the planner streamed the program.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stream: Option<StreamNotes>,
    /// What `--trace` wrote.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trace: Option<TraceNotes>,
}

/// What the trace holds, for the report.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TraceNotes {
    pub file: PathBuf,
    /// Rows written: one a period.
    pub rows: u64,
    /// Periods the real-time thread found no room for (the writer fell behind): the trace
    /// is then not every period's.
    pub dropped: u64,
}

/// `M66` waits that ended at their timeout.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct InputTimeouts {
    pub count: u64,
    /// The line of the last `M66` that timed out.
    pub last_line: Option<u32>,
}

/// Axis names in joint order.
pub const AXES: [&str; 5] = ["X", "Y", "Z", "A/B", "C"];

/// The outcome of a run that ended (`reason` is why it stopped early, if it did).
pub fn outcome(reason: Option<&rt_loop::pipeline::StopReason>, overruns: u64) -> Outcome {
    match reason {
        None if overruns == 0 => Outcome::Completed,
        None => Outcome::CompletedWithOverruns,
        Some(r) if r.by_operator() => Outcome::StoppedByOperator,
        Some(rt_loop::pipeline::StopReason::ProgramRefused { .. }) => Outcome::StoppedByProgram,
        Some(_) => Outcome::StoppedByFault,
    }
}

impl Report {
    /// `summary.txt`: the latency table, then what happened.
    pub fn text(&self) -> String {
        let mut s = self.latency.text();
        s.push_str(&format!("real-time: {}\n", self.realtime.text()));
        s.push_str(&format!(
            "overruns: {} (longest run {})   feed holds (planner underruns): {}   hard stops: {}\n",
            self.overruns, self.max_consecutive_overruns, self.feed_holds, self.hard_stops
        ));
        if let Some(t) = &self.input_timeouts {
            let line = t
                .last_line
                .map_or(String::new(), |l| format!(", the last at line {l}"));
            s.push_str(&format!(
                "M66 waits ended at their timeout: {}{line} (the path went on after each)\n",
                t.count
            ));
        }
        for d in &self.drives {
            let end = d
                .program_end_counts
                .map_or("-".to_owned(), |e| e.to_string());
            s.push_str(&format!(
                "axis {:<3} node {:>3}: target {:>11}  actual {:>11}  program end {end:>11} counts\n",
                d.axis, d.node, d.target_counts, d.actual_counts
            ));
        }
        for b in &self.buses {
            s.push_str(&b.line());
        }
        s.push_str(&crate::words::text(&self.program_words));
        if let Some(c) = &self.compressed {
            s.push_str(&c.line());
        }
        if let Some(n) = &self.stream {
            let lines = n.lines.map_or(String::new(), |l| format!(", {l} lines"));
            let how = if n.checked_whole {
                "checked whole before motion"
            } else {
                "checked beside the planner while it ran"
            };
            s.push_str(&format!(
                "planner: first window planned {:.3} s after the start; program {how}{lines}\n",
                n.first_window_s
            ));
        }
        if let Some(r) = &self.refusal {
            s.push_str(&format!("refused: {r}\n"));
        }
        if let Some(t) = &self.trace {
            let dropped = if t.dropped == 0 {
                String::new()
            } else {
                format!(
                    "; {} periods NOT traced (the writer fell behind the real-time thread)",
                    t.dropped
                )
            };
            s.push_str(&format!(
                "trace: {} periods' targets in {}{dropped}\n",
                t.rows,
                t.file.display()
            ));
        }
        let what = if self.machine.is_empty() {
            self.program.clone()
        } else {
            format!("{} on {}", self.program, self.machine)
        };
        s.push_str(&format!(
            "{what}, dnurbs {}, started {}\n",
            self.dnurbs_version, self.started
        ));
        match &self.stop_reason {
            None => s.push_str(&format!(
                "outcome: {} (exit {})\n",
                self.outcome, self.exit_code
            )),
            Some(why) => {
                let line = self
                    .stop_line
                    .map_or(String::new(), |l| format!(" at program line {l}"));
                s.push_str(&format!(
                    "outcome: {}{line} (exit {}): {why}\n",
                    self.outcome, self.exit_code
                ));
            }
        }
        s
    }

    /// Write summary.txt, summary.json and latency.svg into `dir` (latency.hlog is written
    /// during the run).
    pub fn write(
        &self,
        dir: &Path,
        stats: &rt_loop::stats::Stats,
        title: &str,
        period_ns: u64,
    ) -> anyhow::Result<()> {
        use anyhow::Context;
        let write = |name: &str, body: String| {
            let path = dir.join(name);
            std::fs::write(&path, body).with_context(|| format!("{}: cannot write", path.display()))
        };
        write("summary.txt", self.text())?;
        write("summary.json", serde_json::to_string_pretty(self)? + "\n")?;
        let svg = dir.join("latency.svg");
        rt_loop::report::write_svg(&svg, stats, title, period_ns)
            .with_context(|| format!("{}: cannot write", svg.display()))?;
        Ok(())
    }
}

/// The current time, UTC, RFC 3339 to the second.
pub fn now_utc() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

/// How the planner streamed the program, for the report.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StreamNotes {
    /// Seconds from the planner thread's start to its first window (the pre-pass included
    /// when the program was checked whole before motion).
    pub first_window_s: f64,
    /// The whole program went through the pre-pass before anything moved.
    pub checked_whole: bool,
    /// The program's lines, once the pre-pass has read it to its end.
    pub lines: Option<u32>,
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_start_time_is_rfc3339_utc_to_the_second() {
        let t = super::now_utc();
        assert_eq!(t.len(), "2026-11-23T10:34:56Z".len(), "{t}");
        assert!(t.ends_with('Z'), "{t}");
        let back = humantime::parse_rfc3339(&t).expect("parses back");
        let ago = std::time::SystemTime::now().duration_since(back).unwrap();
        assert!(ago.as_secs() < 60, "{t}");
    }
}
