//! One test per error rule: the variant with its values, and the `line:col` of the offending
//! token (counted by hand; columns are 1-based and count characters).

mod modal;
mod nurbs;
mod syntax;

use super::at;
use crate::{parse, ParseErrorKind as E};

/// Parses `src`, asserts that it fails at `line:col`, returns the rule broken.
#[track_caller]
pub(super) fn fails(src: &str, line: u32, col: u32) -> E {
    let e = parse(src).expect_err("the program must be rejected");
    assert_eq!(e.pos, at(line, col), "wrong position for: {e}");
    e.kind
}

/// The message of the error `src` produces.
pub(super) fn message(src: &str) -> String {
    parse(src)
        .expect_err("the program must be rejected")
        .to_string()
}

/// A valid degree-1 G06.5 block after its start move, with lines 2-4 replaceable:
/// ```text
/// 1 G01 X0 Y0 Z0 F500
/// 2 G06.5 P1 X0 Y0 Z0 U0 V0 W1 K0
/// 3 X10 Y0 Z0 U10 V0 W1 K0
/// 4 K1 K1
/// ```
pub(super) fn g065(open: &str, point: &str, knots: &str) -> String {
    format!("G01 X0 Y0 Z0 F500\n{open}\n{point}\n{knots}\n")
}
pub(super) const OPEN: &str = "G06.5 P1 X0 Y0 Z0 U0 V0 W1 K0";
pub(super) const POINT: &str = "X10 Y0 Z0 U10 V0 W1 K0";
pub(super) const KNOTS: &str = "K1 K1";

#[test]
fn the_reference_block_is_valid() {
    assert!(parse(&g065(OPEN, POINT, KNOTS)).is_ok());
}
