//! `dnurbs fit` as a stream: the program's text is read a line at a time, each run of
//! `G01` moves is fitted as soon as it has ended, and the result is written and checked
//! (`fit::check`) as it goes, so a program of any length is fitted in the memory of a
//! few thousand moves.
//!
//! The runs are those [`super::runs::fit_program`] finds in the whole text, by the same
//! rules and the same code ([`find_runs`] on a window of the parsed blocks), but for one
//! bound: a stretch of more than [`MAX_RUN`] joinable moves is cut there, and the run after
//! the cut starts on the programmed point where the one before it ends. (A run in machine
//! angles that reaches the bound gives up its last moves as `fit_program` does at its end.) The window is cut
//! only where no run can pass: before a block that cannot join the one before it (another
//! line between them, a line with more than the move, not a linear move), at a line that
//! holds more than a move, and at that bound.

use super::check::Check;
use super::deviation::Deviation;
use super::find::{find_open_runs, Found};
use super::online::MAX_RUN;
use super::runs::{
    in_angles, n_word, pure_move_line, restorable, sets_angles, tilt_of, with_angles, write_block,
    Modes, Summary,
};
pub use crate::error::RewriteError;
use crate::options::Options;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::{Block, Program, SrcPos};
use nc_geom::segment::BuildLimits;
use nc_lang::{Entries, Entry, LineSource, ParseError, ReadLines, Setup};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::io::{BufRead, Write};
use std::rc::Rc;
use std::time::Instant;

/// Lines held while no block is read from them (lines of a move and nothing else that
/// move nothing, such as `F` alone): past this many, or this many bytes (a line may be
/// padded), the window is cut there.
const MAX_HELD_LINES: usize = 2 * MAX_RUN + 16;
const MAX_HELD_BYTES: usize = 64 << 20;

/// What the rewrite did and what the check measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Rewritten {
    pub summary: Summary,
    pub dev: Deviation,
    /// Seconds spent fitting (finding the runs and fitting them; reading, writing and the
    /// check excluded).
    pub fit_s: f64,
    /// Physical lines of the program read, up to its end (`M02`/`M30` or its closing `%`).
    pub lines: u32,
}

/// A line read and not yet written: one of a move and nothing else, which a run may take.
struct Held {
    no: u32,
    text: String,
    ending: &'static str,
    /// `G90 G21 G94` in effect at its start, and the modal motion `G01` there.
    plain: bool,
    g01: bool,
    /// The feed per minute in effect (mm/min).
    g94_feed: Option<f64>,
    /// The program's tilt letter so far.
    tilt: Option<char>,
}

/// What the window knows of each of its blocks' lines.
#[derive(Clone, Copy)]
struct Line {
    no: u32,
    plain: bool,
    g01: bool,
}

struct State<'a, W> {
    kin: &'a MachineKinematics,
    opts: &'a Options,
    modes: Modes,
    held: VecDeque<Held>,
    held_bytes: usize,
    lines_read: u32,
    /// The blocks not yet decided, after the last block of the previous piece (block 0 of
    /// the window: the point the next run may start from).
    window: Program,
    lines: Vec<Line>,
    /// Input motion blocks read.
    blocks: usize,
    summary: Summary,
    out: W,
    check: Check<'a>,
    fit_s: f64,
    /// An error met while reading a line (the parser's source cannot return it).
    error: Option<RewriteError>,
    /// The line after a block fitted to moves in angles, when it is a move that leaves an
    /// angle modal: its number and the line as it is written then.
    restore: Option<(u32, String)>,
}

