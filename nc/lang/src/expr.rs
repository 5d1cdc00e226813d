//! RS274/NGC values and expressions: how they read ([`Cursor::value`]) and what they are
//! worth ([`Expr::eval`]), as LinuxCNC reads and computes them.
//!
//! ```text
//! value := number | '#' param | '[' expr ']' | ('+'|'-') value | func '[' expr ']'
//!        | 'atan' '[' expr ']' '/' '[' expr ']' | 'exists' '[' '#' param ']'
//! expr  := value (op value)*          ops, loosest first: AND OR XOR; EQ NE GT GE LT LE;
//!                                     + -; * / MOD; **  (each level left-associative)
//! param := digits-valued value (#1, ##2, #[#1+1]) | '<' name '>'
//! ```
//!
//! A sign before something that is not a digit negates the value that follows, so it binds
//! tighter than `**`: `[-2**2]` is 4, as in LinuxCNC. Angles are in degrees. `EQ` and `NE`
//! compare within 0.0001; the rest exactly. `MOD` is never negative. Every value is checked
//! as it is computed: a NaN or an infinity is an error where it arises.

use crate::error::{ParseError, ParseErrorKind};
use crate::interp_error::InterpError;
use crate::name::Name;
use crate::rules::{MAX_EXPR_DEPTH, MAX_PARAMETER, WHOLE_TOLERANCE};
use crate::text::Normal;
use nc_geom::program::SrcPos;

/// A value or expression, with where it stands.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub pos: SrcPos,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    Number(f64),
    Param(Box<Param>),
    Neg(Box<Expr>),
    Func(Func, Box<Expr>),
    Atan(Box<Expr>, Box<Expr>),
    Exists(Box<Param>),
    Binary(Op, Box<Expr>, Box<Expr>),
}

/// A parameter reference.
#[derive(Clone, Debug, PartialEq)]
pub enum Param {
    /// `#n`: its number, itself a value.
    Numbered(Expr),
    /// `#<name>` (lower case, spaces removed).
    Named(String, SrcPos),
}

/// The functions of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    Abs,
    Acos,
    Asin,
    Cos,
    Exp,
    Fix,
    Fup,
    Ln,
    Round,
    Sin,
    Sqrt,
    Tan,
}

const FUNCS: [(&str, Func); 12] = [
    ("abs", Func::Abs),
    ("acos", Func::Acos),
    ("asin", Func::Asin),
    ("cos", Func::Cos),
    ("exp", Func::Exp),
    ("fix", Func::Fix),
    ("fup", Func::Fup),
    ("ln", Func::Ln),
    ("round", Func::Round),
    ("sin", Func::Sin),
    ("sqrt", Func::Sqrt),
    ("tan", Func::Tan),
];

impl Func {
    fn name(self) -> &'static str {
        FUNCS
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("?", |(n, _)| n)
    }
}

/// The binary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    Pow,
    Mul,
    Div,
    Mod,
    Add,
    Sub,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
    And,
    Or,
    Xor,
}

/// Operators by their spelling, longest first where one spelling starts another.
const OPS: [(&str, Op); 15] = [
    ("**", Op::Pow),
    ("*", Op::Mul),
    ("/", Op::Div),
    ("mod", Op::Mod),
    ("+", Op::Add),
    ("-", Op::Sub),
    ("eq", Op::Eq),
    ("ne", Op::Ne),
    ("gt", Op::Gt),
    ("ge", Op::Ge),
    ("lt", Op::Lt),
    ("le", Op::Le),
    ("and", Op::And),
    ("or", Op::Or),
    ("xor", Op::Xor),
];

impl Op {
    fn precedence(self) -> u8 {
        match self {
            Op::Pow => 6,
            Op::Mul | Op::Div | Op::Mod => 5,
            Op::Add | Op::Sub => 4,
            Op::Eq | Op::Ne | Op::Gt | Op::Ge | Op::Lt | Op::Le => 3,
            Op::And | Op::Or | Op::Xor => 2,
        }
    }
}

/// What an expression reads parameters from.
pub trait Env {
    /// Numbered parameter `n` (1..=[`MAX_PARAMETER`]).
    fn numbered(&self, n: u32, pos: SrcPos) -> Result<f64, ParseError>;
    /// Named parameter `name`: its value, or an error naming it.
    fn named(&self, name: &str, pos: SrcPos) -> Result<f64, ParseError>;
    /// Whether `name` exists (`EXISTS`).
    fn exists(&self, name: &str) -> bool;
}

