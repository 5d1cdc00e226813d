//! The modal state machine: classified lines in, resolved [`Block`]s and [`Action`]s out.
//!
//! Per line, in the order the words take effect (LinuxCNC's order of execution): the modes
//! (plane, units, distance, feed mode, work offset, tool length, path control), `F`, `S`,
//! `T`, `M06`, spindle, coolant, `G04`, the motion (`moves.rs`), then `M00`/`M01` and the
//! program end.

use super::codes::{Code, LengthComp, StopCode};
use super::error::{Context, ParseError, ParseErrorKind};
use super::line::{Line, MOVE_WORDS};
use super::modal::{Modal, Setup};
use super::nurbs::OpenNurbs;
use crate::rules::{MAX_DWELL_S, MIN_VECTOR_LENGTH};
use crate::vocab::Motion;
use nc_geom::program::{
    Action, ActionKind, Block, LengthMode, MoveTooling, Orientation, PathMode, SrcPos, Wait,
};

/// The tool orientation until a program gives one: vertical.
pub(super) const VERTICAL: Orientation = Orientation::Vector([0.0, 0.0, 1.0]);
/// Largest tool or spindle-speed word.
const MAX_RPM: f64 = 1e6;

pub(super) struct Parser<'s> {
    pub setup: &'s Setup,
    pub modal: Modal,
    /// Blocks and actions not yet taken by [`super::stream::Entries`].
    pub blocks: Vec<Block>,
    pub actions: Vec<Action>,
    /// Blocks taken out of `blocks` so far.
    pub drained: usize,
    /// Modal motion mode (G00 G01 G02 G03; NURBS modes are not modal).
    pub mode: Option<Motion>,
    /// Modal feed, mm/min (`G94`).
    pub feed: Option<f64>,
    /// End of the last move (tool tip, workpiece frame, mm); `None` until the start pose.
    pub here: Option<[f64; 3]>,
    pub orientation: Orientation,
    /// `false` while `orientation` is the implicit vertical default.
    pub orientation_given: bool,
    /// The first `A` or `B` word of the program: the machine's first rotary axis.
    pub rotary: Option<(char, SrcPos)>,
    /// What the next motion block waits for.
    pub wait: Wait,
    /// The index of the block that moves to the reference position because the program's
    /// first move does not give a full pose (the machine is there already, homed).
    pub from_reference: Option<usize>,
    pub(super) open: Option<OpenNurbs>,
    /// The NURBS block that ended on the previous line (for a helpful extra-knot error).
    pub(super) just_closed: Option<(SrcPos, usize)>,
    /// After an error inside a NURBS block: skip its remaining control-point and knot lines.
    skipping: bool,
    end: Option<SrcPos>,
    /// The start-up modes did not apply (a setup changed after [`crate::Startup::parse`]
    /// checked them): the first line reports it.
    startup_error: Option<ParseError>,
    /// Moves the canned cycle of the current line has made.
    pub cycle_moves: usize,
    /// `G95`: the programmed feed per revolution, mm.
    pub feed_per_rev: Option<f64>,
    /// The last feed reported as above the machine's highest (mm/min).
    pub(super) clamped: Option<f64>,
    /// A `G5.2` block being read.
    pub g52: Option<crate::open_g52::OpenG52>,
    /// The `P Q` of the last `G5` (a `G5` without `I J` continues it), mm.
    pub last_spline_pq: Option<(f64, f64)>,
    /// The call level the interpreter is at, and the states `M70` and `M73` saved.
    pub level: usize,
    pub saved: crate::saved::SavedStates,
    /// Cutter radius compensation and the moves it holds.
    pub comp: crate::comp::Comp,
    /// G54..G59 as the program has them (the setup's, changed by `G10 L2`/`L20`).
    pub work_offsets: [Option<[f64; 3]>; 6],
    /// Their XY rotations (`G10 L2 R`), degrees.
    pub rotations: [f64; 6],
    /// Tool lengths and diameters as the program has them (the setup's, changed by
    /// `G10 L1`), mm.
    pub tools: std::collections::BTreeMap<u32, f64>,
    pub diameters: std::collections::BTreeMap<u32, f64>,
    /// A compensated arc that could not be built when it was released.
    pub comp_error: Option<ParseError>,
}

