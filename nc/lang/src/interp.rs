//! The interpreter ([`Interp`]): RS274/NGC's parameters, expressions and flow control, between
//! the program's text and the modal state machine (`parser`). It steps through the program's
//! lines as LinuxCNC does (loops go back, calls go into a subroutine's body and return, a false
//! branch is skipped), evaluates every expression on a line with the parameter values from
//! before the line, applies the line's assignments (numbered ones, then named ones, each in
//! source order) and hands the line's words, now plain numbers, to the parser.
//!
//! What runs here is the planner thread's work: it allocates and may take its time, but
//! never without bound. Calls nest at most [`MAX_CALL_DEPTH`](crate::rules::MAX_CALL_DEPTH)
//! deep, a program runs at most [`Setup::max_loop_lines`] lines again (in loops and
//! subroutines, counted line by line, so a long loop body costs what it runs), expressions nest
//! at most [`MAX_EXPR_DEPTH`](crate::rules::MAX_EXPR_DEPTH) deep, and the lines kept are those a
//! loop or a call may still go back to (`tape`).
//!
//! The program's flow (`flow.rs`) and the evaluation of a line (`evaluate.rs`) are methods
//! of [`Interp`] in files of their own.

use crate::error::{ParseError, ParseErrorKind};
use crate::interp_error::InterpError;
use crate::modal::Setup;
use crate::name::Name;
use crate::params::{Params, ARGUMENTS};
use crate::source::LineSource;
use crate::syntax::{self, Body, Keyword};
use crate::tape::Tape;
use crate::text::Normal;
use crate::word::Word;
use nc_geom::program::SrcPos;
use std::collections::HashMap;
use std::path::PathBuf;
use std::rc::Rc;

/// What the interpreter reads from the machine's state: the parameters the state computes
/// and whether the program has ended.
pub(crate) trait State {
    /// A numbered parameter the state gives (read-only: the position `#5420`.., the tool
    /// `#5400`.., the offsets `#5221`..); `None` for a parameter the program keeps.
    fn computed(&self, n: u32) -> Option<Result<f64, InterpError>>;
    /// A predefined named parameter (`_x`, `_metric`, `_motion_mode`, ...): `None` when
    /// `name` is not one.
    fn predefined(&self, name: &str) -> Option<Result<f64, InterpError>>;
    /// `M02`/`M30` has been executed.
    fn ended(&self) -> bool;
    /// The call level changed (a call, a return): the program is at `level` now, before
    /// the next line is evaluated.
    fn level(&mut self, _level: usize) {}
}

/// Where a frame's lines come from.
#[derive(Clone)]
pub(crate) enum Src {
    Main,
    Sub(Rc<Sub>),
}

/// A subroutine: the lines of its body, its `endsub` last.
pub(crate) struct Sub {
    pub name: String,
    pub body: Vec<Rc<Normal>>,
    /// The line of its `sub`.
    pub line: u32,
    /// Where its `sub` line stands in the main program (`None`: from a file), and whether a
    /// call found it by reading ahead (the program must then not run into it).
    pub main_index: Option<usize>,
    pub read_ahead: bool,
}

/// An open `if`, loop or `do`.
#[derive(Clone, Debug)]
pub(crate) struct Open {
    pub label: String,
    pub keyword: Keyword,
    /// Index of its opening line in the frame's source.
    pub start: usize,
    pub line: u32,
    /// `if`: a branch has run. `repeat`: the iterations still to run.
    pub taken: bool,
    pub remaining: i64,
}

/// One level of calls: level 0 is the main program.
pub(crate) struct Frame {
    pub src: Src,
    /// The next line to execute.
    pub pc: usize,
    pub open: Vec<Open>,
    /// The caller's `#1`..`#30`.
    pub saved: [f64; ARGUMENTS],
    /// The subroutine's name ("" for the main program): the scope of its labels.
    pub name: String,
}

impl Frame {
    /// The main program's frame, at its first line.
    fn main() -> Self {
        Frame {
            src: Src::Main,
            pc: 0,
            open: Vec::new(),
            saved: [0.0; ARGUMENTS],
            name: String::new(),
        }
    }
}

