//! MDI: NC lines typed one at a time ([`Mdi`]), read by the same interpreter and parser as a
//! program, the modal state (units, distance mode, offsets, feed, tool, parameters, the
//! spindle and coolant words) carried from each line to the next.
//!
//! A line is taken whole or not at all. A line the interpreter or the parser refuses, or
//! one that leaves something only later lines could finish, changes nothing: the session
//! is rebuilt from the lines it took (and the positions it was given between them), so
//! what the refused line set before its error is gone with it, as if it had never been
//! typed. Each line gives the motion blocks and actions it produced, block indices
//! counting on from the session's last.
//!
//! Not taken in MDI, each with its reason ([`Unfinished`]): a NURBS or `G05.2` block (its
//! control points follow on later lines), cutter radius compensation (`G41`/`G42` hold each
//! move until the next decides its corner), an O-word block or a subroutine definition,
//! `M02`/`M30` (they end a program), a tape's `%`, a line continued with `\`. A subroutine
//! in a file (`o<name> call`, [`Setup::subroutine_dirs`]) runs whole within its line.
//!
//! A dwell or a stop (`G04`, `M00`, `M06`) with no move after it on its line is among the
//! line's actions, for the controller to do; it does not hold the next line's move.
//!
//! A program run after the session starts in the state its lines left
//! ([`Mdi::into_program`]), as in LinuxCNC.
//!
//! The machine moves without the session (a jog): [`Mdi::at`] tells it where the tool now
//! stands, and the next move starts there.
//!
//! Planner thread (or the controller's command thread): allocates.

use crate::error::ParseError;
use crate::modal::Setup;
use crate::restart::Standing;
use crate::source::LineSource;
pub use crate::stream::Unfinished;
use crate::stream::{Entries, Entry};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::{Action, Block, MoveTooling, Orientation, Program, SrcPos};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;

#[cfg(test)]
mod tests;

/// Longest MDI line, in characters (the control protocol's limit).
pub const MAX_MDI_CHARS: usize = 255;

/// Why an MDI line was refused; the session is as it was before the line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MdiError {
    /// The interpreter or the parser refused it (the error's line is the session's).
    #[error("MDI line {line} `{text}`: {error}")]
    Parse {
        line: u32,
        text: String,
        error: Box<ParseError>,
    },
    #[error("MDI line {line} `{text}`: {what}")]
    Unfinished {
        line: u32,
        text: String,
        what: Unfinished,
    },
    /// Not one line of at most [`MAX_MDI_CHARS`] characters, or a tape's `%`.
    #[error("MDI line {line}: {why}")]
    NotALine { line: u32, why: &'static str },
}

/// The lines typed and not yet read, each with its number in the session.
type Typed = Rc<RefCell<VecDeque<(u32, String)>>>;

/// The lines the session is fed.
#[derive(Default)]
struct Feed {
    queue: Typed,
    line: String,
    number: u32,
}

impl LineSource for Feed {
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>> {
        let (n, text) = self.queue.borrow_mut().pop_front()?;
        self.number = n;
        self.line = text;
        Some(Ok((n, &self.line)))
    }

    fn eof(&self) -> SrcPos {
        SrcPos {
            line: self.number.max(1),
            col: u32::try_from(self.line.chars().count() + 1).unwrap_or(u32::MAX),
        }
    }
}

/// What the session took, to rebuild it after a refusal.
#[derive(Clone, Debug)]
enum Step {
    Line(u32, String),
    At([f64; 3], Orientation),
}

/// An MDI session: the modal state of the lines it took.
pub struct Mdi<'s> {
    setup: &'s Setup,
    queue: Typed,
    entries: Entries<'s, Feed>,
    history: Vec<Step>,
    /// Lines typed so far, taken or not: the next line's number is one more.
    typed: u32,
}

impl<'s> Mdi<'s> {
    /// A session in the setup's start-up modes. Until [`Mdi::at`], a move that leaves an
    /// axis out starts at the setup's reference position (an error without one).
    pub fn new(setup: &'s Setup) -> Self {
        let (queue, entries) = Self::fresh(setup);
        Mdi {
            setup,
            queue,
            entries,
            history: Vec::new(),
            typed: 0,
        }
    }

    fn fresh(setup: &'s Setup) -> (Typed, Entries<'s, Feed>) {
        let queue = Rc::new(RefCell::new(VecDeque::new()));
        let feed = Feed {
            queue: Rc::clone(&queue),
            ..Feed::default()
        };
        (queue, Entries::new(feed, setup))
    }

    /// The tool stands at `here` (tool tip in the program's frame, mm, as the blocks give
    /// their end points) with `orientation`: the next move starts there.
    pub fn at(&mut self, here: [f64; 3], orientation: Orientation) {
        self.entries.place(here, orientation);
        // Only the last position between two lines matters.
        if let Some(Step::At(..)) = self.history.last() {
            self.history.pop();
        }
        self.history.push(Step::At(here, orientation));
    }

    /// The machine stands at `standing` on `kin` (read from its drives): the next move
    /// starts at its tool tip, at its angles.
    pub fn standing(&mut self, standing: &Standing, kin: &MachineKinematics) {
        let (here, orientation) = standing.tip(kin);
        self.at(here, orientation);
    }

    /// The tilting-axis letter (`A` or `B`) the session's lines used first, and where.
    pub fn tilt_word(&self) -> Option<(char, SrcPos)> {
        self.entries.tilt_word()
    }

