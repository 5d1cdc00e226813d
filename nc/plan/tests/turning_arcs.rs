//! Arcs that turn the tool (`G02`/`G03` with `A C` words, issue "CAM posts"): the cutter
//! stays on the circle (helix) while the rotary angles change linearly in path length, as
//! along a `G01`, continuously across the pieces a long helix is cut into, ending exactly
//! at the programmed angles, within every limit, for each parameter-update method and
//! through the real-time `Follower`. Checked against the circle and the angle computed
//! here from the setpoints' own positions, not against the segment code.

use nc_follow::{Follower, Queues};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::build;
use nc_geom::setpoint::Setpoint;
use nc_plan::interp::{Interpolator, Method};
use nc_plan::stream::chunks;
use std::f64::consts::TAU;

const PERIOD: f64 = 0.002;

/// A whole turn of a helix of radius 20 about (0, 0) falling 4.5 mm, G03 from (20, 0, 10), while A goes 0 -> 30 deg and C 0 -> 270 deg; then a planar quarter arc
/// turning C back to 180.
const SRC: &str = "%
G90 G21 G17
N10 G01 X20 Y0 Z10 A0 C0 F1000
N20 G03 X20 Y0 Z5.5 I-20 J0 A30 C270 F3000
N30 G03 X0 Y20 R20 C180
M30
%
";

fn run(method: Method) -> (Vec<Setpoint>, nc_geom::segment::Path) {
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let kin = MachineKinematics::Paper;
    let parsed = nc_lang::parse(SRC).expect("parses");
    let path = build(&parsed, &kin, &bl).expect("builds");
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).expect("plans within the limits");
    // The plan's own check allows 1e-9 of rounding over a limit; so does this.
    let m = profile.margins;
    let ok = |x: f64| x <= 1.0 + 1e-9;
    for j in 0..5 {
        assert!(
            ok(m.velocity[j]) && ok(m.acceleration[j]) && ok(m.jerk[j]),
            "axis {j}: {m:?}"
        );
    }
    // The Taylor methods integrate the speed, so they may fall a rounding short of the end
    // when the plan has stopped; they finish at the creep speed `simulate` gives them.
    let creep = cfg.path_acc * PERIOD;
    let mut ip = Interpolator::new(&path, &profile, kin, cfg.rotary, method, PERIOD, creep);
    let mut out = Vec::new();
    loop {
        let sp = ip.step();
        out.push(sp);
        if sp.done {
            break;
        }
        assert!(out.len() < 200_000, "no end");
    }
    (out, path)
}

/// Check every setpoint against the helix and the linear turn of A and C.
fn check(sps: &[Setpoint], name: &str) {
    let (a1, c1) = (30f64.to_radians(), 270f64.to_radians());
    let sweep = TAU;
    let mut phi = 0.0f64;
    let mut prev = 0.0f64;
    let mut in_helix = 0;
    for sp in sps {
        let r = sp.p.x.hypot(sp.p.y);
        assert!((r - 20.0).abs() < 1e-6, "{name}: radius {r} at t {}", sp.t);
        if sp.block != 2 {
            continue;
        }
        in_helix += 1;
        let ang = sp.p.y.atan2(sp.p.x);
        let mut d = ang - prev;
        if d < -std::f64::consts::PI {
            d += TAU;
        }
        if d > std::f64::consts::PI {
            d -= TAU;
        }
        phi += d;
        prev = ang;
        // On a helix the path length is proportional to the angle: the fraction of the
        // block done is phi / sweep, and so is the fraction of the turn.
        let f = phi / sweep;
        let z = 10.0 - 4.5 * f;
        assert!((sp.p.z - z).abs() < 1e-6, "{name}: z {} vs {z}", sp.p.z);
        let (a, c) = (sp.joints[3], sp.joints[4]);
        assert!(
            (a - a1 * f).abs() < 1e-7 && (c - c1 * f).abs() < 1e-7,
            "{name}: at {:.3} of the helix A {} C {} deg, want {} {}",
            f,
            a.to_degrees(),
            c.to_degrees(),
            (a1 * f).to_degrees(),
            (c1 * f).to_degrees()
        );
    }
    assert!(in_helix > 100, "{name}: {in_helix} setpoints in the helix");
    let last = sps.last().unwrap();
    assert!(last.done);
    assert!((last.p.x - 0.0).abs() < 1e-6 && (last.p.y - 20.0).abs() < 1e-6);
    assert!((last.p.z - 5.5).abs() < 1e-9, "{}", last.p.z);
    assert!(
        (last.joints[3] - a1).abs() < 1e-12,
        "A ends at {}",
        last.joints[3]
    );
    assert!(
        (last.joints[4] - 180f64.to_radians()).abs() < 1e-12,
        "C ends at {}",
        last.joints[4].to_degrees()
    );
}

#[test]
fn a_helix_turning_the_tool_keeps_the_circle_and_turns_linearly_in_length() {
    let (sps, path) = run(Method::ArcLength);
    // The helix (degree 4, held to 1e-9 mm: 57 pieces) is more than one real-time piece: the turn
    // must carry on across the pieces.
    let helix = path.segments.iter().filter(|s| s.block == 2).count();
    assert!(helix > 1, "{helix} segments");
    check(&sps, "arclength");
    // By finite differences at the period, the rotary axes are continuous: no step larger
    // than their velocity limit allows (small_mill: 90 deg/s), anywhere, the joints
    // between the helix's pieces included.
    let (cfg, _) = nc_plan::fixtures::small_mill(PERIOD);
    for w in sps.windows(2) {
        for j in 3..5 {
            let v = (w[1].joints[j] - w[0].joints[j]).abs() / PERIOD;
            let lim = cfg.axes[j].velocity;
            assert!(
                v <= lim * (1.0 + 1e-9),
                "joint {j} at {v} rad/s at t {}",
                w[1].t
            );
        }
    }
}

#[test]
fn the_taylor_methods_turn_the_tool_the_same_way() {
    for (m, name) in [(Method::Taylor1, "taylor1"), (Method::Taylor2, "taylor2")] {
        let (sps, _) = run(m);
        check(&sps, name);
    }
}

#[test]
fn the_real_time_follower_streams_the_turning_arc_as_interpolated() {
    let (offline, path) = run(Method::ArcLength);
    let (cfg, _) = nc_plan::fixtures::small_mill(PERIOD);
    let kin = MachineKinematics::Paper;
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).unwrap();
    let (start, all) = chunks(path, &profile, &cfg.hold(), 64);
    let mut source = all.into_iter();
    let mut q = Queues::new();
    let (mut feeder, inlet) = q.split(64);
    let mut f = Follower::new(inlet, start, kin, cfg.rotary, cfg.hold());
    let mut streamed = Vec::new();
    loop {
        feeder.feed(&mut source);
        let sp = f.step();
        streamed.push(sp);
        if sp.done {
            break;
        }
        assert!(streamed.len() < 200_000, "no end");
    }
    assert_eq!(streamed.len(), offline.len());
    for (k, (s, o)) in streamed.iter().zip(&offline).enumerate() {
        assert!((s.p - o.p).norm() < 1e-9, "cycle {k}");
        for j in 0..5 {
            assert!(
                (s.joints[j] - o.joints[j]).abs() < 1e-9,
                "cycle {k} joint {j}"
            );
        }
    }
    check(&streamed, "follower");
}
