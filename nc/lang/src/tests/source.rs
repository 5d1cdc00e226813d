//! Reading a program as a stream: [`ReadLines`] over a reader gives the parse of the same
//! text in memory, whatever the reader's buffer cuts; [`Entries`] yields every action just
//! before the block it precedes; bytes that are not UTF-8 and endless lines are refused at
//! their line and column.

use proptest::prelude::*;
use std::io::BufReader;

use super::{at, G01_5AXIS, G062, PAPER};
use crate::{
    parse_lines, parse_with, Entries, Entry, ParseErrorKind, ReadLines, Setup, StrLines,
    MAX_LINE_BYTES,
};

/// `src` parsed from memory and read through readers of small buffers agree exactly,
/// errors included; and the entries come in the order their `before_block` says.
pub(super) fn streams_alike(src: &str) {
    let setup = Setup::default();
    let whole = parse_with(src, &setup);
    for cap in [1, 7, 64] {
        let reader = BufReader::with_capacity(cap, src.as_bytes());
        let streamed = parse_lines(ReadLines::new(reader), &setup);
        assert_eq!(streamed, whole, "buffer of {cap} bytes on {src:?}");
    }
    let mut blocks = 0;
    for entry in Entries::new(StrLines::new(src), &setup).flatten() {
        match entry {
            Entry::Block(i, _) => {
                assert_eq!(i, blocks, "blocks are numbered in order");
                blocks += 1;
            }
            Entry::Action(a) => assert_eq!(
                a.before_block, blocks,
                "an action comes just before its block: {a:?}"
            ),
        }
    }
}

#[test]
fn the_test_programs_stream_alike() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).expect("tests/data") {
        let path = entry.expect("a directory entry").path();
        if path.extension().is_some_and(|e| e == "nc") {
            streams_alike(&std::fs::read_to_string(&path).expect("UTF-8"));
            n += 1;
        }
    }
    assert!(n >= 5, "only {n} programs in {dir}");
    // Actions on the lines of moves: before the move (M03) and after it (M00).
    let actions = "G00 X0 Y0 Z10\nS1000 M03 G01 Z0 F500\nG01 X5 M00\nM05\nM30\n";
    let program = parse_with(actions, &Setup::default()).expect("it parses");
    assert_eq!(program.actions.len(), 3, "{program:?}");
    for src in [PAPER, G062, G01_5AXIS, actions] {
        streams_alike(src);
        streams_alike(&src.replace('\n', "\r\n"));
    }
}

#[test]
fn a_byte_order_mark_is_dropped_and_crlf_is_a_line_end() {
    let src = "G00 X0 Y0 Z10\r\nG01 Z0 F500\r\nM30\r\n";
    let mut bytes = b"\xef\xbb\xbf".to_vec();
    bytes.extend_from_slice(src.as_bytes());
    let streamed = parse_lines(ReadLines::new(&bytes[..]), &Setup::default());
    assert_eq!(streamed, parse_with(src, &Setup::default()));
    assert_eq!(streamed.expect("it parses").blocks.len(), 2);
}

/// Where a byte that is not UTF-8 stands: its line, and its column in characters.
fn not_utf8_at(prefix: &str) -> (u32, u32) {
    let line = prefix.matches('\n').count() + 1;
    let col = prefix.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line as u32, col as u32)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn a_byte_that_is_not_utf8_is_refused_where_it_stands(
        prefix in "[GXYZ0-9 .\\n(é)]{0,80}",
        bad in prop::sample::select(vec![0x80u8, 0xc3, 0xff, 0xfe, 0xe2]),
        rest in "[GXYZ0-9 \\n]{0,40}",
        cap in 1usize..32,
    ) {
        let mut bytes = prefix.as_bytes().to_vec();
        bytes.push(bad);
        // A lone lead byte followed by ASCII is invalid too.
        bytes.push(b'!');
        bytes.extend_from_slice(rest.as_bytes());
        let reader = BufReader::with_capacity(cap, &bytes[..]);
        let errors = parse_lines(ReadLines::new(reader), &Setup::default())
            .expect_err("not UTF-8");
        let e = errors.errors.iter().find(|e| matches!(e.kind, ParseErrorKind::NotUtf8 { .. }));
        let e = e.expect("the encoding error is reported");
        let (line, col) = not_utf8_at(&prefix);
        prop_assert_eq!(e.pos, at(line, col));
        prop_assert_eq!(e.kind, ParseErrorKind::NotUtf8 { byte: bad });
        // Nothing is read past it.
        prop_assert!(errors.errors.iter().all(|x| x.pos.line <= line));
    }
}

#[test]
fn an_endless_line_is_refused_without_reading_it_whole() {
    let mut src = String::from("G00 X0 Y0 Z10\n(");
    src.push_str(&"x".repeat(MAX_LINE_BYTES + 10));
    src.push_str(")\nG01 Z0 F500\n");
    let too_long = ParseErrorKind::LineTooLong {
        max: MAX_LINE_BYTES,
    };
    let whole = parse_with(&src, &Setup::default()).expect_err("too long");
    assert_eq!(whole.errors[0].kind, too_long);
    assert_eq!(whole.errors[0].pos, at(2, 1));
    let streamed = parse_lines(ReadLines::new(src.as_bytes()), &Setup::default());
    assert_eq!(streamed, Err(whole));
    // One line under the limit is a line.
    let mut ok = String::from("G00 X0 Y0 Z10 (");
    ok.push_str(&"x".repeat(MAX_LINE_BYTES - 100));
    ok.push_str(")\n");
    assert!(parse_lines(ReadLines::new(ok.as_bytes()), &Setup::default()).is_ok());
}
