//! The interpolator over a streamed plan (`nc_plan::rolling::interpolate`: the program read a line
//! at a time through parser, builder and planner into a `Rolling` window that lets go of
//! what lies behind it) gives the setpoints the interpolator gives over the whole path and
//! plan, to the bit, with every parameter update method; and it holds a window, not the
//! program.

use nalgebra::Vector3;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::{build, BuildLimits};
use nc_geom::setpoint::Setpoint;
use nc_lang::{Entries, Setup, StrLines};
use nc_plan::config::PlanConfig;
use nc_plan::interp::{Interpolator, Method};
use nc_plan::plan::plan;
use nc_plan::rolling::{interpolate, Stepping};
use nc_plan::stream::{Machine, Stages};

const PERIOD: f64 = 0.002;

fn stepping(kin: MachineKinematics, cfg: &PlanConfig, bl: &BuildLimits, m: Method) -> Stepping {
    Stepping {
        kin,
        lim: cfg.rotary,
        method: m,
        period: PERIOD,
        creep: cfg.path_acc * PERIOD,
        speed_cap: bl.speed_cap(),
    }
}

/// Every setpoint over the whole path and plan, as `simulate` made them before it streamed.
fn whole(text: &str, st: &Stepping, cfg: &PlanConfig, bl: &BuildLimits) -> Option<Vec<Setpoint>> {
    let program = nc_lang::parse(text).ok()?;
    let path = build(&program, &st.kin, bl).ok()?;
    let profile = plan(&path, &st.kin, cfg).ok()?;
    let mut ip = Interpolator::new(
        &path, &profile, st.kin, st.lim, st.method, st.period, st.creep,
    );
    let mut out = Vec::new();
    loop {
        let sp = ip.step();
        out.push(sp);
        if sp.done || path.segments.is_empty() {
            return Some(out);
        }
        assert!(sp.cycle < 10_000_000, "runs away");
    }
}

/// The same through the stream; also the most segments the window held, and whether each
/// setpoint's segment was in the window it was handed with.
fn rolled(
    text: &str,
    st: &Stepping,
    cfg: &PlanConfig,
    bl: &BuildLimits,
) -> Option<(Vec<Setpoint>, usize)> {
    let setup = Setup::default();
    let machine = Machine {
        kin: &st.kin,
        build: bl,
        plan: cfg,
    };
    let mut stages = Stages::new(Entries::new(StrLines::new(text), &setup), machine);
    let mut out = Vec::new();
    let rolling = interpolate(&mut stages, *st, |sp, w| {
        assert!(
            w.segments.iter().any(|s| s.block == sp.block) || sp.cycle == 0,
            "setpoint {} of block {} handed without its block's segments",
            sp.cycle,
            sp.block
        );
        out.push(*sp);
    })
    .ok()?;
    Some((out, rolling.0.most_held()))
}

/// A wiggle of `n` G01 moves of 0.05 mm (the dense CAM program of issue 12).
fn wiggle(n: usize) -> String {
    let points: Vec<_> = (0..=n)
        .map(|k| {
            let x = 0.05 * k as f64;
            (Vector3::new(x, 2.0 * (x * 0.3).sin(), 0.0), Vector3::z())
        })
        .collect();
    nc_plan::fixtures::g01_program(&points, 3000.0)
}

#[test]
fn the_rolling_interpolator_gives_the_whole_paths_setpoints() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let mut programs: Vec<(String, String)> = nc_plan::fixtures::TEST_PROGRAMS
        .iter()
        .map(|rel| (rel.to_string(), nc_plan::fixtures::test_program(rel)))
        .collect();
    programs.push(("wiggle".into(), wiggle(6_000)));
    let mut compared = 0;
    for (name, text) in &programs {
        for method in [Method::ArcLength, Method::Taylor1, Method::Taylor2] {
            let st = stepping(kin, &cfg, &bl, method);
            let want = whole(text, &st, &cfg, &bl);
            let got = rolled(text, &st, &cfg, &bl);
            match (want, got) {
                (Some(w), Some((g, _))) => {
                    assert_eq!(w.len(), g.len(), "{name} {method:?}: setpoints");
                    if let Some(i) = (0..w.len()).find(|&i| w[i] != g[i]) {
                        panic!("{name} {method:?}: setpoint {i}: {:?} != {:?}", w[i], g[i]);
                    }
                    compared += 1;
                }
                (None, None) => {}
                (w, g) => panic!(
                    "{name} {method:?}: whole {} but rolled {}",
                    w.is_some(),
                    g.is_some()
                ),
            }
        }
    }
    assert!(compared >= 36, "{compared} runs compared");
}