/// Skipping lines up to the next O-line of `label`: a false branch, a loop's exit.
#[derive(Clone, Debug)]
pub(crate) struct Skip {
    pub label: String,
    pub kind: SkipKind,
    pub keyword: Keyword,
    pub line: u32,
    /// The loop's opening line (an exit that turns out to be a stale `continue` goes back
    /// there).
    pub back: usize,
}

/// Why lines are skipped, which decides what the O-lines of the label do meanwhile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum SkipKind {
    /// A branch not taken: the next `elseif`, `else` or `endif` runs as usual.
    Branch,
    /// Out of a loop (its condition false, a `break`, `repeat [0]`): up to and past its
    /// `endwhile`, `endrepeat` or the `do`'s `while`; a `break` or `continue` of the same
    /// loop on the way is skipped too.
    Exit,
    /// `continue` in a `do` loop: on to its `while`, which decides.
    Continue,
}

/// A `%` first in the program (tape mode): a later `%` line ends it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Percent {
    Undecided,
    On,
    Off,
}

/// The interpreter over one main program.
pub(crate) struct Interp<S> {
    pub tape: Tape<S>,
    pub params: Params,
    pub frames: Vec<Frame>,
    pub subs: HashMap<String, Rc<Sub>>,
    /// Labels of `if`, loops and `do` by (scope, label): the keyword and line that opened them.
    pub labels: HashMap<(String, String), (Keyword, u32)>,
    pub skip: Option<Skip>,
    /// A subroutine definition being read (not executed).
    pub defining: Option<Sub>,
    pub dirs: Vec<PathBuf>,
    /// Lines that may still run again (in a loop or a subroutine), of [`Self::max_loop_lines`].
    pub budget: u64,
    pub max_loop_lines: u64,
    /// Main-program lines run so far for the first time (the next new line's index).
    fresh: usize,
    /// Source lines run again or inside a subroutine ([`nc_geom::program::Program::rerun`]).
    pub rerun: Vec<(u32, u32)>,
    /// `#<_value>` and `#<_value_returned>`.
    pub value: f64,
    pub value_returned: bool,
    /// The physical line being executed (`#<_line>`).
    pub line: u32,
    /// LinuxCNC's `doing_break` and `doing_continue`: set by `break` and by `continue` in a
    /// `do` loop, and cleared only where LinuxCNC clears them (a `do`'s `while` that does
    /// not loop back; an `endwhile`/`endrepeat` reached while skipping). So a `break` out
    /// of a `while` makes the next `do` loop run once, and a `continue` in a `do` makes the
    /// next `break` out of a `while` go round again, as in LinuxCNC; a program moves as it
    /// does there.
    pub doing_break: bool,
    pub doing_continue: bool,
    block_delete: bool,
    percent: Percent,
    finished: bool,
}

/// Add `line` to sorted, disjoint, inclusive ranges of lines, merging neighbours: a loop's
/// or a subroutine's body is one range however often it runs.
pub(crate) fn note_line(ranges: &mut Vec<(u32, u32)>, line: u32) {
    let i = ranges.partition_point(|r| r.1.saturating_add(1) < line);
    match ranges.get(i).copied() {
        Some((a, b)) if a <= line && line <= b => {}
        Some((a, b)) if b.saturating_add(1) == line => {
            ranges[i] = (a, line);
            if let Some(&(c, d)) = ranges.get(i + 1) {
                if c == line.saturating_add(1) {
                    ranges[i] = (a, d);
                    ranges.remove(i + 1);
                }
            }
        }
        Some((a, b)) if a == line.saturating_add(1) => ranges[i] = (line, b),
        _ => ranges.insert(i, (line, line)),
    }
}

pub(crate) fn err(kind: InterpError, pos: SrcPos) -> ParseError {
    ParseErrorKind::Interp(kind).at(pos)
}

impl<S: LineSource> Interp<S> {
    pub fn new(lines: S, setup: &Setup) -> Self {
        Interp {
            tape: Tape::new(lines),
            params: Params::default(),
            frames: vec![Frame::main()],
            subs: HashMap::new(),
            labels: HashMap::new(),
            skip: None,
            defining: None,
            dirs: setup.subroutine_dirs.clone(),
            budget: setup.max_loop_lines,
            max_loop_lines: setup.max_loop_lines,
            fresh: 0,
            rerun: Vec::new(),
            value: 0.0,
            value_returned: false,
            line: 0,
            doing_break: false,
            doing_continue: false,
            block_delete: setup.block_delete,
            percent: Percent::Undecided,
            finished: false,
        }
    }

