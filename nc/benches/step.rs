//! One period of the real-time step on the paper's example: feed profile, parameter update,
//! both curve evaluations, tool axis, A/C angles, inverse kinematics. The paper reports
//! ~28 us per period (second-order method, Pentium IV 2.4 GHz); the target here is <= 1 us.
//!
//! Run: `cargo bench -p nc --bench step`. The periods of the whole program are cycled
//! through, so the figure is the mean over every phase of the motion.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use nc::interp::{Interpolator, Method};
use nc::kinematics::{MachineKinematics, RotaryLimits, Tilt};
use nc::plan::{plan, AxisLimit, PlanConfig};
use nc::segment::{build, BuildLimits};
use std::hint::black_box;
use std::time::Instant;

const PAPER: &str = include_str!("../../tests/data/paper-example.nc");

fn bench(c: &mut Criterion) {
    let program = nc::parse::parse(PAPER).expect("paper example parses");
    let lin = AxisLimit {
        velocity: 250.0,
        acceleration: 2500.0,
        jerk: 50000.0,
    };
    let rot = AxisLimit {
        velocity: 90f64.to_radians(),
        acceleration: 900f64.to_radians(),
        jerk: 20000f64.to_radians(),
    };
    let cfg = PlanConfig {
        period: 0.002,
        chord_tol: 0.001,
        path_acc: 1000.0,
        path_jerk: 20000.0,
        axes: [lin, lin, lin, rot, rot],
        rotary: RotaryLimits::UNLIMITED,
    };
    let limits = BuildLimits {
        rapid_mm_s: 250.0,
        max_feed_mm_s: 166.0,
        rotary: cfg.rotary,
    };
    let machines = [
        ("paper", MachineKinematics::Paper),
        (
            "xyzac-trt",
            MachineKinematics::Trt {
                tilt: Tilt::A,
                tilt_point: Vector3::new(0.0, 0.0, -50.0),
                c_point: Vector3::zeros(),
            },
        ),
    ];
    let mut group = c.benchmark_group("step");
    for (kname, kin) in machines {
        let path = build(&program, &kin, &limits).expect("paper example builds");
        let profile = plan(&path, &kin, &cfg);
        for method in [Method::ArcLength, Method::Taylor1, Method::Taylor2] {
            group.bench_function(format!("{kname}/{}", method.name()), |b| {
                b.iter_custom(|iters| {
                    let new = || {
                        Interpolator::new(&path, &profile, kin, cfg.rotary, method, cfg.period, 2.0)
                    };
                    let mut ip = new();
                    let start = Instant::now();
                    for _ in 0..iters {
                        let sp = black_box(ip.step());
                        if sp.done {
                            ip = new();
                        }
                    }
                    start.elapsed()
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
