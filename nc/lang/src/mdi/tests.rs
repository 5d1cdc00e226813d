use super::*;
use nc_geom::program::{Action, ActionKind, Block};

const VERTICAL: Orientation = Orientation::Vector([0.0, 0.0, 1.0]);

fn setup() -> Setup {
    Setup {
        work_offsets: [Some([0.0; 3]), None, None, None, None, None],
        ..Setup::default()
    }
}

/// The end points of the blocks a line gave.
fn ends(out: &[Entry]) -> Vec<[f64; 3]> {
    out.iter()
        .filter_map(|e| match e {
            Entry::Block(_, Block::Linear(m)) => Some(m.end),
            Entry::Block(_, Block::Nurbs(b)) => b.ctrl.last().copied(),
            _ => None,
        })
        .collect()
}

fn take(mdi: &mut Mdi<'_>, line: &str) -> Vec<Entry> {
    mdi.line(line)
        .unwrap_or_else(|e| panic!("`{line}` refused: {e}"))
}

#[test]
fn the_modal_state_carries_from_line_to_line() {
    let s = setup();
    let mut mdi = Mdi::new(&s);
    mdi.at([0.0, 0.0, 50.0], VERTICAL);
    take(&mut mdi, "G21 G90");
    assert_eq!(ends(&take(&mut mdi, "G0 X1 Y2 Z3")), [[1.0, 2.0, 3.0]]);
    take(&mut mdi, "G91");
    assert_eq!(ends(&take(&mut mdi, "G0 X1")), [[2.0, 2.0, 3.0]]);
    // The modal motion and feed carry too.
    take(&mut mdi, "G1 Y1 F300");
    let out = take(&mut mdi, "Z-1");
    assert_eq!(ends(&out), [[2.0, 3.0, 2.0]]);
    match &out[..] {
        [Entry::Block(i, Block::Linear(m))] => {
            assert_eq!(*i, 3, "blocks count on over the session");
            assert!(!m.rapid);
            assert_eq!(m.feed_mm_min, 300.0);
            assert_eq!(m.pos.line, 6, "the session's line");
        }
        other => panic!("{other:?}"),
    }
    take(&mut mdi, "G20 G90");
    assert_eq!(ends(&take(&mut mdi, "G0 X1")), [[25.4, 3.0, 2.0]]);
    assert_eq!(mdi.taken(), 8);
    assert_eq!(mdi.blocks(), 5);
}

#[test]
fn a_refused_line_changes_nothing() {
    let s = setup();
    let mut mdi = Mdi::new(&s);
    mdi.at([0.0, 0.0, 50.0], VERTICAL);
    take(&mut mdi, "G91 #<depth>=5");
    // Each sets modes or parameters before its error.
    let refused = [
        "G90 G20 #<depth>=7 G0 X[1/0]",
        "G90 G18 G0 X#<never_set>",
        "#<depth>=9 G90 G55 G0 X1",
        "G90 G0 X1 G1 Y1",
        "G90 M30",
        "G90 #<depth>=8 o7 if [1]",
        "G90 G41 G1 X5 F100",
    ];
    for line in refused {
        let err = mdi.line(line).expect_err(line);
        assert!(err.to_string().contains(line), "{err}");
    }
    // Still G91, mm, G17, depth 5, the tool where it was.
    assert_eq!(ends(&take(&mut mdi, "G0 X#<depth>")), [[5.0, 0.0, 50.0]]);
    let out = take(&mut mdi, "G2 X5 I2.5 F100");
    match &out[..] {
        [Entry::Block(_, Block::Nurbs(b))] => {
            assert_eq!(b.ctrl.last(), Some(&[10.0, 0.0, 50.0]))
        }
        other => panic!("an arc in G17: {other:?}"),
    }
    assert_eq!(mdi.taken(), 3);
}