impl<'s> Parser<'s> {
    pub fn new(setup: &'s Setup) -> Self {
        let modal = Modal {
            offset: setup.work_offsets[0].unwrap_or([0.0; 3]),
            ..Modal::default()
        };
        let mut parser = Parser {
            setup,
            modal,
            blocks: Vec::new(),
            actions: Vec::new(),
            drained: 0,
            mode: None,
            feed: None,
            here: None,
            orientation: VERTICAL,
            orientation_given: false,
            rotary: None,
            wait: Wait::default(),
            from_reference: None,
            open: None,
            just_closed: None,
            skipping: false,
            end: None,
            startup_error: None,
            clamped: None,
            feed_per_rev: None,
            cycle_moves: 0,
            g52: None,
            last_spline_pq: None,
            level: 0,
            saved: crate::saved::SavedStates::default(),
            comp: crate::comp::Comp::default(),
            work_offsets: setup.work_offsets,
            rotations: [0.0; 6],
            tools: setup.tools.clone(),
            diameters: setup.tool_diameters.clone(),
            comp_error: None,
        };
        let startup = setup.startup.words();
        if !startup.is_empty() {
            parser.startup_error = parser.line(startup).err();
            // The machine's own modes are not the program's words, but for a path-control
            // mode other than LinuxCNC's default: the compressor follows it from the start.
            parser
                .actions
                .retain(|a| matches!(a.kind, ActionKind::PathMode(m) if m != PathMode::default()));
        }
        parser
    }

    /// A new program starts on this state (an MDI session's): its blocks count from 0, its
    /// end and its first move's start are its own.
    pub fn start_program(&mut self) {
        self.drained = 0;
        self.from_reference = None;
        self.end = None;
        self.just_closed = None;
        self.skipping = false;
        self.cycle_moves = 0;
    }

    /// After an error on a line: drop an open NURBS block and skip the rest of its lines.
    pub fn recover(&mut self) {
        if self.open.take().is_some() {
            self.skipping = true;
        }
    }

    /// Takes one logical line (its words from the lexer).
    pub fn line(&mut self, words: &[super::word::Word]) -> Result<(), ParseError> {
        if let Some(e) = self.startup_error.take() {
            return Err(e);
        }
        let Some(first) = words.first() else {
            return Ok(());
        };
        if let Some(end) = self.end {
            let kind = ParseErrorKind::AfterProgramEnd {
                letter: first.letter,
                end,
            };
            return Err(kind.at(first.pos));
        }
        let line = Line::classify(words, &self.setup.user_mcodes)?;
        if !self.setup.rotary_axes {
            if let Some(w) = line.first_of("ABC") {
                let what = match w.letter {
                    'A' => "an A word",
                    'B' => "a B word",
                    _ => "a C word",
                };
                return Err(ParseErrorKind::NoRotaryAxes { what }.at(w.pos));
            }
        }
        if self.skipping {
            if line.knots_only || (!line.has_codes && line.first_of("KRUVW").is_some()) {
                return Ok(());
            }
            self.skipping = false;
        }
        if let Some(open) = &mut self.open {
            if open.take_line(&line)? {
                if let Some(open) = self.open.take() {
                    self.close(open.finish()?);
                }
            }
            return Ok(());
        }
        if let (true, Some((opened, need)), Some(k)) =
            (line.knots_only, self.just_closed, line.body.first())
        {
            let kind = ParseErrorKind::TooManyKnots {
                value: k.value,
                opened,
                need,
            };
            return Err(kind.at(k.pos));
        }
        self.just_closed = None;
        if let Some(o) = line.get('O') {
            if line.body.len() != 1 {
                return Err(ParseErrorKind::MisplacedProgramNumber { value: o.value }.at(o.pos));
            }
            return Ok(());
        }
        let motion = line.motion.map(|(m, _)| m).or_else(|| {
            line.first_of(MOVE_WORDS)
                .and_then(|_| self.mode.filter(|_| !self.is_dwell(&line)))
        });
        self.modes(&line, motion)?;
        self.feed_word(&line)?;
        self.machine_words(&line)?;
        self.rev_feed(line.first);
        self.radius_comp(&line)?;
        let moves = self.blocks.len();
        let moved = if self.is_dwell(&line) {
            // The dwell first, then a move on the same line (LinuxCNC's order).
            self.dwell(&line)?;
            if line.motion.is_some() {
                self.motion(&line)
            } else {
                Ok(())
            }
        } else {
            self.motion(&line)
        };
        if let Err(e) = moved {
            self.assume_end(&line);
            return Err(e);
        }
        if self.blocks.len() > moves {
            self.check_tcp_off(line.motion.map_or(line.first, |m| m.1))?;
        }
        if let Some((Code::Stop(stop), pos)) = line.code_of_group(11) {
            if stop != StopCode::ToolChange {
                // A stop releases the moves compensation holds, where they are.
                self.comp_flush(pos)?;
            }
            match stop {
                StopCode::Stop => self.stop(pos, ActionKind::Stop, true),
                StopCode::Optional => {
                    let taken = self.setup.optional_stop;
                    self.stop(pos, ActionKind::OptionalStop { taken }, taken);
                }
                StopCode::End => self.comp.active = None,
                StopCode::ToolChange => {}
            }
        }
        if let Some(e) = self.comp_error.take() {
            return Err(e);
        }
        self.end = line.end;
        Ok(())
    }

