//! Lexer: source text -> logical lines of [`Word`]s.
//!
//! A physical line is scanned once, character by character, counting columns in characters.
//! Comments (`( ... )` and `;` to the end of the line) and whitespace vanish here; a line that
//! ends in `\` (spaces may follow) is joined with the next one into one logical line, each word
//! keeping its own physical position. A `%` standing alone on a line is dropped. Numbers have
//! no exponent (`E` is a word letter), so the only non-finite value is a digit string too long
//! for an `f64`, which is an error.

use super::error::{ParseError, ParseErrorKind};
use super::source::LineSource;
use nc_geom::program::SrcPos;

/// One word: an (upper-cased) letter and the number that follows it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Word {
    pub letter: char,
    pub value: f64,
    /// The number as a `u32` when it is written as plain digits that fit (for `N`).
    pub uint: Option<u32>,
    pub pos: SrcPos,
}

/// Splits the source into logical lines.
pub(super) struct Lexer<S> {
    lines: S,
    /// Skip lines that start with `/` (else the `/` is dropped).
    block_delete: bool,
}

impl<S: LineSource> Lexer<S> {
    pub fn new(lines: S, block_delete: bool) -> Self {
        Lexer {
            lines,
            block_delete,
        }
    }

    /// Position just past the last character of the source (for errors at end of file),
    /// once the source is read to its end.
    pub fn eof(&self) -> SrcPos {
        self.lines.eof()
    }

    /// Reads the next logical line into `words` (cleared first). Returns `false` at the end
    /// of the source. A line without words (blank, comment, `%`) yields an empty `words`.
    pub fn next_line(&mut self, words: &mut Vec<Word>) -> Result<bool, ParseError> {
        words.clear();
        let mut continued_at: Option<SrcPos> = None;
        loop {
            let Some(next) = self.lines.next_line() else {
                return match continued_at {
                    Some(pos) => Err(ParseErrorKind::ContinuationAtEof.at(pos)),
                    None => Ok(false),
                };
            };
            let (line, text) = next?;
            if continued_at.is_none() && text.trim() == "%" {
                return Ok(true);
            }
            // Block delete: a `/` first on a line (spaces may precede it).
            let trimmed = text.trim_start();
            let text = match trimmed.strip_prefix('/') {
                Some(_) if continued_at.is_none() && self.block_delete => return Ok(true),
                Some(rest) if continued_at.is_none() => {
                    // Keep the columns: blank out the `/` instead of cutting it.
                    let lead = text.len() - trimmed.len();
                    let mut owned = String::with_capacity(text.len());
                    owned.push_str(text.get(..lead).unwrap_or(""));
                    owned.push(' ');
                    owned.push_str(rest);
                    continued_at = scan_line(line, &owned, words)?;
                    if continued_at.is_none() {
                        return Ok(true);
                    }
                    continue;
                }
                _ => text,
            };
            continued_at = scan_line(line, text, words)?;
            if continued_at.is_none() {
                return Ok(true);
            }
        }
    }
}

/// Scans one physical line, appending its words. Returns the position of a trailing `\`.
/// Whether the lexer reads `text` on with the next line (it ends with a backslash outside
/// any comment).
pub fn continues(text: &str) -> bool {
    text.contains('\\') && matches!(scan_line(1, text, &mut Vec::new()), Ok(Some(_)))
}

fn scan_line(line: u32, text: &str, words: &mut Vec<Word>) -> Result<Option<SrcPos>, ParseError> {
    let mut chars = text.char_indices().peekable();
    let mut col = 0u32;
    let err = |col: u32, kind: ParseErrorKind| kind.at(SrcPos { line, col });
    while let Some((start, ch)) = chars.next() {
        col = col.saturating_add(1);
        match ch {
            c if c.is_whitespace() => {}
            ';' => return Ok(None),
            '(' => {
                let open = col;
                loop {
                    match chars.next() {
                        Some((_, ')')) => break,
                        Some(_) => col = col.saturating_add(1),
                        None => return Err(err(open, ParseErrorKind::UnterminatedComment)),
                    }
                }
                col = col.saturating_add(1);
            }
            '\\' => {
                return if chars.all(|(_, c)| c.is_whitespace()) {
                    Ok(Some(SrcPos { line, col }))
                } else {
                    Err(err(col, ParseErrorKind::MisplacedBackslash))
                };
            }
            '%' => return Err(err(col, ParseErrorKind::MisplacedTapeMark)),
            c if c.is_ascii_alphabetic() => {
                let letter = c.to_ascii_uppercase();
                let pos = SrcPos { line, col };
                // The number: optional sign, digits, optional point, digits (one digit at least).
                let num_start = start + c.len_utf8();
                let mut end = num_start;
                let mut digits = 0usize;
                let mut seen_point = false;
                while let Some(&(i, d)) = chars.peek() {
                    let accept = match d {
                        '+' | '-' => i == num_start,
                        '.' => !seen_point,
                        _ => d.is_ascii_digit(),
                    };
                    if !accept {
                        break;
                    }
                    seen_point |= d == '.';
                    digits += usize::from(d.is_ascii_digit());
                    end = i + 1; // all accepted characters are ASCII
                    col = col.saturating_add(1);
                    chars.next();
                }
                let number = text.get(num_start..end).unwrap_or("");
                if digits == 0 {
                    return Err(ParseErrorKind::MissingNumber { letter }.at(pos));
                }
                let value = match number.parse::<f64>() {
                    Ok(v) if v.is_finite() => v,
                    _ => {
                        let kind = ParseErrorKind::NumberOutOfRange {
                            letter,
                            len: number.len(),
                        };
                        return Err(kind.at(pos));
                    }
                };
                let max = word_limit(letter);
                if value.abs() > max {
                    return Err(ParseErrorKind::OutsideDomain { letter, value, max }.at(pos));
                }
                let uint = number
                    .bytes()
                    .all(|b| b.is_ascii_digit())
                    .then(|| number.parse().ok())
                    .flatten();
                words.push(Word {
                    letter,
                    value,
                    uint,
                    pos,
                });
            }
            _ => return Err(err(col, ParseErrorKind::UnexpectedChar { ch })),
        }
    }
    Ok(None)
}

/// Largest magnitude a word's number may have. Coordinates up to 100 m and angles up to
/// 10^6 degrees cover every machine; beyond them the arithmetic of the planner loses the
/// micrometre (and far beyond, overflows), so such a number is refused where it is written.
/// The other words have checks of their own: I J K are normalised as a direction (or are
/// knots, checked by the curve), N is a `u32`, G M P are codes.
pub const fn word_limit(letter: char) -> f64 {
    match letter {
        'X' | 'Y' | 'Z' | 'U' | 'V' | 'W' => 1e5,
        'A' | 'B' | 'C' | 'F' | 'R' => 1e6,
        _ => f64::MAX,
    }
}
