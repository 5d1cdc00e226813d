//! `M62`..`M68` and machine-defined M-codes: recorded as actions before the next move,
//! within the machine's `[io]`, each error with its column.

use super::at;
use crate::{parse_with, InterpError as I, Io, ParseErrorKind as E, Setup};
use nc_geom::program::{ActionKind as A, Input, UserAction, WaitMode};

fn setup() -> Setup {
    let mut s = Setup {
        io: Io {
            digital_outputs: 4,
            digital_inputs: 4,
            analog_outputs: 2,
            analog_inputs: 2,
        },
        ..Setup::default()
    };
    s.user_mcodes.insert(428, UserAction::TcpOn);
    s.user_mcodes.insert(429, UserAction::TcpOff);
    s.user_mcodes.insert(100, UserAction::Ignore);
    s.user_mcodes.insert(101, UserAction::Stop);
    s
}

fn fails(src: &str) -> (E, u32, u32) {
    let e = parse_with(src, &setup()).expect_err(src);
    let first = e.errors[0];
    (first.kind, first.pos.line, first.pos.col)
}

#[test]
fn outputs_and_waits_are_actions_before_the_next_move() {
    let src = "G0 X0 Y0 Z0\nM62 P1\nG1 X1 F100 M63 P2\nM65 P3\nM66 P0 L3 Q5\nM68 E1 Q2.5\nM67 E0 Q-1\nM66 E1\nG1 X2\nM2";
    let p = parse_with(src, &setup()).unwrap();
    let kinds: Vec<(A, usize)> = p.actions.iter().map(|a| (a.kind, a.before_block)).collect();
    assert_eq!(
        kinds,
        [
            (
                A::DigitalOutput {
                    index: 1,
                    on: true,
                    synced: true
                },
                1
            ),
            (
                A::DigitalOutput {
                    index: 2,
                    on: false,
                    synced: true
                },
                1
            ),
            (
                A::DigitalOutput {
                    index: 3,
                    on: false,
                    synced: false
                },
                2
            ),
            (
                A::WaitInput {
                    input: Input::Digital(0),
                    mode: WaitMode::High,
                    timeout_s: 5.0
                },
                2
            ),
            (
                A::AnalogOutput {
                    index: 1,
                    value: 2.5,
                    synced: false
                },
                2
            ),
            (
                A::AnalogOutput {
                    index: 0,
                    value: -1.0,
                    synced: true
                },
                2
            ),
            (
                A::WaitInput {
                    input: Input::Analog(1),
                    mode: WaitMode::Immediate,
                    timeout_s: 0.0
                },
                2
            ),
        ]
    );
    assert_eq!(p.blocks.len(), 3);
}

#[test]
fn io_beyond_the_machine_or_shared_words_are_refused_with_the_column() {
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nM62 P4\nM2"),
        (E::NoSuchIo { count: 4, .. }, 2, 5)
    ));
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nM64\nM2"),
        (E::IoWordMissing { letter: 'P', .. }, 2, 1)
    ));
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nM68 E0\nM2"),
        (E::IoWordMissing { letter: 'Q', .. }, 2, 1)
    ));
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nG4 P1 M64 P2\nM2").0,
        E::RepeatedWord { .. } | E::WordShared { .. }
    ));
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nG64 P0.1 M64 P2\nM2").0,
        E::RepeatedWord { .. } | E::WordShared { .. }
    ));
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nM66 E0 L1\nM2"),
        (E::AnalogWait { mode: 1 }, 2, 1)
    ));
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nM66 P0 L7\nM2"),
        (E::BadWaitMode { .. }, 2, 8)
    ));
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nM66 P0 L1 Q-1\nM2"),
        (E::BadWaitTimeout { .. }, 2, 11)
    ));
    assert!(matches!(
        fails("G0 X0 Y0 Z0\nM66 P0 L1 Q2\n#1=#5399\nM2").0,
        E::Interp(I::InputUnknown)
    ));
    // LinuxCNC: "Zero timeout with wait type != immediate return".
    for src in [
        "G0 X0 Y0 Z0\nM66 P0 L3\nM2",
        "G0 X0 Y0 Z0\nM66 P0 L2 Q0\nM2",
    ] {
        assert!(
            matches!(fails(src), (E::ZeroWaitTimeout { .. }, 2, 1)),
            "{src}"
        );
    }
    // E belongs to M66..M68 only.
    assert!(matches!(
        fails("G0 X0 Y0 Z0 E1\nM2"),
        (E::WordNotAllowed { letter: 'E', .. }, 1, 13)
    ));
    // A machine without [io] has no outputs.
    let e = parse_with("G0 X0 Y0 Z0\nM62 P0\nM2", &Setup::default()).unwrap_err();
    assert!(matches!(e.errors[0].kind, E::NoSuchIo { count: 0, .. }));
    assert!(e.errors[0].to_string().contains("[io]"), "{}", e.errors[0]);
}

