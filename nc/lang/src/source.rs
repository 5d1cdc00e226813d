//! Where the lexer's physical lines come from: a string in memory ([`StrLines`]) or a
//! reader, one line at a time ([`ReadLines`]), so a program of any length is parsed in the
//! memory of its longest line.
//!
//! Both give the same lines: split at `\n` or `\r\n`, the ending dropped, numbered from 1,
//! a byte-order mark at the very start dropped (columns count from after it). A line over
//! [`MAX_LINE_BYTES`] is an error in both, so neither reads without bound.

use super::error::{ParseError, ParseErrorKind};
use nc_geom::program::SrcPos;
use std::io::{BufRead, Read};

/// Longest physical line, in bytes with its ending. NC controls take a few hundred
/// characters; a longer line is not an NC program (and would be read whole).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// The physical lines of a program, in order.
pub trait LineSource {
    /// The next line's number (from 1) and text without its ending; `None` after the last
    /// line (and after an error).
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>>;
    /// Just past the last character of the source, once it is read to its end.
    fn eof(&self) -> SrcPos;
}

impl<L: LineSource + ?Sized> LineSource for Box<L> {
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>> {
        (**self).next_line()
    }

    fn eof(&self) -> SrcPos {
        (**self).eof()
    }
}

/// Line numbers saturate instead of overflowing on absurdly large inputs.
fn to_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

fn too_long(line: usize) -> ParseError {
    ParseErrorKind::LineTooLong {
        max: MAX_LINE_BYTES,
    }
    .at(SrcPos {
        line: to_u32(line),
        col: 1,
    })
}

/// The lines of a program held in memory.
pub struct StrLines<'a> {
    lines: core::str::Lines<'a>,
    count: usize,
    last: &'a str,
    failed: bool,
}

impl<'a> StrLines<'a> {
    pub fn new(src: &'a str) -> Self {
        StrLines {
            lines: src.lines(),
            count: 0,
            last: "",
            failed: false,
        }
    }
}

impl LineSource for StrLines<'_> {
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>> {
        if self.failed {
            return None;
        }
        let mut text = self.lines.next()?;
        self.count += 1;
        if self.count == 1 {
            text = text.strip_prefix('\u{feff}').unwrap_or(text);
        }
        self.last = text;
        if text.len() >= MAX_LINE_BYTES {
            self.failed = true;
            return Some(Err(too_long(self.count)));
        }
        Some(Ok((to_u32(self.count), text)))
    }

    fn eof(&self) -> SrcPos {
        SrcPos {
            line: to_u32(self.count.max(1)),
            col: to_u32(self.last.chars().count() + 1),
        }
    }
}

/// The lines of a program read as it goes: one line's buffer, reused.
pub struct ReadLines<R> {
    reader: R,
    /// The last line read (its ending dropped, a byte-order mark kept), reused.
    text: String,
    count: usize,
    last_chars: usize,
    /// The ending the last line had: `"\n"`, `"\r\n"`, or `""` (the file's end).
    ending: &'static str,
    /// Where the last line's text starts in `text` (after a byte-order mark).
    start: usize,
    failed: bool,
}

impl<R: BufRead> ReadLines<R> {
    pub fn new(reader: R) -> Self {
        ReadLines {
            reader,
            text: String::new(),
            count: 0,
            last_chars: 0,
            ending: "",
            start: 0,
            failed: false,
        }
    }

    /// The last line read, as [`LineSource::next_line`] gave it, with the ending it had:
    /// `"\n"`, `"\r\n"` or `""` (it ended the file), what a rewrite that keeps the
    /// program's bytes writes after it.
    pub fn last_line(&self) -> (u32, &str, &'static str) {
        let text = self.text.get(self.start..).unwrap_or_default();
        (to_u32(self.count), text, self.ending)
    }

    fn fail(
        &mut self,
        col: usize,
        kind: ParseErrorKind,
    ) -> Option<Result<(u32, &str), ParseError>> {
        self.failed = true;
        let pos = SrcPos {
            line: to_u32(self.count),
            col: to_u32(col),
        };
        Some(Err(kind.at(pos)))
    }
}

impl<R: BufRead> LineSource for ReadLines<R> {
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>> {
        if self.failed {
            return None;
        }
        let mut buf = core::mem::take(&mut self.text).into_bytes();
        buf.clear();
        let limit = MAX_LINE_BYTES as u64 + 1;
        match Read::take(&mut self.reader, limit).read_until(b'\n', &mut buf) {
            Ok(0) => return None,
            Ok(_) => self.count += 1,
            Err(e) => {
                self.count += 1;
                return self.fail(1, ParseErrorKind::Unreadable { kind: e.kind() });
            }
        }
        if buf.len() > MAX_LINE_BYTES {
            self.failed = true;
            return Some(Err(too_long(self.count)));
        }
        let start = match self.count == 1 && buf.starts_with(b"\xef\xbb\xbf") {
            true => 3,
            false => 0,
        };
        let mut end = buf.len();
        self.ending = "";
        if buf.get(start..end).is_some_and(|b| b.ends_with(b"\n")) {
            end -= 1;
            self.ending = "\n";
            if buf.get(start..end).is_some_and(|b| b.ends_with(b"\r")) {
                end -= 1;
                self.ending = "\r\n";
            }
        }
        buf.truncate(end);
        match String::from_utf8(buf) {
            Ok(text) => self.text = text,
            Err(e) => {
                let bytes = e.as_bytes().get(start..).unwrap_or_default();
                let good = bytes
                    .get(..e.utf8_error().valid_up_to())
                    .unwrap_or_default();
                let col = core::str::from_utf8(good).map_or(0, |s| s.chars().count()) + 1;
                let byte = bytes.get(good.len()).copied().unwrap_or_default();
                return self.fail(col, ParseErrorKind::NotUtf8 { byte });
            }
        }
        self.start = start;
        let text = self.text.get(start..).unwrap_or_default();
        self.last_chars = text.chars().count();
        Some(Ok((to_u32(self.count), text)))
    }

    fn eof(&self) -> SrcPos {
        SrcPos {
            line: to_u32(self.count.max(1)),
            col: to_u32(self.last_chars + 1),
        }
    }
}