fn err(kind: InterpError, pos: SrcPos) -> ParseError {
    ParseErrorKind::Interp(kind).at(pos)
}

/// `v` as a whole number, within [`WHOLE_TOLERANCE`].
pub fn whole(v: f64, pos: SrcPos) -> Result<i64, ParseError> {
    let f = v.floor();
    let r = if v - f <= WHOLE_TOLERANCE {
        f
    } else if v - f > 1.0 - WHOLE_TOLERANCE {
        f + 1.0
    } else {
        return Err(err(InterpError::NotWhole { value: v }, pos));
    };
    if r.abs() > 9e15 {
        return Err(err(InterpError::NotWhole { value: v }, pos));
    }
    Ok(r as i64)
}

/// A parameter number: a whole value from 1 to [`MAX_PARAMETER`].
pub fn parameter_number(v: f64, pos: SrcPos) -> Result<u32, ParseError> {
    let n = whole(v, pos)?;
    if n < 1 || n > i64::from(MAX_PARAMETER) {
        return Err(err(InterpError::ParameterOutOfRange { value: v }, pos));
    }
    Ok(n as u32)
}

fn checked(v: f64, pos: SrcPos) -> Result<f64, ParseError> {
    if v.is_nan() {
        Err(err(InterpError::NotANumber, pos))
    } else if v.is_infinite() {
        Err(err(InterpError::Infinite, pos))
    } else {
        Ok(v)
    }
}

impl Param {
    /// Its value in `env`.
    pub fn eval(&self, env: &impl Env) -> Result<f64, ParseError> {
        match self {
            Param::Numbered(n) => {
                let v = n.eval(env)?;
                env.numbered(parameter_number(v, n.pos)?, n.pos)
            }
            Param::Named(name, pos) => env.named(name, *pos),
        }
    }
}

impl Expr {
    /// Its value in `env`.
    pub fn eval(&self, env: &impl Env) -> Result<f64, ParseError> {
        let pos = self.pos;
        let v = match &self.kind {
            ExprKind::Number(v) => *v,
            ExprKind::Param(p) => p.eval(env)?,
            ExprKind::Neg(e) => -e.eval(env)?,
            ExprKind::Exists(p) => match &**p {
                Param::Named(name, _) => f64::from(u8::from(env.exists(name))),
                Param::Numbered(n) => {
                    let v = whole(n.eval(env)?, n.pos)?;
                    f64::from(u8::from(v >= 1 && v <= i64::from(MAX_PARAMETER)))
                }
            },
            ExprKind::Atan(y, x) => {
                let (y, x) = (y.eval(env)?, x.eval(env)?);
                y.atan2(x).to_degrees()
            }
            ExprKind::Func(f, a) => func(*f, a.eval(env)?, pos)?,
            ExprKind::Binary(op, a, b) => binary(*op, a.eval(env)?, b.eval(env)?, pos)?,
        };
        checked(v, pos)
    }
}

fn func(f: Func, x: f64, pos: SrcPos) -> Result<f64, ParseError> {
    let inverse = |name: &'static str, g: fn(f64) -> f64| {
        if (-1.0..=1.0).contains(&x) {
            Ok(g(x).to_degrees())
        } else {
            Err(err(
                InterpError::InverseTrigDomain {
                    func: name,
                    value: x,
                },
                pos,
            ))
        }
    };
    Ok(match f {
        Func::Abs => x.abs(),
        Func::Acos => inverse("ACOS", f64::acos)?,
        Func::Asin => inverse("ASIN", f64::asin)?,
        Func::Cos => x.to_radians().cos(),
        Func::Sin => x.to_radians().sin(),
        Func::Tan => x.to_radians().tan(),
        Func::Exp => x.exp(),
        Func::Fix => x.floor(),
        Func::Fup => x.ceil(),
        Func::Ln if x <= 0.0 => return Err(err(InterpError::LnDomain { value: x }, pos)),
        Func::Ln => x.ln(),
        // Half away from zero.
        Func::Round => x.round(),
        Func::Sqrt if x < 0.0 => return Err(err(InterpError::NegativeSqrt { value: x }, pos)),
        Func::Sqrt => x.sqrt(),
    })
}

