//! Lexical and line-structure rules.

use super::{fails, g065, message, KNOTS, OPEN, POINT};
use crate::tests::at;
use crate::{parse, Context, Motion, ParseErrorKind as E};

// ---- lexical rules -------------------------------------------------------------------------

#[test]
fn unexpected_character() {
    assert_eq!(
        fails("G01 X0 Y0 Z0 F500 $1", 1, 19),
        E::UnexpectedChar { ch: '$' }
    );
    // `#` starts an assignment.
    assert_eq!(
        fails("G01 X0 Y0 Z0 F500 #1", 1, 21),
        E::Interp(crate::InterpError::MissingEquals)
    );
    // Columns count characters, not bytes.
    assert_eq!(
        fails("(üü) G00 X0 Y0 Z0 é", 1, 19),
        E::UnexpectedChar { ch: 'é' }
    );
}

#[test]
fn letter_without_number() {
    assert_eq!(fails("G01 X Y0", 1, 5), E::MissingNumber { letter: 'X' });
    assert_eq!(
        fails("G00 X0 Y-. Z0", 1, 8),
        E::MissingNumber { letter: 'Y' }
    );
}

#[test]
fn number_too_large() {
    let src = format!("G00 X{} Y0 Z0", "9".repeat(400));
    assert_eq!(fails(&src, 1, 6), E::Interp(crate::InterpError::Infinite));
    // There are no exponents: `1e999` is X1 followed by the word E999, which only M66..M68
    // take.
    assert_eq!(
        fails("G00 X1e999 Y0 Z0", 1, 7),
        E::WordNotAllowed {
            letter: 'E',
            context: crate::Context::Move(crate::Motion::G00)
        }
    );
}

#[test]
fn unterminated_comment() {
    assert_eq!(
        fails("G00 X0 Y0 Z0\nG01 X0 (oops", 2, 8),
        E::UnterminatedComment
    );
}

#[test]
fn backslash_not_at_end_of_line() {
    assert_eq!(fails("G00 X0 \\ Y0 Z0", 1, 8), E::MisplacedBackslash);
}

#[test]
fn continuation_at_end_of_file() {
    assert_eq!(fails("G00 X0 Y0 Z0 \\", 1, 14), E::ContinuationAtEof);
}

#[test]
fn tape_mark_not_alone() {
    assert_eq!(fails("G00 X0 Y0 Z0 %", 1, 14), E::MisplacedTapeMark);
    assert_eq!(fails("G00 X0 \\\n%\nY0 Z0", 2, 1), E::MisplacedTapeMark);
}

#[test]
fn d_belongs_to_cutter_compensation() {
    assert_eq!(fails("G00 X0 Y0 Z0 D1000", 1, 14), E::DWithoutCompensation);
}

// ---- line structure ------------------------------------------------------------------------

#[test]
fn bad_sequence_number() {
    // A fraction is read and ignored, as LinuxCNC does (`N1.5` is N1).
    let p = parse("N1.5 G00 X0 Y0 Z0").unwrap();
    assert!(matches!(p.blocks[0], nc_geom::program::Block::Linear(m) if m.n == Some(1)));
    assert_eq!(
        fails("N4294967296 G00 X0 Y0 Z0", 1, 1),
        E::BadSequenceNumber {
            value: 4294967296.0
        }
    );
    assert_eq!(
        fails("N-1 G00 X0 Y0 Z0", 1, 1),
        E::BadSequenceNumber { value: -1.0 }
    );
}

#[test]
fn sequence_number_not_first() {
    assert_eq!(
        fails("G00 N10 X0 Y0 Z0", 1, 5),
        E::MisplacedSequenceNumber { value: 10.0 }
    );
}

#[test]
fn repeated_word() {
    assert_eq!(
        fails("G00 X1 Y2 Z3 X4", 1, 14),
        E::RepeatedWord {
            letter: 'X',
            first: at(1, 5)
        }
    );
}

#[test]
fn two_codes_of_one_group() {
    assert_eq!(
        fails("G00 G01 X0 Y0 Z0", 1, 5),
        E::ConflictingCodes {
            letter: 'G',
            first: 0.0,
            second: 1.0
        }
    );
    assert_eq!(
        fails("G00 X0 Y0 Z0 M30 M2", 1, 18),
        E::ConflictingCodes {
            letter: 'M',
            first: 30.0,
            second: 2.0
        }
    );
}

#[test]
fn unsupported_g_code() {
    assert_eq!(
        fails("G90 G21\nG68 G00 X0 Y0 Z0", 2, 1),
        E::UnsupportedGCode { code: 68.0 }
    );
    assert_eq!(
        message("G90 G21\nG68 G00 X0 Y0 Z0"),
        format!(
            "2:1: unsupported G-code G68: dnurbs accepts {}",
            crate::rules::G_LIST
        )
    );
    for (src, name) in [
        ("G43.5", "G43.5"),
        ("G68.2", "G68.2"),
        ("G10.5", "G10.5"),
        ("G06.3", "G06.3"),
    ] {
        let msg = message(src);
        assert!(
            msg.starts_with(&format!("1:1: unsupported G-code {name}:")),
            "{msg}"
        );
    }
}

