//! One normalised line read into its parts ([`read`]), nothing evaluated yet: the sequence
//! number, then either an O-word line (flow control: a label, a keyword, its bracketed
//! arguments) or the line's items (words whose values are expressions, and parameter
//! assignments), in source order.
//!
//! ```text
//! line   := ['n' digits ['.' digits]] ( o-line | item* )
//! o-line := 'o' (number | value | '<' name '>') [keyword ['[' expr ']']*]
//! item   := letter value | '#' param '=' value
//! ```
//!
//! An `o` number with no keyword is a program number (`O1000` on a line of its own, as Fanuc
//! posts write it), passed on as an `O` word.

use crate::error::{ParseError, ParseErrorKind};
use crate::expr::{Cursor, Expr, ExprKind, Param};
use crate::interp_error::InterpError;
use crate::text::Normal;
use nc_geom::program::SrcPos;

/// A line, read.
#[derive(Clone, Debug, PartialEq)]
pub struct Syntax {
    /// The sequence number: its value, written as plain digits, and where it stands.
    pub n: Option<(f64, Option<u32>, SrcPos)>,
    pub body: Body,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Body {
    Items(Vec<Item>),
    O(OLine),
}

/// A word or an assignment.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    Word {
        /// Upper case.
        letter: char,
        value: Expr,
        pos: SrcPos,
    },
    Set {
        param: Param,
        value: Expr,
        pos: SrcPos,
    },
}

/// An O-word line.
#[derive(Clone, Debug, PartialEq)]
pub struct OLine {
    pub label: Label,
    /// `None`: a program number (`O1000` alone).
    pub keyword: Option<Keyword>,
    /// The bracketed arguments (a condition, a count, call arguments, a return value).
    pub args: Vec<Expr>,
    pub pos: SrcPos,
}

/// An O-word's label as written: a number (itself a value) or a name.
#[derive(Clone, Debug, PartialEq)]
pub enum Label {
    Number(Expr),
    Name(String),
}

/// The O-word keywords.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keyword {
    Sub,
    EndSub,
    Call,
    Do,
    While,
    Repeat,
    If,
    ElseIf,
    Else,
    EndIf,
    Break,
    Continue,
    EndWhile,
    EndRepeat,
    Return,
}

/// The keywords by spelling, in the order LinuxCNC tries them (a prefix of a later one
/// never comes first: `elseif` before `else`).
const KEYWORDS: [(&str, Keyword); 15] = [
    ("sub", Keyword::Sub),
    ("endsub", Keyword::EndSub),
    ("call", Keyword::Call),
    ("do", Keyword::Do),
    ("while", Keyword::While),
    ("repeat", Keyword::Repeat),
    ("if", Keyword::If),
    ("elseif", Keyword::ElseIf),
    ("else", Keyword::Else),
    ("endif", Keyword::EndIf),
    ("break", Keyword::Break),
    ("continue", Keyword::Continue),
    ("endwhile", Keyword::EndWhile),
    ("endrepeat", Keyword::EndRepeat),
    ("return", Keyword::Return),
];

impl Keyword {
    pub fn name(self) -> &'static str {
        KEYWORDS
            .iter()
            .find(|(_, k)| *k == self)
            .map_or("?", |(s, _)| s)
    }
}

fn err(kind: InterpError, pos: SrcPos) -> ParseError {
    ParseErrorKind::Interp(kind).at(pos)
}

/// Whether a normalised line is an O-word line (after its optional sequence number).
pub fn is_o_line(n: &Normal) -> bool {
    let t = &n.text;
    let mut i = 0;
    if t.first() == Some(&'n') {
        i = 1;
        while t.get(i).is_some_and(|c| c.is_ascii_digit() || *c == '.') {
            i += 1;
        }
    }
    t.get(i) == Some(&'o')
}

/// Reads a normalised line (not block-deleted, not a `%` line).
pub fn read(n: &Normal) -> Result<Syntax, ParseError> {
    let mut c = Cursor::new(n, 0);
    let number = sequence_number(&mut c)?;
    let body = if c.peek() == Some('o') {
        Body::O(o_line(&mut c)?)
    } else {
        Body::Items(items(&mut c)?)
    };
    Ok(Syntax { n: number, body })
}