    /// After a refused move: the position the line programs, as if it had moved there, so
    /// the lines after it are checked from where the program means them to start (not from
    /// the stale position before it, which would invent errors the program does not have).
    fn assume_end(&mut self, line: &Line<'_>) {
        if self.here.is_none() || self.open.is_some() || line.first_of("XYZ").is_none() {
            return;
        }
        if matches!(
            line.code_of_group(1),
            Some((
                Code::Home
                    | Code::Home30
                    | Code::MachineCoords
                    | Code::CoordOffset(_)
                    | Code::SetTable,
                _
            ))
        ) || matches!(self.mode, Some(crate::vocab::Motion::Cycle(_)))
        {
            return;
        }
        if let Ok(end) = self.end_point(line, line.first) {
            self.here = Some(end);
        }
    }

    fn is_dwell(&self, line: &Line<'_>) -> bool {
        matches!(line.code_of_group(1), Some((Code::Dwell, _)))
    }

    /// At the end of the source: fails if a NURBS block is still open at `eof`; releases
    /// the moves compensation holds.
    pub fn check_end(&mut self, eof: SrcPos) -> Result<(), ParseError> {
        self.g52_unclosed(eof)?;
        if let Some(open) = &self.open {
            return Err(open.incomplete(eof));
        }
        self.comp_flush(eof)?;
        match self.comp_error.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Where `M02`/`M30` stood, if read.
    pub fn end(&self) -> Option<SrcPos> {
        self.end
    }

    /// The modal codes of a line other than motion and stops. `motion` is the line's
    /// effective motion (its code, or the modal one when it has coordinates).
    fn modes(&mut self, line: &Line<'_>, motion: Option<Motion>) -> Result<(), ParseError> {
        for (code, pos) in line.codes() {
            self.comp_allows(code, pos)?;
            match code {
                Code::Plane(p) => self.modal.plane = p,
                Code::Inch(inch) => self.modal.inch = inch,
                Code::Incremental(inc) => self.modal.incremental = inc,
                Code::InverseTime(it) => {
                    self.modal.inverse_time = it;
                    self.modal.per_rev = false;
                    if !it {
                        // LinuxCNC's rule: G94 and G95 set the feed to 0 (an F on the line
                        // sets it again).
                        self.feed = None;
                    }
                }
                Code::PerRev => {
                    self.modal.inverse_time = false;
                    self.modal.per_rev = true;
                    self.feed = None;
                    self.feed_per_rev = None;
                }
                Code::Blend(b) => {
                    let path = if b {
                        self.blend_words(line)?
                    } else {
                        PathMode::Exact
                    };
                    self.modal.path = path;
                    self.act(pos, ActionKind::PathMode(path));
                }
                Code::ArcCentreAbsolute(abs) => self.modal.arc_absolute = abs,
                Code::Retract(to_r) => self.modal.cycle.retract_to_r = to_r,
                Code::CannedOff if line.motion.is_none() => {
                    self.mode = None;
                    self.end_cycle();
                }
                Code::WorkOffset(i) => {
                    let defined = self.work_offsets.get(usize::from(i)).copied().flatten();
                    let work = match (defined, i) {
                        (Some(o), _) => o,
                        (None, 0) => [0.0; 3],
                        (None, _) => {
                            let code = 54.0 + f64::from(i);
                            return Err(ParseErrorKind::UnknownWorkOffset { code }.at(pos));
                        }
                    };
                    self.modal.offset = std::array::from_fn(|k| work[k] + self.modal.g92[k]);
                    self.modal.work = i;
                }
                Code::LengthComp(comp) => self.length_comp(line, comp, pos, motion)?,
                _ => {}
            }
        }
        if let Some(h) = line.get('H') {
            if !matches!(line.code_of_group(7), Some((Code::LengthComp(c), _)) if c != LengthComp::Off)
            {
                let kind = ParseErrorKind::WordNotAllowed {
                    letter: 'H',
                    context: Context::NoMotion,
                };
                return Err(kind.at(h.pos));
            }
        }
        Ok(())
    }

    /// `S`, `T`, `M06`, spindle and coolant codes: recorded as actions.
    fn machine_words(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        if let Some(s) = line.get('S') {
            if !(0.0..=MAX_RPM).contains(&s.value) {
                return Err(ParseErrorKind::BadSpeed { value: s.value }.at(s.pos));
            }
            if let Some(max) = self.setup.max_rpm.filter(|&m| s.value > m) {
                return Err(ParseErrorKind::SpeedAboveMax {
                    value: s.value,
                    max,
                }
                .at(s.pos));
            }
            self.modal.rpm = s.value;
            if line.code_of_group(12).is_none() {
                self.act(s.pos, ActionKind::Speed { rpm: s.value });
            }
        }
        if let Some(t) = line.get('T') {
            let tool = tool_number(t)?;
            self.modal.selected = Some(tool);
            self.act(t.pos, ActionKind::SelectTool { tool });
        }
        for (code, pos) in line.codes() {
            match code {
                Code::Stop(StopCode::ToolChange) => {
                    self.comp_forbids("a tool change (M06)", pos)?;
                    let tool = self.modal.selected;
                    self.modal.loaded = tool;
                    self.stop(pos, ActionKind::ChangeTool { tool }, true);
                }
                Code::Spindle(dir) => {
                    self.modal.spindle = dir;
                    let rpm = self.modal.rpm;
                    self.act(pos, ActionKind::Spindle { dir, rpm });
                }
                Code::Coolant(c) => {
                    use nc_geom::program::Coolant;
                    match c {
                        Coolant::Mist => self.modal.mist = true,
                        Coolant::Flood => self.modal.flood = true,
                        Coolant::Off => (self.modal.mist, self.modal.flood) = (false, false),
                    }
                    self.act(pos, ActionKind::Coolant(c));
                }
                _ => {}
            }
        }
        self.context(line)?;
        if let Some((Code::Io(_), pos)) = line.code_of_group(16) {
            self.comp_forbids("an output or a wait (M62..M68)", pos)?;
        }
        self.io(line)?;
        self.user_m(line)
    }

    /// `G04 P<s>` / `G04 X<s>`; with `G00`/`G01` on the line, `P` only (X is the move's).
    fn dwell(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let with_move = match line.motion {
            Some((Motion::G00 | Motion::G01, _)) => true,
            Some((m, pos)) => {
                // G02/G03 use P for turns, the NURBS blocks for their degree.
                let kind = ParseErrorKind::ConflictingCodes {
                    letter: 'G',
                    first: 4.0,
                    second: motion_value(m),
                };
                return Err(kind.at(pos));
            }
            None => false,
        };
        if !with_move {
            line.only("GMFSTPX", Context::Dwell)?;
        }
        let pos = line.first_of("G").map_or(line.first, |w| w.pos);
        let x = line.get('X').filter(|_| !with_move);
        let t = match (line.get('P'), x) {
            (Some(p), Some(x)) => {
                let kind = ParseErrorKind::RepeatedWord {
                    letter: 'X',
                    first: p.pos,
                };
                return Err(kind.at(x.pos));
            }
            (Some(w), None) | (None, Some(w)) => w,
            (None, None) => return Err(ParseErrorKind::DwellWithoutTime.at(pos)),
        };
        if !(0.0..=MAX_DWELL_S).contains(&t.value) {
            return Err(ParseErrorKind::BadDwell { value: t.value }.at(t.pos));
        }
        self.wait.dwell_s += t.value;
        self.act(pos, ActionKind::Dwell { seconds: t.value });
        Ok(())
    }

    /// Records an action before the next motion block (held behind the moves cutter
    /// compensation holds, if any).
    pub(super) fn act(&mut self, pos: SrcPos, kind: ActionKind) {
        if self.comp.holding() {
            self.comp.queue.push(crate::comp::Queued::Action(pos, kind));
        } else {
            self.act_now(pos, kind);
        }
    }

    /// Records an action before the next motion block the parser emits.
    pub(super) fn act_now(&mut self, pos: SrcPos, kind: ActionKind) {
        self.actions.push(Action {
            pos,
            before_block: self.drained + self.blocks.len(),
            kind,
        });
    }

    /// Records a stop; `wait` makes the next motion block wait for the operator.
    fn stop(&mut self, pos: SrcPos, kind: ActionKind, wait: bool) {
        self.act(pos, kind);
        if wait && self.wait.operator.is_none() {
            self.wait.operator = Some(pos);
        }
    }

    /// The next block's tooling: the tool length, RTCP and the pending wait (taken).
    pub(super) fn tooling(&mut self) -> MoveTooling {
        MoveTooling {
            tool_length: self.modal.tool_length,
            mode: match self.modal.comp {
                LengthComp::Off => LengthMode::None,
                LengthComp::Length | LengthComp::Dynamic | LengthComp::Added
                    if !self.modal.tcp_on =>
                {
                    LengthMode::Length
                }
                _ => LengthMode::Rtcp,
            },
            wait: core::mem::take(&mut self.wait),
        }
    }
}

/// A `T` or `H` word as a tool number.
pub(super) fn tool_number(w: super::word::Word) -> Result<u32, ParseError> {
    match w.uint {
        Some(t) if t <= 99_999 => Ok(t),
        _ => Err(ParseErrorKind::BadNumber {
            letter: w.letter,
            value: w.value,
        }
        .at(w.pos)),
    }
}

fn motion_value(m: Motion) -> f64 {
    match m {
        Motion::G00 => 0.0,
        Motion::G01 => 1.0,
        Motion::G02 => 2.0,
        Motion::G03 => 3.0,
        Motion::G062 => 6.2,
        Motion::G05 => 5.0,
        Motion::G051 => 5.1,
        Motion::G052 => 5.2,
        Motion::G053 => 5.3,
        Motion::G065 => 6.5,
        Motion::Cycle(c) => c.code(),
    }
}

/// `v / |v|`, or `None` when `|v|` is not above [`MIN_VECTOR_LENGTH`]. Scaled first so that
/// squaring cannot overflow for any finite input.
pub(super) fn normalise(v: [f64; 3]) -> Option<[f64; 3]> {
    let scale = v.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    if scale == 0.0 {
        return None;
    }
    let s = v.map(|c| c / scale);
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    (len * scale > MIN_VECTOR_LENGTH).then(|| s.map(|c| c / len))
}
