//! The program's flow: what each O-word line does to the interpreter ([`Interp::o_line`]).
//!
//! - `if`/`elseif`/`else`/`endif`, `while`/`endwhile`, `do`/`while`, `repeat`/`endrepeat`,
//!   `break`, `continue`: an open construct is kept on the frame's stack with the index of
//!   its line; a loop goes back by setting the frame's next line; a false branch or a loop's
//!   exit skips to the next O-line of the same label (labels are used once per subroutine,
//!   as LinuxCNC checks, so the next one is the right one).
//! - `sub`, `call`, `endsub` and `return` are the subroutines' (`subs.rs`).

use crate::error::ParseError;
use crate::expr::whole;
use crate::interp::{err, Interp, Open, Skip, SkipKind, State};
use crate::interp_error::InterpError;
use crate::name::Name;
use crate::source::LineSource;
use crate::syntax::{Keyword, Label, OLine};
use crate::text::Normal;
use nc_geom::program::SrcPos;
use std::rc::Rc;

impl<S: LineSource> Interp<S> {
    /// A label as a name: `o100`, `o[50+50]` and `o<100>` are all "100".
    pub(crate) fn label_name(
        &self,
        label: &Label,
        state: &impl State,
    ) -> Result<String, ParseError> {
        match label {
            Label::Name(n) => Ok(n.clone()),
            Label::Number(e) => {
                let v = e.eval(&self.env(state))?;
                Ok(whole(v, e.pos)?.to_string())
            }
        }
    }

    /// Executes an O-word line whose label reads `label`; `index` is its line's index in the
    /// frame's source.
    pub(crate) fn o_line(
        &mut self,
        o: OLine,
        label: String,
        index: usize,
        line: &Rc<Normal>,
        state: &impl State,
    ) -> Result<(), ParseError> {
        let Some(keyword) = o.keyword else {
            return Ok(()); // a program number (`O1000` alone)
        };
        let pos = o.pos;
        let arg = |this: &Self, k: usize| -> Result<Option<f64>, ParseError> {
            match o.args.get(k) {
                Some(e) => e.eval(&this.env(state)).map(Some),
                None => Ok(None),
            }
        };
        match keyword {
            Keyword::Sub => return self.sub(label, index, line, pos),
            Keyword::Call => {
                let mut args = Vec::with_capacity(o.args.len());
                for k in 0..o.args.len() {
                    args.extend(arg(self, k)?);
                }
                return self.call(label, &args, pos);
            }
            Keyword::EndSub | Keyword::Return => {
                let value = arg(self, 0)?;
                return self.leave(label, keyword, value, pos);
            }
            _ => {}
        }
        let line_no = line.line;
        match keyword {
            Keyword::If => {
                self.first_use(&label, keyword, line_no, pos)?;
                let taken = truth(arg(self, 0)?);
                self.push(label.clone(), keyword, index, line_no, taken, 0);
                if !taken {
                    self.skip_to(label, SkipKind::Branch, keyword, line_no, index);
                }
            }
            Keyword::ElseIf | Keyword::Else => {
                let k = self.find(&label, &[Keyword::If], keyword, pos)?;
                // An `elseif`'s condition is evaluated even after a branch ran, as LinuxCNC.
                let c = truth(arg(self, 0)?) || keyword == Keyword::Else;
                let open = &mut self.frame_mut().open[k];
                if open.taken || !c {
                    self.skip_to(label, SkipKind::Branch, keyword, line_no, index);
                } else {
                    open.taken = true;
                }
            }
            Keyword::EndIf => {
                let k = self.find(&label, &[Keyword::If], keyword, pos)?;
                self.frame_mut().open.truncate(k);
            }
            Keyword::Do => {
                self.first_use(&label, keyword, line_no, pos)?;
                self.push(label, keyword, index, line_no, false, 0);
            }
            Keyword::While => {
                let top = self.frame().open.last();
                if top.is_some_and(|t| t.label == label && t.keyword == Keyword::Do) {
                    // The end of a `do` loop (a stale `break` ends it, see `doing_break`).
                    if truth(arg(self, 0)?) && !self.doing_break {
                        let start = self.frame().open.last().map_or(index, |t| t.start);
                        self.frame_mut().pc = start + 1;
                    } else {
                        self.frame_mut().open.pop();
                        self.doing_break = false;
                    }
                    return Ok(());
                }
                let again = top.is_some_and(|t| t.label == label && t.start == index);
                if !again {
                    self.first_use(&label, keyword, line_no, pos)?;
                    self.push(label.clone(), keyword, index, line_no, false, 0);
                }
                if !truth(arg(self, 0)?) {
                    self.frame_mut().open.pop();
                    self.skip_to(label, SkipKind::Exit, keyword, line_no, index);
                }
            }
            Keyword::EndWhile => {
                let k = self.find(&label, &[Keyword::While], keyword, pos)?;
                let frame = self.frame_mut();
                frame.open.truncate(k + 1);
                frame.pc = frame.open[k].start;
            }
            Keyword::Repeat => {
                self.first_use(&label, keyword, line_no, pos)?;
                let n = arg(self, 0)?.unwrap_or(0.0).round_ties_even();
                if n >= 1.0 {
                    let count = n.min(i64::MAX as f64) as i64;
                    self.push(label, keyword, index, line_no, false, count);
                } else {
                    self.skip_to(label, SkipKind::Exit, keyword, line_no, index);
                }
            }
            Keyword::EndRepeat => {
                let k = self.find(&label, &[Keyword::Repeat], keyword, pos)?;
                let frame = self.frame_mut();
                frame.open.truncate(k + 1);
                let open = &mut frame.open[k];
                open.remaining -= 1;
                let (remaining, start) = (open.remaining, open.start);
                if remaining > 0 {
                    self.frame_mut().pc = start + 1;
                } else {
                    frame.open.pop();
                }
            }
            Keyword::Break | Keyword::Continue => {
                let loops = [Keyword::While, Keyword::Do];
                let k = self.find(&label, &loops, keyword, pos)?;
                let frame = self.frame_mut();
                let open = frame.open[k].clone();
                match (keyword, open.keyword) {
                    (Keyword::Break, _) => {
                        frame.open.truncate(k);
                        self.doing_break = true;
                        self.skip_to(label, SkipKind::Exit, keyword, line_no, open.start);
                    }
                    (_, Keyword::While) => {
                        frame.open.truncate(k + 1);
                        frame.pc = open.start;
                    }
                    _ => {
                        // `do`: on to its `while`, which decides.
                        frame.open.truncate(k + 1);
                        self.doing_continue = true;
                        self.skip_to(label, SkipKind::Continue, keyword, line_no, open.start);
                    }
                }
            }
            Keyword::Sub | Keyword::Call | Keyword::EndSub | Keyword::Return => {}
        }
        Ok(())
    }

