//! The planner takes the path a segment at a time (`nc_plan::plan::Planner`) and keeps only what
//! its next window's check reads: the segments, stations and phases behind that are handed
//! on and dropped, and every index into its buffers moves with them. Dropping must change
//! nothing: here every program is planned twice, by a planner that keeps the whole path and
//! by one that drops, at the default look-ahead and at forced short ones (hundreds of
//! windows and their stops), and the two plans (or refusals) must be the same to the bit.
//! And what the planner holds must not grow with the program.

use nalgebra::Vector3;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::{build, Path};
use nc_plan::config::PlanConfig;
use nc_plan::plan::{plan_whole, start_of, Collect, Planner};

const PERIOD: f64 = 0.002;

fn planner<'a>(
    path: &Path,
    kin: &'a MachineKinematics,
    cfg: &'a PlanConfig,
    reach: Option<f64>,
) -> Planner<'a> {
    let p = Planner::new(start_of(path), kin, cfg);
    match reach {
        Some(r) => p.looking_ahead(r),
        None => p,
    }
}

/// Plans `path` keeping everything and dropping, at three look-aheads; the plans must be
/// the same. Returns how many were accepted.
fn same_either_way(name: &str, path: &Path, kin: &MachineKinematics, cfg: &PlanConfig) -> usize {
    let mut accepted = 0;
    for reach in [None, Some(0.05), Some(1.0)] {
        let kept = plan_whole(path, planner(path, kin, cfg, reach).keeping_everything());
        let dropped = plan_whole(path, planner(path, kin, cfg, reach));
        assert_eq!(kept, dropped, "{name}, look-ahead {reach:?}");
        accepted += usize::from(kept.is_ok());
    }
    accepted
}

/// A finishing raster: rows of `row` mm along X in moves of `step` mm, 0.5 mm apart, the
/// way a CAM post writes a 3-axis pass.
fn raster(rows: usize, row: f64, step: f64) -> String {
    let per_row = (row / step).round() as usize;
    let mut points = Vec::new();
    for r in 0..rows {
        let y = 0.5 * r as f64;
        for i in 0..=per_row {
            let f = i as f64 / per_row as f64;
            let x = if r % 2 == 0 { f * row } else { (1.0 - f) * row };
            points.push((Vector3::new(x, y, 0.02 * (x * 0.7).sin()), Vector3::z()));
        }
    }
    nc_plan::fixtures::g01_program(&points, 3000.0)
}

#[test]
fn dropping_what_the_check_has_read_changes_no_plan() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let mut accepted = 0;
    let mut programs: Vec<(String, String)> = nc_plan::fixtures::TEST_PROGRAMS
        .iter()
        .map(|rel| (rel.to_string(), nc_plan::fixtures::test_program(rel)))
        .collect();
    programs.push(("raster".into(), raster(12, 20.0, 0.1)));
    for (name, text) in &programs {
        let program = nc_lang::parse(text).expect("parses");
        let path = build(&program, &kin, &bl).expect("builds");
        accepted += same_either_way(name, &path, &kin, &cfg);
    }
    assert!(accepted >= 36, "{accepted} plans accepted");
}

/// 0.04 mm chords at F6000 (5 a period at 2 ms) along a line that turns by 0.3 degrees,
/// one way then back, every `every` chords: each turn a kink (not G2-smooth) too slight to
/// slow the feed, the joints between them smooth. A kink's one-sided stencils read the path
/// three periods back, many chords behind the check's resumption mark.
fn kinked_line(n: usize, every: usize) -> String {
    let mut points = vec![(Vector3::zeros(), Vector3::z())];
    let (mut p, mut heading) = (Vector3::<f64>::zeros(), 0.0f64);
    for k in 1..=n {
        if k % every == 0 {
            heading = if heading == 0.0 {
                0.3f64.to_radians()
            } else {
                0.0
            };
        }
        p += 0.04 * Vector3::new(heading.cos(), heading.sin(), 0.0);
        points.push((p - Vector3::new(200.0, 0.0, 0.0), Vector3::z()));
    }
    nc_plan::fixtures::g01_program(&points, 6000.0)
}

#[test]
fn short_chords_between_kinks_plan_the_same_when_the_front_is_dropped() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let program = nc_lang::parse(&kinked_line(10_000, 16)).expect("parses");
    let path = build(&program, &kin, &bl).expect("builds");
    assert_eq!(same_either_way("kinked line", &path, &kin, &cfg), 3);
}

#[test]
fn a_refusal_is_the_same_when_the_front_is_dropped() {
    // X travel is +-300 on the adversarial mill: the move to X400 at the end of a long
    // raster is refused with its line, whether or not the raster before it was dropped.
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::adversarial_mill(PERIOD);
    let text = raster(8, 20.0, 0.1);
    let end = text
        .lines()
        .position(|l| l.starts_with("M30"))
        .expect("ends");
    let mut lines: Vec<&str> = text.lines().collect();
    lines.insert(end, "G01 X400");
    let program = nc_lang::parse(&lines.join("\n")).expect("parses");
    let path = build(&program, &kin, &bl).expect("builds");
    for reach in [None, Some(1.0)] {
        let mut sink = Collect::default();
        let mut p = planner(&path, &kin, &cfg, reach);
        let err = path
            .segments
            .iter()
            .try_for_each(|s| p.push(s.clone(), &mut sink))
            .and_then(|()| p.finish(&mut sink).map(drop))
            .expect_err("X400 leaves the travel");
        assert_eq!(err.pos.line as usize, end + 1, "{err}");
    }
    same_either_way("raster to X400", &path, &kin, &cfg);
}

/// The most segments the planner held at once over a raster of `rows` rows.
fn most_held(rows: usize) -> (usize, usize) {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let program = nc_lang::parse(&raster(rows, 20.0, 0.1)).expect("parses");
    let path = build(&program, &kin, &bl).expect("builds");
    let mut sink = Collect::default();
    let mut p = Planner::new(start_of(&path), &kin, &cfg);
    for seg in &path.segments {
        p.push(seg.clone(), &mut sink).expect("plans");
    }
    let most = p.most_buffered();
    p.finish(&mut sink).expect("plans");
    (path.segments.len(), most)
}

#[test]
fn what_the_planner_holds_does_not_grow_with_the_program() {
    let (n_short, short) = most_held(20);
    let (n_long, long) = most_held(160);
    eprintln!("{short} segments held for {n_short} moves, {long} for {n_long}");
    assert!(n_long >= 8 * n_short - 100, "{n_short} and {n_long} moves");
    // The look-ahead on this raster is a few rows (where the windows fall moves what is
    // held by a third, measured: 1 253 segments at 4 019 moves, 1 609 at 32 159, 1 637 at
    // 64 319); eight times the program holds no more than that.
    assert!(
        2 * long <= 3 * short,
        "{short} segments held for {n_short} moves, {long} for {n_long}"
    );
    assert!(long < n_long / 4, "{long} of {n_long} segments held");
}
