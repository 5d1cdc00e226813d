//! The program as it is read: [`Entries`] yields each motion block and action in the order
//! they take effect, a line at a time, holding nothing of the lines behind it but the modal
//! state. [`super::parse_with`] collects them into a [`Program`]; a streaming planner takes
//! them one by one.

use super::error::ParseError;
use super::interp::Interp;
use super::modal::Setup;
use super::parser::Parser;
use super::source::LineSource;
use super::word::Word;
use nc_geom::program::{Action, Block, Orientation, SrcPos};
use std::collections::VecDeque;

/// One thing a program says: a motion block with its index among the program's motion
/// blocks (from 0, as in [`nc_geom::program::Program::blocks`]), or an action. An action
/// comes before the block its `before_block` names.
#[derive(Clone, Debug, PartialEq)]
pub enum Entry {
    Block(usize, Block),
    Action(Action),
}

/// A program's entries, read as they are needed. After an error the parse goes on from the
/// next line (an open NURBS block is dropped), as [`super::parse_with`] does; a caller that
/// stops at the first error simply stops.
pub struct Entries<'s, S> {
    interp: Interp<S>,
    parser: Parser<'s>,
    words: Vec<Word>,
    pending: VecDeque<Entry>,
    finished: bool,
}

impl<'s, S: LineSource> Entries<'s, S> {
    pub fn new(lines: S, setup: &'s Setup) -> Self {
        Entries {
            interp: Interp::new(lines, setup),
            parser: Parser::new(setup),
            words: Vec::new(),
            pending: VecDeque::new(),
            finished: false,
        }
    }

    /// True once the source is read to its end.
    pub fn is_finished(&self) -> bool {
        self.finished
    }

    /// Where `M02`/`M30` stood, once read.
    pub fn end(&self) -> Option<SrcPos> {
        self.parser.end()
    }

    /// The tilting-axis letter the program's angle words use and where it first stood, once
    /// read (see [`nc_geom::program::Program::tilt_word`]).
    pub fn tilt_word(&self) -> Option<(char, SrcPos)> {
        self.parser.rotary
    }

    /// Just past the last character of the source, once it is read to its end.
    pub fn eof(&self) -> SrcPos {
        self.interp.eof()
    }

    /// The source, positioned after the last line the program read: a program ends at
    /// `M02`/`M30` or its closing `%`, and the lines after it are not read (LinuxCNC's rule).
    /// A reader that passes the text through (`dnurbs fit`) reads them from here.
    pub fn into_source(self) -> S {
        self.interp.tape.into_source()
    }

    /// The index of the block that starts at the reference position (the program's first
    /// move leaves an axis out, so the homed machine starts where it is), once read.
    pub fn from_reference(&self) -> Option<usize> {
        self.parser.from_reference
    }

    /// Lines of the source held for a loop or a call to go back to (and the one being read).
    pub fn kept_lines(&self) -> usize {
        self.interp.tape.kept()
    }

    /// Moves read but held by cutter radius compensation until the next move decides their
    /// corner: their blocks come with a later line's.
    pub fn held_moves(&self) -> usize {
        self.parser.comp.held_moves()
    }

    /// Source lines run again or inside a subroutine so far
    /// ([`nc_geom::program::Program::rerun`]).
    pub fn rerun(&self) -> &[(u32, u32)] {
        &self.interp.rerun
    }

    /// Motion blocks read so far.
    pub fn blocks(&self) -> usize {
        self.parser.drained
    }

    /// What the lines read so far left open that only later lines can finish, if anything:
    /// an MDI line must be whole ([`crate::mdi`]).
    pub(crate) fn unfinished(&self) -> Option<Unfinished> {
        let (p, i) = (&self.parser, &self.interp);
        if p.end().is_some() {
            Some(Unfinished::ProgramEnd)
        } else if p.open.is_some() || p.g52.is_some() {
            Some(Unfinished::Spline)
        } else if p.comp.active.is_some() || p.comp.held_moves() > 0 {
            Some(Unfinished::CutterComp)
        } else if i.defining.is_some() {
            Some(Unfinished::Definition)
        } else if i.skip.is_some() || i.level() > 0 || i.frames.iter().any(|f| !f.open.is_empty()) {
            Some(Unfinished::Flow)
        } else {
            None
        }
    }

