//! A physical line as RS274/NGC reads it ([`normalise`]): spaces, tabs and carriage returns
//! outside comments vanish (anywhere: inside numbers, names and keywords, `G 0 1` is `G01`),
//! letters outside comments are folded to lower case, `( )` comments are cut out (the last
//! one is kept: only it can be an active comment), a `;` ends the line, and every remaining
//! character keeps the column it had, for errors. A `/` first on the line is block delete;
//! a `\` last continues the line on the next one (a dnurbs extension for long control-point
//! lines; LinuxCNC has none).

use crate::error::{ParseError, ParseErrorKind};
use crate::interp_error::InterpError;
use nc_geom::program::SrcPos;

/// A normalised physical line.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Normal {
    /// Its number in the file, 1-based.
    pub line: u32,
    /// The characters outside comments, whitespace removed, ASCII letters in lower case.
    pub text: Vec<char>,
    /// Where each of `text` stands (line and 1-based column in characters; a continued
    /// line's characters keep their own line).
    pub at: Vec<SrcPos>,
    /// The last `( )` comment: its text (case and spaces kept) and where its `(` stands.
    pub comment: Option<(String, SrcPos)>,
    /// A `/` came first: block delete.
    pub slash: bool,
    /// Where a final `\` stood: the line goes on with the next one.
    pub continued: Option<SrcPos>,
}

impl Normal {
    /// Where character `i` of `text` stands (just past the last one for `i` past it).
    pub fn pos(&self, i: usize) -> SrcPos {
        match self.at.get(i) {
            Some(&p) => p,
            None => self.at.last().map_or(
                SrcPos {
                    line: self.line,
                    col: 1,
                },
                |p| SrcPos {
                    line: p.line,
                    col: p.col + 1,
                },
            ),
        }
    }

    /// The line has nothing to execute (blank, or only comments).
    pub fn is_empty(&self) -> bool {
        self.text.is_empty()
    }

    /// The line is a lone `%` (after whitespace removal), with no comment.
    pub fn is_percent(&self) -> bool {
        self.text == ['%'] && self.comment.is_none()
    }

    /// Appends a continuation line: its characters follow these, keeping their own
    /// positions.
    pub fn append(&mut self, next: Normal) {
        self.text.extend(next.text);
        self.at.extend(next.at);
        if next.comment.is_some() {
            self.comment = next.comment;
        }
        self.continued = next.continued;
    }
}

/// Normalises physical line `line` (1-based) of text `text`.
pub fn normalise(line: u32, text: &str) -> Result<Normal, ParseError> {
    let mut out = Normal {
        line,
        ..Normal::default()
    };
    let at = |col: u32| SrcPos { line, col };
    let mut chars = text.chars().enumerate().map(|(i, c)| (i as u32 + 1, c));
    let mut first = true;
    while let Some((col, ch)) = chars.next() {
        match ch {
            ' ' | '\t' | '\r' => continue,
            ';' => break,
            '(' => {
                let mut comment = String::new();
                loop {
                    match chars.next() {
                        Some((_, ')')) => break,
                        Some((c, '(')) => {
                            return Err(ParseErrorKind::Interp(InterpError::NestedComment).at(at(c)))
                        }
                        Some((_, c)) => comment.push(c),
                        None => return Err(ParseErrorKind::UnterminatedComment.at(at(col))),
                    }
                }
                out.comment = Some((comment, at(col)));
            }
            '/' if first => out.slash = true,
            '\\' => {
                // Only whitespace and comments may follow.
                let mut open: Option<u32> = None;
                for (c, rest) in chars.by_ref() {
                    match (open, rest) {
                        (Some(_), ')') => open = None,
                        (Some(_), _) => {}
                        (None, ' ' | '\t' | '\r') => {}
                        (None, ';') => break,
                        (None, '(') => open = Some(c),
                        (None, _) => return Err(ParseErrorKind::MisplacedBackslash.at(at(col))),
                    }
                }
                if let Some(c) = open {
                    return Err(ParseErrorKind::UnterminatedComment.at(at(c)));
                }
                out.continued = Some(at(col));
                break;
            }
            c => {
                out.text.push(c.to_ascii_lowercase());
                out.at.push(at(col));
            }
        }
        first = false;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(n: &Normal) -> String {
        n.text.iter().collect()
    }

    #[test]
    fn whitespace_goes_everywhere_outside_comments_and_letters_fold() {
        let n = normalise(3, "G 0 X +0. 12 34\tY- 2 (Keep  Case) ; gone").unwrap();
        assert_eq!(text(&n), "g0x+0.1234y-2");
        assert_eq!(n.at[0].col, 1);
        assert_eq!(n.pos(1), SrcPos { line: 3, col: 3 }); // the 0
        assert_eq!(n.comment.as_ref().unwrap().0, "Keep  Case");
    }

    #[test]
    fn the_last_comment_is_kept_and_a_nested_one_is_an_error() {
        let n = normalise(1, "(first) G1 (second)").unwrap();
        assert_eq!(n.comment.unwrap().0, "second");
        let e = normalise(1, "(a (b) c)").unwrap_err();
        assert_eq!(e.pos.col, 4);
        assert!(normalise(1, "G1 (open").is_err());
    }

    #[test]
    fn block_delete_percent_and_continuation() {
        assert!(normalise(1, "  /G0 X1").unwrap().slash);
        assert!(!normalise(1, "G0 /X1").unwrap().slash);
        assert!(normalise(1, " % ").unwrap().is_percent());
        let n = normalise(2, "X1 Y2 \\  ").unwrap();
        assert_eq!(n.continued, Some(SrcPos { line: 2, col: 7 }));
        assert!(normalise(2, "X1 \\ Y2").is_err());
        assert!(normalise(2, "X1 \\ (ok) ; fine").is_ok());
    }
}