#[test]
fn the_rolling_window_does_not_grow_with_the_program() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let st = stepping(kin, &cfg, &bl, Method::ArcLength);
    // The planner commits about a metre of these moves at a time (three stops from
    // 50 mm/s at its look-ahead): the window is that, whatever comes after (13 598 and
    // 17 958 segments when this was written: 4x the program, 1.3x the window).
    let (short, held_short) = rolled(&wiggle(40_000), &st, &cfg, &bl).expect("plans");
    let (long, held_long) = rolled(&wiggle(160_000), &st, &cfg, &bl).expect("plans");
    assert!(long.len() > 3 * short.len());
    assert!(
        2 * held_long <= 3 * held_short && held_long < 40_000,
        "the window held {held_short} segments of 40 000 and {held_long} of 160 000"
    );
}

/// The window fed far more finely than the planner feeds it: a segment at a time, with the
/// phases that start on it, the interpolator run after each. It stops at every boundary the
/// data leave it (and a Taylor step that runs off the segments held is taken back), and
/// the setpoints are still those over the whole path, with every method.
#[test]
fn fed_a_segment_at_a_time_the_rolling_interpolator_still_gives_the_whole_paths_setpoints() {
    use nc_plan::plan::{Finished, Sink};
    use nc_plan::rolling::Rolling;
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let mut compared = 0;
    for rel in nc_plan::fixtures::TEST_PROGRAMS {
        let text = nc_plan::fixtures::test_program(rel);
        let Ok(program) = nc_lang::parse(&text) else {
            continue;
        };
        let Ok(path) = build(&program, &kin, &bl) else {
            continue;
        };
        let Ok(profile) = plan(&path, &kin, &cfg) else {
            continue;
        };
        // The Taylor methods also with no margin past the segment they stand on (a speed
        // cap of 0): then every step that runs off the segments held must be taken back.
        let runs = [
            (Method::ArcLength, false),
            (Method::Taylor1, false),
            (Method::Taylor2, false),
            (Method::Taylor1, true),
            (Method::Taylor2, true),
        ];
        for (method, no_margin) in runs {
            let mut st = stepping(kin, &cfg, &bl, method);
            let want = whole(&text, &st, &cfg, &bl).expect("runs whole");
            if no_margin {
                st.speed_cap = 0.0;
            }
            let mut r = Rolling::new(st);
            r.start_at(path.start, path.start_joints);
            let mut got = Vec::new();
            let (mut end, mut next_phase) = (0.0, 0);
            for seg in &path.segments {
                end += seg.length;
                let upto = profile.phases.partition_point(|p| p.s0 <= end);
                r.phases(&profile.phases[next_phase..upto.max(next_phase)]);
                next_phase = next_phase.max(upto);
                r.segment(seg.clone());
                r.run(|sp, _| got.push(*sp)).expect("runs");
            }
            r.phases(&profile.phases[next_phase..]);
            r.finish(&Finished {
                length: profile.length,
                duration: profile.duration,
                margins: profile.margins,
            });
            r.run(|sp, _| got.push(*sp)).expect("runs");
            let name = format!(
                "{rel} {method:?}{}",
                if no_margin { ", no margin" } else { "" }
            );
            assert_eq!(want.len(), got.len(), "{name}: setpoints");
            if let Some(i) = (0..want.len()).find(|&i| want[i] != got[i]) {
                panic!("{name}: setpoint {i}: {:?} != {:?}", want[i], got[i]);
            }
            compared += 1;
        }
    }
    assert!(compared >= 60, "{compared} runs compared");
}
