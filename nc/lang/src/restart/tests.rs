use super::*;
use crate::parse;
use nc_geom::program::SrcPos;

const KIN: MachineKinematics = MachineKinematics::Paper;

/// The machine standing at X0 Y0 Z50 (workpiece = machine frame on the paper's machine),
/// the tool vertical, no tool length.
const UP_HIGH: Standing = Standing {
    joints: [0.0, 0.0, 50.0, 0.0, 0.0],
    tool_length: 0.0,
};

const JOB: &str = "G21 G90 G17
T3 M6
S1200 M3
M8
G0 X0 Y0 Z5
G1 Z-1 F300
G1 X10
M0
G1 Y10
M9
G1 X0
M30
";

const LIMITS: BuildLimits = BuildLimits {
    rapid_mm_s: 100.0,
    max_feed_mm_s: 100.0,
    rotary: nc_geom::kinematics::RotaryLimits::UNLIMITED,
};

fn go(
    p: &Program,
    line: u32,
    standing: &Standing,
    clearance: f64,
) -> Result<Restart, RestartError> {
    from_line(p, line, &KIN, &LIMITS, standing, clearance)
}

fn end(b: &Block) -> [f64; 3] {
    match b {
        Block::Linear(l) => l.end,
        Block::Nurbs(n) => *n.ctrl.last().unwrap(),
    }
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-9)
}

#[test]
fn the_blocks_from_the_line_on_are_the_programs_and_the_state_is_restored() {
    let p = parse(JOB).unwrap();
    let r = go(&p, 9, &UP_HIGH, 10.0).unwrap();
    assert_eq!((r.asked, r.line, r.block), (9, 9, 3));
    // The same blocks, but the first's wait for the M00 on line 8, skipped.
    let mut kept = p.blocks[3..].to_vec();
    set_wait(&mut kept[0], Wait::default());
    assert_eq!(r.program.blocks[4..], kept);
    // Up 10 mm from where it stands, over to 10 mm above X10 Z-1, down at F300.
    assert!(close(r.approach[0], [0.0, 0.0, 60.0]), "{:?}", r.approach);
    assert!(close(r.approach[1], [10.0, 0.0, 9.0]), "{:?}", r.approach);
    assert!(close(r.approach[2], [10.0, 0.0, -1.0]), "{:?}", r.approach);
    let moves: Vec<_> = r.program.blocks[..4].iter().map(end).collect();
    assert!(close(moves[0], [0.0, 0.0, 50.0]));
    assert_eq!(&moves[1..], &r.approach[..]);
    let Block::Linear(plunge) = &r.program.blocks[3] else {
        panic!("{:?}", r.program.blocks[3]);
    };
    assert!(!plunge.rapid && plunge.feed_mm_min == 300.0, "{plunge:?}");
    // The spindle at 1200 clockwise, the flood coolant, tool 3: restored before the move
    // over; the M00 on line 8, before the restart line, skipped; the M09 kept in its place.
    assert_eq!(r.modal.aux.spindle_rpm, 1200.0);
    assert!(r.modal.aux.flood && !r.modal.aux.mist);
    assert_eq!(r.modal.tool, Some(3));
    // Each restored where the program set it: the spindle on line 3, the flood on 4.
    let at: Vec<u32> = r.program.actions.iter().map(|a| a.pos.line).collect();
    assert_eq!(at, [3, 4, 10]);
    let kinds: Vec<_> = r
        .program
        .actions
        .iter()
        .map(|a| (a.before_block, a.kind))
        .collect();
    assert_eq!(
        kinds,
        [
            (
                2,
                ActionKind::Spindle {
                    dir: Spindle::Cw,
                    rpm: 1200.0
                }
            ),
            (2, ActionKind::Coolant(Coolant::Flood)),
            (5, ActionKind::Coolant(Coolant::Off)),
        ]
    );
    assert!(r
        .program
        .blocks
        .iter()
        .all(|b| tooling_of(b).wait == Wait::default()));
}

#[test]
fn a_line_without_a_move_restarts_on_the_next_and_keeps_its_stop() {
    let p = parse(JOB).unwrap();
    let r = go(&p, 8, &UP_HIGH, 10.0).unwrap();
    assert_eq!((r.asked, r.line, r.block), (8, 9, 3));
    // The M00 on line 8 is at or after the line asked: the tool waits for the operator
    // above the restart point, before it comes down.
    let over = tooling_of(&r.program.blocks[2]).wait;
    assert_eq!(over.operator, Some(SrcPos { line: 8, col: 1 }), "{over:?}");
    assert!(r
        .program
        .actions
        .iter()
        .any(|a| a.kind == ActionKind::Stop && a.before_block == 2));
}

