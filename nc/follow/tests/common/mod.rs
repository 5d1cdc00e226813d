//! What the jog tests share: drawn axes, the setpoints' check by finite differences, and
//! how long a stop may take.
#![allow(dead_code)]

use nc_follow::jog::JogLimits;
use proptest::prelude::*;

/// An axis: velocity 1..500, acceleration 10..10 000, jerk 10 to 10 000 times the
/// acceleration a second, travel 1..1 000 wide, period 1, 2 or 4 ms.
pub fn axis() -> impl Strategy<Value = (JogLimits, f64)> {
    (
        0.0..1.0f64,
        0.0..1.0f64,
        0.0..1.0f64,
        1.0..1000.0f64,
        prop_oneof![Just(0.001), Just(0.002), Just(0.004)],
    )
        .prop_map(|(v, a, j, width, period)| {
            let acceleration = 10.0 * 1000f64.powf(a);
            (
                JogLimits {
                    velocity: 500f64.powf(v),
                    acceleration,
                    jerk: acceleration * 10.0 * 1000f64.powf(j),
                    min: -width / 3.0,
                    max: 2.0 * width / 3.0,
                },
                period,
            )
        })
}

/// The setpoints, checked window by window as they come.
pub struct Check {
    lim: JogLimits,
    period: f64,
    last: [f64; 3],
    n: u64,
}

impl Check {
    pub fn new(start: f64, lim: JogLimits, period: f64) -> Self {
        Check {
            lim,
            period,
            last: [start; 3],
            n: 0,
        }
    }

    pub fn see(&mut self, p: f64) -> Result<(), TestCaseError> {
        let [p0, p1, p2] = self.last;
        let ts = self.period;
        let v = (p - p2).abs() / ts;
        let a = (p - 2.0 * p2 + p1).abs() / (ts * ts);
        let j = (p - 3.0 * p2 + 3.0 * p1 - p0).abs() / (ts * ts * ts);
        let l = &self.lim;
        // Rounding of positions near 1 000 (1e-13) over the period's powers.
        let noise = 1e-12 * (1.0 + p.abs());
        prop_assert!(
            v <= l.velocity * (1.0 + 1e-9) + noise / ts,
            "v {v} > {} at {}",
            l.velocity,
            self.n
        );
        prop_assert!(
            a <= l.acceleration * (1.0 + 1e-9) + 4.0 * noise / (ts * ts),
            "a {a} > {} at {}",
            l.acceleration,
            self.n
        );
        prop_assert!(
            j <= l.jerk * (1.0 + 1e-9) + 8.0 * noise / (ts * ts * ts),
            "j {j} > {} at {}",
            l.jerk,
            self.n
        );
        prop_assert!(
            p >= l.min - 1e-9 && p <= l.max + 1e-9,
            "{p} outside {}..{}",
            l.min,
            l.max
        );
        self.last = [p1, p2, p];
        self.n += 1;
        Ok(())
    }
}

/// Periods a stop can take from anywhere: the longest change from full speed, and two.
pub fn stop_periods(lim: &JogLimits, period: f64) -> u32 {
    let t = 2.0 * lim.velocity / lim.acceleration + 2.0 * lim.acceleration / lim.jerk;
    (t / period).ceil() as u32 + 2
}
