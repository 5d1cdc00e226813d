//! Jogging along a line (`nc_follow::jog_line`), proven on generated inputs: drawn axes X
//! Y Z (limits, travel, one period), a drawn table-tilting machine standing at drawn
//! angles, a drawn direction (the workpiece's X, Y or Z, the tool axis, or any), a drawn
//! start inside the travel, and drawn operator sessions (continuous jogs held, released or
//! left to the dead-man, driven into the travel; incremental jogs). Every axis's setpoints
//! hold its velocity, acceleration and jerk by finite differences at the period and stay in
//! its travel; the tool tip stays on the line in the workpiece (its axis still: the rotary
//! axes do not move), and an incremental jog lands on its target exactly.
//!
//! Cases: `JOG_LINE_CASES` (default 64). Nothing is allocated while jogging.

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

mod common;
use common::{axis, stop_periods, Check};

use nalgebra::Vector3;
use nc_follow::jog::JogLimits;
use nc_follow::jog_line::{tool_direction, workpiece_direction, LineJog, LineRefused};
use nc_geom::kinematics::{Kinematics, MachineKinematics, Tilt};
use proptest::prelude::*;

const DEADMAN: u32 = 100;

#[derive(Clone, Copy, Debug)]
enum Act {
    Hold {
        frac: f64,
        periods: u32,
        release: bool,
    },
    To {
        at: f64,
        speed: f64,
    },
}

fn act() -> impl Strategy<Value = Act> {
    prop_oneof![
        (
            prop_oneof![-1.0..-0.01f64, 0.01..1.0f64],
            1u32..3000,
            any::<bool>()
        )
            .prop_map(|(frac, periods, release)| Act::Hold {
                frac,
                periods,
                release
            }),
        (0.0..=1.0f64, 0.01..=1.0f64).prop_map(|(at, speed)| Act::To { at, speed }),
    ]
}

fn kinematics() -> impl Strategy<Value = MachineKinematics> {
    (
        any::<bool>(),
        prop::array::uniform3(-200.0..200.0f64),
        prop::array::uniform3(-200.0..200.0f64),
    )
        .prop_map(|(a, t, c)| MachineKinematics::Trt {
            tilt: if a { Tilt::A } else { Tilt::B },
            tilt_point: Vector3::from(t),
            c_point: Vector3::from(c),
        })
}

/// Where the jog goes: 0..3 the workpiece's X Y Z, 3 the tool axis, 4 any.
fn direction(kin: &MachineKinematics, which: u8, any: [f64; 3], tilt: f64, c: f64) -> [f64; 3] {
    match which {
        0..=2 => {
            let mut w = [0.0; 3];
            w[which as usize] = 1.0;
            workpiece_direction(kin, w, tilt, c)
        }
        3 => tool_direction(kin, tilt, c),
        _ => any,
    }
}

/// The tool tip's distance from the workpiece line through where it started.
fn off_line(
    kin: &MachineKinematics,
    p: [f64; 3],
    o: [f64; 3],
    d: [f64; 3],
    tilt: f64,
    c: f64,
) -> f64 {
    let w = |x: [f64; 3]| kin.unplace(&Vector3::from(x), tilt, c);
    let (wp, wo) = (w(p), w(o));
    let wd = w([o[0] + d[0], o[1] + d[1], o[2] + d[2]]) - wo;
    let r = wp - wo;
    (r - wd * r.dot(&wd) / wd.norm_squared()).norm()
}

#[allow(clippy::too_many_arguments)]
fn session(
    axes: [JogLimits; 3],
    period: f64,
    kin: &MachineKinematics,
    tilt: f64,
    c: f64,
    origin: [f64; 3],
    dir: [f64; 3],
    acts: &[Act],
) -> Result<(), TestCaseError> {
    let mut jog = match LineJog::new(origin, dir, &axes, period, DEADMAN) {
        Ok(j) => j,
        Err(LineRefused::Direction { .. }) => return Ok(()),
        Err(e) => return Err(TestCaseError::fail(e.to_string())),
    };
    let d = jog.direction();
    let line = jog.limits();
    let mut checks: Vec<Check> = (0..3)
        .map(|i| Check::new(origin[i], axes[i], period))
        .collect();
    let stop_n = stop_periods(&line, period);
    let mut see = |p: [f64; 3]| -> Result<(), TestCaseError> {
        for (k, check) in checks.iter_mut().enumerate() {
            check.see(p[k])?;
        }
        let off = off_line(kin, p, origin, d, tilt, c);
        prop_assert!(
            off < 1e-9 * (1.0 + p.iter().map(|x| x.abs()).sum::<f64>()),
            "{off} mm off the line"
        );
        Ok(())
    };
    test_support::arm_this_thread();
    for act in acts {
        match *act {
            Act::Hold {
                frac,
                periods,
                release,
            } => {
                let v = frac * line.velocity.min(1e6);
                if jog.velocity(v).is_err() {
                    continue;
                }
                for _ in 0..periods {
                    jog.renew();
                    see(jog.step())?;
                }
                if release {
                    jog.stop();
                }
                let within = if release { stop_n } else { DEADMAN + stop_n };
                let mut k = 0;
                while !jog.at_rest() {
                    prop_assert!(k < within, "still moving {k} periods after the release");
                    see(jog.step())?;
                    k += 1;
                }
            }
            Act::To { at, speed } => {
                let target = line.min + at * (line.max - line.min);
                jog.to(target, speed * line.velocity.min(1e6))
                    .map_err(|e| TestCaseError::fail(e.to_string()))?;
                let mut k = 0u64;
                loop {
                    let p = jog.step();
                    see(p)?;
                    if jog.at_rest() {
                        prop_assert_eq!(p, jog.at(target), "lands exactly");
                        break;
                    }
                    k += 1;
                    prop_assert!(k < 50_000_000, "never arrives");
                }
            }
        }
    }
    let allocated = test_support::disarm_this_thread();
    prop_assert_eq!(allocated, 0, "allocations while jogging");
    Ok(())
}

