//! Operator stops and single block: a program that waits at an `M00`, a taken `M01`, an
//! `M06` or (single block) a block's end is paused until `resume` or `step` lets it go.
//!
//! Single block is chosen when the program starts: `step` from rest plans it with a stop
//! before each block (each block then ends at rest); `step` while it waits runs the next
//! block; `resume` runs on, the block stops let go as they come (still at rest at each
//! block's end). A program started with `run` is planned without them: it cannot be
//! stepped from the middle (stop it, then `step` it from the start, or restart it from a
//! line).

use super::{Asker, Hub};
use crate::serve::state::{Command, State};
use rt_loop::control::Command as RunCommand;
use rt_loop::life::Order;

impl Hub<'_> {
    /// `step`: from rest, the loaded program in single block; while it waits at a block's
    /// end, the next block.
    pub(super) fn step(&mut self, who: Asker) -> Result<Option<State>, String> {
        match self.ctl.state() {
            State::Paused if self.block_stops.is_empty() => Err(format!(
                "step refused in state paused: the program was started with run, planned \
                 without block stops; stop it and start it with step (single block from \
                 its first block){}",
                ""
            )),
            State::Paused => {
                self.ctl.command(Command::Step).map_err(|e| e.to_string())?;
                self.released = self.status.run.snapshot().awaiting;
                self.send(Order::Run(RunCommand::Resume));
                Ok(Some(self.ctl.state()))
            }
            _ => self.run(who, true),
        }
    }

    /// What the thread says the path waits at: a stop while running or stepping pauses
    /// the program (a block stop while running in single block is let go at once).
    pub(super) fn watch_stops(&mut self) {
        let state = self.ctl.state();
        if !matches!(state, State::Running | State::Stepping) {
            return;
        }
        let Some(line) = self.status.run.snapshot().awaiting else {
            self.released = None;
            return;
        };
        if self.released == Some(line) {
            return;
        }
        if state == State::Running && self.block_stops.binary_search(&line).is_ok() {
            self.released = Some(line);
            self.send(Order::Run(RunCommand::Resume));
            return;
        }
        self.released = None;
        if self.ctl.command(Command::Pause).is_ok() {
            self.message = Some(format!(
                "waiting at line {line}: resume{}",
                if self.block_stops.is_empty() {
                    ""
                } else {
                    " (or step: the next block)"
                }
            ));
        }
    }
}
