//! The modal state machine: classified lines in, resolved [`Block`]s out.

use super::error::{Context, Motion, ParseError, ParseErrorKind};
use super::line::{Line, MOVE_WORDS};
use super::nurbs::OpenNurbs;
use crate::program::{Block, LinearMove, NurbsBlock, NurbsKind, Orientation, Program, SrcPos};

/// Tool-vector length below which `I J K` is rejected (it has no direction).
pub(super) const MIN_VECTOR_LENGTH: f64 = 1e-9;
/// Slowest programmable feed, mm/min (0.06 mm/min was measured to run a 27 mm move for
/// hours; the planner refuses any plan over 24 h at 1 ms in any case).
pub const MIN_FEED_MM_MIN: f64 = 0.001;
/// Smallest NURBS weight (the largest is the `R` word's bound, 1e6).
pub const MIN_WEIGHT: f64 = 1e-6;
/// The tool orientation until a program gives one: vertical.
const VERTICAL: Orientation = Orientation::Vector([0.0, 0.0, 1.0]);

pub(super) struct Parser {
    blocks: Vec<Block>,
    /// Modal G00/G01 mode (NURBS modes are not modal).
    mode: Option<Motion>,
    feed: Option<f64>,
    /// End of the last move; `None` until the start pose.
    here: Option<[f64; 3]>,
    orientation: Orientation,
    /// `false` while `orientation` is the implicit vertical default.
    orientation_given: bool,
    /// The first `A` or `B` word of the program: the machine's first rotary axis.
    rotary: Option<(char, SrcPos)>,
    open: Option<OpenNurbs>,
    /// The NURBS block that ended on the previous line (for a helpful extra-knot error).
    just_closed: Option<(SrcPos, usize)>,
    end: Option<SrcPos>,
}

impl Parser {
    pub fn new() -> Self {
        Parser {
            blocks: Vec::new(),
            mode: None,
            feed: None,
            here: None,
            orientation: VERTICAL,
            orientation_given: false,
            rotary: None,
            open: None,
            just_closed: None,
            end: None,
        }
    }

    /// Takes one logical line (its words from the lexer).
    pub fn line(&mut self, words: &[super::lexer::Word]) -> Result<(), ParseError> {
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
        let line = Line::classify(words)?;
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
        if let Some(f) = line.get('F') {
            if f.value < MIN_FEED_MM_MIN {
                return Err(ParseErrorKind::BadFeed { value: f.value }.at(f.pos));
            }
            self.feed = Some(f.value);
        }
        match line.motion {
            Some((motion @ (Motion::G062 | Motion::G065), pos)) => {
                let Some(here) = self.here else {
                    return Err(ParseErrorKind::NurbsBeforeStart { motion }.at(pos));
                };
                self.open = Some(OpenNurbs::open(&line, (motion, pos), here, self.feed)?);
            }
            Some((motion, pos)) => {
                self.mode = Some(motion);
                self.linear(&line, motion, pos)?;
            }
            None => match line.first_of(MOVE_WORDS) {
                Some(w) => {
                    let Some(motion) = self.mode else {
                        return Err(ParseErrorKind::NoMotionMode { letter: w.letter }.at(w.pos));
                    };
                    self.linear(&line, motion, line.first)?;
                }
                None => line.only("GMF", Context::NoMotion)?,
            },
        }
        self.end = line.end;
        Ok(())
    }

    /// Ends the program: fails if a NURBS block is still open at `eof`.
    pub fn finish(self, eof: SrcPos) -> Result<Program, ParseError> {
        match &self.open {
            Some(open) => Err(open.incomplete(eof)),
            None => Ok(Program {
                blocks: self.blocks,
                end: self.end,
                tilt_word: self.rotary,
            }),
        }
    }

    fn close(&mut self, block: NurbsBlock) {
        self.here = block.ctrl.last().copied().or(self.here);
        if block.kind == NurbsKind::G065 {
            if let (Some(xyz), Some(uvw)) = (block.ctrl.last(), block.tool_ctrl.last()) {
                // Never zero: control points keep at least MIN_TOOL_OFFSET_MM from their tool point.
                if let Some(v) = normalise([uvw[0] - xyz[0], uvw[1] - xyz[1], uvw[2] - xyz[2]]) {
                    self.orientation = Orientation::Vector(v);
                    self.orientation_given = true;
                }
            }
        }
        self.just_closed = Some((block.pos, block.knots.len()));
        self.blocks.push(Block::Nurbs(block));
    }

