//! `run --trace FILE` and `demo --trace FILE`: every target as sent to the drives, one row a
//! period, written outside the real-time thread from the queue it fills
//! (`rt_loop::trace`). Columns, as `simulate --trace` writes its: `cycle` (the period from
//! the loop's start), `t` (s), `stage` (enabling, approach, running, stopping, disabling),
//! the axes' positions those targets stand for (X Y Z, A or B, C: mm and degrees, from
//! each drive's counts), then each node's target as sent, `BUS:NODE` (counts for an axis,
//! velocity units for a spindle, the output byte for an I/O module).

use crate::report::TraceNotes;
use config::Machine;
use rt_loop::control::STAGES;
use rt_loop::trace::{Consumer, TraceRow};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Which target of a row is which axis's drive, with its scale.
struct AxisColumn {
    node_index: usize,
    drive: config::bus::Drive,
}

/// The file being written.
pub(crate) struct TraceWriter {
    w: std::io::BufWriter<std::fs::File>,
    file: PathBuf,
    period_s: f64,
    axes: Vec<AxisColumn>,
    rows: u64,
}

impl TraceWriter {
    /// Creates `file` with its header, for `machine`'s nodes in the master's order.
    pub(crate) fn create(file: &Path, machine: &Machine) -> anyhow::Result<TraceWriter> {
        let f = std::fs::File::create(file)
            .map_err(|e| anyhow::anyhow!("{}: cannot create the trace: {e}", file.display()))?;
        let mut w = std::io::BufWriter::new(f);
        let (mut nodes, mut axes) = (Vec::new(), Vec::new());
        for (bi, bus) in machine.buses.iter().enumerate() {
            for setup in super::node_setups(machine, bi) {
                let node = setup.node().get();
                if let Some(d) = machine
                    .drives
                    .iter()
                    .find(|d| d.bus == bi && d.node == node)
                {
                    axes.push(AxisColumn {
                        node_index: nodes.len(),
                        drive: d.clone(),
                    });
                }
                nodes.push(format!("{}:{node}", bus.name));
            }
        }
        axes.sort_by_key(|a| a.drive.axis);
        let names: Vec<&str> = machine.axes.all().iter().map(|a| a.0).collect();
        let axis_names: Vec<&str> = axes
            .iter()
            .filter_map(|a| names.get(a.drive.axis).copied())
            .collect();
        writeln!(
            w,
            "cycle,t,stage,{},{}",
            axis_names.join(","),
            nodes.join(",")
        )
        .map_err(|e| anyhow::anyhow!("{}: cannot write the trace: {e}", file.display()))?;
        Ok(TraceWriter {
            w,
            file: file.to_path_buf(),
            period_s: machine.period_s,
            axes,
            rows: 0,
        })
    }

    /// Writes every row the queue holds.
    pub(crate) fn drain(&mut self, rows: &mut Consumer<'_, TraceRow>) -> anyhow::Result<()> {
        while let Some(row) = rows.dequeue() {
            self.row(&row).map_err(|e| {
                anyhow::anyhow!("{}: cannot write the trace: {e}", self.file.display())
            })?;
        }
        Ok(())
    }

    fn row(&mut self, row: &TraceRow) -> std::io::Result<()> {
        let stage = STAGES.get(usize::from(row.stage)).copied().unwrap_or("?");
        write!(
            self.w,
            "{},{},{stage}",
            row.period,
            row.period as f64 * self.period_s
        )?;
        let targets = row.targets();
        for a in &self.axes {
            let counts = targets.get(a.node_index).copied().unwrap_or(0);
            write!(self.w, ",{}", a.drive.position(counts))?;
        }
        for t in targets {
            write!(self.w, ",{t}")?;
        }
        writeln!(self.w)?;
        self.rows += 1;
        Ok(())
    }

    /// Flushes the file; what it holds, with the rows the real-time thread dropped.
    pub(crate) fn finish(mut self, dropped: u64) -> anyhow::Result<TraceNotes> {
        self.w
            .flush()
            .map_err(|e| anyhow::anyhow!("{}: cannot write the trace: {e}", self.file.display()))?;
        Ok(TraceNotes {
            file: self.file,
            rows: self.rows,
            dropped,
        })
    }
}
