//! `simulate --operator`: a replay of an operator's actions through the real-time thread's
//! follower (`dnurbs_tools::simulate::operator`). Scripts generated from seeds pause,
//! resume, stop and change the override at random moments on the test programs and the
//! classics (the 5-axis ones on the A/C mill, where C turns fast near the vertical): every
//! setpoint holds every axis's velocity and acceleration limit and its travel. And the
//! command line: its summary, its trace, a bad script refused with its line.

mod common;

use common::{data, dnurbs, machine, temp};
use dnurbs_tools::setup::MachineSetup;
use dnurbs_tools::simulate::operator::replay;
use dnurbs_tools::simulate::script::{self, Act, Action, When};
use nc_plan::stream::ProgramEntries;

/// Six actions at moments from a seed: mostly pauses and overrides, each followed in time
/// by a resume or a return to 100 %, sometimes a stop.
fn script(seed: u64, duration_s: f64) -> Vec<Action> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = Vec::new();
    let mut t = 0.0;
    for line in 0..6 {
        t += next() * duration_s / 4.0;
        let act = match (next() * 10.0) as u32 {
            0..=2 => Act::Pause,
            3..=4 => Act::Resume,
            5..=8 => Act::Override((next() * 100.0) as u8),
            _ => Act::Stop,
        };
        out.push(Action {
            when: When::At(t),
            act,
            line,
        });
    }
    // Whatever it did, the run goes on to its end.
    out.push(Action {
        when: When::After(0.2),
        act: Act::Override(100),
        line: 7,
    });
    out.push(Action {
        when: When::After(0.0),
        act: Act::Resume,
        line: 8,
    });
    out
}

#[test]
fn random_operator_actions_keep_every_axis_within_its_limits() {
    let cases: [(&str, &str); 6] = [
        ("paper-example.nc", "paper-ac-table.toml"),
        ("two-blocks-g2.nc", "paper-ac-table.toml"),
        ("helix-ramp.nc", "paper-ac-table.toml"),
        ("classics/fan-5axis.nc", "xyzac-trt-mill.toml"),
        ("classics/dual-spline.nc", "xyzac-trt-mill.toml"),
        ("vertical-turns.nc", "xyzac-trt-mill.toml"),
    ];
    let mut replays = 0;
    let mut ended = std::collections::BTreeMap::new();
    for (program, machine_file) in cases {
        let m = config::load(&machine(machine_file)).unwrap();
        let shop = dnurbs_tools::shop::ShopOptions::default();
        let parse = dnurbs_tools::shop::parse_setup(&m, &shop).unwrap();
        let setup = MachineSetup::new(&m);
        let prog = dnurbs_tools::load_program(&data(program), &parse).unwrap();
        // The plan's duration, from a replay without actions.
        let plain = replay(ProgramEntries::new(prog.clone()), &setup, 64, &[], |_| {}).unwrap();
        assert_eq!(plain.ending, "end", "{program}");
        assert!(plain.over.is_empty(), "{program}: {:?}", plain.over);
        for seed in 1..=12 {
            let s = script(seed, plain.time_s);
            let r = replay(ProgramEntries::new(prog.clone()), &setup, 64, &s, |_| {}).unwrap();
            assert!(
                r.over.is_empty() && r.outside_travel.is_empty(),
                "{program} on {machine_file}, seed {seed}: {:?} {:?}\n{s:?}",
                r.over,
                r.outside_travel
            );
            assert!(
                matches!(r.ending, "end" | "stopped"),
                "{program} seed {seed}: {}",
                r.ending
            );
            *ended.entry(r.ending).or_insert(0) += 1;
            replays += 1;
        }
    }
    assert_eq!(replays, 72);
    assert!(ended.get("stopped").is_some_and(|&n| n > 0), "{ended:?}");
    assert!(ended.get("end").is_some_and(|&n| n > 0), "{ended:?}");
}

#[test]
fn simulate_operator_prints_the_actions_and_refuses_a_bad_script() {
    let s = temp("operator.txt");
    std::fs::write(
        &s,
        "at 1s pause\nafter 0.5s resume\nat line 8 override 30\n",
    )
    .unwrap();
    let trace = temp("operator-trace.csv");
    let prog = data("paper-example.nc");
    let mach = machine("paper-ac-table.toml");
    let args = |extra: &[&str]| {
        let mut a = vec![
            "simulate",
            prog.to_str().unwrap(),
            "--machine",
            mach.to_str().unwrap(),
            "--operator",
            s.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        dnurbs(
            &a.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .iter()
                .map(String::as_str)
                .collect::<Vec<_>>(),
        )
    };
    let out = args(&["--trace", trace.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("3 actions taken, 0 not reached"), "{text}");
    assert!(
        text.contains("ended              the program's end"),
        "{text}"
    );
    assert!(
        text.contains("within limits, holds and overrides included"),
        "{text}"
    );
    let rows = std::fs::read_to_string(&trace).unwrap();
    assert!(
        rows.starts_with("cycle,t,block,u,"),
        "the trace is simulate --trace's"
    );
    assert!(rows.lines().count() > 1000);
    let json = args(&["--json"]);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(v["taken"].as_array().unwrap().len(), 3);
    std::fs::write(&s, "at 1s pause\nat 2s dance\n").unwrap();
    let bad = args(&[]);
    assert_eq!(bad.status.code(), Some(2));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("line 2: the action is pause, resume, stop or override"),
        "{err}"
    );
    assert_eq!(script::parse("at 1s stop\n").unwrap().len(), 1);
    let _ = std::fs::remove_file(&trace);
}
