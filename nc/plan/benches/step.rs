//! One period of the real-time step on the paper's example: feed profile, parameter update,
//! both curve evaluations, tool axis, A/C angles, inverse kinematics. The paper reports
//! ~28 us per period (second-order method, Pentium IV 2.4 GHz); the target here is <= 1 us.
//!
//! Run: `cargo bench -p nc --bench step`. The periods of the whole program are cycled
//! through, so the figure is the mean over every phase of the motion.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use nc_geom::kinematics::{MachineKinematics, Tilt};
use nc_geom::segment::build;
use nc_plan::interp::{Interpolator, Method};
use nc_plan::plan::plan;
use std::hint::black_box;
use std::time::Instant;

const PAPER: &str = include_str!("../../../tests/data/paper-example.nc");

fn bench(c: &mut Criterion) {
    let program = nc_lang::parse(PAPER).expect("paper example parses");
    let (cfg, limits) = nc_plan::fixtures::small_mill(0.002);
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
        let profile = plan(&path, &kin, &cfg).unwrap();
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