fn truth(v: f64) -> bool {
    v != 0.0
}

fn binary(op: Op, a: f64, b: f64, pos: SrcPos) -> Result<f64, ParseError> {
    let flag = |t: bool| f64::from(u8::from(t));
    Ok(match op {
        Op::Pow => {
            if a < 0.0 && b != b.floor() {
                return Err(err(
                    InterpError::NegativePower {
                        base: a,
                        exponent: b,
                    },
                    pos,
                ));
            }
            a.powf(b)
        }
        Op::Mul => a * b,
        Op::Div if b == 0.0 => return Err(err(InterpError::DivideByZero, pos)),
        Op::Div => a / b,
        Op::Mod => {
            let r = a % b;
            if r < 0.0 {
                r + b.abs()
            } else {
                r
            }
        }
        Op::Add => a + b,
        Op::Sub => a - b,
        Op::Eq => flag((a - b).abs() < 1e-4),
        Op::Ne => flag((a - b).abs() >= 1e-4),
        Op::Gt => flag(a > b),
        Op::Ge => flag(a >= b),
        Op::Lt => flag(a < b),
        Op::Le => flag(a <= b),
        Op::And => flag(truth(a) && truth(b)),
        Op::Or => flag(truth(a) || truth(b)),
        Op::Xor => flag(truth(a) != truth(b)),
    })
}

/// Reads values and expressions from a normalised line.
pub struct Cursor<'n> {
    n: &'n Normal,
    pub i: usize,
    depth: usize,
}

impl<'n> Cursor<'n> {
    pub fn new(n: &'n Normal, i: usize) -> Self {
        Cursor { n, i, depth: 0 }
    }

    pub fn peek(&self) -> Option<char> {
        self.n.text.get(self.i).copied()
    }

    pub fn pos(&self) -> SrcPos {
        self.n.pos(self.i)
    }

    pub fn at_end(&self) -> bool {
        self.i >= self.n.text.len()
    }

    /// The text at the cursor starts with `s` (lower case).
    pub fn starts_with(&self, s: &str) -> bool {
        (self.i..)
            .zip(s.chars())
            .all(|(k, c)| self.n.text.get(k) == Some(&c))
    }

    /// Consumes `s` if the text at the cursor starts with it.
    pub fn eat(&mut self, s: &str) -> bool {
        let ok = self.starts_with(s);
        if ok {
            self.i += s.chars().count();
        }
        ok
    }

    fn enter(&mut self) -> Result<(), ParseError> {
        self.depth += 1;
        if self.depth > MAX_EXPR_DEPTH {
            return Err(err(InterpError::TooDeep, self.pos()));
        }
        Ok(())
    }

    /// A value (a word's value, an assignment's right-hand side).
    pub fn value(&mut self) -> Result<Expr, ParseError> {
        self.enter()?;
        let r = self.value_inner();
        self.depth -= 1;
        r
    }

    fn value_inner(&mut self) -> Result<Expr, ParseError> {
        let pos = self.pos();
        let node = |kind| Expr { kind, pos };
        match self.peek() {
            Some('[') => {
                self.i += 1;
                self.bracketed_rest()
            }
            Some('#') => {
                self.i += 1;
                Ok(node(ExprKind::Param(Box::new(self.param()?))))
            }
            Some(s @ ('+' | '-')) => {
                let next = self.n.text.get(self.i + 1).copied();
                if next.is_some_and(|c| c.is_ascii_digit() || c == '.') {
                    return self.number();
                }
                self.i += 1;
                let v = self.value()?;
                Ok(if s == '-' {
                    node(ExprKind::Neg(Box::new(v)))
                } else {
                    v
                })
            }
            Some(c) if c.is_ascii_digit() || c == '.' => self.number(),
            Some(c) if c.is_ascii_alphabetic() => self.function(),
            _ => Err(err(InterpError::ExpectedValue, pos)),
        }
    }

    /// `[` read: the expression and its `]`.
    fn bracketed_rest(&mut self) -> Result<Expr, ParseError> {
        let e = self.expression(0)?;
        if !self.eat("]") {
            return Err(match self.peek() {
                None => err(InterpError::UnclosedExpression, self.pos()),
                Some(_) => err(InterpError::ExpectedOperator, self.pos()),
            });
        }
        Ok(e)
    }