#[test]
fn each_refusal_says_why_and_names_the_sessions_line() {
    let s = setup();
    let mut mdi = Mdi::new(&s);
    mdi.at([0.0, 0.0, 50.0], VERTICAL);
    let cases: [(&str, &str); 9] = [
        ("M30", "ends a program"),
        ("o100 sub", "subroutine is defined"),
        ("o101 while [1 LT 2]", "O-word block"),
        (
            "G06.2 P4 K0 X0 Y0 Z50 F100",
            "NURBS or spline block takes its control points",
        ),
        ("G41 G1 X1 F100", "cutter radius compensation"),
        ("%", "tape"),
        ("G0 X1 \\", "continued"),
        ("G0 X1\nG0 X2", "more than one line"),
        ("G0 X1 Q", ""),
    ];
    for (i, (line, why)) in cases.iter().enumerate() {
        let err = mdi.line(line).expect_err(line).to_string();
        assert!(err.contains(why), "{line}: {err}");
        assert!(
            err.starts_with(&format!("MDI line {}", i + 1)),
            "{line}: {err}"
        );
    }
    let long = format!("G0 X1 ({})", "c".repeat(250));
    let err = mdi.line(&long).expect_err("long").to_string();
    assert!(err.contains("longer than 255"), "{err}");
    // After all that, a plain move from where the tool stands.
    assert_eq!(ends(&take(&mut mdi, "G0 X1")), [[1.0, 0.0, 50.0]]);
    assert_eq!(mdi.taken(), 1);
}