impl<W: Write> State<'_, W> {
    /// A line is read (before its block is parsed).
    fn on_line(&mut self, no: u32, text: &str, ending: &'static str) -> Result<(), RewriteError> {
        let at = self.modes.line(text);
        self.summary.bytes_in += text.len() + ending.len();
        self.lines_read = no;
        if !pure_move_line(text) {
            // No run takes this line, so none goes on past it: every line before it is
            // decided, and so is this one.
            self.close(None, Some((no, text)), false)?;
            return self.emit(text, ending);
        }
        if self.held.len() >= MAX_HELD_LINES || self.held_bytes >= MAX_HELD_BYTES {
            self.close(None, Some((no, text)), false)?;
        }
        self.held_bytes += text.len();
        self.held.push_back(Held {
            no,
            text: text.to_owned(),
            ending,
            plain: at.plain,
            g01: at.g01,
            g94_feed: at.g94_feed,
            tilt: self.modes.tilt,
        });
        Ok(())
    }

    /// Input block `i` is read.
    fn on_block(&mut self, i: usize, block: Block) -> Result<(), RewriteError> {
        let no = block.pos().line;
        let (plain, g01) = self
            .held
            .iter()
            .rev()
            .find(|h| h.no == no)
            .map_or((false, false), |h| (h.plain, h.g01));
        let joins = matches!(block, Block::Linear(_))
            && plain
            && self
                .lines
                .last()
                .is_some_and(|l| l.no.checked_add(1) == Some(no));
        let len = self.window.blocks.len();
        if len > 1 && (!joins || len > MAX_RUN) {
            self.close(Some(no), None, joins)?;
        }
        if i > 0 && matches!(&block, Block::Linear(m) if !m.rapid) {
            self.summary.moves_in += 1;
        }
        self.blocks += 1;
        self.check.block(i, &block).map_err(RewriteError::Build)?;
        self.window.blocks.push(block);
        self.lines.push(Line { no, plain, g01 });
        Ok(())
    }

    /// The window's runs are fitted and written, the held lines before line `upto` (all
    /// of them if `None`) written, and the piece checked; the window keeps its last block.
    /// `next`: the line being read, if it is not held. `full`: the window is cut only
    /// because it holds [`MAX_RUN`] moves, so it keeps the run that reaches its end.
    fn close(
        &mut self,
        upto: Option<u32>,
        next: Option<(u32, &str)>,
        full: bool,
    ) -> Result<(), RewriteError> {
        let len = self.window.blocks.len();
        let mut keep = len.saturating_sub(1);
        if len > 1 {
            let t0 = Instant::now();
            let (lines, held, blocks) = (&self.lines, &self.held, &self.window.blocks);
            // The held line numbered `no` (held lines are in order).
            let held_line = |no: u32| {
                held.binary_search_by_key(&no, |h| h.no)
                    .ok()
                    .and_then(|i| held.get(i))
                    .map(|h| h.text.as_str())
            };
            let (mut found, open) = find_open_runs(
                &self.window,
                self.kin,
                self.opts,
                |b| (lines[b].plain && lines[b].g01).then_some(self.opts.tol),
                |k| lines[k].plain && lines[k - 1].no.checked_add(1) == Some(lines[k].no),
                // The line after block k (the next move of the run, or the line after it).
                |k, _| {
                    let Some(after) = lines[k].no.checked_add(1) else {
                        return false;
                    };
                    !in_angles(&blocks[k])
                        || held_line(after)
                            .or(next.filter(|n| n.0 == after).map(|n| n.1))
                            .is_some_and(sets_angles)
                        || (k + 1 < blocks.len()
                            && lines[k + 1].no == after
                            && restorable(blocks.get(k + 1), lines[k + 1].plain))
                },
            );
            self.fit_s += t0.elapsed().as_secs_f64();
            // A window cut for its size keeps the run that reaches its end (it is fitted
            // again with what follows), unless that run is the whole window.
            if let Some(b) = open.filter(|&b| full && b > 1) {
                keep = b - 1;
                found.retain(|r| r.blocks.0 < b);
            }
            for f in &found {
                let (l0, l1) = (self.lines[f.blocks.0].no, self.lines[f.blocks.1].no);
                self.write_run(f, l0, l1)?;
            }
        }
        // The lines of the blocks kept stay held.
        let upto = match self.lines.get(keep + 1) {
            Some(l) => Some(l.no),
            None => upto,
        };
        while let Some(h) = self.held.front() {
            if upto.is_some_and(|u| h.no >= u) {
                break;
            }
            if let Some(h) = self.pop_held() {
                self.emit_held(&h)?;
            }
        }
        // Input blocks up to the one kept first are decided (`blocks` counts every block
        // read; the last kept is the window's last).
        let decided = self.blocks - (len.saturating_sub(1) - keep);
        let s = &self.summary;
        self.check
            .piece(decided - s.moves_fitted + s.fitted_blocks, decided)?;
        self.window.blocks.drain(..keep);
        self.lines.drain(..keep);
        Ok(())
    }

    /// Run `f` (lines `l0..=l1`), fitted, replaces its lines; kept, it is only counted.
    fn write_run(&mut self, f: &Found, l0: u32, l1: u32) -> Result<(), RewriteError> {
        let Some(fitted) = &f.fitted else {
            self.summary.runs_kept += 1;
            return Ok(());
        };
        while let Some(h) = self.held.front() {
            if h.no >= l0 {
                break;
            }
            if let Some(h) = self.pop_held() {
                self.emit_held(&h)?;
            }
        }
        let (mut n, mut eol, mut g94_feed) = (None, "\n", None);
        while self.held.front().is_some_and(|h| h.no <= l1) {
            if let Some(h) = self.pop_held().filter(|h| h.no == l0) {
                n = n_word(&h.text);
                if h.ending == "\r\n" {
                    eol = "\r\n";
                }
                g94_feed = h.g94_feed;
            }
        }
        let mut text = String::new();
        write_block(&mut text, fitted, f, n.as_deref(), eol, g94_feed);
        for line in text.split_inclusive('\n') {
            let body = line.trim_end_matches('\n').trim_end_matches('\r');
            self.emit(body, &line[body.len()..])?;
        }
        // A move after it that leaves an angle modal is written with both.
        let k = f.blocks.1;
        let blocks = &self.window.blocks;
        let after = self
            .held
            .front()
            .filter(|h| Some(h.no) == l1.checked_add(1));
        self.restore = after
            .filter(|h| {
                in_angles(&blocks[k])
                    && !sets_angles(&h.text)
                    && self.lines.get(k + 1).is_some_and(|l| l.no == h.no)
                    && restorable(blocks.get(k + 1), self.lines[k + 1].plain)
            })
            .map(|h| {
                let tilt = tilt_of(h.tilt, self.kin);
                (h.no, with_angles(&h.text, &blocks[k + 1], tilt))
            });
        let s = &mut self.summary;
        s.fitted_blocks += 1;
        s.moves_fitted += f.blocks.1 + 1 - f.blocks.0;
        s.fit_mm = s.fit_mm.max(fitted.dev_mm);
        s.fit_deg = s.fit_deg.max(fitted.dev_rad.to_degrees());
        Ok(())
    }

    /// A held line, as it was or with both angles ([`Self::restore`]).
    fn emit_held(&mut self, h: &Held) -> Result<(), RewriteError> {
        match self.restore.take() {
            Some((no, text)) if no == h.no => self.emit(&text, h.ending),
            other => {
                self.restore = other;
                self.emit(&h.text, h.ending)
            }
        }
    }

    fn pop_held(&mut self) -> Option<Held> {
        let h = self.held.pop_front()?;
        self.held_bytes -= h.text.len();
        Some(h)
    }

    fn emit(&mut self, text: &str, ending: &str) -> Result<(), RewriteError> {
        self.out.write_all(text.as_bytes())?;
        self.out.write_all(ending.as_bytes())?;
        self.summary.bytes_out += text.len() + ending.len();
        self.check.written(text)
    }
}

