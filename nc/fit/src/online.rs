//! On-line compression inside the streaming window ([`Compressing`]): a program's entries in,
//! the same entries out with each run of `G01` moves replaced by its G06.5 block, holding
//! only the run being gathered. The rules are [`super::compress`]'s (a run is what
//! [`super::find::find_runs`] finds, no program word between its moves), and so is the fit;
//! a run that reaches [`MAX_RUN`] moves is fitted there and the next move starts a new one,
//! so memory is bounded however long the program's runs. Up to that length the blocks are
//! those [`super::compress::compress`] makes of the whole program (tested). The program's
//! path-control words turn it on and off and set its tolerance as they come ([`Policy`]).

use super::compress::{fitted_block, Compressed};
use super::find::{is_corner, keeps_vertical, may_follow, point, run_feed, same_run};
use super::{fit, Point};
use crate::options::{Options, Policy};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::{ActionKind, Block, LinearMove, SrcPos};
use nc_lang::{Entry, ParseError};
use nc_plan::stream::ProgramSource;
use std::collections::VecDeque;

/// Most moves one run gathers before it is fitted (a block of 250 mm of 0.05 mm moves).
/// The planner thread fits it at once, in about 40 ms (the fit runs at 124 000 to 132 000
/// moves a second with the parse): the chunks queued ahead of the tool must cover that.
pub const MAX_RUN: usize = 5_000;

/// See the module's text.
pub struct Compressing<'k, E> {
    inner: E,
    kin: &'k MachineKinematics,
    /// When it is on, and how close.
    policy: Policy,
    /// How it fits now (the path-control mode in effect); None: off, every entry passes as
    /// it is (counted).
    opts: Option<Options>,
    /// It was on at some point.
    engaged: bool,
    /// The last block read, when it is a linear move (a run's start point).
    prev: Option<LinearMove>,
    /// The run being gathered: the move it starts from, its moves, and its points (its
    /// start, then each move's end).
    prev_of_run: Option<LinearMove>,
    run: Vec<LinearMove>,
    points: Vec<Point>,
    /// Entries ready to give, in order.
    out: VecDeque<Result<Entry, ParseError>>,
    /// Blocks given so far: the next block's index in the program given.
    given: usize,
    /// Blocks read so far.
    read: usize,
    done: Compressed,
    ended: bool,
}

impl<'k, E: ProgramSource> Compressing<'k, E> {
    /// A policy that never compresses passes the entries through as they are.
    pub fn new(inner: E, kin: &'k MachineKinematics, policy: Policy) -> Self {
        let opts = policy.at(None);
        Compressing {
            inner,
            kin,
            policy,
            opts,
            engaged: opts.is_some(),
            prev: None,
            prev_of_run: None,
            run: Vec::new(),
            points: Vec::new(),
            out: VecDeque::new(),
            given: 0,
            read: 0,
            done: Compressed::default(),
            ended: false,
        }
    }

    /// What the compressor did so far (all of it once the entries have ended); None while
    /// it has never been on.
    pub fn compressed(&self) -> Option<Compressed> {
        self.engaged.then_some(self.done)
    }

    /// The entries it reads (what they have noted on the way).
    pub fn inner_mut(&mut self) -> &mut E {
        &mut self.inner
    }

    fn give(&mut self, block: Block) {
        self.out.push_back(Ok(Entry::Block(self.given, block)));
        self.given += 1;
        self.done.blocks_out = self.given;
    }

    /// Fit the run gathered (or give its moves as they are) and start none.
    fn close_run(&mut self) {
        let moves = core::mem::take(&mut self.run);
        let Some(opts) = &self.opts else {
            return;
        };
        if moves.is_empty() {
            return;
        }
        // As `find_runs`: a run too short, or in inverse time at a speed no feed per minute
        // can give, is no run; one the fit cannot bring within the tolerances is kept.
        let feed = (moves.len() >= opts.min_moves)
            .then(|| run_feed(moves.iter(), &self.points))
            .flatten();
        let fitted = feed.and_then(|(feed, _)| {
            let f = fit(&self.points, opts.tol, opts.degree);
            self.done.runs_kept += usize::from(f.is_none());
            f.map(|f| (f, feed))
        });
        match (fitted, moves.first()) {
            (Some((f, feed)), Some(first)) => {
                self.done.fitted_blocks += 1;
                self.done.moves_fitted += moves.len();
                self.done.fit_mm = self.done.fit_mm.max(f.dev_mm);
                self.done.fit_deg = self.done.fit_deg.max(f.dev_rad.to_degrees());
                self.give(Block::Nurbs(fitted_block(first, &f, feed)));
            }
            _ => {
                for m in moves {
                    self.give(Block::Linear(m));
                }
            }
        }
        self.points.clear();
    }

