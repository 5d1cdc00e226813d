//! The length a planner cuts its chunks by (`stop_length`): the follower's stop distance
//! from full speed, shared over the chunks held. It grows with the speed and with the
//! margins the plan may use (a program streamed before it is planned is cut by the
//! check's ceiling), and it is finite for every plan a planner accepts. `--nocapture`
//! prints it on the small mill of the generated-input suite, for docs/measurements.md.

use nc_follow::{stop_length, HoldConfig};
use nc_geom::limits::{AxisLimit, Margins};

fn small_mill() -> HoldConfig {
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
    // `PlanConfig::hold` of the small mill: half its path acceleration and jerk.
    HoldConfig {
        period: 0.001,
        acc: 500.0,
        jerk: 10000.0,
        axes: [lin, lin, lin, rot, rot],
    }
}

fn margins(x: f64) -> Margins {
    Margins {
        velocity: [x; 5],
        acceleration: [x; 5],
        jerk: [x; 5],
        chord: 1.0,
        cycles: 0,
    }
}

#[test]
fn the_stop_length_grows_with_the_speed_and_the_margins() {
    let hold = small_mill();
    for (name, m) in [("ceiling", 1.0), ("half", 0.5), ("a tenth", 0.1)] {
        let mut last = 0.0;
        for v in [10.0, 50.0, 166.0, 250.0] {
            let l = stop_length(v, &margins(m), &hold, 64);
            eprintln!("stop length, {name} margins, {v} mm/s: {l:.3} mm");
            assert!(l.is_finite() && l > last, "{name} {v}: {l} after {last}");
            let fuller = stop_length(v, &margins((m * 1.5).min(1.0)), &hold, 64);
            assert!(fuller >= l * (1.0 - 1e-12), "{name} {v}: {fuller} < {l}");
            last = l;
        }
    }
}
