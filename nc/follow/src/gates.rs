//! Where the path waits: at an operator stop (`M00`, `M01`, `M06`: the plan is at rest
//! where the chunk that carries it starts; the path holds there, paused, until resumed)
//! and before a move that needs the spindle at speed (held there until the drive reports
//! that speed; the move's spindle command goes out at once), and before a move after `M66`
//! (held there until each digital input it waits for rises, falls, is high or is low, or
//! its timeout has passed; the move's outputs go out at once, so an `M64` before the
//! `M66` is in effect while it waits). Only the next chunk boundary can hold one, so the
//! gates look at the first two chunks at hand.

use crate::chunk::Chunk;
use nc_geom::program::{Aux, MAX_INPUT_WAITS};

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
    /// The program's digital inputs as last read (bit n: `M66 P<n>`); None without an
    /// I/O module: an input wait then passes at once (simulated inputs).
    pub(crate) inputs: Option<u64>,
    /// Chunks from this index on may still hold input waits not yet passed; of the first
    /// such chunk, waits from `input_k` on.
    input_from: usize,
    input_k: usize,
    /// The wait under way: seconds waited, and whether the level before its edge was seen.
    waited_s: f64,
    seen: bool,
    /// Line of the `M66` waited for, while it waits.
    pub(crate) awaiting_input: Option<u32>,
    /// Waits that ended at their timeout, and the last one's line.
    pub(crate) input_timeouts: u64,
    pub(crate) last_timeout: Option<u32>,
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

    /// A move ahead that waits for inputs, reached by plan time `tau`: the plan time to hold
    /// at while one of its waits is not over, and the move's outputs (and spindle and
    /// coolant) to command from now on. `dt`: the period, s. Paused (at an operator stop
    /// before the same move, or by the operator), nothing is switched and nothing waited
    /// for until the run resumes.
    pub(crate) fn input<'c>(
        &mut self,
        ahead: impl Iterator<Item = &'c Box<Chunk>>,
        tau: f64,
        tau_now: f64,
        paused: bool,
        dt: f64,
    ) -> (Option<f64>, Option<Aux>) {
        self.awaiting_input = None;
        let mut ahead = ahead.take(2);
        let found = ahead.find(|c| {
            c.index >= self.input_from && c.first().is_some_and(|g| g.inputs[0].is_some())
        });
        let Some((c, g)) = found.and_then(|c| Some((c, c.first()?))) else {
            return (None, None);
        };
        if tau < c.t_start {
            return (None, None);
        }
        let held = Some(c.t_start.max(tau_now));
        if paused {
            return (held, None);
        }
        // At most MAX_INPUT_WAITS waits pass in one period (no loop without a bound).
        for _ in 0..=MAX_INPUT_WAITS {
            let Some(w) = g.inputs.get(self.input_k).copied().flatten() else {
                self.input_from = c.index + 1;
                self.input_k = 0;
                return (None, Some(g.aux));
            };
            let high = |bits: u64| bits.checked_shr(u32::from(w.input)).unwrap_or(0) & 1 == 1;
            let over = match self.inputs {
                None => true,
                Some(bits) if w.met(high(bits), &mut self.seen) => true,
                Some(_) if self.waited_s + 0.5 * dt >= w.timeout_s => {
                    self.input_timeouts += 1;
                    self.last_timeout = Some(w.pos.line);
                    true
                }
                Some(_) => false,
            };
            if !over {
                self.waited_s += dt;
                self.awaiting_input = Some(w.pos.line);
                return (held, Some(g.aux));
            }
            self.input_k += 1;
            self.waited_s = 0.0;
            self.seen = false;
        }
        (held, Some(g.aux))
    }
}
