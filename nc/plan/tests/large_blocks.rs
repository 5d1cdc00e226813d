//! Any curve size (issue "Limits guaranteed", part 5): a G06.5 block of 10 000 control
//! points, as CAD writes long curves, parses, plans within every limit, interpolates to its
//! end, and streams through the real-time `Follower` exactly as it interpolates offline.
//! The real-time side still sees only pieces of at most `MAX_CTRL` points.

use nc_follow::{Follower, Queues};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::MAX_CTRL;
use nc_geom::segment::{build, Geometry};
use nc_plan::interp::Method;
use nc_plan::stream::chunks;
use std::fmt::Write;

const N: usize = 10_000;
const PERIOD: f64 = 0.002;

/// A cubic G06.5 block: the cutter on a slowly rising spiral of 210 mm, the tool tilted
/// 10 degrees and turning a quarter around the vertical (A near 10 degrees, C 90 degrees).
fn program() -> (String, [f64; 3]) {
    let tilt = 10f64.to_radians();
    let at = |i: usize| {
        let a = i as f64 * 7e-4;
        let p = [30.0 * a.cos(), 30.0 * a.sin(), 0.002 * i as f64];
        let phi = i as f64 * std::f64::consts::FRAC_PI_2 / N as f64;
        let t = [tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos()];
        (p, t)
    };
    let (p0, t0) = at(0);
    let mut s = format!(
        "%\nG90 G21\nN10 G01 X{} Y{} Z{} I{} J{} K{} F1000\nN20 G06.5 P3 F6000 ",
        p0[0], p0[1], p0[2], t0[0], t0[1], t0[2]
    );
    let knot = |j: usize| {
        if j <= 3 {
            0.0
        } else if j >= N {
            1.0
        } else {
            (j - 3) as f64 / (N - 3) as f64
        }
    };
    for i in 0..N {
        let (p, t) = at(i);
        let _ = writeln!(
            s,
            "X{} Y{} Z{} U{} V{} W{} R1 K{}",
            p[0],
            p[1],
            p[2],
            p[0] + 20.0 * t[0],
            p[1] + 20.0 * t[1],
            p[2] + 20.0 * t[2],
            knot(i)
        );
    }
    s.push_str("K1 K1 K1 K1\nM30\n%\n");
    (s, at(N - 1).0)
}

#[test]
fn a_ten_thousand_point_block_plans_runs_and_streams() {
    let (src, end) = program();
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let kin = MachineKinematics::Paper;
    let parsed = nc_lang::parse(&src).expect("parses");
    let path = build(&parsed, &kin, &bl).expect("builds");
    // Cut into pieces the real-time thread can hold, all from block 2.
    assert!(
        path.segments.len() >= N / MAX_CTRL,
        "{}",
        path.segments.len()
    );
    for seg in &path.segments {
        assert_eq!(seg.block, 2);
        assert!(!seg.stop, "a smooth block has no corner");
        let Geometry::Nurbs { curve, .. } = &seg.geometry else {
            panic!("not a curve")
        };
        assert!(curve.knots().len() - curve.degree() - 1 <= MAX_CTRL);
    }
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).expect("plans within the limits");
    let m = profile.margins;
    for j in 0..5 {
        assert!(m.velocity[j] <= 1.0 && m.acceleration[j] <= 1.0 && m.jerk[j] <= 1.0);
    }
    assert!(m.chord <= 1.0);
    // The pieces join with the curve's own C2 continuity: the feed is not broken at them.
    // 210 mm at 100 mm/s is 2.1 s; allow the ramps, refuse a stop at every piece.
    assert!(profile.duration < 3.0, "{} s", profile.duration);

    let offline =
        nc_plan::fixtures::interpolate(&path, &profile, kin, &cfg, Method::ArcLength, 1 << 20)
            .expect("an end");
    let last = offline[offline.len() - 1].p;
    let miss =
        ((last.x - end[0]).powi(2) + (last.y - end[1]).powi(2) + (last.z - end[2]).powi(2)).sqrt();
    assert!(miss < 1e-6, "ends {miss} mm from the block's end");

    // Streamed: the planner thread keeps the queue full; the real-time Follower takes the
    // pieces as they come (64 in flight, as `run` does with the default depth).
    let hold = cfg.hold();
    let (start, all) = chunks(path.clone(), &profile, &hold, 64);
    let mut source = all.into_iter();
    let mut q = Queues::new();
    let (mut feeder, inlet) = q.split(64);
    let mut f = Follower::new(inlet, start, kin, cfg.rotary, hold);
    let mut k = 0;
    loop {
        feeder.feed(&mut source);
        let sp = f.step();
        let want = &offline[k.min(offline.len() - 1)];
        assert!(
            (sp.p - want.p).norm() < 1e-9,
            "cycle {k}: {} vs {}",
            sp.p,
            want.p
        );
        for j in 0..5 {
            assert!(
                (sp.joints[j] - want.joints[j]).abs() < 1e-9,
                "cycle {k} joint {j}"
            );
        }
        k += 1;
        if sp.done {
            break;
        }
        assert!(k < offline.len() + 10, "the stream runs past the plan");
    }
    feeder.feed(&mut std::iter::empty());
    assert_eq!(k, offline.len());
    assert_eq!(f.counters().underruns, 0);
}
