//! A move that waits (a `G04` dwell before it, an `M00` for the operator, the spindle
//! coming to speed after `M03`, an input after `M66`) starts from rest: the plan arrives there at speed zero,
//! rests, and leaves from zero. It once arrived and left at the planner's slowest feed
//! (1 um/s): harmless where the axes move a micrometre per millimetre of path, but where a
//! move turns C fast next to the vertical (hundreds of degrees per millimetre), leaving at
//! that speed stepped C's velocity in one period, and a compressed post was refused with
//! C's jerk 4.4x its limit where it ran as posted (`compressed_posts.rs`).
//!
//! Here proptest writes passes in machine angles whose moves turn C at random rates up to
//! several hundred degrees per millimetre near the vertical, with waits of each kind at
//! random moves; each plan (at the default look-ahead and a short one) must be at rest
//! wherever a move waits, and hold every limit over the whole path by the setpoint check.

use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::{build, Path};
use nc_plan::plan::{plan, plan_looking_ahead};
use nc_plan::profile::FeedProfile;
use nc_plan::verify::{check, smooth_junctions};
use proptest::prelude::*;
use std::fmt::Write;

use test_support::generated::{env, seeded_runner};

const PERIOD: f64 = 0.002;

#[derive(Clone, Copy, Debug)]
enum Wait {
    Dwell,
    Operator,
    Spindle,
    Input,
}

/// A pass of `moves` moves of `step` mm along X and Y, A stepping by `da` and C by `dc`
/// degrees a move from (a0, c0), with `waits` before the moves they name.
fn program(
    (a0, c0, da, dc): (f64, f64, f64, f64),
    (moves, step): (usize, f64),
    waits: &[(usize, Wait)],
) -> String {
    let mut s = String::from("%\nG90 G21 G94\nG01 X0 Y0 Z0 A");
    let _ = writeln!(s, "{a0:.4} C{c0:.4} F3000");
    for k in 1..=moves {
        for (_, w) in waits.iter().filter(|(at, _)| *at == k) {
            s += match w {
                Wait::Dwell => "G04 P0.05\n",
                Wait::Operator => "M00\n",
                Wait::Spindle => "M03 S8000\n",
                Wait::Input => "M64 P1\nM66 P0 L3 Q2\n",
            };
        }
        let t = k as f64 * step;
        let _ = writeln!(
            s,
            "X{:.4} Y{:.4} A{:.4} C{:.4}",
            t,
            0.3 * t,
            a0 + da * k as f64,
            c0 + dc * k as f64
        );
    }
    s + "M30\n%\n"
}

/// Every move that waits starts where the plan rests: each phase that begins there begins
/// at speed zero, and the phase before it ends at zero.
fn at_rest_where_moves_wait(path: &Path, profile: &FeedProfile) -> Result<(), TestCaseError> {
    let eps = 1e-9 * profile.length.max(1.0);
    for (seg, &at) in path.segments.iter().zip(&profile.seg_start).skip(1) {
        if !seg.waits() {
            continue;
        }
        let mut found = false;
        for (i, p) in profile.phases.iter().enumerate() {
            if (p.s0 - at).abs() > eps || i == 0 {
                continue;
            }
            found = true;
            let before = &profile.phases[i - 1];
            let end = before.at(before.dur);
            prop_assert!(
                p.v0 == 0.0 && end.v.abs() <= 1e-12,
                "the move at {at:.6} mm waits ({:?}): arrives at {:e}, leaves at {:e} mm/s",
                seg.wait,
                end.v,
                p.v0
            );
        }
        prop_assert!(found, "no phase starts where the move at {at:.6} mm waits");
    }
    Ok(())
}