/// `n` and plain digits (an optional `.digits` is read and ignored, as LinuxCNC).
fn sequence_number(c: &mut Cursor) -> Result<Option<(f64, Option<u32>, SrcPos)>, ParseError> {
    if c.peek() != Some('n') {
        return Ok(None);
    }
    let pos = c.pos();
    c.i += 1;
    let mut digits = String::new();
    while let Some(d) = c.peek().filter(char::is_ascii_digit) {
        digits.push(d);
        c.i += 1;
    }
    if c.eat(".") {
        while c.peek().is_some_and(|d| d.is_ascii_digit()) {
            c.i += 1;
        }
    }
    if digits.is_empty() {
        // `N-1`, `N[1]`: a value, but not plain digits.
        return Err(match c.value() {
            Ok(Expr {
                kind: ExprKind::Number(value),
                ..
            }) => ParseErrorKind::BadSequenceNumber { value }.at(pos),
            _ => ParseErrorKind::MissingNumber { letter: 'N' }.at(pos),
        });
    }
    let value = digits.parse::<f64>().unwrap_or(f64::MAX);
    Ok(Some((value, digits.parse().ok(), pos)))
}

fn items(c: &mut Cursor) -> Result<Vec<Item>, ParseError> {
    let mut out = Vec::new();
    while let Some(ch) = c.peek() {
        let pos = c.pos();
        match ch {
            '#' => {
                c.i += 1;
                let param = c.param()?;
                if !c.eat("=") {
                    return Err(err(InterpError::MissingEquals, c.pos()));
                }
                let value = c.value()?;
                out.push(Item::Set { param, value, pos });
            }
            'n' => {
                let value = match sequence_number(c) {
                    Ok(Some((v, _, _))) => v,
                    _ => 0.0,
                };
                return Err(ParseErrorKind::MisplacedSequenceNumber { value }.at(pos));
            }
            l if l.is_ascii_alphabetic() || l == '@' || l == '^' => {
                c.i += 1;
                if c.at_end() {
                    return Err(ParseErrorKind::MissingNumber {
                        letter: l.to_ascii_uppercase(),
                    }
                    .at(pos));
                }
                let letter = l.to_ascii_uppercase();
                let value = c.value().map_err(|e| missing_number(e, letter, pos))?;
                // An operator after a value outside brackets is a common slip: say so.
                if matches!(c.peek(), Some('+' | '*' | '/')) {
                    return Err(err(InterpError::OperatorOutsideBrackets, c.pos()));
                }
                out.push(Item::Word {
                    letter: l.to_ascii_uppercase(),
                    value,
                    pos,
                });
            }
            '%' => return Err(ParseErrorKind::MisplacedTapeMark.at(pos)),
            ch => return Err(ParseErrorKind::UnexpectedChar { ch }.at(pos)),
        }
    }
    Ok(out)
}

fn o_line(c: &mut Cursor) -> Result<OLine, ParseError> {
    let pos = c.pos();
    c.i += 1;
    let label = if c.eat("<") {
        let mut name = String::new();
        loop {
            match c.peek() {
                Some('>') => {
                    c.i += 1;
                    break;
                }
                Some(ch) => {
                    name.push(ch);
                    c.i += 1;
                }
                None => return Err(err(InterpError::NameNotClosed, pos)),
            }
        }
        Label::Name(name)
    } else {
        let v = c.value()?;
        // A plain whole number reads as its name ("o100" is "o<100>").
        match v.kind {
            ExprKind::Number(x) if x.fract() == 0.0 && x.abs() < 1e15 => {
                Label::Name(format!("{}", x as i64))
            }
            _ => Label::Number(v),
        }
    };
    if c.at_end() {
        return Ok(OLine {
            label,
            keyword: None,
            args: Vec::new(),
            pos,
        });
    }
    let Some(&(spelling, keyword)) = KEYWORDS.iter().find(|(s, _)| c.starts_with(s)) else {
        return Err(err(InterpError::UnknownControl, c.pos()));
    };
    c.eat(spelling);
    let mut args = Vec::new();
    while c.peek() == Some('[') {
        args.push(c.value()?);
    }
    let needs = match keyword {
        Keyword::If | Keyword::ElseIf | Keyword::While => Some("condition"),
        Keyword::Repeat => Some("count"),
        _ => None,
    };
    if let (Some(what), true) = (needs, args.is_empty()) {
        return Err(err(
            InterpError::ControlBracket {
                keyword: keyword.name(),
                what,
            },
            c.pos(),
        ));
    }
    if !c.at_end() {
        return Err(err(InterpError::AfterOWord, c.pos()));
    }
    let most = match keyword {
        Keyword::Call => 30,
        Keyword::If
        | Keyword::ElseIf
        | Keyword::While
        | Keyword::Repeat
        | Keyword::Return
        | Keyword::EndSub => 1,
        _ => 0,
    };
    if args.len() > most {
        return Err(match keyword {
            Keyword::Call => err(
                InterpError::TooManyArguments {
                    label: crate::name::Name::new(&label_text(&label)),
                },
                pos,
            ),
            _ => err(InterpError::AfterOWord, args[most].pos),
        });
    }
    Ok(OLine {
        label,
        keyword: Some(keyword),
        args,
        pos,
    })
}

