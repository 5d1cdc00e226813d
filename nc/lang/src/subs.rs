//! Subroutines: a definition met in the flow is kept, not executed ([`Interp::sub`],
//! [`Interp::define`]); `call` runs a defined subroutine, else the file `<name>.ngc` from the
//! subroutine directories, else one defined further down the main program (read ahead to
//! it, as LinuxCNC does); `endsub`/`return` go back after the call with an optional value
//! (`#<_value>`). Calls nest at most [`MAX_CALL_DEPTH`] deep.

use crate::error::ParseError;
use crate::interp::{err, Frame, Interp, Src, Sub};
use crate::interp_error::InterpError;
use crate::name::Name;
use crate::rules::MAX_CALL_DEPTH;
use crate::source::LineSource;
use crate::syntax::{self, Body, Keyword, Label, OLine};
use crate::text::{normalise, Normal};
use nc_geom::program::SrcPos;
use std::rc::Rc;

impl<S: LineSource> Interp<S> {
    /// `o<name> sub` met in the flow: a definition to keep, not to execute.
    pub(crate) fn sub(
        &mut self,
        name: String,
        index: usize,
        line: &Rc<Normal>,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        if self.level() > 0 {
            return Err(err(
                InterpError::NestedDefinition {
                    label: Name::new(&name),
                    outer: Name::new(&self.frame().name),
                },
                pos,
            ));
        }
        if let Some(known) = self.subs.get(&name) {
            if known.main_index != Some(index) {
                return Err(err(
                    InterpError::Redefined {
                        label: Name::new(&name),
                        line: known.line,
                    },
                    pos,
                ));
            }
            if known.read_ahead {
                return Err(err(
                    InterpError::DefinitionInTheWay {
                        label: Name::new(&name),
                    },
                    pos,
                ));
            }
        }
        self.defining = Some(Sub {
            name,
            body: Vec::new(),
            line: line.line,
            main_index: Some(index),
            read_ahead: false,
        });
        Ok(())
    }

