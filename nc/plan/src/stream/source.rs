//! [`Source`]: a program in, chunks out, read a line at a time. It chains the streaming
//! stages: the parser's entries ([`nc_lang::Entries`], or a parsed program's,
//! [`ProgramEntries`]; on-line compression wraps either, `nc_fit::online`), the segment
//! builder and the [`Planner`] ([`Stages`], whose final plan can go to any [`Sink`]), and
//! the [`Cutter`], and holds only what each holds: a line, a block (or the run of moves
//! being compressed), the planner's windows, the chunks not yet taken.
//! Its chunks are the ones [`super::cut`] cuts from [`crate::plan::plan`]'s plan of the
//! whole program, but for what only the whole plan knows: each chunk's `vmax_ahead` is the
//! machine's speed cap, and the start's margins are [`crate::verify::ceiling`].

use super::Cutter;
use crate::config::PlanConfig;
use crate::plan::{Finished, PlanError, Planner, Sink};
use nc_follow::{stop_length, Chunk, Start};
use nc_geom::kinematics::{Joints, MachineKinematics};
use nc_geom::program::{Action, Block, Program, SrcPos};
use nc_geom::segment::{BuildError, BuildLimits, Builder, Segment};
use nc_lang::{Entries, Entry, LineSource, ParseError};

/// A program's entries in the order they take effect, and its tilting-axis word.
pub trait ProgramSource: Iterator<Item = Result<Entry, ParseError>> {
    /// The letter the program's angle words use and where it first stood, once read.
    fn tilt_word(&self) -> Option<(char, SrcPos)>;
}

impl<S: LineSource> ProgramSource for Entries<'_, S> {
    fn tilt_word(&self) -> Option<(char, SrcPos)> {
        Entries::tilt_word(self)
    }
}

/// A parsed program's entries (after on-line compression, which needs it whole), in the
/// order [`nc_geom::segment::build`] takes them.
pub struct ProgramEntries {
    blocks: std::iter::Enumerate<std::vec::IntoIter<Block>>,
    actions: std::iter::Peekable<std::vec::IntoIter<Action>>,
    held: Option<(usize, Block)>,
    tilt: Option<(char, SrcPos)>,
}

impl ProgramEntries {
    pub fn new(program: Program) -> Self {
        ProgramEntries {
            blocks: program.blocks.into_iter().enumerate(),
            actions: program.actions.into_iter().peekable(),
            held: None,
            tilt: program.tilt_word,
        }
    }
}

impl Iterator for ProgramEntries {
    type Item = Result<Entry, ParseError>;

    fn next(&mut self) -> Option<Self::Item> {
        let Some((i, block)) = self.held.take().or_else(|| self.blocks.next()) else {
            return self.actions.next().map(|a| Ok(Entry::Action(a)));
        };
        if let Some(a) = self.actions.next_if(|a| a.before_block <= i) {
            self.held = Some((i, block));
            return Some(Ok(Entry::Action(a)));
        }
        Some(Ok(Entry::Block(i, block)))
    }
}

impl ProgramSource for ProgramEntries {
    fn tilt_word(&self) -> Option<(char, SrcPos)> {
        self.tilt
    }
}

/// Why a streamed program stops: the first error of its parse, build or plan.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StreamError {
    #[error(transparent)]
    Parse(#[from] ParseError),
    #[error(transparent)]
    Build(#[from] BuildError),
    #[error(transparent)]
    Plan(#[from] PlanError),
}

impl StreamError {
    /// Where in the program.
    pub fn pos(&self) -> SrcPos {
        match self {
            StreamError::Parse(e) => e.pos,
            StreamError::Build(e) => e.pos,
            StreamError::Plan(e) => e.pos,
        }
    }
}

/// The machine a [`Source`] plans for.
#[derive(Clone, Copy)]
pub struct Machine<'a> {
    pub kin: &'a MachineKinematics,
    pub build: &'a BuildLimits,
    pub plan: &'a PlanConfig,
}

/// A program read an entry at a time through the parser, the segment builder and the
/// [`Planner`], whose final plan goes to a [`Sink`] the caller hands in: the [`Cutter`] for
/// a [`Source`]'s chunks, a rolling window for `simulate` ([`crate::rolling::Rolling`]).
pub struct Stages<'a, E> {
    entries: E,
    machine: Machine<'a>,
    builder: Builder<'a>,
    /// Created once the start pose is final (the first segment is built).
    planner: Option<Planner<'a>>,
    segments: Vec<Segment>,
    tilt_checked: bool,
    start: Option<Start>,
    end: Option<(Joints, Finished)>,
    blocks: usize,
    failed: bool,
}

impl<'a, E: ProgramSource> Stages<'a, E> {
    pub fn new(entries: E, machine: Machine<'a>) -> Self {
        Stages {
            entries,
            machine,
            builder: Builder::new(machine.kin, machine.build),
            planner: None,
            segments: Vec::new(),
            tilt_checked: false,
            start: None,
            end: None,
            blocks: 0,
            failed: false,
        }
    }

