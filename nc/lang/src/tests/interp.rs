//! The interpreter: parameters, the order of evaluation on a line, flow control,
//! subroutines, `%` and the end of the program, as LinuxCNC's `rs274` does them (each case
//! was run through `rs274 -g`; the conformance suite in `tests/conformance.rs` compares whole
//! programs).

use super::{at, linear};
use crate::{parse, parse_with, InterpError as I, ParseErrorKind as E, Setup};
use nc_geom::program::Program;

/// The X of every move.
fn xs(p: &Program) -> Vec<f64> {
    p.blocks.iter().map(|b| linear(b).end[0]).collect()
}

fn run(src: &str) -> Vec<f64> {
    xs(&parse(src).unwrap_or_else(|e| panic!("{e}\n{src}")))
}

fn fails(src: &str) -> (E, u32, u32) {
    let e = parse(src).expect_err("the program must be rejected");
    (e.kind, e.pos.line, e.pos.col)
}

#[test]
fn expressions_read_the_parameters_from_before_the_line() {
    let src = "G0 X0 Y0 Z0\n#1=5 G0 X#1\nG0 X#1\n#1=1 #2=2 #1=#2 #2=#1\nG0 X[#1*10+#2]\nM2";
    // #1 = old #2 = 0, #2 = old #1 = 5.
    assert_eq!(run(src), [0.0, 0.0, 5.0, 5.0]);
    let src = "G0 X0 Y0 Z0\n#1=2\nG0 X[2**3 + 10 MOD 4 - ABS[-1] + [1 GT 0]] Y0\nM2";
    assert_eq!(run(src), [0.0, 8.0 + 2.0 - 1.0 + 1.0]);
    let src = "G0 X0 Y0 Z0\nG0 X[ATAN[1]/[1]] Y[SQRT[16]] Z[ROUND[2.5]]\nM2";
    let p = parse(src).unwrap();
    assert_eq!(linear(&p.blocks[1]).end, [45.0, 4.0, 3.0]);
    // Indirection, and a G code from a parameter.
    let src = "#2=7 #7=3\nG0 X0 Y0 Z0\nG0 X##2\n#3=1\nG#3 X1 F100\nM2";
    let p = parse(src).unwrap();
    assert_eq!(xs(&p), [0.0, 3.0, 1.0]);
    assert!(!linear(&p.blocks[2]).rapid);
}

#[test]
fn named_parameters_local_global_and_created_by_their_assignment() {
    let src = "#<a>=[#<a>+1]\n#<a>=[#<a>+1]\n#<_g>=3\nG0 X#<a> Y#<_g> Z[EXISTS[#<a>]]\nM2";
    let p = parse(src).unwrap();
    assert_eq!(linear(&p.blocks[0]).end, [2.0, 3.0, 1.0]);
    let (kind, line, col) = fails("G0 X#<nope> Y0 Z0\nM2");
    assert_eq!(
        kind,
        E::Interp(I::UndefinedNamed {
            name: crate::Name::new("nope")
        })
    );
    assert_eq!((line, col), (1, 5));
    // A main program's local is not visible in a subroutine.
    let src = "o<s> sub\nG0 X[EXISTS[#<x>]] Y#<_k> Z0\no<s> endsub\n#<x>=3 #<_k>=4\no<s> call\nM2";
    assert_eq!(run(src), [0.0]);
}

#[test]
fn predefined_parameters_read_the_state() {
    let src = "G0 X1 Y2 Z3\nG0 X[#5420+#<_y>] Y#<_metric> Z#<_motion_mode>\nG20\nG0 X#<_x>\nM2";
    let p = parse(src).unwrap();
    assert_eq!(linear(&p.blocks[1]).end, [3.0, 1.0, 0.0]);
    // In inches, #<_x> reads inches: X3 mm is X0.11811 in, written back unchanged.
    assert!((linear(&p.blocks[2]).end[0] - 3.0).abs() < 1e-12);
    let (kind, ..) = fails("#5420=1\nM2");
    assert!(matches!(
        kind,
        E::Interp(I::ReadOnlyParameter { number: 5420, .. })
    ));
    let (kind, ..) = fails("#<_x>=1\nM2");
    assert!(matches!(kind, E::Interp(I::ReadOnlyNamed { .. })));
    let (kind, ..) = fails("G0 X#<_x>\nM2");
    assert!(matches!(kind, E::Interp(I::PositionUnknown { .. })));
}