    /// A line of the definition being read.
    pub(crate) fn define(&mut self, line: &Rc<Normal>) -> Result<(), ParseError> {
        let Some(sub) = &mut self.defining else {
            return Ok(());
        };
        sub.body.push(Rc::clone(line));
        if let Some((label, keyword, pos)) = o_label(line) {
            match keyword {
                Some(Keyword::EndSub) if label == sub.name => {
                    if let Some(sub) = self.defining.take() {
                        self.subs
                            .entry(sub.name.clone())
                            .or_insert_with(|| Rc::new(sub));
                    }
                }
                Some(Keyword::Sub) => {
                    return Err(err(
                        InterpError::NestedDefinition {
                            label: Name::new(&label),
                            outer: Name::new(&sub.name),
                        },
                        pos,
                    ))
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// `o<name> call [args]`.
    pub(crate) fn call(
        &mut self,
        name: String,
        args: &[f64],
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        if self.level() >= MAX_CALL_DEPTH {
            return Err(err(
                InterpError::TooManyCalls {
                    label: Name::new(&name),
                },
                pos,
            ));
        }
        let sub = match self.subs.get(&name) {
            Some(sub) => Rc::clone(sub),
            None => {
                let sub = match self.sub_file(&name, pos)? {
                    Some(sub) => sub,
                    None => self.read_ahead(&name, pos)?,
                };
                let sub = Rc::new(sub);
                self.subs.insert(name.clone(), Rc::clone(&sub));
                sub
            }
        };
        let saved = self.params.enter(args);
        self.frames.push(Frame {
            src: Src::Sub(sub),
            pc: 0,
            open: Vec::new(),
            saved,
            name,
        });
        Ok(())
    }

    /// `endsub` or `return`: back to the caller, with `value`.
    pub(crate) fn leave(
        &mut self,
        name: String,
        keyword: Keyword,
        value: Option<f64>,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        if self.level() == 0 {
            return Err(err(
                InterpError::NotInSubroutine {
                    label: Name::new(&name),
                    keyword: keyword.name(),
                },
                pos,
            ));
        }
        self.value = value.unwrap_or(0.0);
        self.value_returned = value.is_some();
        if let Some(frame) = self.frames.pop() {
            self.params.leave(&frame.saved);
        }
        Ok(())
    }

    /// The subroutine `name` from the file `name.ngc` in the first subroutine directory that
    /// has one: its lines from `o<name> sub` to `o<name> endsub`.
    fn sub_file(&self, name: &str, pos: SrcPos) -> Result<Option<Sub>, ParseError> {
        let Some(path) = self
            .dirs
            .iter()
            .map(|d| d.join(format!("{name}.ngc")))
            .find(|p| p.is_file())
        else {
            return Ok(None);
        };
        let failed = |kind| {
            err(
                InterpError::SubroutineFile {
                    label: Name::new(name),
                    kind,
                },
                pos,
            )
        };
        let text = std::fs::read_to_string(&path).map_err(|e| failed(e.kind()))?;
        let mut sub: Option<Sub> = None;
        for (k, raw) in text.lines().enumerate() {
            let n = u32::try_from(k + 1).unwrap_or(u32::MAX);
            let line = Rc::new(normalise(n, raw)?);
            match &mut sub {
                None => {
                    if matches!(o_label(&line), Some((l, Some(Keyword::Sub), _)) if l == name) {
                        sub = Some(Sub {
                            name: name.to_owned(),
                            body: Vec::new(),
                            line: n,
                            main_index: None,
                            read_ahead: true,
                        });
                    }
                }
                Some(s) => {
                    s.body.push(Rc::clone(&line));
                    if matches!(o_label(&line), Some((l, Some(Keyword::EndSub), _)) if l == name) {
                        return Ok(sub);
                    }
                }
            }
        }
        Err(failed(std::io::ErrorKind::InvalidData))
    }

    /// The subroutine `name` defined further down the main program (LinuxCNC reads ahead to
    /// it, so a program may define its subroutines after `M02`).
    fn read_ahead(&mut self, name: &str, pos: SrcPos) -> Result<Sub, ParseError> {
        let missing = || {
            err(
                InterpError::SubroutineNotFound {
                    label: Name::new(name),
                },
                pos,
            )
        };
        // From the line after the call, in the file it stands in: the main program, or a
        // subroutine defined in it (a subroutine from a file is not searched).
        let frame = self.frame();
        let mut i = match &frame.src {
            Src::Main => frame.pc,
            Src::Sub(sub) => match sub.main_index {
                Some(m) => m + 1 + frame.pc,
                None => return Err(missing()),
            },
        };
        let mut sub: Option<Sub> = None;
        while let Some(line) = self.tape.line(i)? {
            match &mut sub {
                None => {
                    if matches!(o_label(&line), Some((l, Some(Keyword::Sub), _)) if l == name) {
                        sub = Some(Sub {
                            name: name.to_owned(),
                            body: Vec::new(),
                            line: line.line,
                            main_index: Some(i),
                            read_ahead: true,
                        });
                    }
                }
                Some(s) => {
                    s.body.push(Rc::clone(&line));
                    if matches!(o_label(&line), Some((l, Some(Keyword::EndSub), _)) if l == name) {
                        return sub.ok_or_else(missing);
                    }
                }
            }
            i += 1;
        }
        Err(missing())
    }
}

/// An O-line's label (a name or a plain number, not evaluated) and keyword; `None` for any
/// other line, or an O-line that does not read.
fn o_label(line: &Normal) -> Option<(String, Option<Keyword>, SrcPos)> {
    if !syntax::is_o_line(line) {
        return None;
    }
    match syntax::read(line).ok()?.body {
        Body::O(OLine {
            label: Label::Name(n),
            keyword,
            pos,
            ..
        }) => Some((n, keyword, pos)),
        _ => None,
    }
}