    fn push(
        &mut self,
        label: String,
        keyword: Keyword,
        start: usize,
        line: u32,
        taken: bool,
        remaining: i64,
    ) {
        self.frame_mut().open.push(Open {
            label,
            keyword,
            start,
            line,
            taken,
            remaining,
        });
    }

    fn skip_to(&mut self, label: String, kind: SkipKind, keyword: Keyword, line: u32, back: usize) {
        self.skip = Some(Skip {
            label,
            kind,
            back,
            keyword,
            line,
        });
    }

    /// One more line run again (in a loop or a subroutine), within the program's budget.
    pub(crate) fn again(&mut self, line: &Normal) -> Result<(), ParseError> {
        if self.budget == 0 {
            return Err(err(
                InterpError::TooManyIterations {
                    most: self.max_loop_lines,
                },
                line.pos(0),
            ));
        }
        self.budget -= 1;
        Ok(())
    }

    /// The label opens a construct here: it must not open another one elsewhere in this
    /// subroutine (labels are used once per subroutine).
    fn first_use(
        &mut self,
        label: &str,
        keyword: Keyword,
        line: u32,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        let key = (self.frame().name.clone(), label.to_owned());
        match self.labels.get(&key) {
            Some(&(found, at)) if at != line || found != keyword => Err(err(
                InterpError::DuplicateLabel {
                    label: Name::new(label),
                    keyword: keyword.name(),
                    found: found.name(),
                    line: at,
                },
                pos,
            )),
            Some(_) => Ok(()),
            None => {
                self.labels.insert(key, (keyword, line));
                Ok(())
            }
        }
    }

    /// The innermost open construct of `label`, which must be one of `kinds`.
    fn find(
        &self,
        label: &str,
        kinds: &[Keyword],
        keyword: Keyword,
        pos: SrcPos,
    ) -> Result<usize, ParseError> {
        let open = &self.frame().open;
        match open.iter().rposition(|o| o.label == label) {
            Some(k) if kinds.contains(&open[k].keyword) => Ok(k),
            Some(k) => Err(err(
                InterpError::MismatchedLabel {
                    label: Name::new(label),
                    keyword: keyword.name(),
                    found: open[k].keyword.name(),
                    line: open[k].line,
                },
                pos,
            )),
            None => Err(err(
                InterpError::UnmatchedLabel {
                    label: Name::new(label),
                    keyword: keyword.name(),
                    opens: kinds.first().map_or("", |k| k.name()),
                },
                pos,
            )),
        }
    }
}

fn truth(v: Option<f64>) -> bool {
    v.is_some_and(|v| v != 0.0)
}