    /// A G00/G01 line, or a line continuing that modal motion; `pos` is the block's position.
    fn linear(&mut self, line: &Line<'_>, motion: Motion, pos: SrcPos) -> Result<(), ParseError> {
        line.only("GMFXYZABCIJK", Context::Move(motion))?;
        if line.first_of(MOVE_WORDS).is_none() {
            return Ok(()); // `G01 F500`: sets the mode, moves nothing
        }
        let rapid = motion == Motion::G00;
        if !rapid && self.feed.is_none() {
            return Err(ParseErrorKind::NoFeed { motion }.at(pos));
        }
        let mut end = [0.0; 3];
        for ((slot, axis), prev) in end
            .iter_mut()
            .zip(['X', 'Y', 'Z'])
            .zip(self.here.map_or([None; 3], |h| h.map(Some)))
        {
            *slot = match (line.value(axis), prev) {
                (Some(v), _) | (None, Some(v)) => v,
                (None, None) => return Err(ParseErrorKind::MissingStartAxis { axis }.at(pos)),
            };
        }
        let orientation = self.orientation(line)?;
        self.here = Some(end);
        self.orientation_given |= line.first_of("ABCIJK").is_some();
        self.orientation = orientation;
        self.blocks.push(Block::Linear(LinearMove {
            pos,
            n: line.n,
            rapid,
            end,
            orientation,
            feed_mm_min: self.feed.unwrap_or(0.0),
        }));
        Ok(())
    }

    /// The orientation at the end of a linear move (modal values resolved).
    fn orientation(&mut self, line: &Line<'_>) -> Result<Orientation, ParseError> {
        let angle = line.first_of("ABC");
        let vector = line.first_of("IJK");
        match (angle, vector) {
            (Some(a), Some(v)) => {
                let later = if a.pos > v.pos { a.pos } else { v.pos };
                let kind = ParseErrorKind::MixedOrientation {
                    angle: a.letter,
                    vector: v.letter,
                };
                Err(kind.at(later))
            }
            (None, Some(given)) => {
                let mut ijk = [0.0; 3];
                for (slot, letter) in ijk.iter_mut().zip(['I', 'J', 'K']) {
                    let missing = ParseErrorKind::IncompleteVector {
                        given: given.letter,
                        missing: letter,
                    };
                    *slot = line.value(letter).ok_or(missing.at(given.pos))?;
                }
                let zero = ParseErrorKind::ZeroVector { ijk }.at(given.pos);
                Ok(Orientation::Vector(normalise(ijk).ok_or(zero)?))
            }
            (Some(_), None) => self
                .angles(line)
                .map(|(r1_deg, r2_deg)| Orientation::Angles { r1_deg, r2_deg }),
            (None, None) => Ok(self.orientation),
        }
    }

    /// The rotary angles of a line with angle words.
    fn angles(&mut self, line: &Line<'_>) -> Result<(f64, f64), ParseError> {
        let r1 = match (line.get('A'), line.get('B')) {
            (Some(a), Some(b)) => {
                let kind = ParseErrorKind::MixedRotaryAxes {
                    letter: 'B',
                    first: 'A',
                    first_pos: a.pos,
                };
                return Err(kind.at(b.pos));
            }
            (r1, None) | (None, r1) => r1,
        };
        if let Some(w) = r1 {
            match self.rotary {
                Some((first, first_pos)) if first != w.letter => {
                    let kind = ParseErrorKind::MixedRotaryAxes {
                        letter: w.letter,
                        first,
                        first_pos,
                    };
                    return Err(kind.at(w.pos));
                }
                Some(_) => {}
                None => self.rotary = Some((w.letter, w.pos)),
            }
        }
        let r2 = line.get('C');
        let (prev1, prev2) = match self.orientation {
            Orientation::Angles { r1_deg, r2_deg } => (r1_deg, r2_deg),
            // The implicit vertical tool is A0 C0 (B0 C0) on the machines dnurbs drives.
            Orientation::Vector(_) if !self.orientation_given => (0.0, 0.0),
            Orientation::Vector(_) => match (r1, r2) {
                (Some(given), None) | (None, Some(given)) => {
                    let kind = ParseErrorKind::PartialAngles {
                        given: given.letter,
                    };
                    return Err(kind.at(given.pos));
                }
                _ => (0.0, 0.0),
            },
        };
        Ok((r1.map_or(prev1, |w| w.value), r2.map_or(prev2, |w| w.value)))
    }
}

/// `v / |v|`, or `None` when `|v|` is not above [`MIN_VECTOR_LENGTH`]. Scaled first so that
/// squaring cannot overflow for any finite input.
fn normalise(v: [f64; 3]) -> Option<[f64; 3]> {
    let scale = v.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    if scale == 0.0 {
        return None;
    }
    let s = v.map(|c| c / scale);
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    (len * scale > MIN_VECTOR_LENGTH).then(|| s.map(|c| c / len))
}