#[test]
fn a_restart_on_the_first_move_comes_down_onto_the_start() {
    let p = parse(JOB).unwrap();
    let r = go(&p, 1, &UP_HIGH, 5.0).unwrap();
    assert_eq!((r.line, r.block), (5, 0));
    assert!(close(r.approach[2], [0.0, 0.0, 5.0]));
    assert_eq!(r.program.blocks[4..], p.blocks[1..]);
    // Everything before the first move is kept as the program wrote it, the tool change
    // (which waits for the operator) included.
    assert_eq!(r.program.actions.len(), p.actions.len());
    assert!(tooling_of(&r.program.blocks[2]).wait.operator.is_some());
}

#[test]
fn the_tool_backs_off_along_its_own_axis_and_comes_down_along_the_restart_axis() {
    let src = "G0 X0 Y0 Z5 A0 C0\nG1 X10 A30 C90 F500\nG1 X20\nM30\n";
    let p = parse(src).unwrap();
    let standing = Standing {
        joints: [5.0, 0.0, 20.0, 45f64.to_radians(), 0.0],
        tool_length: 0.0,
    };
    let r = go(&p, 3, &standing, 8.0).unwrap();
    let axis = |a: f64, c: f64| KIN.tool_axis(a.to_radians(), c.to_radians());
    let here = Vector3::new(5.0, 0.0, 20.0);
    let up = Vector3::from(r.approach[0]);
    assert!(((up - here) - axis(45.0, 0.0) * 8.0).norm() < 1e-9, "{up}");
    let (above, target) = (Vector3::from(r.approach[1]), Vector3::from(r.approach[2]));
    assert!(((above - target) - axis(30.0, 90.0) * 8.0).norm() < 1e-9);
    assert!(close(r.approach[2], [10.0, 0.0, 5.0]));
}

#[test]
fn a_canned_cycle_line_is_one_restart_point() {
    let src = "G0 X0 Y0 Z10\nG81 X5 Y5 Z-3 R2 F200\nX10\nG80\nG0 Z20\nM30\n";
    let p = parse(src).unwrap();
    let r = go(&p, 3, &UP_HIGH, 10.0).unwrap();
    let first = p.blocks.iter().position(|b| b.pos().line == 3).unwrap();
    assert_eq!(r.block, first);
    assert!(
        p.blocks[first + 1].pos().line == 3,
        "one line, several moves"
    );
    assert_eq!(r.program.blocks[4..], p.blocks[first..]);
}

#[test]
fn what_is_not_one_point_of_the_program_is_refused() {
    let p = parse(JOB).unwrap();
    assert_eq!(
        go(&p, 12, &UP_HIGH, 10.0),
        Err(RestartError::PastTheEnd { line: 12, last: 11 })
    );
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1000.5] {
        assert!(matches!(
            go(&p, 9, &UP_HIGH, bad),
            Err(RestartError::Clearance { .. })
        ));
    }
    let looped = "G0 X0 Y0 Z5\n#1=0\no100 while [#1 lt 3]\nG1 X[#1] F100\n#1=[#1+1]\no100 endwhile\nG1 Y5\nM30\n";
    let p = parse(looped).unwrap();
    let e = go(&p, 4, &UP_HIGH, 10.0).unwrap_err();
    assert_eq!(e, RestartError::Repeated { line: 4 });
    assert!(
        e.to_string().contains("restart from a line outside it"),
        "{e}"
    );
    // So is a line of a subroutine, called once, and one of a loop body without a move.
    let called = "o<side> sub
G1 X10 F100
o<side> endsub
G0 X0 Y0 Z5
o<side> call
G1 Y5
M30
";
    let p2 = parse(called).unwrap();
    let e = go(&p2, 2, &UP_HIGH, 10.0).unwrap_err();
    assert_eq!(e, RestartError::Repeated { line: 2 });
    assert_eq!(go(&p2, 6, &UP_HIGH, 10.0).unwrap().line, 6);
    // After the loop, a restart is one point again.
    assert_eq!(go(&p, 7, &UP_HIGH, 10.0).unwrap().line, 7);
    let nurbs = "G0 X0 Y0 Z0\nG06.2 P3 K0 X0 Y0 Z0 R1 F600\nK0 X10 Y10 Z0 R1\nK0 X20 Y0 Z0 R1\nK1 X30 Y10 Z0 R1\nK1\nK1\nK1\nG1 X40\nM30\n";
    let p = parse(nurbs).unwrap();
    let e = go(&p, 4, &UP_HIGH, 10.0).unwrap_err();
    assert_eq!(e, RestartError::InsideNurbs { line: 4, opened: 2 });
    assert!(e.to_string().contains("restart from line 2"), "{e}");
    let r = go(&p, 2, &UP_HIGH, 10.0).unwrap();
    assert_eq!(r.program.blocks[4..], p.blocks[1..]);
}