#[test]
fn machine_defined_m_codes_do_what_the_machine_file_says() {
    let src = "M428\nG0 X0 Y0 Z0 A0 C0\nG1 X1 A10 F100\nG1 A0\nM429\nG1 X2\nM100\nM101\nG1 X3\nM2";
    let p = parse_with(src, &setup()).unwrap();
    let users: Vec<(u32, UserAction)> = p
        .actions
        .iter()
        .filter_map(|a| match a.kind {
            A::UserM { code, action } => Some((code, action)),
            _ => None,
        })
        .collect();
    assert_eq!(
        users,
        [
            (428, UserAction::TcpOn),
            (429, UserAction::TcpOff),
            (100, UserAction::Ignore),
            (101, UserAction::Stop)
        ]
    );
    // M101 stops the path for the operator before the next move.
    let last = super::linear(p.blocks.last().unwrap());
    assert_eq!(last.tooling.wait.operator, Some(at(8, 1)));
    // With TCP off, a move that turns the table is refused where it stands.
    let (kind, line, _) = fails("G0 X0 Y0 Z0 A0 C0\nM429\nG1 X1 A10 F100\nM2");
    assert!(matches!(kind, E::TcpOffTurned { code: 429, .. }), "{kind}");
    assert_eq!(line, 3);
    // An M-code the machine does not define is refused, naming [mcodes].
    let (kind, line, col) = fails("G0 X0 Y0 Z0\nM200\nM2");
    assert!(matches!(kind, E::UnsupportedMCode { .. }));
    assert_eq!((line, col), (2, 1));
    assert!(kind.to_string().contains("[mcodes]"), "{kind}");
}

#[test]
fn a_machine_defined_output_or_wait_is_the_action_its_m62_or_m66_would_be() {
    let mut s = setup();
    s.user_mcodes
        .insert(110, UserAction::Output { index: 3, on: true });
    let wait = UserAction::Wait {
        input: 1,
        mode: WaitMode::Fall,
        timeout_s: 2.0,
    };
    s.user_mcodes.insert(111, wait);
    s.user_mcodes
        .insert(112, UserAction::Output { index: 9, on: true });
    let p = parse_with("G0 X0 Y0 Z0\nM110\nM111\nG1 X1 F100\nM2", &s).unwrap();
    let kinds: Vec<A> = p.actions.iter().map(|a| a.kind).collect();
    assert_eq!(
        kinds,
        [
            A::UserM {
                code: 110,
                action: UserAction::Output { index: 3, on: true }
            },
            A::DigitalOutput {
                index: 3,
                on: true,
                synced: true
            },
            A::UserM {
                code: 111,
                action: wait
            },
            A::WaitInput {
                input: Input::Digital(1),
                mode: WaitMode::Fall,
                timeout_s: 2.0
            },
        ]
    );
    // Beyond the machine's outputs: refused where it stands.
    let e = parse_with("G0 X0 Y0 Z0\nM112\nM2", &s).expect_err("P9 of 4");
    assert!(matches!(e.errors[0].kind, E::NoSuchIo { count: 4, .. }));
    assert_eq!(e.errors[0].pos, at(2, 1));
}

#[test]
fn tcp_on_makes_g43_place_the_tool_tip_and_g53_turns_the_table() {
    use nc_geom::program::{LengthMode, Orientation};
    let mut s = setup();
    s.tools.insert(1, 50.0);
    s.kinematics = Some(nc_geom::kinematics::MachineKinematics::Paper);
    let src = "M428\nG0 X0 Y0 Z0 A0 C0\nG43 H1 G0 Z10\nG1 X1 A10 F100\nG53 G0 Z80 A0 C0\nM2";
    let p = parse_with(src, &s).unwrap();
    let modes: Vec<LengthMode> = p
        .blocks
        .iter()
        .map(|b| super::linear(b).tooling.mode)
        .collect();
    assert_eq!(modes[1..], [LengthMode::Rtcp; 3]);
    // G53 Z80 A0 C0: the table back to 0 and the spindle at machine Z 80 (tip 30 below).
    let last = super::linear(p.blocks.last().unwrap());
    assert_eq!(last.end, [1.0, 0.0, 30.0]);
    assert_eq!(
        last.orientation,
        Orientation::Angles {
            r1_deg: 0.0,
            r2_deg: 0.0
        }
    );
    // Without M428, G43 is the posts' reading for the table at 0 (refused tilted later).
    let p = parse_with(&src[5..], &s).unwrap();
    assert_eq!(super::linear(&p.blocks[1]).tooling.mode, LengthMode::Length);
}
