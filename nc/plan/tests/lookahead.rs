//! Look-ahead in distance, not in segments: a CAM program of 20 000 moves of 0.05 mm at
//! F3000 streams through the real-time follower exactly as the plan interpolates it, with
//! the planner keeping up and never a feed hold, at the default queue depth and at a
//! shallow one. With one segment a chunk, the follower saw 64 of them (3.2 mm), less than the
//! 12 mm it needs to stop from 50 mm/s, and held the feed about 5 900 times (the issue
//! "Dense CAM programs", measured with `dnurbs run`).

use nc_follow::{Follower, Queues, StreamCounters};
use nc_geom::kinematics::MachineKinematics;
use nc_plan::interp::Method;
use nc_plan::stream::{chunk_length, chunks};

const PERIOD: f64 = 0.002;

/// 20 000 moves of 0.05 mm along a rippled circle in X Y (radius 160 mm, ripple 2 mm),
/// the tool vertical, F3000: written as a post writes it.
fn program() -> String {
    // A circle of radius 160 mm about the origin with a 2 mm ripple, 12 waves a turn.
    let wave = |t: f64| {
        let r = 160.0 + 2.0 * (12.0 * t).sin();
        (
            nalgebra::Vector3::new(r * t.cos(), r * t.sin(), 0.0),
            nalgebra::Vector3::new(0.0, 0.0, 1.0),
        )
    };
    let points = nc_plan::fixtures::resample(wave, std::f64::consts::TAU, 20_000, 0.05);
    nc_plan::fixtures::g01_program(&points, 3000.0)
}

#[test]
fn twenty_thousand_short_moves_stream_as_planned_without_a_feed_hold() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let parsed = nc_lang::parse(&program()).expect("parses");
    let path = nc_geom::segment::build(&parsed, &kin, &bl).expect("builds");
    assert_eq!(path.segments.len(), 20_000);
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).expect("plans");
    let hold = cfg.hold();
    let offline =
        nc_plan::fixtures::interpolate(&path, &profile, kin, &cfg, Method::ArcLength, 1 << 20)
            .expect("an end");
    let peak = offline.iter().map(|sp| sp.feed).fold(0.0, f64::max);
    assert!(peak > 45.0, "the plan itself reaches {peak} mm/s of 50");

    for depth in [64, 8] {
        let len = chunk_length(&profile, &hold, depth);
        let (start, all) = chunks(path.clone(), &profile, &hold, depth);
        assert!(all.len() < path.segments.len(), "no segment merged");
        assert!(all.last().is_some_and(|c| c.last) && all.iter().filter(|c| c.last).count() == 1);
        for c in &all {
            assert!(c.last || c.s1 - c.s0 >= len, "chunk {}", c.index);
        }
        let mut source = all.into_iter();
        let mut q = Queues::new();
        let (mut feeder, inlet) = q.split(depth);
        let mut f = Follower::new(inlet, start, kin, cfg.rotary, hold);
        // The planner thread tops the queue up every period: it keeps up.
        let mut k = 0;
        loop {
            feeder.feed(&mut source);
            let sp = f.step();
            let want = &offline[k.min(offline.len() - 1)];
            assert!(
                (sp.p - want.p).norm() < 1e-9 && (k == 0 || sp.block == want.block),
                "depth {depth}, cycle {k}: {:?} block {} where the plan is at {:?} block {}",
                sp.p,
                sp.block,
                want.p,
                want.block
            );
            k += 1;
            if sp.done {
                break;
            }
            assert!(k <= offline.len(), "depth {depth}: later than the plan");
        }
        feeder.feed(&mut std::iter::empty());
        assert_eq!(k, offline.len(), "depth {depth}");
        assert_eq!(f.counters(), StreamCounters::default(), "depth {depth}");
    }
}