#[test]
fn the_lines_run_again_are_kept_as_ranges() {
    use crate::interp::note_line;
    let mut r = Vec::new();
    for line in [5, 6, 7, 5, 6, 7, 20, 9, 8, 21, 19, 30, 7] {
        note_line(&mut r, line);
    }
    assert_eq!(r, [(5, 9), (19, 21), (30, 30)]);
    note_line(&mut r, 10);
    note_line(&mut r, 18);
    note_line(&mut r, 11);
    note_line(&mut r, 12);
    note_line(&mut r, 13);
    note_line(&mut r, 14);
    note_line(&mut r, 15);
    note_line(&mut r, 16);
    note_line(&mut r, 17);
    assert_eq!(r, [(5, 21), (30, 30)]);
    note_line(&mut r, u32::MAX);
    assert_eq!(r, [(5, 21), (30, 30), (u32::MAX, u32::MAX)]);
}

#[test]
fn the_approach_turns_c_to_where_the_whole_run_has_it_turns_included() {
    // C wound twice round before line 4: the program's C730 there turns it 10 degrees,
    // so the tool must come down with C at 720, not at 0 where the tool axis is the same.
    let src = "G0 X0 Y0 Z5 A0 C0\nG1 A20 C360 F500\nG1 C720\nG1 X10 C730\nM30\n";
    let p = parse(src).unwrap();
    let r = go(&p, 4, &UP_HIGH, 5.0).unwrap();
    for b in &r.program.blocks[2..4] {
        let Block::Linear(l) = b else { panic!("{b:?}") };
        match l.orientation {
            Orientation::Angles { r1_deg, r2_deg } => {
                assert!(
                    (r1_deg - 20.0).abs() < 1e-9 && (r2_deg - 720.0).abs() < 1e-9,
                    "{l:?}"
                );
            }
            o => panic!("{o:?}"),
        }
    }
}

#[test]
fn a_program_of_one_move_restarts_onto_its_start_and_ends_there() {
    let p = parse("G0 X1 Y2 Z3\nM30\n").unwrap();
    let r = go(&p, 1, &UP_HIGH, 10.0).unwrap();
    assert_eq!(r.program.blocks.len(), 4);
    assert!(close(r.approach[2], [1.0, 2.0, 3.0]));
    let Block::Linear(down) = &r.program.blocks[3] else {
        panic!()
    };
    assert!(down.rapid, "no feed in effect: {down:?}");
    assert!(matches!(
        go(&p, 2, &UP_HIGH, 10.0),
        Err(RestartError::PastTheEnd { line: 2, last: 1 })
    ));
    assert_eq!(
        go(&parse("M30\n").unwrap(), 1, &UP_HIGH, 10.0),
        Err(RestartError::NoMoves)
    );
}

/// Any line, clearance and standing: a restart or a refusal, never a panic; a restart's
/// blocks from the line on are the program's, its approach finite.
mod generated {
    use super::*;
    use proptest::prelude::*;

    const PROGRAMS: [&str; 4] = [
        JOB,
        "G0 X0 Y0 Z10\nG81 X5 Y5 Z-3 R2 F200\nX10\nG80\nG0 Z20\nM30\n",
        "G0 X0 Y0 Z5\n#1=0\no100 while [#1 lt 3]\nG1 X[#1] F100\n#1=[#1+1]\no100 endwhile\nG1 Y5\nM30\n",
        "G0 X0 Y0 Z0 A0 C0\nG06.2 P3 K0 X0 Y0 Z0 R1 F600\nK0 X10 Y10 Z0 R1\nK0 X20 Y0 Z0 R1\nK1 X30 Y10 Z0 R1\nK1\nK1\nK1\nG1 X40 A30 C400\nG2 X50 R5 C-30\nM30\n",
    ];

    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            -1e3..1e3f64,
            Just(0.0),
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(-1e300),
            Just(1e300),
        ]
    }

    #[test]
    fn a_restart_or_a_refusal() {
        let cases = (
            0..PROGRAMS.len(),
            prop_oneof![0..40u32, Just(u32::MAX)],
            value(),
            proptest::array::uniform5(value()),
            value(),
        );
        let mut runner =
            test_support::generated::seeded_runner(ProptestConfig::with_cases(2000), 55);
        runner
            .run(&cases, |(which, line, clearance, joints, tool_length)| {
                let p = parse(PROGRAMS[which]).unwrap();
                let standing = Standing {
                    joints,
                    tool_length,
                };
                if let Ok(r) = go(&p, line, &standing, clearance) {
                    let first = r.block.max(1);
                    let (ours, theirs) = (
                        5.min(r.program.blocks.len()),
                        (first + 1).min(p.blocks.len()),
                    );
                    prop_assert_eq!(&r.program.blocks[ours..], &p.blocks[theirs..]);
                    prop_assert!(r.approach.iter().flatten().all(|x| x.is_finite()));
                    prop_assert!(clearance > 0.0 && joints.iter().all(|x| x.is_finite()));
                }
                Ok(())
            })
            .unwrap();
    }
}
