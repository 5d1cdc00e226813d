//! The program's lines as the interpreter steps through them ([`Tape`]): logical lines (a
//! line ending in `\` joined with the next), normalised, numbered from 0 in the order they
//! are read, and kept only while something may go back to them (a loop to repeat, a call to
//! return after). Going forward reads the source a line at a time, so a program of any
//! length streams in the memory of its longest loop.

use crate::error::ParseError;
use crate::error::ParseErrorKind;
use crate::source::LineSource;
use crate::text::{normalise, Normal};
use nc_geom::program::SrcPos;
use std::collections::VecDeque;
use std::rc::Rc;

/// Lines of one source, by their logical index.
pub struct Tape<S> {
    source: S,
    /// Lines `base..base + kept.len()`.
    kept: VecDeque<Rc<Normal>>,
    base: usize,
    /// The source failed: it has no more lines.
    ended: bool,
}

impl<S: LineSource> Tape<S> {
    pub fn new(source: S) -> Self {
        Tape {
            source,
            kept: VecDeque::new(),
            base: 0,
            ended: false,
        }
    }

    /// Line `i`, reading the source up to it; `None` past the source's end.
    pub fn line(&mut self, i: usize) -> Result<Option<Rc<Normal>>, ParseError> {
        while self.base + self.kept.len() <= i {
            match self.read()? {
                Some(line) => self.kept.push_back(Rc::new(line)),
                None => return Ok(None),
            }
        }
        Ok(i.checked_sub(self.base)
            .and_then(|k| self.kept.get(k))
            .cloned())
    }

    /// The source, to read what the program did not (lines after its end).
    pub fn into_source(self) -> S {
        self.source
    }

    /// How many lines are kept.
    pub fn kept(&self) -> usize {
        self.kept.len()
    }

    /// Lines before `i` will not be asked for again.
    pub fn release(&mut self, i: usize) {
        while self.base < i && !self.kept.is_empty() {
            self.kept.pop_front();
            self.base += 1;
        }
    }

    /// Just past the source's last character, once it is read to its end.
    pub fn eof(&self) -> SrcPos {
        self.source.eof()
    }

    /// The next logical line of the source.
    fn read(&mut self) -> Result<Option<Normal>, ParseError> {
        if self.ended {
            return Ok(None);
        }
        let mut joined: Option<Normal> = None;
        loop {
            let Some(next) = self.source.next_line() else {
                // Not the end for good: a source fed as it goes may have more lines later.
                return match joined {
                    Some(j) => match j.continued {
                        Some(at) => Err(ParseErrorKind::ContinuationAtEof.at(at)),
                        None => Ok(Some(j)),
                    },
                    None => Ok(None),
                };
            };
            let (n, text) = match next {
                Ok(line) => line,
                Err(e) => {
                    self.ended = true;
                    return Err(e);
                }
            };
            let line = normalise(n, text)?;
            let more = line.continued.is_some();
            match &mut joined {
                Some(j) => j.append(line),
                None => joined = Some(line),
            }
            if !more {
                return Ok(joined);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::StrLines;

    #[test]
    fn lines_are_kept_until_released_and_continuations_join() {
        let mut t = Tape::new(StrLines::new("G0 X1\nG1 \\\n Y2\nM2\n"));
        assert_eq!(
            t.line(1).unwrap().unwrap().text.iter().collect::<String>(),
            "g1y2"
        );
        assert_eq!(t.line(0).unwrap().unwrap().line, 1);
        t.release(1);
        assert!(t.line(0).unwrap().is_none(), "released");
        assert_eq!(t.line(2).unwrap().unwrap().line, 4);
        assert!(t.line(3).unwrap().is_none());
        let mut t = Tape::new(StrLines::new("G0 \\\n"));
        assert!(t.line(0).is_err());
    }
}