    /// Just past the source's last character, once it is read to its end.
    pub fn eof(&self) -> SrcPos {
        self.tape.eof()
    }

    /// The interpreter as it stands (parameters, subroutines found in files, the loop
    /// quirks' flags) over a new main program, `lines`, read from its start: an MDI
    /// session's state carried into a program. Nothing may be open (the MDI session
    /// refuses a line that leaves anything open).
    pub fn with_source<S2: LineSource>(self, lines: S2) -> Interp<S2> {
        Interp {
            tape: Tape::new(lines),
            params: self.params,
            frames: vec![Frame::main()],
            subs: self.subs,
            labels: HashMap::new(),
            skip: None,
            defining: None,
            dirs: self.dirs,
            budget: self.max_loop_lines,
            max_loop_lines: self.max_loop_lines,
            fresh: 0,
            rerun: Vec::new(),
            value: self.value,
            value_returned: self.value_returned,
            line: 0,
            doing_break: self.doing_break,
            doing_continue: self.doing_continue,
            block_delete: self.block_delete,
            percent: Percent::Undecided,
            finished: false,
        }
    }

    /// The call level (0: the main program).
    pub fn level(&self) -> usize {
        self.frames.len() - 1
    }

    pub fn frame(&self) -> &Frame {
        // There is always the main program's frame.
        &self.frames[self.frames.len() - 1]
    }

    pub fn frame_mut(&mut self) -> &mut Frame {
        let last = self.frames.len() - 1;
        &mut self.frames[last]
    }

    /// The current frame's next line, and its index; `None` at the end of its source.
    fn fetch(&mut self) -> Result<Option<(Rc<Normal>, usize)>, ParseError> {
        let frame = self.frame();
        let pc = frame.pc;
        let line = match &frame.src {
            Src::Main => self.tape.line(pc)?,
            Src::Sub(sub) => sub.body.get(pc).cloned(),
        };
        Ok(line.map(|l| (l, pc)))
    }

    /// Lets the tape drop the main program's lines nothing can go back to: those before the
    /// line being executed (it may open a loop) and before every open construct.
    fn release(&mut self, current: usize) {
        let main = &self.frames[0];
        let here = if self.level() == 0 { current } else { main.pc };
        let keep = main.open.iter().map(|o| o.start).fold(here, usize::min);
        self.tape.release(keep);
    }

    /// The next line with words for the parser, into `words` (cleared first): `Ok(false)` at
    /// the program's end, or when the source has no line yet. After an error in the flow
    /// (an O-line), interpretation stops: the lines after it would run in a flow the program
    /// did not mean.
    pub fn next(
        &mut self,
        state: &mut impl State,
        words: &mut Vec<Word>,
    ) -> Result<bool, ParseError> {
        words.clear();
        loop {
            if self.finished || state.ended() {
                self.finished = true;
                return Ok(false);
            }
            let Some((line, index)) = self.fetch()? else {
                return Ok(false);
            };
            self.frame_mut().pc = index + 1;
            self.release(index);
            self.line = line.line;
            if self.level() == 0 && index >= self.fresh {
                self.fresh = index + 1;
            } else if let Err(e) = self.again(&line) {
                self.finished = true;
                return Err(e);
            } else {
                note_line(&mut self.rerun, line.line);
            }
            let levels = self.frames.len();
            let stepped = self.step(&line, index, &*state, words);
            if self.frames.len() != levels {
                state.level(self.level());
            }
            match stepped {
                Ok(true) => return Ok(true),
                Ok(false) => {}
                Err(e) => {
                    // An error in the flow stops here: the lines after it would run in a
                    // flow the program did not mean. A line's own error (a word, an
                    // expression) does not: the next line is read as usual.
                    let aborted =
                        matches!(e.kind, ParseErrorKind::Interp(InterpError::Abort { .. }));
                    self.finished = aborted || syntax::is_o_line(&line) || self.defining.is_some();
                    return Err(e);
                }
            }
        }
    }

