//! MDI against the program reader: every program of the conformance suite and the corpus,
//! typed into an MDI session a line at a time with refused lines among them, gives what
//! the program gives when read whole.
//!
//! Each program is cut at its `M02`/`M30` (not taken in MDI) and its `%` lines are left
//! out; lines that set modes and then fail (units, distance mode, plane, parameters) are
//! typed in between, at places chosen by a seeded hash. They must be refused, and every
//! entry the session gives (blocks, actions, positions) must equal the whole program's
//! with those lines blank (but for the waits a line leaves to the next move: an MDI
//! line's are its own). A program MDI does not take (a NURBS block, cutter
//! compensation, an O-word block, a continued line, an error of its own) is counted with
//! its reason and left out.

use nc_geom::program::SrcPos;
use nc_geom::program::{Block, Wait};
use nc_lang::mdi::{Mdi, MdiError};
use nc_lang::{Entries, Entry, LineSource, ParseError, Setup, StrLines};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Lines that change the modal state before their error.
const JUNK: [&str; 6] = [
    "G91 G20 #<mdi_junk>=7 G0 X[1/0]",
    "G18 G91 G0 X#<mdi_never_set>",
    "#1=9 #2=8 G93 G0 X1 G1 Y1",
    "G19 G92 X5 M30",
    "G90 G21 o9 if [1]",
    "G20 F5 G1 X1 Q",
];

fn setup() -> Setup {
    Setup {
        reference: Some([0.0; 3]),
        work_offsets: [Some([0.0; 3]); 6],
        tools: [(1, 12.9794), (2, 2.54), (3, 32.3342)]
            .into_iter()
            .collect(),
        tool_diameters: [(1, 3.175), (2, 1.5875), (3, 5.1054)].into_iter().collect(),
        ..Setup::default()
    }
}

fn programs() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests");
    let mut out = Vec::new();
    let mut dirs = vec![
        root.join("conformance/programs"),
        root.join("corpus/programs"),
    ];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let p = e.expect("entry").path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "ngc" || x == "nc") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// A 64-bit mix (splitmix64) for the junk's places.
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// The program's lines as MDI takes them: up to its end, `%` lines blank.
fn mdi_lines(src: &str, setup: &Setup) -> Vec<String> {
    let mut whole = Entries::new(StrLines::new(src), setup);
    for _ in whole.by_ref() {}
    let end = whole.end().map_or(u32::MAX, |p| p.line);
    src.lines()
        .enumerate()
        .take_while(|(i, _)| (*i as u32) + 1 < end)
        .map(|(_, l)| {
            if l.trim() == "%" {
                String::new()
            } else {
                l.to_owned()
            }
        })
        .collect()
}

/// The entry with its block's wait taken out: a `G04` or `M00` with no move after it on
/// its line holds a program's next move, and is the MDI line's own (its actions say it;
/// `nc/lang/src/mdi/tests.rs` checks that it holds no later line).
fn without_wait(e: &Entry) -> Entry {
    let mut e = e.clone();
    if let Entry::Block(_, b) = &mut e {
        let tooling = match b {
            Block::Linear(m) => &mut m.tooling,
            Block::Nurbs(n) => &mut n.tooling,
        };
        tooling.wait = Wait::default();
    }
    e
}

/// The program typed line by line, junk among its lines: `Ok` with how many junk lines
/// were refused, or why MDI does not take it.
fn typed(name: &str, src: &str, setup: &Setup) -> Result<usize, String> {
    let lines = mdi_lines(src, setup);
    let mut mdi = Mdi::new(setup);
    let mut got: Vec<Entry> = Vec::new();
    let mut text: Vec<String> = Vec::new();
    let mut junk = 0;
    let seed = name.bytes().fold(0u64, |h, b| mix(h ^ u64::from(b)));
    for (i, line) in lines.iter().enumerate() {
        let h = mix(seed ^ i as u64);
        if h % 5 == 0 {
            let bad = JUNK[(h >> 8) as usize % JUNK.len()];
            match mdi.line(bad) {
                Err(e) => assert!(e.to_string().contains(bad), "{name}: {e}"),
                Ok(out) => panic!("{name}: `{bad}` was taken: {out:?}"),
            }
            text.push(String::new());
            junk += 1;
        }
        match mdi.line(line) {
            Ok(out) => got.extend(out),
            Err(MdiError::Unfinished { what, .. }) => return Err(what.to_string()),
            Err(MdiError::Parse { .. }) => return Err("an error of its own".into()),
            Err(MdiError::NotALine { why, .. }) => return Err(why.into()),
        }
        text.push(line.clone());
    }
    let program = text.join("\n");
    let mut want = Vec::new();
    for e in Entries::new(StrLines::new(&program), setup) {
        match e {
            Ok(e) => want.push(e),
            Err(e) => panic!("{name}: typed whole: {e}"),
        }
    }
    assert_eq!(got.len(), want.len(), "{name}: entries");
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(without_wait(g), without_wait(w), "{name}");
    }
    Ok(junk)
}