#[test]
fn if_elseif_else() {
    let prog = |v: i32| {
        format!(
            "G0 X0 Y0 Z0\n#1={v}\no1 if [#1 EQ 1]\nG0 X1\no1 elseif [#1 EQ 2]\nG0 X2\no1 else\nG0 X3\no1 endif\nM2"
        )
    };
    assert_eq!(run(&prog(1)), [0.0, 1.0]);
    assert_eq!(run(&prog(2)), [0.0, 2.0]);
    assert_eq!(run(&prog(7)), [0.0, 3.0]);
    // A false branch is not read: its errors do not count.
    assert_eq!(
        run("o1 if [0]\nG0 X[1/0] garbage $$\no1 endif\nG0 X1 Y0 Z0\nM2"),
        [1.0]
    );
}

#[test]
fn loops() {
    let src = "G0 X0 Y0 Z0\n#1=0\no1 while [#1 LT 3]\n#1=[#1+1]\nG0 X#1\no1 endwhile\nM2";
    assert_eq!(run(src), [0.0, 1.0, 2.0, 3.0]);
    let src = "G0 X0 Y0 Z0\n#1=0\no2 do\n#1=[#1+1]\nG0 X#1\no2 while [#1 LT 2]\nM2";
    assert_eq!(run(src), [0.0, 1.0, 2.0]);
    // repeat rounds half to even: [2.5] is 2.
    let src = "G0 X0 Y0 Z0\n#1=0\no3 repeat [2.5]\n#1=[#1+1]\nG0 X#1\no3 endrepeat\nM2";
    assert_eq!(run(src), [0.0, 1.0, 2.0]);
    let src =
        "G0 X0 Y0 Z0\n#1=0\no4 while [1]\n#1=[#1+1]\no5 if [#1 EQ 2]\no4 continue\no5 endif\n\
               o6 if [#1 GT 3]\no4 break\no6 endif\nG0 X#1\no4 endwhile\nG0 X9\nM2";
    assert_eq!(run(src), [0.0, 1.0, 3.0, 9.0]);
}

#[test]
fn a_loop_that_never_ends_is_refused_at_its_line() {
    let setup = Setup {
        max_loop_lines: 1000,
        ..Setup::default()
    };
    let e = parse_with("G0 X0 Y0 Z0\no1 while [1]\no1 endwhile\nM2", &setup).unwrap_err();
    let first = e.errors[0];
    assert!(
        matches!(first.kind, E::Interp(I::TooManyIterations { .. })),
        "{first}"
    );
    // The 1001st line run again is the `while` (lines 2 and 3 alternate from there).
    assert_eq!(first.pos, at(2, 1));
    assert_eq!(e.errors.len(), 1, "interpretation stops at a flow error");
}

#[test]
fn the_loop_budget_counts_lines_so_a_long_body_costs_what_it_runs() {
    let setup = Setup {
        max_loop_lines: 1000,
        ..Setup::default()
    };
    // 9 lines a round, the first round's new: 100 rounds run 891 lines again, 200 too many.
    let body = "#1=[#1+1]\n".repeat(8);
    let program = |rounds: u32| {
        format!("G0 X0 Y0 Z0\n#1=0\no1 repeat [{rounds}]\n{body}o1 endrepeat\nG0 X[#1/8]\nM2")
    };
    let ok = parse_with(&program(100), &setup).expect("100 rounds fit the budget");
    assert_eq!(xs(&ok), [0.0, 100.0]);
    let e = parse_with(&program(200), &setup).unwrap_err();
    assert!(matches!(
        e.errors[0].kind,
        E::Interp(I::TooManyIterations { most: 1000 })
    ));
    // Subroutine bodies count too: a sub called from a loop.
    let sub = "o<s> sub\n#1=[#1+1]\no<s> endsub\nG0 X0 Y0 Z0\n#1=0\no1 repeat [1000]\no<s> call\no1 endrepeat\nM2";
    let e = parse_with(sub, &setup).unwrap_err();
    assert!(matches!(
        e.errors[0].kind,
        E::Interp(I::TooManyIterations { .. })
    ));
}

#[test]
fn subroutines_with_arguments_and_return_values() {
    let src = "o<twice> sub\no<twice> return [#1*2]\no<twice> endsub\n\
               G0 X0 Y0 Z0\n#1=7\no<twice> call [5]\nG0 X#<_value> Y#1\nM2";
    let p = parse(src).unwrap();
    assert_eq!(
        linear(&p.blocks[1]).end,
        [10.0, 7.0, 0.0],
        "#1 restored after the call"
    );
    // Called before its definition, which stands after M2.
    let src = "G0 X0 Y0 Z0\no100 call [3]\nM2\no100 sub\nG0 X#1\no100 endsub\n";
    assert_eq!(run(src), [0.0, 3.0]);
    // Recursion ends at the call depth.
    let src = "o<r> sub\no<r> call\no<r> endsub\no<r> call\nM2";
    assert!(matches!(fails(src).0, E::Interp(I::TooManyCalls { .. })));
    // Falling into a definition the program read ahead to.
    let src = "o<a> call\no<a> sub\no<a> endsub\nM2";
    assert!(matches!(
        fails(src).0,
        E::Interp(I::DefinitionInTheWay { .. })
    ));
    let (kind, line, _) = fails("G0 X0 Y0 Z0\no<nowhere> call\nM2");
    assert!(matches!(kind, E::Interp(I::SubroutineNotFound { .. })));
    assert_eq!(line, 2);
}