    /// The program's start, once its first segment is built or the program ended.
    pub fn start(&self) -> Option<Start> {
        self.start
    }

    /// Where the program leaves the machine's joints and what its plan came to, once it
    /// ended.
    pub fn end(&self) -> Option<(Joints, Finished)> {
        self.end
    }

    /// The motion blocks read so far.
    pub fn blocks(&self) -> usize {
        self.blocks
    }

    /// The entries the stages read (what they have noted on the way).
    pub fn entries(&self) -> &E {
        &self.entries
    }

    pub fn entries_mut(&mut self) -> &mut E {
        &mut self.entries
    }

    /// Read the next entry through the stages, the plan it makes final into `sink`; at the
    /// program's end, plan the rest into it. False once the program has ended or failed.
    pub fn read(&mut self, sink: &mut impl Sink) -> Result<bool, StreamError> {
        if self.end.is_some() || self.failed {
            return Ok(false);
        }
        let read = self.entry(sink);
        self.failed = read.is_err();
        read?;
        Ok(self.end.is_none())
    }

    fn entry(&mut self, sink: &mut impl Sink) -> Result<(), StreamError> {
        let Some(entry) = self.entries.next() else {
            return self.finish(sink);
        };
        let entry = entry?;
        if !self.tilt_checked {
            if let Some(word) = self.entries.tilt_word() {
                self.tilt_checked = true;
                self.builder.tilt_word(Some(word))?;
            }
        }
        match entry {
            Entry::Action(a) => self.builder.action(&a),
            Entry::Block(i, block) => {
                self.blocks += 1;
                self.builder.block(i, &block, &mut self.segments)?;
                for seg in self.segments.drain(..) {
                    let planner = match &mut self.planner {
                        Some(p) => p,
                        None => self.planner.insert(Self::planner_for(
                            &self.builder,
                            self.machine,
                            &mut self.start,
                            false,
                        )?),
                    };
                    planner.push(seg, sink)?;
                }
            }
        }
        Ok(())
    }

    /// The planner, once the builder's start pose is final (a segment is built, or the
    /// program ended: `empty`), and the program's start.
    fn planner_for(
        builder: &Builder,
        m: Machine<'a>,
        start: &mut Option<Start>,
        empty: bool,
    ) -> Result<Planner<'a>, StreamError> {
        let pose = builder.start()?;
        *start = Some(Start {
            pose: pose.0,
            joints: pose.2,
            empty,
            margins: crate::verify::ceiling(m.plan),
        });
        Ok(Planner::new(pose, m.kin, m.plan))
    }

    fn finish(&mut self, sink: &mut impl Sink) -> Result<(), StreamError> {
        let planner = match self.planner.take() {
            Some(p) => p,
            // Nothing moves: the start pose alone, checked by the planner (its travel).
            None => Self::planner_for(&self.builder, self.machine, &mut self.start, true)?,
        };
        let end = planner.finish(sink)?;
        self.end = Some((self.builder.joints(), end));
        Ok(())
    }
}

/// Chunks of a program as it is read (see the module's text).
pub struct Source<'a, E> {
    stages: Stages<'a, E>,
    cutter: Cutter,
    /// The stages have ended (or failed): the cutter has all it will get.
    cut_last: bool,
}

impl<'a, E: ProgramSource> Source<'a, E> {
    /// Chunks for a follower holding `depth` of them (each at least the stop distance from
    /// the machine's speed cap over what it holds, [`super::stop_length`]).
    pub fn new(entries: E, machine: Machine<'a>, depth: usize) -> Self {
        let cap = machine.build.speed_cap();
        // A plan's speed reaches the cap by the planner's rounding at most.
        let vmax = cap * (1.0 + 1e-6);
        let hold = machine.plan.hold();
        let min_len = stop_length(vmax, &crate::verify::ceiling(machine.plan), &hold, depth);
        Source {
            stages: Stages::new(entries, machine),
            cutter: Cutter::new(min_len, vmax),
            cut_last: false,
        }
    }

    /// The program has `lines` source lines (each chunk's progress is measured by it).
    pub fn set_lines(&mut self, lines: u32) {
        self.cutter.set_lines(lines);
    }

    /// The program's start, once the first chunk has been cut or the program ended.
    pub fn start(&self) -> Option<Start> {
        self.stages.start()
    }

    /// Where the program leaves the machine's joints, once it ended.
    pub fn end_joints(&self) -> Option<Joints> {
        self.stages.end().map(|e| e.0)
    }

    /// The entries it reads (what they have noted on the way).
    pub fn entries(&self) -> &E {
        self.stages.entries()
    }

    /// The next chunk; None once the program has ended. After an error, None.
    pub fn next_chunk(&mut self) -> Result<Option<Box<Chunk>>, StreamError> {
        loop {
            if let Some(c) = self.cutter.next_chunk() {
                return Ok(Some(c));
            }
            if self.cut_last {
                return Ok(None);
            }
            if !self.stages.read(&mut self.cutter)? {
                self.cut_last = true;
                if let Some((_, end)) = self.stages.end() {
                    self.cutter.finish(end.duration);
                }
            }
        }
    }
}