#[test]
fn a_program_typed_line_by_line_is_the_program() {
    let setup = setup();
    let mut taken = Vec::new();
    let mut refused: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut junk = 0;
    for p in programs() {
        let name = p.display().to_string();
        let Ok(src) = std::fs::read_to_string(&p) else {
            continue;
        };
        match typed(&name, &src, &setup) {
            Ok(n) => {
                junk += n;
                taken.push(name);
            }
            Err(why) => refused.entry(why).or_default().push(name),
        }
    }
    eprintln!(
        "MDI: {} programs typed line by line as read whole, {junk} refused lines among them",
        taken.len()
    );
    for (why, names) in &refused {
        eprintln!("  {} not taken: {why}", names.len());
    }
    assert!(taken.len() >= 40, "{taken:?}");
    assert!(junk >= 200, "{junk}");
}

/// A program's lines numbered from `by + 1`: the rest of a program after its first `by`
/// lines were typed in MDI keeps the whole program's line numbers.
struct After<'a> {
    lines: StrLines<'a>,
    by: u32,
}

impl LineSource for After<'_> {
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>> {
        let by = self.by;
        Some(self.lines.next_line()?.map(|(n, t)| (n + by, t)))
    }

    fn eof(&self) -> SrcPos {
        let e = self.lines.eof();
        SrcPos {
            line: e.line + self.by,
            col: e.col,
        }
    }
}

/// The program's first `k` lines typed in MDI, the rest run as a program after them:
/// the same entries and errors as the whole program read at once (the rest's blocks
/// counted from 0). `Err`: MDI refused one of the first `k` lines.
fn split(name: &str, src: &str, k: usize, setup: &Setup) -> Result<(), String> {
    let lines: Vec<&str> = src.lines().collect();
    let typed: Vec<String> = lines[..k]
        .iter()
        .map(|l| {
            if l.trim() == "%" {
                String::new()
            } else {
                (*l).to_owned()
            }
        })
        .collect();
    let rest = lines[k..].join("\n");
    let whole = format!("{}\n{rest}", typed.join("\n"));
    let mut mdi = Mdi::new(setup);
    let mut before = 0;
    for line in &typed {
        let out = mdi.line(line).map_err(|e| e.to_string())?;
        before += out.iter().filter(|e| matches!(e, Entry::Block(..))).count();
    }
    let program = mdi.into_program(After {
        lines: StrLines::new(&rest),
        by: k as u32,
    });
    // Errors too: the rest reads to the same errors at the same places.
    let got: Vec<Result<Entry, String>> = program.map(|e| e.map_err(|e| e.to_string())).collect();
    let want: Vec<Result<Entry, String>> = Entries::new(StrLines::new(&whole), setup)
        .map(|e| e.map_err(|e| e.to_string()))
        .collect();
    // The whole program's entries from its line k + 1 on (the typed lines' own first).
    assert!(
        want.len() >= got.len(),
        "{name} after {k} lines: more entries"
    );
    let skip = want.len() - got.len();
    let shift = |e: &Entry| match e.clone() {
        Entry::Block(i, b) => Entry::Block(i - before, b),
        Entry::Action(mut a) => {
            a.before_block -= before;
            Entry::Action(a)
        }
    };
    for (g, w) in got.iter().zip(&want[skip..]) {
        match (g, w) {
            (Ok(g), Ok(w)) => {
                assert_eq!(
                    without_wait(g),
                    without_wait(&shift(w)),
                    "{name} after {k} lines"
                )
            }
            (g, w) => assert_eq!(g.as_ref().err(), w.as_ref().err(), "{name} after {k} lines"),
        }
    }
    assert!(
        want[..skip].iter().all(|e| match e {
            Ok(Entry::Block(_, b)) => (b.pos().line as usize) <= k,
            Ok(Entry::Action(a)) => (a.pos.line as usize) <= k,
            Err(_) => false,
        }),
        "{name} after {k} lines: the typed lines' entries come first"
    );
    Ok(())
}

#[test]
fn a_program_after_mdi_lines_runs_as_the_whole_program() {
    let setup = setup();
    let (mut ran, mut not) = (0, 0);
    for p in programs() {
        let name = p.display().to_string();
        let Ok(src) = std::fs::read_to_string(&p) else {
            continue;
        };
        // Cut where the program's lines before can all be typed.
        let n = mdi_lines(&src, &setup).len();
        if n < 2 {
            continue;
        }
        let seed = name.bytes().fold(7u64, |h, b| mix(h ^ u64::from(b)));
        let k = 1 + (seed % (n as u64 - 1)) as usize;
        match split(&name, &src, k, &setup) {
            Ok(()) => ran += 1,
            Err(_) => not += 1,
        }
    }
    eprintln!("MDI then a program: {ran} programs cut and run as a whole, {not} not cut there");
    assert!(ran >= 100, "{ran}");
}