    /// Motion blocks the session has produced.
    pub fn blocks(&self) -> usize {
        self.entries.blocks()
    }

    /// Lines the session has taken.
    pub fn taken(&self) -> usize {
        self.history
            .iter()
            .filter(|s| matches!(s, Step::Line(..)))
            .count()
    }

    /// One MDI line: what it produced, in order, or why it was refused (the session then
    /// unchanged).
    pub fn line(&mut self, text: &str) -> Result<Vec<Entry>, MdiError> {
        self.typed = self.typed.saturating_add(1);
        let line = self.typed;
        if let Some(why) = not_a_line(text) {
            return Err(MdiError::NotALine { line, why });
        }
        match self.read(line, text) {
            Ok(out) => {
                self.history.push(Step::Line(line, text.to_owned()));
                Ok(out)
            }
            Err(e) => {
                self.rebuild();
                Err(e)
            }
        }
    }

    /// The line last taken was refused after it was read (the planner, the travel, the
    /// operator): the session as it was before it, as if it had never been typed. Positions
    /// given since stay. Returns whether there was a line to take back.
    pub fn take_back(&mut self) -> bool {
        let Some(i) = self
            .history
            .iter()
            .rposition(|s| matches!(s, Step::Line(..)))
        else {
            return false;
        };
        self.history.remove(i);
        self.rebuild();
        true
    }

    /// A program run after the session's lines, `lines`, starts in the state they left:
    /// modes, offsets, the tool and its length, the feed, the parameters, where the tool
    /// stands (as LinuxCNC runs a program after MDI). Its blocks count from 0; a first move
    /// that leaves an axis out starts where the tool stands.
    pub fn into_program<S: LineSource>(self, lines: S) -> Entries<'s, S> {
        self.entries.continue_with(lines)
    }

    /// Reads one line to its end (a subroutine it calls included).
    fn read(&mut self, line: u32, text: &str) -> Result<Vec<Entry>, MdiError> {
        self.queue.borrow_mut().push_back((line, text.to_owned()));
        let mut out = Vec::new();
        // Bounded: the line is read once, and the lines a call runs are bounded by the
        // setup's loop budget.
        while let Some(read) = self.entries.read_line() {
            read.map_err(|error| MdiError::Parse {
                line,
                text: text.to_owned(),
                error: Box::new(error),
            })?;
            while let Some(e) = self.entries.take_read() {
                out.push(e);
            }
        }
        self.entries.end_mdi_line();
        match self.entries.unfinished() {
            Some(what) => Err(MdiError::Unfinished {
                line,
                text: text.to_owned(),
                what,
            }),
            None => Ok(out),
        }
    }

    /// The session again from the lines it took and the positions it was given, their
    /// output dropped: as it was before the refused line.
    fn rebuild(&mut self) {
        let (queue, entries) = Self::fresh(self.setup);
        self.queue = queue;
        self.entries = entries;
        for step in &self.history {
            match step {
                Step::At(here, o) => self.entries.place(*here, *o),
                Step::Line(n, text) => {
                    self.queue.borrow_mut().push_back((*n, text.clone()));
                    // Taken once, so taken again: the same lines read the same way (a
                    // subroutine file changed on disk meanwhile is the one exception, and
                    // its error is dropped with the rest of the output).
                    while self.entries.read_line().is_some() {}
                    while self.entries.take_read().is_some() {}
                    self.entries.end_mdi_line();
                }
            }
        }
    }
}

/// What a line gave, as a program from where the machine stands (`standing`): a start
/// there, then the line's blocks, its actions before the blocks they came before (after
/// the last, those after its moves), and the tilting-axis letter the session's lines used
/// (`tilt_word`, [`Mdi::tilt_word`]; the segment builder checks it against the machine).
/// Planned and run as any program is.
pub fn program(
    out: &[Entry],
    tilt_word: Option<(char, SrcPos)>,
    standing: &Standing,
    kin: &MachineKinematics,
) -> Program {
    let base = out
        .iter()
        .map(|e| match e {
            Entry::Block(i, _) => *i,
            Entry::Action(a) => a.before_block,
        })
        .min()
        .unwrap_or(0);
    let mut blocks = Vec::with_capacity(out.len() + 1);
    let mut actions = Vec::new();
    let first = out.iter().find_map(|e| match e {
        Entry::Block(_, b) => Some(b),
        Entry::Action(_) => None,
    });
    let (pos, tooling) = match first {
        Some(Block::Linear(m)) => (m.pos, m.tooling),
        Some(Block::Nurbs(b)) => (b.pos, b.tooling),
        None => (SrcPos::default(), MoveTooling::default()),
    };
    blocks.push(standing.start(kin, pos, None, tooling));
    for e in out {
        match e {
            Entry::Block(_, b) => blocks.push(b.clone()),
            Entry::Action(a) => actions.push(Action {
                before_block: a.before_block - base + 1,
                ..*a
            }),
        }
    }
    Program {
        blocks,
        end: None,
        actions,
        tilt_word,
        rerun: Vec::new(),
    }
}

/// Why `text` is not one MDI line, if it is not.
fn not_a_line(text: &str) -> Option<&'static str> {
    if text.chars().count() > MAX_MDI_CHARS {
        Some("longer than 255 characters")
    } else if text.contains(['\n', '\r']) {
        Some("more than one line: send each line on its own")
    } else if crate::word::continues(text) {
        Some("continued with `\\`: send the whole line")
    } else if text.trim() == "%" {
        Some("`%` marks a program's tape: not taken in MDI")
    } else {
        None
    }
}
