//! MDI through the planner (`nc_lang::mdi`, issue 55), on the CAM posts' five-axis
//! machine: each line a session takes becomes a program from where the machine stands
//! (`mdi::program`), is built, planned and interpolated as any program is, and must hold
//! every limit of the machine; the machine then stands where its last setpoint is, and the
//! next line starts there. A line the planner refuses (over the travel) is taken back, and
//! the session goes on as if it had never been typed.
//!
//! A hand session (tool change, spindle, feeds, an arc, incremental moves, the table tilted,
//! refused lines between) and a generated one (seeded: lines from the words an operator
//! types, junk among them).

mod common;

use dnurbs_tools::setup::MachineSetup;
use nc_geom::kinematics::Kinematics;
use nc_geom::program::Block;
use nc_lang::mdi::{self, Mdi};
use nc_lang::restart::Standing;
use nc_lang::Entry;

struct Machine {
    setup: MachineSetup,
    parse: nc_lang::Setup,
}

fn machine() -> Machine {
    let (setup, parse) = common::posts_machine();
    Machine { setup, parse }
}

/// What one line did on the machine.
#[derive(Debug, PartialEq)]
enum Outcome {
    Refused,
    TakenBack,
    Ran,
}

/// Types `line`; a line taken is planned from `standing` and run, within every limit,
/// and `standing` moves to its end.
fn type_line(m: &Machine, mdi: &mut Mdi<'_>, standing: &mut Standing, line: &str) -> Outcome {
    let Ok(out) = mdi.line(line) else {
        return Outcome::Refused;
    };
    let kin = &m.setup.kin;
    let program = mdi::program(&out, mdi.tilt_word(), standing, kin);
    let ran = match dnurbs_tools::simulate::run(&program, &m.setup, m.setup.method) {
        Ok(ran) => ran,
        Err(e) => {
            let text = e.to_string();
            assert!(
                text.contains("travel") || text.contains("axis"),
                "`{line}` refused by the planner: {text}"
            );
            if std::env::var_os("MDI_WHY").is_some() {
                eprintln!("`{line}` taken back: {text}");
            }
            assert!(mdi.take_back());
            return Outcome::TakenBack;
        }
    };
    let s = dnurbs_tools::simulate::summarize(&ran, &m.setup, program.blocks.len());
    let s = serde_json::to_value(&s).unwrap();
    if std::panic::catch_unwind(|| common::assert_within_limits(&s)).is_err() {
        panic!("`{line}`: over a limit: {s}");
    }
    let last = ran.setpoints.last().expect("a setpoint");
    let tool_length = match program.blocks.last() {
        Some(Block::Linear(b)) => b.tooling.tool_length,
        Some(Block::Nurbs(b)) => b.tooling.tool_length,
        None => standing.tool_length,
    };
    *standing = Standing {
        joints: last.joints,
        tool_length,
    };
    // The tool ends where the line's last move ends.
    let end = out.iter().rev().find_map(|e| match e {
        Entry::Block(_, Block::Linear(b)) => Some(b.end),
        Entry::Block(_, Block::Nurbs(b)) => b.ctrl.last().copied(),
        Entry::Action(_) => None,
    });
    if let Some(end) = end {
        let (tip, _) = standing.tip(kin);
        let d = (0..3)
            .map(|i| (tip[i] - end[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(d < 1e-6, "`{line}`: ends {d} mm from its end point");
        let p = kin.unplace(
            &nalgebra::Vector3::new(last.joints[0], last.joints[1], last.joints[2] - tool_length),
            last.joints[3],
            last.joints[4],
        );
        assert!(
            (p - last.p).norm() < 1e-6,
            "`{line}`: the setpoint's own tip"
        );
    }
    mdi.standing(standing, kin);
    Outcome::Ran
}

#[test]
fn an_operators_mdi_session_plans_within_the_limits_line_by_line() {
    let m = machine();
    let mut mdi = Mdi::new(&m.parse);
    let mut standing = Standing {
        joints: [0.0, 0.0, 300.0, 0.0, 0.0],
        tool_length: 0.0,
    };
    mdi.standing(&standing, &m.setup.kin);
    use Outcome::*;
    let session: [(&str, Outcome); 20] = [
        ("G21 G90 G54 G17", Ran),
        ("T1 M6", Ran),
        ("G43.4 H1", Ran),
        ("S8000 M3 M8", Ran),
        ("G0 X10 Y10", Ran),
        ("G0 X[1/0]", Refused),
        ("G0 Z120", Ran),
        ("G1 Z100 F500", Ran),
        ("G91 G1 X5 Y5", Ran),
        ("G0 X900", TakenBack),
        ("X5", Ran),
        ("G90 G2 X30 Y15 I5 J0", Ran),
        ("G41 D1 G1 X0", Refused),
        ("G0 Z150", Ran),
        ("G0 A30 C45", Ran),
        ("G1 X0 Y0 F1000", Ran),
        ("G0 A0 C0", Ran),
        ("M30", Refused),
        ("M5 M9", Ran),
        ("G0 Z200", Ran),
    ];
    for (line, want) in session {
        let got = type_line(&m, &mut mdi, &mut standing, line);
        assert_eq!(got, want, "`{line}`");
    }
    // The incremental X5 after the refused X900 went from X15: G91 held, the travel's
    // refusal took nothing with it.
    let (tip, _) = standing.tip(&m.setup.kin);
    assert!(
        (tip[0] - 0.0).abs() < 1e-6 && (tip[2] - 200.0).abs() < 1e-6,
        "{tip:?}"
    );
}

/// A 64-bit mix (splitmix64).
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// A line an operator might type, from the hash `h`: modes, moves in both distance
/// modes, rotary moves, arcs, dwells, the spindle and coolant, parameters, and junk.
fn generated_line(h: u64) -> String {
    let num = |k: u32, span: f64| {
        let x = (mix(h ^ u64::from(k)) % 10_000) as f64 / 10_000.0;
        ((x * 2.0 - 1.0) * span * 10.0).round() / 10.0
    };
    match h % 16 {
        0 => "G90".into(),
        1 => "G91".into(),
        2 => format!("G0 X{} Y{}", num(1, 150.0), num(2, 150.0)),
        3 => format!(
            "G1 Z{} F{}",
            num(3, 60.0),
            100.0 + num(4, 50.0).abs() * 20.0
        ),
        4 => format!("G0 A{} C{}", num(5, 40.0), num(6, 400.0)),
        5 => format!("G1 X{} Y{} Z{}", num(7, 30.0), num(8, 30.0), num(9, 30.0)),
        6 => format!(
            "G2 X{} Y{} R{}",
            num(10, 20.0),
            num(11, 20.0),
            15.0 + num(12, 5.0)
        ),
        7 => format!("#<d>={} G0 X#<d>", num(13, 100.0)),
        8 => format!("S{} M3", 1000 + (h >> 20) % 8000),
        9 => "M5 M9".into(),
        10 => format!("G4 P{}", ((h >> 24) % 5) as f64 / 10.0),
        11 => "G20".into(),
        12 => "G21".into(),
        13 => format!("G0 X{}", num(14, 900.0)),
        14 => "G0 X[1/0]".into(),
        _ => format!("G1 X{} F[#<never>]", num(15, 10.0)),
    }
}

#[test]
fn a_generated_mdi_session_holds_every_limit_and_takes_back_what_the_planner_refuses() {
    let m = machine();
    let mut mdi = Mdi::new(&m.parse);
    let mut standing = Standing {
        joints: [0.0, 0.0, 300.0, 0.0, 0.0],
        tool_length: 0.0,
    };
    mdi.standing(&standing, &m.setup.kin);
    let mut counts = [0usize; 3];
    for i in 0..300u64 {
        let line = generated_line(mix(55 ^ i));
        let outcome = type_line(&m, &mut mdi, &mut standing, &line);
        counts[outcome as usize] += 1;
    }
    eprintln!("generated MDI session: {counts:?} (refused, taken back, ran)");
    assert!(
        counts[2] >= 150 && counts[1] >= 5 && counts[0] >= 20,
        "{counts:?}"
    );
}