    /// The state the lines read so far left (modes, offsets, tool, parameters, where the
    /// tool stands) over a new program, `lines`, read from its start, its blocks counted
    /// from 0. Whatever was read and not taken is dropped.
    pub(crate) fn continue_with<S2: LineSource>(self, lines: S2) -> Entries<'s, S2> {
        let mut parser = self.parser;
        parser.start_program();
        Entries {
            interp: self.interp.with_source(lines),
            parser,
            words: Vec::new(),
            pending: VecDeque::new(),
            finished: false,
        }
    }

    /// An MDI line read to its end. What the next motion block would wait for (a `G04`,
    /// `M00`, `M06` with no move after it on its line) is dropped: an MDI line's waits are
    /// its own, reported among its actions, and do not hold the next line's move. And the
    /// budget of lines run again starts afresh, as for a program: a session a machine keeps
    /// for months does not run out of it.
    pub(crate) fn end_mdi_line(&mut self) {
        self.parser.wait = nc_geom::program::Wait::default();
        self.interp.budget = self.interp.max_loop_lines;
    }

    /// The tool stands at `here` (tool tip, the program's frame, mm) with `orientation`: the
    /// next move starts there (the machine moved without the program: a jog).
    pub(crate) fn place(&mut self, here: [f64; 3], orientation: Orientation) {
        self.parser.here = Some(here);
        self.parser.orientation = orientation;
        self.parser.orientation_given = true;
    }

    /// Moves what the parser produced into `pending`, each action before the block its
    /// `before_block` names.
    fn drain(&mut self) {
        let base = self.parser.drained;
        let parser = &mut self.parser;
        let mut actions = parser.actions.drain(..).peekable();
        let mut n = 0;
        for (k, block) in parser.blocks.drain(..).enumerate() {
            let index = base + k;
            while let Some(a) = actions.next_if(|a| a.before_block <= index) {
                self.pending.push_back(Entry::Action(a));
            }
            self.pending.push_back(Entry::Block(index, block));
            n = k + 1;
        }
        self.pending.extend(actions.map(Entry::Action));
        parser.drained = base + n;
    }
}

impl<S: LineSource> Entries<'_, S> {
    /// Reads one line, if the source has one now, and keeps what it produced for
    /// [`Self::take_read`]; `None` when the source has no line yet (nothing is finished: a
    /// source fed as it goes can be read again). The iterator reads through it; a reader
    /// that must parse each line as soon as it is written (`dnurbs fit`'s check of its own
    /// output) calls it directly.
    pub fn read_line(&mut self) -> Option<Result<(), ParseError>> {
        if self.finished {
            return None;
        }
        let result = match self.interp.next(&mut self.parser, &mut self.words) {
            Ok(true) => self.parser.line(&self.words),
            Ok(false) => return None,
            Err(e) => Err(e),
        };
        self.drain();
        if let Err(e) = result {
            self.parser.recover();
            return Some(Err(e));
        }
        Some(Ok(()))
    }

    /// What the lines read so far produced, in order.
    pub fn take_read(&mut self) -> Option<Entry> {
        self.pending.pop_front()
    }
}

impl<S: LineSource> Iterator for Entries<'_, S> {
    type Item = Result<Entry, ParseError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(entry) = self.pending.pop_front() {
                return Some(Ok(entry));
            }
            if self.finished {
                return None;
            }
            match self.read_line() {
                Some(Ok(())) => {}
                Some(Err(e)) => return Some(Err(e)),
                None => {
                    self.finished = true;
                    let eof = self.interp.eof();
                    let result = self
                        .interp
                        .check_end(eof)
                        .and_then(|()| self.parser.check_end(eof));
                    self.drain();
                    if let Err(e) = result {
                        self.parser.recover();
                        return Some(Err(e));
                    }
                }
            }
        }
    }
}

/// What a line left open that only later lines could finish, or that MDI does not take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unfinished {
    /// `M02`/`M30`.
    ProgramEnd,
    /// A `G06.2`/`G06.5` NURBS block or a `G05.2` spline: control points on later lines.
    Spline,
    /// `G41`/`G42`: each move waits for the next to decide its corner.
    CutterComp,
    /// `o... sub`: a subroutine's body on later lines.
    Definition,
    /// An `if`, `while`, `do` or `repeat` closed on a later line.
    Flow,
}

impl core::fmt::Display for Unfinished {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Unfinished::ProgramEnd => "M02/M30 ends a program: not taken in MDI",
            Unfinished::Spline => {
                "a NURBS or spline block takes its control points from later lines: \
                 not taken in MDI (run it in a program)"
            }
            Unfinished::CutterComp => {
                "cutter radius compensation (G41/G42) holds each move until the next \
                 decides its corner: not taken in MDI (run it in a program)"
            }
            Unfinished::Definition => {
                "a subroutine is defined over several lines: not taken in MDI \
                 (call one from a file: o<name> call)"
            }
            Unfinished::Flow => {
                "an O-word block (if, while, do, repeat) is closed on a later line: \
                 not taken in MDI"
            }
        })
    }
}