fn cases() -> u32 {
    std::env::var("JOG_LINE_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn every_line_jog_holds_every_axis_and_stays_on_its_line(
        ((x, period), (y, _), (z, _)) in (axis(), axis(), axis()),
        kin in kinematics(),
        tilt in -1.9..1.9f64,
        c in -7.0..7.0f64,
        which in 0u8..5,
        any in prop::array::uniform3(-1.0..1.0f64),
        start in prop::array::uniform3(0.0..=1.0f64),
        acts in prop::collection::vec(act(), 1..5),
    ) {
        let axes = [x, y, z];
        let origin = [0, 1, 2].map(|i| axes[i].min + start[i] * (axes[i].max - axes[i].min));
        let dir = direction(&kin, which, any, tilt, c);
        session(axes, period, &kin, tilt, c, origin, dir, &acts)?;
    }
}

fn axis_mm(min: f64, max: f64) -> JogLimits {
    JogLimits {
        velocity: 100.0,
        acceleration: 1000.0,
        jerk: 50_000.0,
        min,
        max,
    }
}

#[test]
fn a_diagonal_jog_takes_the_slower_share_and_stops_at_the_first_travel() {
    let axes = [
        axis_mm(-10.0, 10.0),
        axis_mm(-100.0, 100.0),
        axis_mm(-100.0, 100.0),
    ];
    // Along X + Y: each axis carries 1/sqrt 2 of the line, so the line may go sqrt 2 times
    // faster; X's travel ends it at 10 sqrt 2.
    let jog = LineJog::new([0.0; 3], [1.0, 1.0, 0.0], &axes, 0.001, 100).unwrap();
    let l = jog.limits();
    let r2 = 2f64.sqrt();
    assert!((l.velocity - 100.0 * r2).abs() < 1e-9, "{l:?}");
    assert!(
        (l.max - 10.0 * r2).abs() < 1e-9 && (l.min + 10.0 * r2).abs() < 1e-9,
        "{l:?}"
    );
    let mut jog = jog;
    jog.velocity(100.0).unwrap();
    let mut last = [0.0; 3];
    for _ in 0..3000 {
        jog.renew();
        last = jog.step();
    }
    assert!(jog.at_rest() && jog.limited());
    assert!(
        last[0] <= 10.0 && last[0] > 9.0 && (last[0] - last[1]).abs() < 1e-12,
        "{last:?}"
    );
}

#[test]
fn refusals_say_why() {
    let axes = [
        axis_mm(-10.0, 10.0),
        axis_mm(-10.0, 10.0),
        axis_mm(-10.0, 10.0),
    ];
    let e = LineJog::new([0.0; 3], [0.0; 3], &axes, 0.001, 100).unwrap_err();
    assert!(e.to_string().contains("not a direction"), "{e}");
    let e = LineJog::new([0.0, 0.0, 11.0], [1.0, 0.0, 0.0], &axes, 0.001, 100).unwrap_err();
    assert_eq!(
        e.to_string(),
        "the Z axis stands at 11, outside its travel -10..10: jog it alone back inside"
    );
    let mut jog = LineJog::new([0.0; 3], [1.0, 0.0, 0.0], &axes, 0.001, 100).unwrap();
    assert!(jog.to(20.0, 10.0).is_err());
    assert!(jog.velocity(1000.0).is_err());
    assert!(jog.at_rest());
}

#[test]
fn the_tool_axis_of_a_table_machine_is_its_z() {
    let kin = MachineKinematics::Trt {
        tilt: Tilt::A,
        tilt_point: Vector3::new(0.0, 0.0, 100.0),
        c_point: Vector3::new(10.0, 0.0, 0.0),
    };
    let d = tool_direction(&kin, 0.5, 1.2);
    assert!(
        (d[0]).abs() < 1e-12 && (d[1]).abs() < 1e-12 && (d[2] - 1.0).abs() < 1e-12,
        "{d:?}"
    );
    // The workpiece's X with the table turned by C is a diagonal of the machine.
    let x = workpiece_direction(&kin, [1.0, 0.0, 0.0], 0.0, std::f64::consts::FRAC_PI_4);
    assert!(
        (x[0].abs() - x[1].abs()).abs() < 1e-12 && x[2].abs() < 1e-12,
        "{x:?}"
    );
}
