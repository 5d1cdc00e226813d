//! The tracker on its own, on generated axes, plans and operators: whatever the targets
//! and whenever they change, k stays in [0, 1], a period covers between none and one
//! period of plan time, the rate changes by at most a step of what the path and the axes
//! allow, and the axes' terms of the jerk (`3 k k' a` and `k'' w`, see the crate's text)
//! stay within what the plan leaves them.

use super::{Jerk, Tracker};
use crate::hold::{AxisHold, HoldConfig};
use nc_geom::limits::{AxisLimit, Margins};
use proptest::prelude::*;

/// An axis: velocity, acceleration as velocity / (0.01..1 s), jerk as acceleration /
/// (0.005..0.5 s).
fn axis() -> impl Strategy<Value = AxisLimit> {
    (1.0f64..500.0, 0.01f64..1.0, 0.005f64..0.5).prop_map(|(v, ta, tj)| AxisLimit {
        velocity: v,
        acceleration: v / ta,
        jerk: v / ta / tj,
    })
}

/// A plan's margins: every fraction in 0..=1.
fn margins() -> impl Strategy<Value = Margins> {
    let f = || prop::array::uniform5(0.0f64..=1.0);
    (f(), f(), f()).prop_map(|(velocity, acceleration, jerk)| Margins {
        velocity,
        acceleration,
        jerk,
        chord: 0.0,
        cycles: 0,
    })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 300,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn the_override_and_its_rate_keep_every_bound(
        axes in prop::array::uniform5(axis()),
        m in margins(),
        v in 1.0f64..300.0,
        targets in prop::collection::vec((0.0f64..=1.0, 1usize..400), 1..12),
        period in prop::sample::select(vec![0.00025, 0.001, 0.002]),
    ) {
        let hold = HoldConfig { period, acc: 500.0, jerk: 10_000.0, axes };
        let ax = AxisHold::new(&hold, &m);
        let jerk = Jerk { path: hold.jerk / v, cap: 1.0 };
        let rmax = hold.acc / v;
        let mut t = Tracker::new();
        for (target, periods) in targets {
            for _ in 0..periods {
                let (k0, r0) = (t.k, t.r);
                let rates = t.rate_bound(rmax, jerk, period, &ax);
                let step = jerk.at(&ax, (k0 + period * r0.max(0.0) + jerk.path * period * period).min(1.0));
                let covered = t.track(target, rates, jerk, period, &ax);
                prop_assert!((0.0..=1.0).contains(&t.k), "k {}", t.k);
                prop_assert!(covered >= 0.0 && covered <= period * (1.0 + 1e-12), "{covered}");
                let dr = (t.r - r0).abs();
                prop_assert!(
                    dr <= step * period * (1.0 + 1e-9) + 1e-12,
                    "rate {r0} -> {} (step {} a period) toward {target} at k {k0}",
                    t.r, step * period
                );
                // The rate within what the axes allow where k stands.
                let k_hi = t.k.max(k0);
                prop_assert!(
                    t.r.abs() <= ax.rate(k_hi) * (1.0 + 1e-9) + 1e-12
                        || t.r.abs() <= r0.abs(),
                    "rate {} over the axes' {} at k {k_hi}", t.r, ax.rate(k_hi)
                );
            }
        }
    }
}
