//! The planner plans in windows of bounded look-ahead (`nc_plan::plan`, `plan/window.rs`): each
//! window is scheduled to a stop at its end, checked at the period where the committed plan
//! left off, and committed up to a joint well before its end; where the next window cannot
//! keep the committed speed, the last window's own stop is taken. Whatever the look-ahead,
//! the plan must hold every limit: here each plan is checked again over the whole path at
//! once (`nc_plan::verify::check`, from the first setpoint, no resumption), which must find no
//! violation and the very margins the windows reported. Short look-aheads (0.05 mm, 1 mm)
//! force hundreds of windows and their stops; the default is the path's own stop distance.

use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::{build, BuildLimits, Path};
use nc_plan::config::PlanConfig;
use nc_plan::plan::{plan, plan_looking_ahead};
use nc_plan::profile::FeedProfile;
use nc_plan::verify::{check, smooth_junctions};

const PERIOD: f64 = 0.002;

/// Look-aheads to plan with: the default, then forced short ones.
const REACHES: [Option<f64>; 3] = [None, Some(0.05), Some(1.0)];

fn plan_with(
    path: &Path,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    reach: Option<f64>,
) -> Option<FeedProfile> {
    match reach {
        None => plan(path, kin, cfg),
        Some(r) => plan_looking_ahead(path, kin, cfg, r),
    }
    .ok()
}

/// Plan `path` at every look-ahead; each accepted plan is checked over the whole path.
/// Returns the plans' durations (None where refused).
fn every_reach_holds(
    name: &str,
    path: &Path,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
) -> Vec<Option<f64>> {
    let smooth = smooth_junctions(path, kin, cfg);
    let total: f64 = path.segments.iter().map(|s| s.length).sum();
    REACHES
        .iter()
        .map(|&reach| {
            let profile = plan_with(path, kin, cfg, reach)?;
            let whole = check(path, &profile, kin, cfg, &smooth);
            assert!(
                whole.violations.is_empty(),
                "{name}, look-ahead {reach:?}: {:?}",
                whole.violations[0]
            );
            assert_eq!(
                whole.margins, profile.margins,
                "{name}, look-ahead {reach:?}: the windows measured other margins"
            );
            assert!((profile.length - total).abs() <= 1e-9 * total.max(1.0));
            Some(profile.duration)
        })
        .collect()
}

#[test]
fn the_test_programs_hold_every_limit_at_any_look_ahead() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let mut accepted = 0;
    for rel in nc_plan::fixtures::TEST_PROGRAMS {
        let program = nc_lang::parse(&nc_plan::fixtures::test_program(rel)).expect("parses");
        let path = build(&program, &kin, &bl).expect("builds");
        let times = every_reach_holds(rel, &path, &kin, &cfg);
        assert!(times[0].is_some(), "{rel} is refused");
        accepted += times.iter().flatten().count();
    }
    assert!(accepted >= 13, "{accepted} plans");
}

/// A dense CAM program: 4 000 moves of 0.05 mm around a rippled circle, with a dwell and a
/// program stop on the way, which the windows must keep where the program has them.
fn rippled(moves: usize, stops: bool) -> String {
    let wave = |t: f64| {
        let r = 60.0 + 1.5 * (9.0 * t).sin();
        (
            nalgebra::Vector3::new(r * t.cos(), r * t.sin(), 0.0),
            nalgebra::Vector3::new(0.0, 0.0, 1.0),
        )
    };
    let points = nc_plan::fixtures::resample(wave, std::f64::consts::TAU, moves, 0.05);
    let text = nc_plan::fixtures::g01_program(&points, 3000.0);
    if !stops {
        return text;
    }
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        out.push_str(line);
        out.push('\n');
        if i == moves / 3 {
            out.push_str("G04 P0.5\n");
        }
        if i == 2 * moves / 3 {
            out.push_str("G04 P0.25\n");
        }
    }
    out
}

#[test]
fn a_dense_program_holds_every_limit_in_hundreds_of_windows() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let mut durations = Vec::new();
    for stops in [false, true] {
        let program = nc_lang::parse(&rippled(4_000, stops)).expect("parses");
        let path = build(&program, &kin, &bl).expect("builds");
        let times = every_reach_holds("rippled", &path, &kin, &cfg);
        let times: Vec<f64> = times.into_iter().map(|t| t.expect("accepted")).collect();
        durations.push(times);
    }
    // The dwells are in the plan: 0.75 s of rest at least, at every look-ahead.
    for (plain, dwelt) in durations[0].iter().zip(&durations[1]) {
        assert!(
            dwelt - plain >= 0.75,
            "{plain} s without the dwells, {dwelt} s with"
        );
    }
}

#[test]
fn a_program_that_breaks_a_limit_at_any_speed_is_refused_at_any_look_ahead() {
    // X travel is +-300 on the adversarial mill: the move to X400 is refused however the
    // path is windowed, with the line of the move that leaves it.
    let kin = MachineKinematics::Paper;
    let (cfg, bl): (PlanConfig, BuildLimits) = nc_plan::fixtures::adversarial_mill(PERIOD);
    let moves = rippled(400, false);
    let end = moves
        .lines()
        .position(|l| l.starts_with("M30") || l.starts_with("M2"))
        .expect("the program ends");
    let mut lines: Vec<&str> = moves.lines().collect();
    lines.insert(end, "G01 X400");
    let text = lines.join("\n");
    let program = nc_lang::parse(&text).expect("parses");
    let path = build(&program, &kin, &bl).expect("builds");
    let last = end + 1;
    for reach in REACHES {
        let err = match reach {
            None => plan(&path, &kin, &cfg),
            Some(r) => plan_looking_ahead(&path, &kin, &cfg, r),
        }
        .expect_err("X400 leaves the travel");
        assert_eq!(err.pos.line as usize, last, "{err}");
    }
}