#[test]
fn a_jog_between_lines_moves_the_start() {
    let s = setup();
    let mut mdi = Mdi::new(&s);
    mdi.at([0.0, 0.0, 50.0], VERTICAL);
    take(&mut mdi, "G91");
    mdi.at([10.0, 20.0, 30.0], VERTICAL);
    mdi.at([11.0, 20.0, 30.0], VERTICAL);
    assert_eq!(ends(&take(&mut mdi, "G0 X1")), [[12.0, 20.0, 30.0]]);
    // A refusal after the jog rebuilds the session with the jog in it.
    mdi.line("G0 X[1/0]").expect_err("refused");
    assert_eq!(ends(&take(&mut mdi, "G0 Y1")), [[12.0, 21.0, 30.0]]);
    mdi.at(
        [0.0, 0.0, 40.0],
        Orientation::Angles {
            r1_deg: 10.0,
            r2_deg: 20.0,
        },
    );
    mdi.line("G0 X[1/0]").expect_err("refused");
    let out = take(&mut mdi, "G0 Z1");
    match &out[..] {
        [Entry::Block(_, Block::Linear(m))] => {
            assert_eq!(m.end, [0.0, 0.0, 41.0]);
            assert_eq!(
                m.orientation,
                Orientation::Angles {
                    r1_deg: 10.0,
                    r2_deg: 20.0
                }
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn without_a_position_a_move_needs_the_reference() {
    let s = setup();
    let mut mdi = Mdi::new(&s);
    let err = mdi.line("G0 X1").expect_err("no start").to_string();
    assert!(err.contains("MDI line 1 `G0 X1`"), "{err}");
    let s = Setup {
        reference: Some([0.0, 0.0, 100.0]),
        ..setup()
    };
    let mut mdi = Mdi::new(&s);
    let out = take(&mut mdi, "G0 X1");
    assert_eq!(ends(&out), [[0.0, 0.0, 100.0], [1.0, 0.0, 100.0]]);
}

#[test]
fn actions_come_with_their_line() {
    let s = setup();
    let mut mdi = Mdi::new(&s);
    mdi.at([0.0, 0.0, 50.0], VERTICAL);
    let out = take(&mut mdi, "S1000 M3 M8");
    assert!(
        out.iter().any(|e| matches!(
            e,
            Entry::Action(Action {
                kind: ActionKind::Coolant(_),
                ..
            })
        )),
        "{out:?}"
    );
    let out = take(&mut mdi, "G4 P0.5");
    assert!(!out.is_empty(), "a dwell is an action: {out:?}");
    // It is the line's own: the next line's move does not wait, not even after a refusal
    // rebuilt the session from its lines.
    mdi.line("G0 X[1/0]").expect_err("refused");
    let out = take(&mut mdi, "G0 X1");
    match &out[..] {
        [Entry::Block(_, Block::Linear(m))] => {
            assert_eq!(m.tooling.wait, nc_geom::program::Wait::default())
        }
        other => panic!("{other:?}"),
    }
    // A dwell before a move on its line holds that move.
    let out = take(&mut mdi, "G4 P0.5 G0 X2");
    match &out[..] {
        [.., Entry::Block(_, Block::Linear(m))] => assert_eq!(m.tooling.wait.dwell_s, 0.5),
        other => panic!("{other:?}"),
    }
}

/// Any text, any order of lines and positions: never a panic, and a refused line never
/// counts as taken.
#[test]
fn any_text_is_taken_or_refused() {
    use proptest::prelude::*;
    let words = prop::sample::select(vec![
        "G0",
        "G1",
        "G2",
        "G3",
        "G90",
        "G91",
        "G20",
        "G21",
        "G17",
        "G18",
        "X1",
        "Y-2",
        "Z3.5",
        "I1",
        "J1",
        "K1",
        "F100",
        "M3",
        "M30",
        "S500",
        "#1=2",
        "#<a>=[#1*2]",
        "X#<a>",
        "o1",
        "if",
        "sub",
        "[1/0]",
        "Q",
        "G41",
        "G40",
        "%",
        "\\",
        "(c)",
        "G06.2",
        "P4",
        "R1",
        "G4",
        "P1",
        "M6",
        "T1",
        "G43",
        "H1",
        "G54",
        "G55",
        "G92",
        "G28",
    ]);
    let line = prop::collection::vec(words, 0..6).prop_map(|w| w.join(" "));
    let session = prop::collection::vec(
        prop_oneof![
            line.prop_map(Some),
            Just(None), // a jog
        ],
        1..12,
    );
    let s = setup();
    proptest!(ProptestConfig::with_cases(2000), |(steps in session)| {
        let mut mdi = Mdi::new(&s);
        mdi.at([0.0, 0.0, 50.0], VERTICAL);
        let mut taken = 0;
        for (i, step) in steps.iter().enumerate() {
            match step {
                Some(line) => taken += usize::from(mdi.line(line).is_ok()),
                None => mdi.at([i as f64, 0.0, 50.0], VERTICAL),
            }
        }
        prop_assert_eq!(mdi.taken(), taken);
    });
}

#[test]
fn a_line_refused_downstream_is_taken_back() {
    let s = setup();
    let mut mdi = Mdi::new(&s);
    assert!(!mdi.take_back(), "nothing to take back");
    mdi.at([0.0, 0.0, 50.0], VERTICAL);
    take(&mut mdi, "G91 #<step>=2");
    // The planner refuses this one (say, over the travel): its G90 and #<step> go with it.
    take(&mut mdi, "G90 #<step>=900 G0 X#<step>");
    mdi.at([3.0, 0.0, 50.0], VERTICAL);
    assert!(mdi.take_back());
    assert_eq!(mdi.taken(), 1);
    assert_eq!(ends(&take(&mut mdi, "G0 X#<step>")), [[5.0, 0.0, 50.0]]);
}

#[test]
fn a_program_after_the_session_starts_in_its_state() {
    let s = setup();
    let mut mdi = Mdi::new(&s);
    mdi.at([1.0, 2.0, 50.0], VERTICAL);
    take(&mut mdi, "G20 G91 #<d>=2 F10");
    take(&mut mdi, "G0 Y1");
    let program = mdi.into_program(crate::StrLines::new("G1 X#<d>\nG90 G21 G0 X0\nM30\n"));
    let got: Vec<Entry> = program.map(|e| e.expect("read")).collect();
    match &got[..] {
        [Entry::Block(0, Block::Linear(a)), Entry::Block(1, Block::Linear(b))] => {
            // Inches, incremental, the feed and #<d> from the session; from where it stood.
            assert_eq!(a.end, [1.0 + 50.8, 2.0 + 25.4, 50.0]);
            assert_eq!(a.feed_mm_min, 254.0);
            assert_eq!(a.pos.line, 1, "the program's own lines");
            assert_eq!(b.end, [0.0, 27.4, 50.0]);
        }
        other => panic!("{other:?}"),
    }
}
