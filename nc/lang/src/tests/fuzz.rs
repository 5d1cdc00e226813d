//! Property tests: `parse` returns (`Ok` or `Err`) on any input and never panics; what it
//! accepts satisfies the invariants of [`Program`](nc_geom::program::Program), and every error
//! points inside the source.

use proptest::prelude::*;

use super::PAPER;
use crate::parse;
use nc_geom::program::{Block, MAX_CTRL};

/// Checks the result of parsing `src` beyond "did not panic", and that streaming gives
/// the same (see `source.rs`).
fn check(src: &str) {
    super::source::streams_alike(src);
    match parse(src) {
        Ok(program) => {
            for block in &program.blocks {
                if let Block::Nurbs(b) = block {
                    let p = usize::from(b.degree);
                    assert!((1..=5).contains(&p));
                    assert!(b.ctrl.len() > p && b.ctrl.len() <= MAX_CTRL);
                    assert_eq!(b.knots.len(), b.ctrl.len() + p + 1);
                    assert_eq!(b.weights.len(), b.ctrl.len());
                    assert_eq!(b.ctrl_pos.len(), b.ctrl.len());
                    assert!(b.knots.windows(2).all(|w| w[0] <= w[1]));
                }
            }
        }
        Err(e) => {
            let lines = u32::try_from(src.lines().count()).unwrap_or(u32::MAX);
            assert!(e.pos.line >= 1 && e.pos.col >= 1, "{e}");
            assert!(
                e.pos.line <= lines.max(1),
                "{e} is past the end of {lines} lines"
            );
            let _ = e.to_string();
        }
    }
}

/// Strings made of the characters NC programs are made of, so that the parser gets deep.
fn nc_like() -> impl Strategy<Value = String> {
    proptest::string::string_regex(r"([GgNXYZIJKABCUVWRPFM ]|[0-9]|[-+.]|\\\n|\n|%|\(|\)|;){0,200}")
        .expect("valid regex")
}

#[derive(Clone, Debug)]
enum Edit {
    Insert(usize, char),
    Delete(usize),
    Replace(usize, char),
}

fn edit() -> impl Strategy<Value = Edit> {
    let ch = prop_oneof![
        prop::char::any(),
        prop::sample::select(
            r"0123456789.-+XYZUVWKRPFGNM \\%();"
                .chars()
                .collect::<Vec<_>>()
        ),
        Just('\n'),
    ];
    prop_oneof![
        (any::<usize>(), ch.clone()).prop_map(|(i, c)| Edit::Insert(i, c)),
        any::<usize>().prop_map(Edit::Delete),
        (any::<usize>(), ch).prop_map(|(i, c)| Edit::Replace(i, c)),
    ]
}

/// Applies `edits` to the characters of `src` (indices wrap around the current length).
fn mutate(src: &str, edits: &[Edit]) -> String {
    let mut chars: Vec<char> = src.chars().collect();
    for e in edits {
        let len = chars.len().max(1);
        match *e {
            Edit::Insert(i, c) => chars.insert(i % (chars.len() + 1), c),
            Edit::Delete(i) if !chars.is_empty() => {
                chars.remove(i % len);
            }
            Edit::Replace(i, c) if !chars.is_empty() => chars[i % len] = c,
            _ => {}
        }
    }
    chars.into_iter().collect()
}

/// Cases of each property: `LANG_FUZZ_CASES` (default 500; `.ci/run` sets 2 000).
fn cases() -> u32 {
    std::env::var("LANG_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(500)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn arbitrary_text_never_panics(src in any::<String>()) {
        check(&src);
    }

    #[test]
    fn nc_like_text_never_panics(src in nc_like()) {
        check(&src);
    }

    #[test]
    fn mutated_paper_example_never_panics(edits in prop::collection::vec(edit(), 1..8)) {
        check(&mutate(PAPER, &edits));
    }
}

#[test]
fn hostile_inputs_are_errors() {
    for src in [
        "N99999999999999999999999 G00 X0 Y0 Z0",
        "G00 X1e999 Y0 Z0",
        &format!("G00 X{} Y0 Z0", "9".repeat(400)),
        "G00 X0 Y0 Z0 \\",
        "G06.5 P99999999999999999999",
        "\\",
        "(",
        "%%",
    ] {
        check(src);
        assert!(parse(src).is_err(), "{src}");
    }
    // Huge but finite: squaring would overflow, the scaled normalisation does not.
    let big = "9".repeat(300);
    let program = parse(&format!("G00 X0 Y0 Z0 I{big} J{big} K{big}")).unwrap();
    let Block::Linear(m) = &program.blocks[0] else {
        panic!("a linear move")
    };
    assert_eq!(
        m.orientation,
        nc_geom::program::Orientation::Vector([1.0 / 3f64.sqrt(); 3])
    );
}