/// A word's letter followed by something that is not a value (`X Y1`, `Y-.`): say that the
/// letter has no number, where the letter stands.
fn missing_number(e: ParseError, letter: char, pos: SrcPos) -> ParseError {
    match e.kind {
        ParseErrorKind::Interp(
            InterpError::UnknownFunction { .. } | InterpError::ExpectedValue,
        ) => ParseErrorKind::MissingNumber { letter }.at(pos),
        _ => e,
    }
}

/// A label as written, for messages (`<name>` or a number's text).
pub fn label_text(label: &Label) -> String {
    match label {
        Label::Name(n) if n.parse::<i64>().is_ok() => n.clone(),
        Label::Name(n) => format!("<{n}>"),
        Label::Number(_) => "[..]".to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::normalise;

    fn syn(src: &str) -> Result<Syntax, ParseError> {
        read(&normalise(1, src).unwrap())
    }

    #[test]
    fn items_words_and_assignments_in_order() {
        let s = syn("N10 G1 X[#1+2] #<a b>=5 F#2").unwrap();
        assert_eq!(s.n.map(|n| n.1), Some(Some(10)));
        let Body::Items(items) = s.body else { panic!() };
        let letters: Vec<String> = items
            .iter()
            .map(|i| match i {
                Item::Word { letter, .. } => letter.to_string(),
                Item::Set { param, .. } => format!("{param:?}").chars().take(5).collect(),
            })
            .collect();
        assert_eq!(letters, ["G", "X", "Named", "F"]);
    }

    #[test]
    fn o_lines_with_their_labels_keywords_and_arguments() {
        let s = syn("o100 if [#1 GT 2]").unwrap();
        let Body::O(o) = s.body else { panic!() };
        assert_eq!(o.label, Label::Name("100".into()));
        assert_eq!(o.keyword, Some(Keyword::If));
        assert_eq!(o.args.len(), 1);
        let s = syn("O<My Sub> call [1] [2] [3]").unwrap();
        let Body::O(o) = s.body else { panic!() };
        assert_eq!(o.label, Label::Name("mysub".into()));
        assert_eq!((o.keyword, o.args.len()), (Some(Keyword::Call), 3));
        let Body::O(o) = syn("o 1 0 0 e n d i f").unwrap().body else {
            panic!()
        };
        assert_eq!(o.keyword, Some(Keyword::EndIf));
        let Body::O(o) = syn("O1000").unwrap().body else {
            panic!()
        };
        assert_eq!(o.keyword, None);
    }

    #[test]
    fn o_line_errors() {
        let kind = |src: &str| match syn(src).unwrap_err().kind {
            ParseErrorKind::Interp(k) => k,
            k => panic!("{src}: {k:?}"),
        };
        assert_eq!(kind("o100 frobnicate"), InterpError::UnknownControl);
        assert!(matches!(
            kind("o100 if 1"),
            InterpError::ControlBracket { keyword: "if", .. }
        ));
        assert_eq!(kind("o100 if [1] G0 X1"), InterpError::AfterOWord);
        assert_eq!(kind("o<a call"), InterpError::NameNotClosed);
        let many = format!("o<s> call {}", "[1]".repeat(31));
        assert!(matches!(kind(&many), InterpError::TooManyArguments { .. }));
        assert_eq!(kind("G1 X1+2"), InterpError::OperatorOutsideBrackets);
        assert_eq!(kind("#1 5"), InterpError::MissingEquals);
    }
}