    /// One line: `Ok(true)` when it has words for the parser.
    fn step(
        &mut self,
        line: &Rc<Normal>,
        index: usize,
        state: &impl State,
        words: &mut Vec<Word>,
    ) -> Result<bool, ParseError> {
        if self.defining.is_some() {
            self.define(line)?;
            return Ok(false);
        }
        if line.slash && self.block_delete {
            return Ok(false);
        }
        let main = self.level() == 0;
        if main && self.percent == Percent::Undecided {
            if line.is_empty() && line.comment.is_none() {
                return Ok(false);
            }
            self.percent = if line.is_percent() {
                Percent::On
            } else {
                Percent::Off
            };
            if self.percent == Percent::On {
                return Ok(false);
            }
        }
        if line.text == ['%'] {
            if main && self.percent == Percent::On && self.skip.is_none() {
                self.finished = true;
                return Ok(false);
            }
            if self.skip.is_none() {
                return Err(ParseErrorKind::MisplacedTapeMark.at(line.pos(0)));
            }
            return Ok(false);
        }
        if let Some(skip) = &self.skip {
            if !syntax::is_o_line(line) {
                return Ok(false);
            }
            let syn = syntax::read(line)?;
            let Body::O(o) = syn.body else {
                return Ok(false);
            };
            let label = self.label_name(&o.label, state)?;
            if label != skip.label {
                return Ok(false);
            }
            match (skip.kind, o.keyword) {
                (SkipKind::Branch, _) | (SkipKind::Continue, Some(Keyword::While)) => {
                    self.skip = None;
                    self.o_line(o, label, index, line, state)?;
                }
                (SkipKind::Exit, Some(Keyword::EndWhile | Keyword::EndRepeat)) => {
                    let back = skip.back;
                    self.skip = None;
                    if self.doing_continue {
                        self.doing_continue = false;
                        self.frame_mut().pc = back;
                    }
                }
                (SkipKind::Exit, Some(Keyword::While)) => {
                    self.skip = None;
                    self.doing_break = false;
                }
                _ => {}
            }
            return Ok(false);
        }
        if line.is_empty() {
            self.comment(line)?;
            return Ok(false);
        }
        let syn = syntax::read(line)?;
        match syn.body {
            Body::O(o) => {
                let label = self.label_name(&o.label, state)?;
                self.o_line(o, label, index, line, state)?;
                Ok(false)
            }
            Body::Items(items) => {
                self.evaluate(syn.n, &items, state, words)?;
                self.comment(line)?;
                Ok(!words.is_empty())
            }
        }
    }

    /// A line's comment: `(ABORT, ...)` stops the program with its text.
    fn comment(&self, line: &Normal) -> Result<(), ParseError> {
        let Some((text, pos)) = &line.comment else {
            return Ok(());
        };
        let body = text.trim_start();
        if body.get(..6).map(str::to_ascii_lowercase).as_deref() == Some("abort,") {
            let message = Name::new(body.get(6..).unwrap_or("").trim());
            return Err(err(InterpError::Abort { message }, *pos));
        }
        Ok(())
    }

    /// At the source's end: what is still open is an error at `eof`.
    pub fn check_end(&mut self, eof: SrcPos) -> Result<(), ParseError> {
        if self.finished {
            return Ok(());
        }
        self.finished = true;
        if let Some(sub) = &self.defining {
            return Err(err(
                InterpError::NotClosed {
                    label: Name::new(&sub.name),
                    keyword: "sub",
                    closer: "endsub",
                    line: sub.line,
                },
                eof,
            ));
        }
        if let Some(skip) = &self.skip {
            return Err(err(
                InterpError::NotClosed {
                    label: Name::new(&skip.label),
                    keyword: skip.keyword.name(),
                    closer: "line",
                    line: skip.line,
                },
                eof,
            ));
        }
        if let Some(open) = self.frames[0].open.last() {
            return Err(err(
                InterpError::NotClosed {
                    label: Name::new(&open.label),
                    keyword: open.keyword.name(),
                    closer: closer(open.keyword),
                    line: open.line,
                },
                eof,
            ));
        }
        Ok(())
    }
}

/// The keyword that closes `k`.
pub(crate) fn closer(k: Keyword) -> &'static str {
    match k {
        Keyword::If | Keyword::ElseIf | Keyword::Else => "endif",
        Keyword::While => "endwhile",
        Keyword::Do => "while",
        Keyword::Repeat => "endrepeat",
        Keyword::Sub => "endsub",
        _ => "end",
    }
}
