//! Where the path waits: at an operator stop (`M00`, `M01`, `M06`: the plan is at rest
//! where the chunk that carries it starts; the path holds there, paused, until resumed)
//! and before a move that needs the spindle at speed (held there until the drive reports
//! that speed; the move's spindle command goes out at once). Only the next chunk boundary
//! can hold one, so the gates look at the first two chunks at hand.

use crate::chunk::Chunk;
use nc_geom::program::Aux;

/// The gates' state.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Gates {
    /// Chunks from this index on may still hold an operator stop not yet reached.
    operator_from: usize,
    /// Source line of the operator stop the path waits at.
    pub(crate) awaiting: Option<u32>,
    /// Hold at the spindle waits ([`Wait::spindle`](nc_geom::program::Wait)) until the
    /// spindle is at speed; off without a spindle (dry runs).
    pub(crate) spindle_on: bool,
    /// The speed (rpm, signed) the spindle has reached, as last reported.
    pub(crate) spindle_at: Option<f64>,
    /// Chunks from this index on may still hold a spindle wait not yet passed.
    spindle_from: usize,
    /// Source line of the move that waits for the spindle, while it waits.
    pub(crate) awaiting_spindle: Option<u32>,
}

impl Gates {
    /// An operator stop ahead that plan time `tau` has reached: the plan time to hold at
    /// (its chunk's start, never before `tau_now`). The path then waits there, paused.
    pub(crate) fn operator<'c>(
        &mut self,
        ahead: impl Iterator<Item = &'c Box<Chunk>>,
        tau: f64,
        tau_now: f64,
    ) -> Option<f64> {
        let mut ahead = ahead.take(2);
        let c = ahead.find(|c| {
            c.index >= self.operator_from && c.first().is_some_and(|g| g.wait.operator.is_some())
        })?;
        if tau < c.t_start {
            return None;
        }
        self.awaiting = c.first().and_then(|g| g.wait.operator).map(|p| p.line);
        self.operator_from = c.index + 1;
        Some(c.t_start.max(tau_now))
    }

    /// A move ahead that waits for the spindle, reached by plan time `tau`: the plan time to
    /// hold at while the drive has not reported the move's speed (or the operator has the
    /// run paused there: the spindle then keeps its command until the run resumes, and never
    /// starts while the operator changes the tool), and the move's spindle and coolant to
    /// command from now on.
    pub(crate) fn spindle<'c>(
        &mut self,
        ahead: impl Iterator<Item = &'c Box<Chunk>>,
        tau: f64,
        tau_now: f64,
        paused: bool,
    ) -> (Option<f64>, Option<Aux>) {
        self.awaiting_spindle = None;
        let mut ahead = ahead.take(2);
        let found = ahead
            .find(|c| c.index >= self.spindle_from && c.first().is_some_and(|g| g.wait.spindle));
        let Some((c, g)) = found.and_then(|c| Some((c, c.first()?))) else {
            return (None, None);
        };
        if tau < c.t_start {
            return (None, None);
        }
        let rpm = g.aux.spindle_rpm;
        let aux = (!paused).then_some(g.aux);
        if !paused && (!self.spindle_on || self.spindle_at == Some(rpm)) {
            self.spindle_from = c.index + 1;
            return (None, aux);
        }
        if !paused {
            self.awaiting_spindle = Some(g.src.line);
        }
        (Some(c.t_start.max(tau_now)), aux)
    }
}
