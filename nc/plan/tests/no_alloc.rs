//! The per-period step must not touch the heap: a counting global allocator watches every
//! `Interpolator::step` over whole programs (>= 100 000 periods in all, all three methods,
//! paper and RTCP kinematics, 2 ms and 1 ms periods) and must see zero allocations, reallocations and frees.
//!
//! This file is its own test binary, so no other test's allocations are counted.

use nalgebra::Vector3;
use nc_geom::kinematics::{MachineKinematics, Tilt};
use nc_geom::segment::build;
use nc_plan::config::PlanConfig;
use nc_plan::interp::{Interpolator, Method};
use nc_plan::plan::plan;

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

const PROGRAMS: [&str; 4] = [
    include_str!("../../../tests/data/paper-example.nc"),
    include_str!("../../../tests/data/vertical-turns.nc"),
    include_str!("../../../tests/data/tight-curvature.nc"),
    include_str!("../../../tests/data/two-blocks-g2.nc"),
];

#[test]
fn step_never_allocates() {
    let (base, limits) = nc_plan::fixtures::small_mill(0.002);
    let kins = [
        MachineKinematics::Paper,
        MachineKinematics::Trt {
            tilt: Tilt::A,
            tilt_point: Vector3::new(0.0, 0.0, -50.0),
            c_point: Vector3::zeros(),
        },
    ];
    let mut periods = 0u64;
    for (src, period) in PROGRAMS.iter().flat_map(|p| [(p, 0.002), (p, 0.001)]) {
        let cfg = PlanConfig { period, ..base };
        let program = nc_lang::parse(src).expect("test program parses");
        for kin in kins {
            let path = build(&program, &kin, &limits).expect("test program builds");
            let profile = plan(&path, &kin, &cfg).unwrap();
            for method in [Method::ArcLength, Method::Taylor1, Method::Taylor2] {
                let mut ip =
                    Interpolator::new(&path, &profile, kin, cfg.rotary, method, cfg.period, 2.0);
                let mut sum = 0.0;
                test_support::arm_this_thread();
                loop {
                    let sp = ip.step();
                    sum += sp.joints[0];
                    periods += 1;
                    if sp.done || sp.cycle > 10_000_000 {
                        break;
                    }
                }
                let events = test_support::disarm_this_thread();
                assert!(sum.is_finite());
                assert_eq!(events, 0, "heap touched during {} steps", method.name());
            }
        }
    }
    assert!(periods >= 100_000, "only {periods} periods checked");
}
