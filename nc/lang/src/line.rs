//! One logical line, classified: its sequence number, its G and M codes decoded into their
//! modal groups (`codes`), and its remaining words indexed by letter.
//!
//! The rules that need no modal state are checked here: unknown letters, unsupported codes,
//! two codes of one group, a misplaced or malformed `N`, a word repeated on a line.

use super::codes::{g_code, m_code, Code, StopCode, GROUPS};
use super::error::{Context, ParseError, ParseErrorKind};
use super::word::Word;
use crate::vocab::Motion;
use nc_geom::program::SrcPos;

/// Letters the language knows. Anything else is [`ParseErrorKind::UnsupportedWord`].
pub(super) const KNOWN: &str = "ABCDEFGHIJKLMNOPQRSTUVWXYZ@^";

/// Words that make a line move the machine (in the modal motion mode if no G word is given).
pub(super) const MOVE_WORDS: &str = "XYZABCIJKR@^";

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
    /// The decoded codes by modal group, with their position.
    codes: [Option<(Code, SrcPos)>; GROUPS],
    /// The non-code words, indexed by letter (unused when `knots_only`).
    slots: [Option<Word>; 28],
}

impl<'w> Line<'w> {
    /// Classifies a logical line. `words` must not be empty.
    /// `user`: the M-codes the machine defines (`[mcodes]`).
    pub fn classify(
        words: &'w [Word],
        user: &std::collections::BTreeMap<u32, nc_geom::program::UserAction>,
    ) -> Result<Self, ParseError> {
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
            codes: [None; GROUPS],
            slots: [None; 28],
        };
        let mut values: [f64; GROUPS] = [0.0; GROUPS];
        for w in body {
            let code = match w.letter {
                l if !KNOWN.contains(l) => Err(ParseErrorKind::UnsupportedWord {
                    letter: l,
                    value: w.value,
                }),
                'N' => Err(ParseErrorKind::MisplacedSequenceNumber { value: w.value }),
                'G' => code_number(w.value, 10.0, 0.001).and_then(g_code),
                'M' => code_number(w.value, 1.0, 1e-4).and_then(|v| {
                    m_code(v).or_else(|e| match super::word::as_uint(v) {
                        Some(n) if user.contains_key(&n) => Ok(Code::User(n)),
                        _ => Err(e),
                    })
                }),
                _ => {
                    if !line.knots_only {
                        line.insert(w)?;
                    }
                    continue;
                }
            };
            let code = code.map_err(|kind| kind.at(w.pos))?;
            line.has_codes = true;
            let group = code.group();
            let (Some(slot), Some(value)) = (line.codes.get_mut(group), values.get_mut(group))
            else {
                continue; // unreachable: every group is below GROUPS
            };
            if slot.is_some() {
                let kind = ParseErrorKind::ConflictingCodes {
                    letter: w.letter,
                    first: *value,
                    second: w.value,
                };
                return Err(kind.at(w.pos));
            }
            *slot = Some((code, w.pos));
            *value = w.value;
            match code {
                Code::Motion(m) => line.motion = Some((m, w.pos)),
                Code::Stop(StopCode::End) => line.end = Some(w.pos),
                _ => {}
            }
        }
        Ok(line)
    }

    fn insert(&mut self, w: &Word) -> Result<(), ParseError> {
        let Some(slot) = self.slots.get_mut(letter_index(w.letter)) else {
            return Ok(()); // unreachable: the syntax only produces ASCII letters
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

    /// The codes of the line, in group order.
    pub fn codes(&self) -> impl Iterator<Item = (Code, SrcPos)> + '_ {
        self.codes.iter().flatten().copied()
    }

    /// The code of `code`'s group, if the line has one.
    pub fn code_of_group(&self, group: usize) -> Option<(Code, SrcPos)> {
        self.codes.get(group).copied().flatten()
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
            // U V W on a move: an axis dnurbs's machines do not have.
            Some(w) if matches!(context, Context::Move(_)) && "UVW".contains(w.letter) => {
                Err(ParseErrorKind::NoSuchAxis { letter: w.letter }.at(w.pos))
            }
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

/// A G or M word's value as its code, read as LinuxCNC does: `value * scale` within `tol` of
/// a whole number (`G1.0001` is G1, `G[0.1*10]` is G1, `G1.001` is no code).
fn code_number(value: f64, scale: f64, tol: f64) -> Result<f64, ParseErrorKind> {
    let t = value * scale;
    let n = t.round();
    if (t - n).abs() <= tol {
        Ok(n / scale)
    } else {
        Err(ParseErrorKind::NotACode {
            letter: if scale == 1.0 { 'M' } else { 'G' },
            value,
        })
    }
}

fn sequence_number(w: &Word) -> Result<u32, ParseError> {
    w.uint
        .ok_or(ParseErrorKind::BadSequenceNumber { value: w.value }.at(w.pos))
}

/// Slot of an upper-case ASCII letter; anything else maps out of range (and is never stored).
fn letter_index(letter: char) -> usize {
    match letter {
        '@' => 26,
        '^' => 27,
        _ => u8::try_from(letter).map_or(usize::MAX, |b| usize::from(b.wrapping_sub(b'A'))),
    }
}
