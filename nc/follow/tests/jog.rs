//! Jogging, proven on generated inputs: drawn axes (limits, travel, period) and drawn
//! operator sessions (continuous jogs held and released, or left to the dead-man, reversed
//! while moving, driven into the travel's ends; incremental jogs to drawn targets). Every
//! setpoint sequence holds the axis's velocity, acceleration and jerk by finite differences
//! at the period and stays within the travel; a jog left alone stops by the dead-man within
//! its window and a stop; an incremental jog lands on its target exactly.
//!
//! Cases: `JOG_CASES` (default 64). The jog allocates nothing (a counting allocator).

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

use nc_follow::jog::{Jog, JogLimits, JogRefused};
use proptest::prelude::*;

mod common;
use common::{axis, stop_periods, Check};

#[derive(Clone, Copy, Debug)]
enum Act {
    /// Continuous jog at `frac` of the velocity limit for `periods`, renewed every `renew`
    /// periods, then released (`release`) or left to the dead-man.
    Hold {
        frac: f64,
        periods: u32,
        renew: u32,
        release: bool,
    },
    /// Incremental jog to `at` (a fraction of the travel) at `speed` of the limit.
    To { at: f64, speed: f64 },
}

fn act() -> impl Strategy<Value = Act> {
    prop_oneof![
        (
            prop_oneof![-1.0..-0.01f64, 0.01..1.0f64],
            1u32..3000,
            1u32..60,
            any::<bool>()
        )
            .prop_map(|(frac, periods, renew, release)| Act::Hold {
                frac,
                periods,
                renew,
                release
            }),
        (0.0..=1.0f64, 0.01..=1.0f64).prop_map(|(at, speed)| Act::To { at, speed }),
    ]
}

const DEADMAN: u32 = 100;

fn session(lim: JogLimits, period: f64, start: f64, acts: &[Act]) -> Result<(), TestCaseError> {
    let mut jog = Jog::new(start, lim, period, DEADMAN);
    let mut check = Check::new(start, lim, period);
    let stop_n = stop_periods(&lim, period);
    for act in acts {
        match *act {
            Act::Hold {
                frac,
                periods,
                renew,
                release,
            } => {
                jog.velocity(frac * lim.velocity)
                    .map_err(|e| TestCaseError::fail(e.to_string()))?;
                for k in 0..periods {
                    if k % renew == 0 {
                        jog.renew();
                    }
                    check.see(jog.step())?;
                }
                if release {
                    jog.stop();
                } else {
                    jog.renew();
                }
                // At rest within the dead-man's window and a stop (released: a stop).
                let within = if release { stop_n } else { DEADMAN + stop_n };
                let mut k = 0;
                while !jog.at_rest() {
                    prop_assert!(k < within, "still moving {k} periods after the release");
                    check.see(jog.step())?;
                    k += 1;
                }
            }
            Act::To { at, speed } => {
                let target = lim.min + at * (lim.max - lim.min);
                prop_assert!(jog.at_rest());
                jog.to(target, speed * lim.velocity)
                    .map_err(|e| TestCaseError::fail(e.to_string()))?;
                let mut k = 0u64;
                loop {
                    let p = jog.step();
                    check.see(p)?;
                    if jog.at_rest() {
                        prop_assert_eq!(p, target, "lands exactly");
                        break;
                    }
                    k += 1;
                    prop_assert!(k < 50_000_000, "never arrives");
                }
            }
        }
    }
    Ok(())
}

fn cases() -> u32 {
    std::env::var("JOG_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn every_jog_holds_every_limit_and_the_travel(
        (lim, period) in axis(),
        start in 0.0..=1.0f64,
        acts in prop::collection::vec(act(), 1..6),
    ) {
        let start = lim.min + start * (lim.max - lim.min);
        session(lim, period, start, &acts)?;
    }
}

fn axis_x() -> JogLimits {
    JogLimits {
        velocity: 100.0,
        acceleration: 1000.0,
        jerk: 50_000.0,
        min: -10.0,
        max: 10.0,
    }
}

#[test]
fn a_continuous_jog_into_the_travels_end_stops_short_of_it() {
    let mut jog = Jog::new(0.0, axis_x(), 0.001, u32::MAX);
    jog.velocity(100.0).unwrap();
    let mut last = 0.0;
    for _ in 0..5_000 {
        last = jog.step();
    }
    assert!(jog.at_rest() && jog.limited());
    assert!(last <= 10.0 && last > 9.0, "{last}");
    // Back out of it.
    jog.velocity(-10.0).unwrap();
    for _ in 0..100 {
        last = jog.step();
    }
    assert!(last < 9.9, "{last}");
}

#[test]
fn a_jog_left_alone_stops_by_the_dead_man() {
    let mut jog = Jog::new(0.0, axis_x(), 0.001, 200);
    jog.velocity(5.0).unwrap();
    let mut k = 0;
    while !jog.at_rest() {
        jog.step();
        k += 1;
        assert!(k < 10_000);
    }
    // 200 periods of 1 ms, then a stop from 5 mm/s.
    assert!((200..260).contains(&k), "{k}");
}

#[test]
fn refusals_leave_the_jog_as_it_was() {
    let mut jog = Jog::new(1.0, axis_x(), 0.001, 200);
    assert_eq!(
        jog.velocity(150.0),
        Err(JogRefused::Speed {
            speed: 150.0,
            limit: 100.0
        })
    );
    assert!(jog.velocity(0.0).is_err());
    assert!(jog.velocity(f64::NAN).is_err());
    assert_eq!(
        jog.to(12.0, 10.0),
        Err(JogRefused::OutsideTravel {
            target: 12.0,
            min: -10.0,
            max: 10.0
        })
    );
    assert!(jog.at_rest());
    jog.velocity(10.0).unwrap();
    jog.step();
    assert_eq!(jog.to(5.0, 10.0), Err(JogRefused::Moving));
    assert_eq!(
        JogRefused::Moving.to_string(),
        "an incremental jog starts from rest: the axis is moving"
    );
}

#[test]
fn jogging_allocates_nothing() {
    let mut jog = Jog::new(0.0, axis_x(), 0.001, 50);
    test_support::arm_this_thread();
    jog.velocity(80.0).unwrap();
    for k in 0..3_000 {
        if k == 700 {
            jog.velocity(-30.0).unwrap();
        }
        if k % 20 == 0 && k < 1_500 {
            jog.renew();
        }
        jog.step();
    }
    jog.to(3.0, 50.0).unwrap();
    for _ in 0..3_000 {
        jog.step();
    }
    let events = test_support::disarm_this_thread();
    assert_eq!(events, 0, "heap events while jogging");
    assert_eq!(jog.state().0, 3.0);
}
