//! A line's items evaluated ([`Interp::evaluate`]), in LinuxCNC's order: every expression on
//! the line reads the parameters as they were before the line (left to right), then the
//! numbered assignments take effect in source order, then the named ones. A named parameter
//! assigned on the line exists from its assignment on (an unset one reads 0 there), so
//! `#<n> = [#<n> + 1]` counts from 0.

use crate::error::{ParseError, ParseErrorKind};
use crate::expr::{parameter_number, Env};
use crate::interp::{err, Interp, State};
use crate::interp_error::InterpError;
use crate::name::Name;
use crate::params::Params;
use crate::source::LineSource;
use crate::syntax::Item;
use crate::word::{as_uint, word_limit, Word};
use nc_geom::program::SrcPos;

/// Most assignments on one line (LinuxCNC has fixed buffers of 50 each).
const MAX_ASSIGNMENTS: usize = 50;

/// The parameters as an expression reads them on one line.
pub(crate) struct LineEnv<'a, T> {
    params: &'a Params,
    state: &'a T,
    /// The interpreter's own: `_line`, `_call_level`, `_value`, `_value_returned`.
    line: u32,
    level: usize,
    value: f64,
    value_returned: bool,
    /// Named parameters created by this line's assignments so far.
    created: Vec<&'a str>,
}

impl<T: State> LineEnv<'_, T> {
    fn own(&self, name: &str) -> Option<f64> {
        Some(match name {
            "_line" => f64::from(self.line),
            "_call_level" => self.level as f64,
            "_value" => self.value,
            "_value_returned" => f64::from(u8::from(self.value_returned)),
            _ => return None,
        })
    }
}

impl<T: State> Env for LineEnv<'_, T> {
    fn numbered(&self, n: u32, pos: SrcPos) -> Result<f64, ParseError> {
        match self.state.computed(n) {
            Some(v) => v.map_err(|k| err(k, pos)),
            None => Ok(self.params.numbered(n)),
        }
    }

    fn named(&self, name: &str, pos: SrcPos) -> Result<f64, ParseError> {
        if let Some(v) = self.own(name) {
            return Ok(v);
        }
        if let Some(v) = self.state.predefined(name) {
            return v.map_err(|k| err(k, pos));
        }
        match self.params.named(name) {
            Some(v) => Ok(v),
            None if self.created.contains(&name) => Ok(0.0),
            None => Err(err(
                InterpError::UndefinedNamed {
                    name: Name::new(name),
                },
                pos,
            )),
        }
    }

    fn exists(&self, name: &str) -> bool {
        self.own(name).is_some()
            || self.state.predefined(name).is_some()
            || self.params.named(name).is_some()
            || self.created.contains(&name)
    }
}

impl<S: LineSource> Interp<S> {
    /// How expressions read the parameters now.
    pub(crate) fn env<'a, T: State>(&'a self, state: &'a T) -> LineEnv<'a, T> {
        LineEnv {
            params: &self.params,
            state,
            line: self.line,
            level: self.level(),
            value: self.value,
            value_returned: self.value_returned,
            created: Vec::new(),
        }
    }

    /// Evaluates a line's items into `words` (its sequence number first) and applies its
    /// assignments.
    pub(crate) fn evaluate(
        &mut self,
        n: Option<(f64, Option<u32>, SrcPos)>,
        items: &[Item],
        state: &impl State,
        words: &mut Vec<Word>,
    ) -> Result<(), ParseError> {
        if let Some((value, uint, pos)) = n {
            words.push(Word {
                letter: 'N',
                value,
                uint,
                pos,
            });
        }
        let mut numbered: Vec<(u32, f64, SrcPos)> = Vec::new();
        let mut named: Vec<(&str, f64, SrcPos)> = Vec::new();
        let mut env = self.env(state);
        for item in items {
            match item {
                Item::Word { letter, value, pos } => {
                    let v = value.eval(&env)?;
                    let max = word_limit(*letter);
                    if v.abs() > max {
                        let kind = ParseErrorKind::OutsideDomain {
                            letter: *letter,
                            value: v,
                            max,
                        };
                        return Err(kind.at(*pos));
                    }
                    words.push(Word {
                        letter: *letter,
                        value: v,
                        uint: as_uint(v),
                        pos: *pos,
                    });
                }
                Item::Set {
                    param: crate::expr::Param::Numbered(index),
                    value,
                    pos,
                } => {
                    let k = parameter_number(index.eval(&env)?, index.pos)?;
                    let v = value.eval(&env)?;
                    numbered.push((k, v, *pos));
                }
                Item::Set {
                    param: crate::expr::Param::Named(name, _),
                    value,
                    pos,
                } => {
                    env.created.push(name);
                    let v = value.eval(&env)?;
                    named.push((name, v, *pos));
                }
            }
            if numbered.len() > MAX_ASSIGNMENTS || named.len() > MAX_ASSIGNMENTS {
                let pos = match item {
                    Item::Word { pos, .. } | Item::Set { pos, .. } => *pos,
                };
                return Err(err(
                    InterpError::TooManyAssignments {
                        most: MAX_ASSIGNMENTS,
                    },
                    pos,
                ));
            }
        }
        for &(k, _, pos) in &numbered {
            if state.computed(k).is_some() {
                return Err(err(
                    InterpError::ReadOnlyParameter {
                        number: k,
                        why: read_only_why(k),
                    },
                    pos,
                ));
            }
        }
        for &(name, _, pos) in &named {
            if env.own(name).is_some() || state.predefined(name).is_some() {
                return Err(err(
                    InterpError::ReadOnlyNamed {
                        name: Name::new(name),
                        why: "the interpreter's state",
                    },
                    pos,
                ));
            }
        }
        drop(env);
        for (k, v, _) in numbered {
            self.params.set_numbered(k, v);
        }
        for (name, v, _) in named {
            self.params.set_named(name, v);
        }
        Ok(())
    }
}

/// Why numbered parameter `k` cannot be assigned.
fn read_only_why(k: u32) -> &'static str {
    match k {
        5400..=5413 => "the tool in the spindle",
        5420..=5428 => "the current position",
        _ => "it comes from the machine file (offsets, reference position); change it there",
    }
}