/// The program's lines, each shown to the rewrite as it is read.
struct Recorder<'a, R, W> {
    lines: ReadLines<R>,
    state: Rc<RefCell<State<'a, W>>>,
}

impl<R: BufRead, W: Write> LineSource for Recorder<'_, R, W> {
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>> {
        if let Err(e) = self.lines.next_line()? {
            return Some(Err(e));
        }
        let (no, text, ending) = self.lines.last_line();
        let mut state = self.state.borrow_mut();
        if state.error.is_some() {
            return None;
        }
        if let Err(e) = state.on_line(no, text, ending) {
            state.error = Some(e);
            return None;
        }
        Some(Ok((no, text)))
    }

    fn eof(&self) -> SrcPos {
        self.lines.eof()
    }
}

/// Fit the runs of the program read from `input` (parsed with `setup`, which should leave
/// out work offsets: the program's own numbers are written back) and write the result to
/// `out`, each piece measured against its input by dense sampling every `step` mm.
pub fn rewrite<R: BufRead, W: Write>(
    input: R,
    setup: &Setup,
    kin: &MachineKinematics,
    limits: &BuildLimits,
    opts: &Options,
    step: f64,
    out: W,
) -> Result<Rewritten, RewriteError> {
    let state = Rc::new(RefCell::new(State {
        kin,
        opts,
        modes: Modes::default(),
        held: VecDeque::new(),
        held_bytes: 0,
        lines_read: 0,
        window: Program::default(),
        lines: Vec::new(),
        blocks: 0,
        summary: Summary::default(),
        out,
        check: Check::new(kin, limits, setup, step, opts.tol.mm),
        fit_s: 0.0,
        error: None,
        restore: None,
    }));
    let recorder = Recorder {
        lines: ReadLines::new(input),
        state: Rc::clone(&state),
    };
    let mut entries = Entries::new(recorder, setup);
    let failed = |state: &RefCell<State<'_, W>>| state.borrow_mut().error.take();
    for entry in entries.by_ref() {
        if let Some(e) = failed(&state) {
            return Err(e);
        }
        let mut s = state.borrow_mut();
        match entry.map_err(RewriteError::Parse)? {
            Entry::Action(a) => s.check.action(&a),
            Entry::Block(i, b) => s.on_block(i, b)?,
        }
    }
    // The lines after the program's end are not the program's, but they are the file's:
    // they pass through unchanged.
    let program_lines = state.borrow().lines_read;
    let mut rest = entries.into_source();
    while let Some(line) = rest.next_line() {
        line.map_err(RewriteError::Parse)?;
    }
    if let Some(e) = failed(&state) {
        return Err(e);
    }
    let mut s = state.borrow_mut();
    s.close(None, None, false)?;
    let blocks = s.blocks;
    let sm = &mut s.summary;
    sm.blocks_in = blocks;
    sm.blocks_out = blocks - sm.moves_fitted + sm.fitted_blocks;
    let expected = sm.blocks_out;
    let dev = s.check.finish(expected, blocks)?;
    s.out.flush()?;
    Ok(Rewritten {
        summary: s.summary.clone(),
        dev,
        fit_s: s.fit_s,
        lines: program_lines,
    })
}
