//! The chord across a corner holds at every sampling phase, not only at the plan's own.
//!
//! The setpoint check measures the chord error at the phase the plan is sampled at (period
//! k at k Ts). A G01 corner passed at speed is straddled by one chord, whose distance from
//! the corner depends on where in the period the corner falls. A feed hold, a pause or an
//! override shifts that phase, and a plan made only for its own would then cut the corner
//! by more than the tolerance. On a long program the check found such corners one replanning
//! round after another, each round's slowing moving every later corner's phase: a CAM raster
//! of 200 000 moves took 20 rounds and 24 s to plan (61x the time of 20 000 moves). The
//! planner now passes every corner at a speed whose worst phase keeps the tolerance
//! (`corner_chord_speed` in `nc/src/plan.rs`).
//!
//! Generated zigzags (turns of 2 to 179 degrees, moves of 0.02 to 5 mm, feeds of 300 to
//! 9 000 mm/min) are planned, then sampled at the period with the start shifted by a
//! fraction of it, as after a hold; every chord that straddles a corner stays within the
//! tolerance.

use nalgebra::Vector3;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::Path;
use proptest::prelude::*;

const PERIOD: f64 = 0.002;

/// A polyline in X Y that turns by `turns[i]` (radians, alternately left and right) after
/// move i of length `lens[i]`.
fn zigzag(lens: &[f64], turns: &[f64]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let mut p = Vector3::new(0.0, 0.0, 0.0);
    let mut heading = 0.0f64;
    let mut out = vec![(p, Vector3::z())];
    for (i, &len) in lens.iter().enumerate() {
        p += Vector3::new(heading.cos(), heading.sin(), 0.0) * len;
        out.push((p, Vector3::z()));
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        heading += sign * turns.get(i).copied().unwrap_or(0.0);
    }
    out
}

/// The cutter point at path position `s`.
fn point_at(path: &Path, seg_start: &[f64], s: f64) -> (usize, Vector3<f64>) {
    let i = seg_start
        .partition_point(|&b| b <= s)
        .saturating_sub(1)
        .min(path.segments.len() - 1);
    let seg = &path.segments[i];
    (i, seg.pose((s - seg_start[i]).clamp(0.0, seg.length)).p)
}

/// The largest distance of a corner from a chord straddling it, sampling the plan at
/// `k Ts + phase`.
fn worst_corner_chord(path: &Path, profile: &nc_plan::profile::FeedProfile, phase: f64) -> f64 {
    let seg_start = &profile.seg_start;
    let n = ((profile.duration - phase) / PERIOD).floor() as usize;
    let mut worst = 0.0f64;
    let mut prev: Option<(usize, Vector3<f64>)> = None;
    for k in 0..=n {
        let t = phase + k as f64 * PERIOD;
        let s = profile.motion_at(t).s;
        let (i, p) = point_at(path, seg_start, s);
        if let Some((i0, p0)) = prev {
            for seg in &path.segments[i0..i] {
                let corner = seg.pose(seg.length).p;
                worst = worst.max(nc_plan::verify::dist_to_chord(&corner, &p0, &p));
            }
        }
        prev = Some((i, p));
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn a_corner_keeps_the_chord_tolerance_at_every_phase(
        lens in prop::collection::vec(0.02..5.0f64, 4..24),
        turns in prop::collection::vec(2.0..179.0f64, 24),
        feed in 300.0..9000.0f64,
    ) {
        let turns: Vec<f64> = turns.iter().map(|d| d.to_radians()).collect();
        let points = zigzag(&lens, &turns);
        let src = nc_plan::fixtures::g01_program(&points, feed);
        let kin = MachineKinematics::Paper;
        let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
        let parsed = nc_lang::parse(&src).expect("parses");
        let path = nc_geom::segment::build(&parsed, &kin, &bl).expect("builds");
        let profile = match nc_plan::plan::plan(&path, &kin, &cfg) {
            Ok(p) => p,
            Err(e) => return Err(TestCaseError::fail(format!("refused: {e}\n{src}"))),
        };
        for f in [0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875] {
            let e = worst_corner_chord(&path, &profile, f * PERIOD);
            prop_assert!(
                e <= cfg.chord_tol * (1.0 + 1e-6),
                "phase {f}: a corner {e} mm from its chord (tolerance {})\n{src}",
                cfg.chord_tol
            );
        }
    }
}
