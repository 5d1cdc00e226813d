//! How far the follower may need to stop: the bound a planner cuts its chunks by
//! ([`stop_length`]), from the follower's own stop distance.

use crate::hold::{AxisHold, HoldConfig};
use crate::queue::{LOOKAHEAD, MAX_DEPTH, MIN_DEPTH};
use crate::tracker::{Jerk, Tracker};
use nc_geom::limits::Margins;

/// The length each chunk must have (`nc_plan::stream::chunk_length`) for a plan no faster
/// than `vmax` whose margins are at most `margins`:
/// what a program streamed before it is planned is cut by (its speed cap and
/// `nc_plan::verify::ceiling`).
pub fn stop_length(vmax: f64, margins: &Margins, hold: &HoldConfig, depth: usize) -> f64 {
    if vmax <= 0.0 || !vmax.is_finite() {
        return 0.0;
    }
    let axes = AxisHold::new(hold, margins);
    let held = depth.clamp(MIN_DEPTH, MAX_DEPTH).min(LOOKAHEAD);
    let spare = held.saturating_sub(2).max(1) as f64;
    1.25 * stop_bound(hold, &axes, vmax) / spare
}

/// Upper bound of the distance the follower needs to stop from the full plan at speed `v`:
/// [`super::Follower`]'s stop distance at override 1, its rate as high as it may be.
fn stop_bound(hold: &HoldConfig, axes: &AxisHold, v: f64) -> f64 {
    let jerk = Jerk {
        path: hold.jerk / v,
        cap: 1.0,
    };
    // From k = 1 with the rate as high as it may be there: the follower's own bound.
    let mut t = Tracker::new();
    t.r = (hold.acc / v).min(axes.rate(1.0));
    t.stop_distance(v, hold.acc / v, jerk, hold.period, axes)
}
