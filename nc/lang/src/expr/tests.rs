//! Values and expressions as LinuxCNC 2.9's `rs274` computes them (the cases of its
//! interpreter's own rules: precedence, signs, MOD, the tolerance of EQ, the domains).

use super::*;
use crate::text::normalise;
use std::collections::HashMap;

struct Vars {
    numbered: HashMap<u32, f64>,
    named: HashMap<String, f64>,
}

impl Env for Vars {
    fn numbered(&self, n: u32, _: SrcPos) -> Result<f64, ParseError> {
        Ok(self.numbered.get(&n).copied().unwrap_or(0.0))
    }
    fn named(&self, name: &str, pos: SrcPos) -> Result<f64, ParseError> {
        self.named.get(name).copied().ok_or(err(
            InterpError::UndefinedNamed {
                name: Name::new(name),
            },
            pos,
        ))
    }
    fn exists(&self, name: &str) -> bool {
        self.named.contains_key(name)
    }
}

fn vars() -> Vars {
    Vars {
        numbered: HashMap::from([(1, 3.0), (2, 1.0), (5, 2.5)]),
        named: HashMap::from([("abc".to_owned(), 7.0)]),
    }
}

fn value(src: &str) -> Result<f64, ParseError> {
    let n = normalise(1, src).unwrap();
    let mut c = Cursor::new(&n, 0);
    let e = c.value()?;
    assert!(c.at_end(), "{src}: left {:?}", &n.text[c.i..]);
    e.eval(&vars())
}

fn v(src: &str) -> f64 {
    value(src).unwrap_or_else(|e| panic!("{src}: {e}"))
}

fn kind(src: &str) -> InterpError {
    match value(src).unwrap_err().kind {
        ParseErrorKind::Interp(k) => k,
        other => panic!("{src}: {other:?}"),
    }
}

#[test]
fn precedence_and_associativity_as_linuxcnc() {
    for (src, want) in [
        ("[2+3*4]", 14.0),
        ("[2*3**2]", 18.0),
        ("[2**3**2]", 64.0),
        ("[10-4-3]", 3.0),
        ("[12/3/2]", 2.0),
        ("[1+1 EQ 2]", 1.0),
        ("[1 EQ 1 AND 0]", 0.0),
        ("[2 GT 1 GT 0]", 1.0),
        ("[1 OR 0 AND 0]", 0.0),
        ("[0 AND 1 OR 1]", 1.0),
        ("[-2**2]", 4.0),
        ("[0-2**2]", -4.0),
        ("[1 ++ 2]", 3.0),
        ("[2*-3]", -6.0),
        ("[1 2]", 12.0),
        ("[1 mod2]", 1.0),
    ] {
        assert_eq!(v(src), want, "{src}");
    }
}

#[test]
fn signs_numbers_and_parameters() {
    assert_eq!(v("--1"), 1.0);
    assert_eq!(v("+-1"), -1.0);
    assert_eq!(v(".5"), 0.5);
    assert_eq!(v("5."), 5.0);
    assert_eq!(v("-#1"), -3.0);
    assert_eq!(v("##2"), 3.0); // #[#2] = #1
    assert_eq!(v("#[#2 + 4]"), 2.5);
    assert_eq!(v("#<abc>"), 7.0);
    assert_eq!(v("#<a b c>"), 7.0); // spaces vanish, case folds
    assert_eq!(v("#4"), 0.0); // unset numbered: 0
    assert!(matches!(
        kind("#<nope>"),
        InterpError::UndefinedNamed { .. }
    ));
    assert!(matches!(
        kind("#0"),
        InterpError::ParameterOutOfRange { .. }
    ));
    assert!(matches!(
        kind("#5602"),
        InterpError::ParameterOutOfRange { .. }
    ));
    assert!(matches!(kind("#1.5"), InterpError::NotWhole { .. }));
    assert_eq!(v("#1.00001"), 3.0);
    assert!(matches!(kind("1.2.3"), InterpError::ExpectedValue));
}

#[test]
fn operators_and_functions() {
    assert_eq!(v("[-7 MOD 3]"), 2.0);
    assert_eq!(v("[7 MOD -3]"), 1.0);
    assert_eq!(v("[7.5 MOD 2]"), 1.5);
    assert_eq!(v("[0.00005 EQ 0]"), 1.0);
    assert_eq!(v("[0.0001 EQ 0]"), 0.0);
    assert_eq!(v("[1 LT 1.00001]"), 1.0);
    assert_eq!(v("[0.5 AND 2]"), 1.0);
    assert_eq!(v("[3 XOR 3]"), 0.0);
    assert!((v("SIN[30]") - 0.5).abs() < 1e-15);
    assert!((v("ATAN[1]/[1]") - 45.0).abs() < 1e-13);
    assert_eq!(v("ATAN[0]/[0]"), 0.0);
    assert_eq!(v("FIX[-2.8]"), -3.0);
    assert_eq!(v("FUP[-2.8]"), -2.0);
    assert_eq!(v("ROUND[2.5]"), 3.0);
    assert_eq!(v("ROUND[-2.5]"), -3.0);
    assert_eq!(v("EXISTS[#<abc>]"), 1.0);
    assert_eq!(v("EXISTS[#<x>]"), 0.0);
    assert_eq!(v("EXISTS[#1]"), 1.0);
    assert_eq!(v("[0**0]"), 1.0);
}

#[test]
fn domain_errors_name_the_value() {
    assert_eq!(kind("[1/0]"), InterpError::DivideByZero);
    assert_eq!(kind("[0/0]"), InterpError::DivideByZero);
    assert_eq!(kind("SQRT[-1]"), InterpError::NegativeSqrt { value: -1.0 });
    assert_eq!(kind("LN[0]"), InterpError::LnDomain { value: 0.0 });
    assert!(matches!(
        kind("ACOS[2]"),
        InterpError::InverseTrigDomain { func: "ACOS", .. }
    ));
    assert!(matches!(
        kind("[-8**0.5]"),
        InterpError::NegativePower { .. }
    ));
    assert_eq!(kind("[1 MOD 0]"), InterpError::NotANumber);
    assert_eq!(kind("EXP[1000]"), InterpError::Infinite);
}

#[test]
fn malformed_expressions_say_what_is_missing() {
    assert_eq!(kind("[1+2"), InterpError::UnclosedExpression);
    assert_eq!(kind("[1 & 2]"), InterpError::ExpectedOperator);
    assert_eq!(kind("[]"), InterpError::ExpectedValue);
    assert!(matches!(
        kind("foo[1]"),
        InterpError::UnknownFunction { .. }
    ));
    assert!(matches!(
        kind("sin30"),
        InterpError::FunctionBracket { func: "SIN" }
    ));
    assert_eq!(kind("atan[1]"), InterpError::AtanForm);
    assert_eq!(kind("atan[1]/1"), InterpError::AtanForm);
    assert_eq!(kind("exists[1]"), InterpError::ExistsForm);
    assert_eq!(kind("#<abc"), InterpError::NameNotClosed);
    let deep = format!("{}1{}", "[".repeat(100), "]".repeat(100));
    assert_eq!(kind(&deep), InterpError::TooDeep);
}