#[test]
fn canned_cycles_dnurbs_does_not_run_are_refused_by_name() {
    assert_eq!(
        fails("G84 X0 Y0 Z-5 R2", 1, 1),
        E::CannedCycle { code: 84.0 }
    );
    assert!(message("G87").contains("post the cycle expanded into G00/G01 moves"));
    assert_eq!(fails("G38.2 Z-10 F100", 1, 1), E::Probing { code: 38.2 });
    assert_eq!(
        fails("G33.1 Z-10 K1", 1, 1),
        E::SpindleSynchronised { code: 33.1 }
    );
    assert!(message("G76 P1 Z-1 I-0.1 J0.1 K0.1").contains("threading"));
    assert_eq!(fails("G07", 1, 1), E::LatheDiameterMode);
}

#[test]
fn unsupported_m_code() {
    assert_eq!(
        fails("G00 X0 Y0 Z0 M98", 1, 14),
        E::UnsupportedMCode { code: 98.0 }
    );
    assert!(message("M99").starts_with("1:1: unsupported M-code M99:"));
}

#[test]
fn words_after_program_end_are_not_read() {
    // LinuxCNC stops reading at M02/M30: what follows is never parsed.
    let src = "G00 X0 Y0 Z0\nM30\n(comment)\n%\n\nG00 X1 garbage $$\n";
    let p = parse(src).unwrap();
    assert_eq!((p.blocks.len(), p.end), (1, Some(at(2, 1))));
    let p = parse("G00 X0 Y0 Z0 M02\nX1").unwrap();
    assert_eq!((p.blocks.len(), p.end), (1, Some(at(1, 14))));
}

#[test]
fn word_not_allowed_in_context() {
    let g01 = Context::Move(Motion::G01);
    assert_eq!(
        fails("G01 X0 Y0 Z0 F500 P3", 1, 19),
        E::WordNotAllowed {
            letter: 'P',
            context: g01
        }
    );
    let g00 = Context::Move(Motion::G00);
    assert_eq!(
        fails("G00 X0 Y0 Z0 R1", 1, 14),
        E::WordNotAllowed {
            letter: 'R',
            context: g00
        }
    );
    assert_eq!(
        fails("G00 X0 Y0 Z0\nR1", 2, 1),
        E::WordNotAllowed {
            letter: 'R',
            context: g00
        }
    );
    assert_eq!(
        fails("G00 X0 Y0 Z0\nG90 P1", 2, 5),
        E::WordNotAllowed {
            letter: 'P',
            context: Context::NoMotion
        }
    );
    let cp062 = Context::ControlPoint(Motion::G062);
    let src = "G01 X0 Y0 Z0 F500\nG06.2 K0 X0 Y0 Z0 U1";
    assert_eq!(
        fails(src, 2, 19),
        E::WordNotAllowed {
            letter: 'U',
            context: cp062
        }
    );
    let cp065 = Context::ControlPoint(Motion::G065);
    let src = g065(OPEN, "X10 Y0 Z0 U10 V0 W1 K0 F600", KNOTS);
    assert_eq!(
        fails(&src, 3, 24),
        E::WordNotAllowed {
            letter: 'F',
            context: cp065
        }
    );
    let src = g065("G06.5 P1 X0 Y0 Z0 U0 V0 W1 K0 M30", POINT, KNOTS);
    assert_eq!(
        fails(&src, 2, 31),
        E::WordNotAllowed {
            letter: 'M',
            context: cp065
        }
    );
}

#[test]
fn k_alone_on_a_g01_names_the_word() {
    let src = "G01 X0 Y0 Z0 F500\nX1 K0.5";
    assert_eq!(
        fails(src, 2, 4),
        E::IncompleteVector {
            given: 'K',
            missing: 'I'
        }
    );
    assert_eq!(
        message(src),
        "2:4: tool vector word K without I: I, J and K must be given together"
    );
}

#[test]
fn control_point_word_missing() {
    let cp065 = Context::ControlPoint(Motion::G065);
    let src = g065(OPEN, "X10 Y0 Z0 U10 V0 K0", KNOTS);
    assert_eq!(
        fails(&src, 3, 1),
        E::MissingWord {
            letter: 'W',
            context: cp065
        }
    );
    let src = g065("G06.5 P1 X0 Z0 U0 V0 W1 K0", POINT, KNOTS);
    assert_eq!(
        fails(&src, 2, 10),
        E::MissingWord {
            letter: 'Y',
            context: cp065
        }
    );
    let src = "G01 X0 Y0 Z0 F500\nG06.2 P2 K0 X0 Y0 Z0\nK0 X10 Y0\nK1 K1";
    let cp062 = Context::ControlPoint(Motion::G062);
    assert_eq!(
        fails(src, 3, 1),
        E::MissingWord {
            letter: 'Z',
            context: cp062
        }
    );
}