    /// Move `m` joins the run being gathered: it follows the run's last move, has its feed
    /// and tool length ([`same_run`]), does not wait, keeps the tool vertical if the run's
    /// first move does and only then ([`keeps_vertical`]), and the run's last move is no
    /// corner.
    fn joins(&self, m: &LinearMove) -> bool {
        let (Some(last), Some(first), Some(opts)) = (self.run.last(), self.run.first(), &self.opts)
        else {
            return false;
        };
        // The end before the run's last move: the move before it, or the run's start.
        let before = match self.run.len() {
            1 => self.prev_of_run.as_ref(),
            n => self.run.get(n - 2),
        };
        let upright = |prev: Option<&LinearMove>, m: &LinearMove| {
            prev.is_some_and(|p| keeps_vertical(p, m, self.kin))
        };
        self.run.len() < MAX_RUN
            && may_follow(last, m, self.kin)
            && same_run(first, m)
            && upright(Some(last), m) == upright(self.prev_of_run.as_ref(), first)
            && !m.tooling.wait.is_some()
            && before.is_some_and(|b| !is_corner(b, last, m, opts.corner_deg))
    }

    fn block(&mut self, block: Block) {
        let index = self.read;
        self.read += 1;
        self.done.blocks_in = self.read;
        if let Block::Linear(m) = &block {
            self.done.moves_in += usize::from(index > 0 && !m.rapid);
        }
        let m = match block {
            Block::Linear(m) if self.opts.is_some() => m,
            Block::Linear(m) => {
                // Off here: it passes, and may start a run if the compressor comes on.
                self.give(Block::Linear(m));
                self.prev = Some(m);
                return;
            }
            other => {
                self.close_run();
                self.prev = None;
                self.give(other);
                return;
            }
        };
        if self.joins(&m) {
            self.points.push(point(&m, self.kin));
            self.run.push(m);
            self.prev = self.run.last().copied();
            return;
        }
        self.close_run();
        // It may start a run: a feed move after a linear move (not the start pose).
        match self.prev.take() {
            Some(prev) if index > 0 && may_follow(&prev, &m, self.kin) => {
                self.points.push(point(&prev, self.kin));
                self.points.push(point(&m, self.kin));
                self.prev_of_run = Some(prev);
                self.run.push(m);
            }
            _ => self.give(Block::Linear(m)),
        }
        self.prev = Some(m);
    }
}

impl<E: ProgramSource> Iterator for Compressing<'_, E> {
    type Item = Result<Entry, ParseError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(e) = self.out.pop_front() {
                return Some(e);
            }
            if self.ended {
                return None;
            }
            match self.inner.next() {
                None => {
                    self.close_run();
                    self.ended = true;
                }
                Some(Ok(Entry::Block(_, block))) => self.block(block),
                Some(Ok(Entry::Action(mut a))) => {
                    // A program word ends the run; it stands before the next block given.
                    self.close_run();
                    if let ActionKind::PathMode(mode) = a.kind {
                        self.opts = self.policy.at(Some(mode));
                        self.engaged |= self.opts.is_some();
                    }
                    a.before_block = self.given;
                    self.out.push_back(Ok(Entry::Action(a)));
                }
                Some(Err(e)) => {
                    self.close_run();
                    self.out.push_back(Err(e));
                }
            }
        }
    }
}

impl<E: ProgramSource> ProgramSource for Compressing<'_, E> {
    fn tilt_word(&self) -> Option<(char, SrcPos)> {
        self.inner.tilt_word()
    }
}