    /// An expression of values and operators binding at least as tightly as `min`.
    fn expression(&mut self, min: u8) -> Result<Expr, ParseError> {
        self.enter()?;
        let mut lhs = self.value()?;
        loop {
            let pos = self.pos();
            let Some(&(spelling, op)) = OPS.iter().find(|(s, _)| self.starts_with(s)) else {
                break;
            };
            if op.precedence() < min {
                break;
            }
            self.eat(spelling);
            let rhs = self.expression(op.precedence() + 1)?;
            lhs = Expr {
                kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                pos,
            };
        }
        self.depth -= 1;
        Ok(lhs)
    }

    fn number(&mut self) -> Result<Expr, ParseError> {
        let pos = self.pos();
        let start = self.i;
        if matches!(self.peek(), Some('+' | '-')) {
            self.i += 1;
        }
        let (mut digits, mut points) = (0, 0);
        while let Some(c) = self.peek() {
            match c {
                '0'..='9' => digits += 1,
                '.' => points += 1,
                _ => break,
            }
            self.i += 1;
        }
        let text: String = self.n.text[start..self.i].iter().collect();
        if digits == 0 || points > 1 {
            return Err(err(InterpError::ExpectedValue, pos));
        }
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Expr {
                kind: ExprKind::Number(v),
                pos,
            }),
            _ => Err(err(InterpError::Infinite, pos)),
        }
    }

    fn function(&mut self) -> Result<Expr, ParseError> {
        let pos = self.pos();
        let node = |kind| Expr { kind, pos };
        if self.eat("atan") {
            if !self.eat("[") {
                return Err(err(InterpError::AtanForm, self.pos()));
            }
            let y = self.bracketed_rest()?;
            if !self.eat("/[") {
                return Err(err(InterpError::AtanForm, self.pos()));
            }
            let x = self.bracketed_rest()?;
            return Ok(node(ExprKind::Atan(Box::new(y), Box::new(x))));
        }
        if self.eat("exists") {
            if !self.eat("[#") {
                return Err(err(InterpError::ExistsForm, self.pos()));
            }
            let p = self.param()?;
            if !self.eat("]") {
                return Err(err(InterpError::ExistsForm, self.pos()));
            }
            return Ok(node(ExprKind::Exists(Box::new(p))));
        }
        // Longest name first: "asin" before "abs" cannot clash, but "exp" and "exists" can.
        let Some(&(name, f)) = FUNCS.iter().find(|(n, _)| self.starts_with(n)) else {
            let word: String = self.n.text[self.i..]
                .iter()
                .take_while(|c| c.is_ascii_alphabetic())
                .collect();
            return Err(err(
                InterpError::UnknownFunction {
                    word: Name::new(&word),
                },
                pos,
            ));
        };
        self.eat(name);
        if !self.eat("[") {
            return Err(err(
                InterpError::FunctionBracket {
                    func: upper(f.name()),
                },
                self.pos(),
            ));
        }
        let a = self.bracketed_rest()?;
        Ok(node(ExprKind::Func(f, Box::new(a))))
    }

    /// After `#`: a named parameter `<name>` or a numbered one (its number a value).
    pub fn param(&mut self) -> Result<Param, ParseError> {
        // Where its `#` stands.
        let pos = self.n.pos(self.i.saturating_sub(1));
        if self.eat("<") {
            let mut name = String::new();
            loop {
                match self.peek() {
                    Some('>') => {
                        self.i += 1;
                        return Ok(Param::Named(name, pos));
                    }
                    Some(c) => {
                        name.push(c);
                        self.i += 1;
                    }
                    None => return Err(err(InterpError::NameNotClosed, pos)),
                }
            }
        }
        Ok(Param::Numbered(self.value()?))
    }
}

fn upper(name: &str) -> &'static str {
    match name {
        "abs" => "ABS",
        "acos" => "ACOS",
        "asin" => "ASIN",
        "cos" => "COS",
        "exp" => "EXP",
        "fix" => "FIX",
        "fup" => "FUP",
        "ln" => "LN",
        "round" => "ROUND",
        "sin" => "SIN",
        "sqrt" => "SQRT",
        _ => "TAN",
    }
}

#[cfg(test)]
mod tests;
