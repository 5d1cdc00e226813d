//! One logical line, classified: its sequence number, its G and M codes decoded into their
//! modal groups, and its remaining words indexed by letter.
//!
//! The rules that need no modal state are checked here: unknown letters, unsupported codes,
//! two codes of one group, a misplaced or malformed `N`, a word repeated on a line.

use super::error::{Context, Motion, ParseError, ParseErrorKind};
use super::lexer::Word;
use crate::program::SrcPos;

/// Letters the language knows. Anything else is [`ParseErrorKind::UnsupportedWord`].
const KNOWN: &str = "ABCFGIJKMNPRUVWXYZ";

/// Words that make a line move the machine (in the modal G00/G01 mode if no G word is given).
pub(super) const MOVE_WORDS: &str = "XYZABCIJK";

/// A classified, non-empty logical line.
pub(super) struct Line<'w> {
    /// `N` number, if the line starts with one.
    pub n: Option<u32>,
    /// Position of the first word (the `N` word if there is one).
    pub first: SrcPos,
    /// The words after `N`, in source order (G and M words included).
    pub body: &'w [Word],
    /// Motion code and its position.
    pub motion: Option<(Motion, SrcPos)>,
    /// Position of `M02` / `M30`.
    pub end: Option<SrcPos>,
    /// `true` when the body has G or M words.
    pub has_codes: bool,
    /// `true` when the body is one or more `K` words and nothing else (trailing knots).
    pub knots_only: bool,
    /// The non-code words, indexed by letter (unused when `knots_only`).
    slots: [Option<Word>; 26],
}

impl<'w> Line<'w> {
    /// Classifies a logical line. `words` must not be empty.
    pub fn classify(words: &'w [Word]) -> Result<Self, ParseError> {
        let first = words.first().map(|w| w.pos).unwrap_or_default();
        let (n, body) = match words.split_first() {
            Some((w, rest)) if w.letter == 'N' => (Some(sequence_number(w)?), rest),
            _ => (None, words),
        };
        let mut line = Line {
            n,
            first,
            body,
            motion: None,
            end: None,
            has_codes: false,
            knots_only: !body.is_empty() && body.iter().all(|w| w.letter == 'K'),
            slots: [None; 26],
        };
        // Modal groups seen on this line: motion, distance (G90), units (G21), program end.
        let mut groups: [Option<f64>; 4] = [None; 4];
        for w in body {
            let group = match w.letter {
                l if !KNOWN.contains(l) => Err(ParseErrorKind::UnsupportedWord {
                    letter: l,
                    value: w.value,
                }),
                'N' => Err(ParseErrorKind::MisplacedSequenceNumber { value: w.value }),
                'G' => g_code(w.value).map(|g| match g {
                    GCode::Motion(m) => {
                        line.motion = Some((m, w.pos));
                        0
                    }
                    GCode::Absolute => 1,
                    GCode::Metric => 2,
                }),
                'M' => m_code(w.value).map(|()| {
                    line.end = Some(w.pos);
                    3
                }),
                _ => {
                    if !line.knots_only {
                        line.insert(w)?;
                    }
                    continue;
                }
            };
            let group = group.map_err(|kind| kind.at(w.pos))?;
            line.has_codes = true;
            if let Some(Some(prev)) = groups.get(group) {
                let kind = ParseErrorKind::ConflictingCodes {
                    letter: w.letter,
                    first: *prev,
                    second: w.value,
                };
                return Err(kind.at(w.pos));
            }
            if let Some(slot) = groups.get_mut(group) {
                *slot = Some(w.value);
            }
        }
        Ok(line)
    }

    fn insert(&mut self, w: &Word) -> Result<(), ParseError> {
        let Some(slot) = self.slots.get_mut(letter_index(w.letter)) else {
            return Ok(()); // unreachable: the lexer only produces ASCII letters
        };
        if let Some(prev) = slot {
            let kind = ParseErrorKind::RepeatedWord {
                letter: w.letter,
                first: prev.pos,
            };
            return Err(kind.at(w.pos));
        }
        *slot = Some(*w);
        Ok(())
    }

    /// The word with this (upper-case) letter, if the line has it.
    pub fn get(&self, letter: char) -> Option<Word> {
        self.slots.get(letter_index(letter)).copied().flatten()
    }

    /// The value of the word with this letter, if the line has it.
    pub fn value(&self, letter: char) -> Option<f64> {
        self.get(letter).map(|w| w.value)
    }

    /// The first word in source order whose letter is in `letters`.
    pub fn first_of(&self, letters: &str) -> Option<Word> {
        self.body
            .iter()
            .find(|w| letters.contains(w.letter))
            .copied()
    }

    /// Fails on the first word whose letter is not in `allowed`.
    pub fn only(&self, allowed: &str, context: Context) -> Result<(), ParseError> {
        match self.body.iter().find(|w| !allowed.contains(w.letter)) {
            Some(w) => Err(ParseErrorKind::WordNotAllowed {
                letter: w.letter,
                context,
            }
            .at(w.pos)),
            None => Ok(()),
        }
    }

    /// The word `letter`, or [`ParseErrorKind::MissingWord`] at `at`.
    pub fn require(&self, letter: char, context: Context, at: SrcPos) -> Result<Word, ParseError> {
        self.get(letter)
            .ok_or(ParseErrorKind::MissingWord { letter, context }.at(at))
    }
}

/// Decoded G codes.
enum GCode {
    Motion(Motion),
    /// G90, absolute coordinates (the only mode supported).
    Absolute,
    /// G21, millimetres (the only unit supported).
    Metric,
}

fn g_code(value: f64) -> Result<GCode, ParseErrorKind> {
    // Exact comparisons are sound: `06.5` and `6.5` parse to the same correctly-rounded f64.
    const TABLE: [(f64, GCode); 6] = [
        (0.0, GCode::Motion(Motion::G00)),
        (1.0, GCode::Motion(Motion::G01)),
        (6.2, GCode::Motion(Motion::G062)),
        (6.5, GCode::Motion(Motion::G065)),
        (90.0, GCode::Absolute),
        (21.0, GCode::Metric),
    ];
    TABLE
        .into_iter()
        .find(|(v, _)| *v == value)
        .map(|(_, g)| g)
        .ok_or(ParseErrorKind::UnsupportedGCode { code: value })
}

/// `M02` and `M30` (program end) are the only M codes.
fn m_code(value: f64) -> Result<(), ParseErrorKind> {
    if value == 2.0 || value == 30.0 {
        Ok(())
    } else {
        Err(ParseErrorKind::UnsupportedMCode { code: value })
    }
}

fn sequence_number(w: &Word) -> Result<u32, ParseError> {
    w.uint
        .ok_or(ParseErrorKind::BadSequenceNumber { value: w.value }.at(w.pos))
}

/// Slot of an upper-case ASCII letter; anything else maps out of range (and is never stored).
fn letter_index(letter: char) -> usize {
    u8::try_from(letter).map_or(usize::MAX, |b| usize::from(b.wrapping_sub(b'A')))
}
