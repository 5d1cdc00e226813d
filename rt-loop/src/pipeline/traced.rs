//! `run --trace`: each period's targets, as sent to the drives, into the trace's
//! preallocated queue ([`crate::trace`]), never blocking.

use super::Pipeline;
use drives::link::CanLink;
use drives::master::MAX_NODES;

impl<'q, L: CanLink> Pipeline<'q, L> {
    /// Send every period's targets into this queue, as sent to the drives. `Err` with the
    /// number of nodes when the buses have more than a row holds.
    pub fn set_trace(
        &mut self,
        trace: crate::trace::Producer<'q, crate::trace::TraceRow>,
    ) -> Result<(), usize> {
        let nodes: usize = self.buses.iter().map(|b| b.master.status().len()).sum();
        if nodes > crate::trace::TRACE_NODES {
            return Err(nodes);
        }
        self.trace = Some(trace);
        Ok(())
    }

    /// Rows the trace's queue had no room for (its writer fell behind).
    pub fn trace_dropped(&self) -> u64 {
        self.trace_dropped
    }

    /// This period's targets into the trace, if one is kept (bounded by the nodes).
    pub(super) fn trace_period(&mut self) {
        let Some(q) = self.trace.as_mut() else {
            return;
        };
        let mut row = crate::trace::TraceRow {
            period: self.cycles,
            stage: self.phase.stage().index(),
            targets: [0; crate::trace::TRACE_NODES],
            nodes: 0,
        };
        let sent = self.buses.iter().flat_map(|b| {
            let n = b.master.status().len().min(MAX_NODES);
            b.targets[..n].iter()
        });
        for (slot, &t) in row.targets.iter_mut().zip(sent) {
            *slot = t;
            row.nodes += 1;
        }
        if q.enqueue(row).is_err() {
            self.trace_dropped += 1;
        }
    }
}