#[test]
fn a_subroutine_file_from_the_subroutine_directories() {
    let dir = std::env::temp_dir().join(format!("dnurbs-subs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("hop.ngc"),
        "(header)\no<hop> sub\nG0 X#1\no<hop> endsub\nM2\n",
    )
    .unwrap();
    let setup = Setup {
        subroutine_dirs: vec![dir.join("missing"), dir.clone()],
        ..Setup::default()
    };
    let p = parse_with("G0 X0 Y0 Z0\no<hop> call [4]\nG0 X5\nM2", &setup).unwrap();
    assert_eq!(xs(&p), [0.0, 4.0, 5.0]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn labels_are_checked() {
    let src = "o10 if [1]\no10 endif\no10 if [1]\no10 endif\nM2";
    assert!(matches!(
        fails(src),
        (E::Interp(I::DuplicateLabel { line: 1, .. }), 3, 1)
    ));
    let src = "o10 if [1]\no11 endif\nM2";
    assert!(matches!(fails(src).0, E::Interp(I::UnmatchedLabel { .. })));
    let src = "o100 repeat [2]\no100 break\no100 endrepeat\nM2";
    assert!(matches!(fails(src).0, E::Interp(I::MismatchedLabel { .. })));
    let src = "G0 X0 Y0 Z0\no1 while [1]\nG0 X1\n";
    assert!(matches!(
        fails(src),
        (E::Interp(I::NotClosed { line: 2, .. }), 3, 6)
    ));
    assert!(matches!(
        fails("o<s> endsub\nM2").0,
        E::Interp(I::NotInSubroutine { .. })
    ));
}

#[test]
fn percent_lines_and_the_program_end() {
    // `%` first: a later `%` ends the program, nothing after it is read.
    assert_eq!(run("\n%\nG0 X1 Y0 Z0\n%\nG0 X$$\n"), [1.0]);
    // Without a `%` first, a `%` line is an error.
    assert_eq!(fails("G0 X1 Y0 Z0\n%\nM2").0, E::MisplacedTapeMark);
    // `% text` is no tape mark.
    assert_eq!(fails("% O1000\nM2").0, E::MisplacedTapeMark);
    // Text after M2 is not read.
    assert_eq!(run("G0 X1 Y0 Z0\nM2\nthis is not gcode\n"), [1.0]);
}

#[test]
fn spaces_anywhere_and_abort() {
    assert_eq!(run("G 0 X 1 . 5 Y- 2 Z0\nG0X  16.339\nM2"), [1.5, 16.339]);
    let (kind, line, col) = fails("G0 X0 Y0 Z0\n(ABORT, tool broken)\nG0 X1\nM2");
    assert_eq!(
        kind,
        E::Interp(I::Abort {
            message: crate::Name::new("tool broken")
        })
    );
    assert_eq!((line, col), (2, 1));
}

#[test]
fn the_tape_keeps_only_what_a_loop_may_go_back_to() {
    use crate::source::StrLines;
    use crate::stream::Entries;
    let mut src = String::from("G0 X0 Y0 Z0\n");
    for k in 0..2000 {
        src.push_str("#1=[#1+1] G1 X[#1*0.001] F100\n");
        if k == 1000 {
            src.push_str("o1 repeat [3]\nG1 X1\nG1 X2\no1 endrepeat\n");
        }
    }
    src.push_str("M2\n");
    let setup = Setup::default();
    let mut entries = Entries::new(StrLines::new(&src), &setup);
    let mut most = 0;
    while let Some(e) = entries.next() {
        e.unwrap();
        most = most.max(entries.kept_lines());
    }
    assert!(most <= 6, "kept {most} lines");
}

#[test]
fn codes_as_linuxcnc_reads_them() {
    // A dwell and a move on one line: the dwell first, X is the move's.
    let p = parse("G0 X0 Y0 Z0\nG4 P0.5 G0 X10\nM2").unwrap();
    assert_eq!(xs(&p), [0.0, 10.0]);
    assert_eq!(p.actions.len(), 1);
    // G and M values within LinuxCNC's tolerance; `G1.001` is no code.
    assert_eq!(
        run("G0.0001 X0 Y0 Z0\nG[0.1 * 10] X2 F100\nM[1 + 1]"),
        [0.0, 2.0]
    );
    assert!(matches!(
        fails("G1.001 X0 Y0 Z0").0,
        E::NotACode { letter: 'G', .. }
    ));
    // G64 P Q are accepted (dnurbs follows the programmed path), W is no axis.
    assert_eq!(run("G64 P0.01 Q0.01\nG0 X1 Y0 Z0\nM2"), [1.0]);
    let (kind, line, col) = fails("G0 X0 Y0 Z0\nG1 X1 W5 F100\nM2");
    assert_eq!((kind, line, col), (E::NoSuchAxis { letter: 'W' }, 2, 7));
    // G90.1: arc centres are coordinates (work offset applied), both of the plane's needed.
    let p = parse("G0 X10 Y0 Z0\nG90.1 G3 X-10 Y0 I0 J0 F100\nM2").unwrap();
    let nc_geom::program::Block::Nurbs(arc) = &p.blocks[1] else {
        panic!()
    };
    let mid = arc.ctrl[arc.ctrl.len() / 2];
    assert!(
        (mid[0].hypot(mid[1]) - 10.0).abs() < 1e-9 && mid[1] > 0.0,
        "{mid:?}"
    );
    let (kind, ..) = fails("G0 X10 Y0 Z0\nG90.1 G3 X-10 Y0 I0 F100\nM2");
    assert!(matches!(kind, E::MissingWord { letter: 'J', .. }));
}

#[test]
fn canned_cycles_are_refused_with_what_they_miss() {
    let start = "G0 X0 Y0 Z10\nF100 S1000 M3\n";
    let kind = |rest: &str| fails(&format!("{start}{rest}\nM2")).0;
    assert!(matches!(
        kind("G81 X1 Y1 Z-2"),
        E::MissingWord { letter: 'R', .. }
    ));
    assert!(matches!(
        kind("G81 X1 Y1 R2"),
        E::MissingWord { letter: 'Z', .. }
    ));
    assert!(matches!(
        kind("G82 X1 Y1 R2 Z-2"),
        E::MissingWord { letter: 'P', .. }
    ));
    assert!(matches!(kind("G83 X1 Y1 R2 Z-2 Q0"), E::BadPeck { .. }));
    assert!(matches!(kind("G81 X1 Y1 R2 Z-2 L0"), E::BadRepeat { .. }));
    assert!(matches!(
        kind("G81 X1 Y1 R-3 Z-2"),
        E::CycleRBelowDepth { .. }
    ));
    assert!(matches!(
        kind("M5\nG86 X1 Y1 R2 Z-2 P1"),
        E::CycleSpindleOff { .. }
    ));
    assert!(matches!(
        kind("G93 G81 X1 Y1 R2 Z-2 F1"),
        E::CycleInverseTime { .. }
    ));
    // G80 ends the cycle and the motion mode: a position alone is then an error.
    assert!(matches!(
        kind("G81 X1 Y1 R2 Z-2\nG80\nX5"),
        E::NoMotionMode { .. }
    ));
    // A G81 hole: over it at the start level, down to R, feed to Z, back up (G99: to R).
    let p = parse(&format!("{start}G81 X1 Y2 R2 Z-2\nM2")).unwrap();
    let ends: Vec<[f64; 3]> = p.blocks.iter().map(|b| linear(b).end).collect();
    let want = [
        [0.0, 0.0, 10.0],
        [1.0, 2.0, 10.0],
        [1.0, 2.0, 2.0],
        [1.0, 2.0, -2.0],
        [1.0, 2.0, 2.0],
    ];
    assert_eq!(ends, want);
    assert_eq!(
        p.blocks.iter().map(|b| linear(b).rapid).collect::<Vec<_>>(),
        [true, true, true, false, true]
    );
}

#[test]
fn g92_shifts_the_program_zero_and_its_parameters_are_in_mm() {
    // G92 X0: here is X0 from now; G92.2 suspends, G92.3 restores, G92.1 cancels.
    let src = "G0 X5 Y0 Z0\nG92 X0\nG0 X1\nG92.2\nG0 X1\nG92.3\nG0 X2\nG92.1\nG0 X2\nM2";
    assert_eq!(run(src), [5.0, 6.0, 1.0, 7.0, 2.0]);
    // Its parameters keep mm (the machine's units) in an inch program; #5210 says it is on.
    let src = "G20 G0 X1 Y0 Z0\nG92 X0\nG21 G0 X[#5211] Y[#5210]\nG92.2\nG0 Y[#5210] X[#5211]\nM2";
    let p = parse(src).unwrap();
    let ends: Vec<[f64; 3]> = p.blocks.iter().map(|b| linear(b).end).collect();
    assert_eq!(ends[1], [50.8, 1.0, 0.0]);
    assert_eq!(ends[2], [25.4, 0.0, 0.0]);
    // A work offset chosen later keeps the G92 offset on top of it.
    let setup = Setup {
        work_offsets: [
            Some([0.0; 3]),
            Some([100.0, 0.0, 0.0]),
            None,
            None,
            None,
            None,
        ],
        ..Setup::default()
    };
    let p = parse_with("G0 X5 Y0 Z0\nG92 X0\nG55 G0 X0\nM2", &setup).unwrap();
    assert_eq!(xs(&p), [5.0, 105.0]);
}

#[test]
fn g92_refuses_what_it_cannot_honour_with_the_column() {
    // A rotary offset needs the angles in effect, not a tool vector.
    let (kind, line, col) = fails("G0 X0 Y0 Z0 I0 J0.5 K1\nG92 A0\nM2");
    assert!(matches!(kind, E::OffsetRotary { axis: 'A' }), "{kind}");
    assert_eq!((line, col), (2, 5));
    let (kind, line, _) = fails("G0 X0 Y0 Z0\nG92\nM2");
    assert!(matches!(kind, E::OffsetWithoutAxes), "{kind}");
    assert_eq!(line, 2);
    let (kind, _, col) = fails("G0 X0 Y0 Z0\nG92 G1 X1 F100\nM2");
    assert!(matches!(kind, E::AxisWordsTwice { .. }), "{kind}");
    assert_eq!(col, 5);
    let (kind, _, col) = fails("G0 X0 Y0 Z0\nG92.1 X1\nM2");
    assert!(
        matches!(kind, E::WordNotAllowed { letter: 'X', .. }),
        "{kind}"
    );
    assert_eq!(col, 7);
}

#[test]
fn g43_without_h_takes_the_tool_in_the_spindle() {
    // `T1 M6 G43` (LinuxCNC's mmount.ngc): M06 comes first, so G43 takes T1's length; a
    // later G43 alone the tool loaded; none loaded is tool 0, no length.
    let mut setup = Setup {
        reference: Some([0.0, 0.0, 100.0]),
        ..Setup::default()
    };
    setup.tools.insert(1, 30.0);
    setup.tools.insert(2, 45.0);
    let src = "G43\nG0 X0 Y0 Z0\nT1 M6 G43\nG0 Z1\nT2\nG49\nG43\nG0 Z2\nM2";
    let p = parse_with(src, &setup).unwrap();
    let lengths: Vec<f64> = p
        .blocks
        .iter()
        .map(|b| linear(b).tooling.tool_length)
        .collect();
    assert_eq!(lengths, [0.0, 30.0, 30.0]);
}

#[test]
fn m72_restores_the_spindle_and_coolant_with_actions_and_needs_an_m70() {
    use nc_geom::program::{ActionKind as A, Coolant, Spindle};
    let src = "G0 X0 Y0 Z0\nS1000 M3 M8\nM70\nM5 M9\nG20 F10\nM72\nG1 X1 F100\nM2";
    let p = parse(src).unwrap();
    let after: Vec<A> = p
        .actions
        .iter()
        .filter(|a| a.pos.line == 6)
        .map(|a| a.kind)
        .collect();
    assert_eq!(
        after,
        [
            A::Spindle {
                dir: Spindle::Cw,
                rpm: 1000.0
            },
            A::Coolant(Coolant::Flood)
        ]
    );
    // Back in mm: X1 is 1 mm.
    assert_eq!(xs(&p), [0.0, 1.0]);
    let (kind, line, col) = fails("G0 X0 Y0 Z0\nM70\nM71\nM72\nM2");
    assert_eq!((kind, line, col), (E::NothingSaved, 4, 1));
}

#[test]
fn polar_coordinates_as_linuxcnc_reads_them_and_their_refusals() {
    // G90: radius and angle about the program's zero; a word left out keeps the current
    // point's. G91: added to the current point's radius and angle.
    let src = "G0 X0 Y0 Z0\nG0 @10 ^90\nG0 ^0\nG0 @5\nG91 G0 ^90\nG0 @1\nM2";
    let p = parse(src).unwrap();
    let ends: Vec<[f64; 2]> = p
        .blocks
        .iter()
        .map(|b| {
            let e = linear(b).end;
            [(e[0] * 1e9).round() / 1e9, (e[1] * 1e9).round() / 1e9]
        })
        .collect();
    assert_eq!(
        ends,
        [
            [0.0, 0.0],
            [0.0, 10.0],
            [10.0, 0.0],
            [5.0, 0.0],
            [0.0, 5.0],
            [0.0, 6.0]
        ]
    );
    let (kind, line, col) = fails("G0 X0 Y0 Z0\nG0 X1 @2\nM2");
    assert_eq!((kind, line, col), (E::PolarWithXy { letter: 'X' }, 2, 4));
    let (kind, line, col) = fails("G0 X0 Y0 Z0\nG18 G0 @2\nM2");
    assert_eq!((kind, line, col), (E::PolarPlane { letter: '@' }, 2, 8));
    let (kind, line, _) = fails("G0 X0 Y0 Z0\nG0 @2\nM2");
    assert_eq!((kind, line), (E::PolarAtOrigin { incremental: false }, 2));
    let (kind, line, _) = fails("G0 X0 Y0 Z0\nG91 G0 ^30\nM2");
    assert_eq!((kind, line), (E::PolarAtOrigin { incremental: true }, 2));
}

#[test]
fn g43_1_and_g43_2_set_and_add_tool_lengths() {
    let mut setup = Setup {
        reference: Some([0.0, 0.0, 100.0]),
        ..Setup::default()
    };
    setup.tools.insert(1, 30.0);
    let src = "G0 X0 Y0 Z0\nG43.1 Z10\nG0 Z1\nG43.2 Z5\nG0 Z2\nG43.2 H1\nG0 Z3\nG20 G43.1 Z1\nG0 Z0.2\nG49\nG0 Z4\nM2";
    let p = parse_with(src, &setup).unwrap();
    let lengths: Vec<f64> = p
        .blocks
        .iter()
        .map(|b| linear(b).tooling.tool_length)
        .collect();
    assert_eq!(lengths, [0.0, 10.0, 15.0, 45.0, 25.4, 0.0]);
    // The Z word is the offset: no move on its line, and not with a motion code.
    let (kind, line, _) = fails("G0 X0 Y0 Z0\nG43.1 X1 Z1\nM2");
    assert!(
        matches!(kind, E::WordNotAllowed { letter: 'X', .. }),
        "{kind}"
    );
    assert_eq!(line, 2);
    let (kind, _, _) = fails("G0 X0 Y0 Z0\nG1 G43.1 Z1 F100\nM2");
    assert!(matches!(kind, E::AxisWordsTwice { .. }), "{kind}");
    let (kind, _, _) = fails("G0 X0 Y0 Z0\nG43.1\nM2");
    assert!(matches!(kind, E::MissingWord { letter: 'Z', .. }), "{kind}");
}

#[test]
fn g30_goes_to_the_second_reference_position() {
    let setup = Setup {
        reference: Some([0.0, 0.0, 100.0]),
        g30: Some([10.0, 20.0, 90.0]),
        ..Setup::default()
    };
    let p = parse_with("G0 X1 Y2 Z3\nG30 Z[#5183]\nG30\nM2", &setup).unwrap();
    let ends: Vec<[f64; 3]> = p.blocks.iter().map(|b| linear(b).end).collect();
    // Through Z 90 (the line's point) to the G30 position along Z (there already: a move of
    // nothing), then along every axis.
    assert_eq!(
        ends,
        [
            [1.0, 2.0, 3.0],
            [1.0, 2.0, 90.0],
            [1.0, 2.0, 90.0],
            [10.0, 20.0, 90.0]
        ]
    );
    let (kind, line, _) = fails("G0 X0 Y0 Z0\nG30\nM2");
    assert_eq!((kind, line), (E::NoReference { code: 30.0 }, 2));
}

#[test]
fn g5_and_g5_1_are_the_bezier_curves_linuxcnc_defines() {
    use nc_geom::nurbs::DoubleNurbs;
    let src = "G0 X0 Y0 Z1\nG1 F100\nG5.1 X10 Y0 I5 J5\nG5 I2 J3 P-2 Q3 X20 Y0\nG5 P-1 Q1 X25 Y5\nG91 G5.1 X1 Y1 I1 J0\nM2";
    let p = parse(src).unwrap();
    let bezier = |pts: &[[f64; 2]], t: f64| -> [f64; 2] {
        let mut q = pts.to_vec();
        for k in (1..q.len()).rev() {
            for i in 0..k {
                q[i] = [
                    q[i][0] + t * (q[i + 1][0] - q[i][0]),
                    q[i][1] + t * (q[i + 1][1] - q[i][1]),
                ];
            }
        }
        q[0]
    };
    // Quadratic: start, start + I J, end. Cubic: start, start + I J, end + P Q, end; the
    // second G5's I J are the first's P Q negated.
    let want: [&[[f64; 2]]; 4] = [
        &[[0.0, 0.0], [5.0, 5.0], [10.0, 0.0]],
        &[[10.0, 0.0], [12.0, 3.0], [18.0, 3.0], [20.0, 0.0]],
        &[[20.0, 0.0], [22.0, -3.0], [24.0, 6.0], [25.0, 5.0]],
        &[[25.0, 5.0], [26.0, 5.0], [26.0, 6.0]],
    ];
    let curves: Vec<_> = p
        .blocks
        .iter()
        .filter_map(|b| match b {
            nc_geom::program::Block::Nurbs(n) => Some(n),
            _ => None,
        })
        .collect();
    assert_eq!(curves.len(), 4);
    for (n, pts) in curves.iter().zip(want) {
        let c =
            DoubleNurbs::new(usize::from(n.degree), &n.ctrl, &[], &n.weights, &n.knots).unwrap();
        for k in 0..=20 {
            let t = f64::from(k) / 20.0;
            let (got, w) = (c.cutter(t, 0).p, bezier(pts, t));
            assert!(
                (got.x - w[0]).abs() < 1e-12 && (got.y - w[1]).abs() < 1e-12 && got.z == 1.0,
                "{t}: {got:?} {w:?}"
            );
        }
    }
    let (kind, line, _) = fails("G0 X0 Y0 Z0\nG18 G5.1 X1 Z1 I1 K1 F100\nM2");
    assert!(
        matches!(kind, E::WordNotAllowed { .. } | E::SplinePlane { .. }),
        "{kind}"
    );
    assert_eq!(line, 2);
    let (kind, _, _) = fails("G0 X0 Y0 Z0\nG5 X1 Y1 I1 P1 Q1 F100\nM2");
    assert_eq!(kind, E::SplineWithoutIj);
    let (kind, _, _) = fails("G0 X0 Y0 Z0\nG5 X1 Y1 I1 J1 P1 F100\nM2");
    assert!(matches!(kind, E::MissingWord { letter: 'Q', .. }), "{kind}");
    let (kind, _, _) = fails("G0 X0 Y0 Z0\nG5.1 X1 Y1 I1 F100\nM2");
    assert!(matches!(kind, E::MissingWord { letter: 'J', .. }), "{kind}");
    let (kind, _, col) = fails("G0 X0 Y0 Z0\nG5.1 X1 Y1 Z2 I1 J1 F100\nM2");
    assert!(
        matches!(kind, E::WordNotAllowed { letter: 'Z', .. }),
        "{kind}"
    );
    assert_eq!(col, 12);
}

#[test]
fn g5_2_blocks_are_linuxcncs_nurbs() {
    // LinuxCNC's construction (checked against its Python interpreter's samples of these
    // two blocks: 1e-15 in): the current point first, the order 3 unless L > 3, the weights P,
    // the knots the clamped uniform integers.
    let src =
        "G20 G90 G17\nG0 X0 Y0 Z0\nF10\nG5.2 X0 Y1 P1 L3\nX2 Y2 P1\nX2 Y0 P1\nX0 Y0 P2\nG5.3\n\
               G5.2 P2 L4\nX1 Y1 P1\nX2 Y-1 P3\nX3 Y1 P1\nX4 Y0 P1\nG5.3\nG1 X5\nM2";
    let p = parse(src).unwrap();
    let curves: Vec<_> = p
        .blocks
        .iter()
        .filter_map(|b| match b {
            nc_geom::program::Block::Nurbs(n) => Some(n),
            _ => None,
        })
        .collect();
    assert_eq!(curves.len(), 2);
    let inch = |pts: &[[f64; 2]]| -> Vec<[f64; 3]> {
        pts.iter()
            .map(|p| [p[0] * 25.4, p[1] * 25.4, 0.0])
            .collect()
    };
    assert_eq!(curves[0].degree, 2);
    assert_eq!(
        curves[0].ctrl,
        inch(&[[0.0, 0.0], [0.0, 1.0], [2.0, 2.0], [2.0, 0.0], [0.0, 0.0]])
    );
    assert_eq!(curves[0].weights, [1.0, 1.0, 1.0, 1.0, 2.0]);
    assert_eq!(curves[0].knots, [0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0]);
    assert_eq!(curves[1].degree, 3);
    assert_eq!(curves[1].weights, [2.0, 1.0, 3.0, 1.0, 1.0]);
    assert_eq!(
        curves[1].knots,
        [0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0]
    );
    // After G5.3 the point is the block's last; the next move goes on from there.
    assert_eq!(linear(p.blocks.last().unwrap()).end[0], 5.0 * 25.4);
    for (src, want) in [
        ("G5.2 X1 P1\nX2 Y0 P1\nG5.3", "needs both X and Y"),
        ("G5.2 X1 Y1 P1\nX2 Y0 P0\nG5.3", "above 0"),
        ("G5.2 X1 Y1 P1\nG5.3", "fewer than the order 3"),
        ("G5.2 X1 Y1 P1\nX2 Y0 P1\nG1 X3", "not closed by G05.3"),
        ("G5.3", "without a G05.2"),
        ("G5.2 X1 Y1 P1 L7\nG5.3", "at most 6"),
        ("G5.2 X1 Y1 Z1 P1\nG5.3", "Z"),
    ] {
        let e = parse(&format!("G0 X0 Y0 Z0\nF100\n{src}\nM2")).unwrap_err();
        assert!(e.to_string().contains(want), "{src}: {e}");
    }
    // Not closed at the end of the program.
    let e = parse("G0 X0 Y0 Z0\nF100\nG5.2 X1 Y1 P1\nX2 Y0 P1").unwrap_err();
    assert!(e.to_string().contains("not closed"), "{e}");
}

#[test]
fn every_path_control_word_is_an_action_in_mm_with_linuxcnc_merge_rule() {
    use nc_geom::program::{ActionKind, Merge, PathMode};
    let src = "G20 G64 P0.001 Q0.002\nG0 X0 Y0 Z0\nG61\nG1 X1 F10\nG64 P0.004\nG61.1\n\
               G64\nG64 P0.01 Q0\nM2";
    let p = crate::parse(src).unwrap();
    let modes: Vec<(PathMode, usize, u32)> = p
        .actions
        .iter()
        .filter_map(|a| match a.kind {
            ActionKind::PathMode(m) => Some((m, a.before_block, a.pos.line)),
            _ => None,
        })
        .collect();
    let near = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-12);
    assert_eq!(modes.len(), 6, "{modes:?}");
    match modes[0].0 {
        PathMode::Blend { p_mm, q_mm } => assert!(near(p_mm, 0.0254) && near(q_mm, 0.0508)),
        m => panic!("{m:?}"),
    }
    assert!(matches!(modes[0].0.merge(), Merge::Within(q) if (q - 0.0508).abs() < 1e-12));
    // Where each stands: before the move after it.
    assert_eq!(
        modes.iter().map(|m| (m.1, m.2)).collect::<Vec<_>>(),
        [(0, 1), (1, 3), (2, 5), (2, 6), (2, 7), (2, 8)]
    );
    // Q absent: P is the naive-CAM tolerance too (LinuxCNC's rule).
    assert!(matches!(modes[2].0.merge(), Merge::Within(q) if (q - 0.1016).abs() < 1e-12));
    assert_eq!(modes[1].0.merge(), Merge::Off);
    assert_eq!(modes[3].0.merge(), Merge::Off);
    assert_eq!(modes[4].0.merge(), Merge::Machine);
    // Q0 merges nothing.
    assert_eq!(modes[5].0.merge(), Merge::Off);
    let e = crate::parse("G0 X0 Y0 Z0\nG64 P0.01 Q-1\nM2").unwrap_err();
    assert_eq!((e.pos.line, e.pos.col), (2, 11), "{e}");
    assert!(e.to_string().contains("a distance, 0 or more"), "{e}");
}

#[test]
fn an_m72_restore_brings_back_the_path_mode_as_an_action() {
    use nc_geom::program::{ActionKind, PathMode};
    let src = "G0 X0 Y0 Z0 F100\nG64 P0.02\nM70\nG61\nG1 X1\nM72\nG1 X2\nM2";
    let p = crate::parse(src).unwrap();
    let modes: Vec<(PathMode, usize)> = p
        .actions
        .iter()
        .filter_map(|a| match a.kind {
            ActionKind::PathMode(m) => Some((m, a.before_block)),
            _ => None,
        })
        .collect();
    assert_eq!(modes.len(), 3, "{modes:?}");
    assert_eq!(modes[1], (PathMode::Exact, 1));
    assert_eq!(modes[2].1, 2);
    assert_eq!(modes[2].0, modes[0].0);
}

#[test]
fn a_canned_cycle_line_makes_a_bounded_number_of_moves() {
    // Found by the fuzz target: L81115040 on a G81 line built 81 million holes' moves at
    // once (2.3 GB); a peck of 1e-9 mm over a deep hole did the same with pecks.
    for src in [
        "G0 X0 Y0 Z1\nG91 G81 X1 R0.1 Z-0.5 F600 L81115040\nM2",
        "G0 X0 Y0 Z1\nG83 X1 R0.1 Z-500 Q0.000001 F600\nM2",
    ] {
        let e = crate::parse(src).expect_err(src);
        assert_eq!(
            (e.kind, e.pos.line),
            (
                E::CycleTooLong {
                    max: crate::cycles::MAX_CYCLE_MOVES
                },
                2
            ),
            "{src}"
        );
    }
    // 10 000 holes on a line are fine.
    assert!(crate::parse("G0 X0 Y0 Z1\nG91 G81 X1 R0.1 Z-0.5 F600 L10000\nM2").is_ok());
}