#[test]
fn the_plan_rests_wherever_a_move_waits_and_holds_every_limit() {
    let cases = env("WAIT_CASES", 48) as u32;
    let config = ProptestConfig {
        cases,
        max_shrink_iters: 64,
        failure_persistence: None,
        ..ProptestConfig::default()
    };
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::adversarial_mill(PERIOD);
    let wait = prop_oneof![
        Just(Wait::Dwell),
        Just(Wait::Operator),
        Just(Wait::Spindle),
        Just(Wait::Input)
    ];
    let mut setup = nc_lang::Setup::default();
    setup.io.digital_inputs = 1;
    setup.io.digital_outputs = 2;
    let strategy = (
        (-3.0..3.0f64, -180.0..180.0f64, -0.2..0.2f64, -60.0..60.0f64),
        (4usize..40, 0.01..0.3f64),
        prop::collection::vec((1usize..40, wait), 1..4),
    );
    let planned = std::cell::Cell::new(0u32);
    let result =
        seeded_runner(config, env("WAIT_SEED", 0)).run(&strategy, |(angles, pass, waits)| {
            let src = program(angles, pass, &waits);
            let program = nc_lang::parse_with(&src, &setup)
                .map_err(|e| TestCaseError::fail(format!("{e:?}")))?;
            let path =
                build(&program, &kin, &bl).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let smooth = smooth_junctions(&path, &kin, &cfg);
            for profile in [
                plan(&path, &kin, &cfg),
                plan_looking_ahead(&path, &kin, &cfg, 0.05),
            ]
            .into_iter()
            .flatten()
            {
                planned.set(planned.get() + 1);
                at_rest_where_moves_wait(&path, &profile)
                    .map_err(|e| TestCaseError::fail(format!("{e}\n{src}")))?;
                let whole = check(&path, &profile, &kin, &cfg, &smooth);
                prop_assert!(
                    whole.violations.is_empty(),
                    "{:?}\n{src}",
                    whole.violations[0]
                );
            }
            Ok(())
        });
    if let Err(e) = result {
        panic!("{e}");
    }
    // Most passes are feasible: the test must plan them, not only see refusals.
    assert!(
        planned.get() >= cases,
        "only {} plans of {cases} cases",
        planned.get()
    );
}

/// The builder puts each `M66` wait on the first segment after it, in order, with the
/// outputs in effect; a fifth wait between two moves is refused at its line.
#[test]
fn input_waits_and_outputs_reach_the_segment_after_them() {
    use nc_geom::program::WaitMode;
    let mut setup = nc_lang::Setup::default();
    setup.io.digital_inputs = 4;
    setup.io.digital_outputs = 4;
    let (_, bl) = nc_plan::fixtures::adversarial_mill(PERIOD);
    let kin = MachineKinematics::Paper;
    let src =
        "G01 X0 Y0 Z0 A0 C0 F3000\nX1\nM62 P3\nM66 P1 L1 Q2\nM66 P2 L4 Q0.5\nX2\nM63 P3\nX3\nM2";
    let path = build(&nc_lang::parse_with(src, &setup).unwrap(), &kin, &bl).unwrap();
    let waits: Vec<_> = path.segments[1].inputs.iter().flatten().collect();
    assert_eq!(waits.len(), 2, "{:?}", path.segments[1].inputs);
    assert_eq!(
        (waits[0].input, waits[0].mode, waits[0].pos.line),
        (1, WaitMode::Rise, 4)
    );
    assert_eq!((waits[1].input, waits[1].timeout_s), (2, 0.5));
    assert!(path.segments[1].stop && path.segments[1].waits());
    let outputs: Vec<u64> = path.segments.iter().map(|s| s.aux.outputs).collect();
    assert_eq!(outputs, [0, 1 << 3, 0]);
    let five = "G01 X0 Y0 Z0 A0 C0 F3000\nM66 P0 L3 Q1\nM66 P0 L3 Q1\nM66 P0 L3 Q1\n\
                M66 P0 L3 Q1\nM66 P0 L3 Q1\nX1\nM2";
    let e = build(&nc_lang::parse_with(five, &setup).unwrap(), &kin, &bl).unwrap_err();
    assert_eq!(e.pos.line, 6, "{e}");
    assert!(e.to_string().contains("more than 4 M66 waits"), "{e}");
}
