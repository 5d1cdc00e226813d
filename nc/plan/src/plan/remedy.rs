//! What the planner does where the setpoint check finds a limit broken: the caps on the
//! stations a violation's stencil holds ([`cap_for`]), and where those change nothing, the
//! caps widened to the stations on either side ([`widening`], [`cap_widened`]), the path's
//! share of the axes' limits lowered ([`lower_share`]), or the ceilings lowered from where
//! they are ([`Remedy`]).

use super::stations::{Station, AXIS_SHARE_FLOOR, AXIS_SHARE_LEAST};
use super::{CAP_MARGIN, V_JOINT_FLOOR};
use crate::verify::{Quantity, Violation};
use nc_geom::limits::V_FLOOR;

/// Cap the stations violation `v`'s stencil holds, whose speed must drop by `factor`. An
/// axis's jerk over its limit lowers the path's share of it there too (slowing down does
/// not lower the path's own term, `q_s s'''`; an acceleration over it is a corner's
/// velocity jump or the curvature's term, which slowing down lowers). A joint's step
/// ([`below_floor`]) is capped down to [`V_JOINT_FLOOR`], every other cap to the floor.
pub(super) fn cap_for(st: &mut [Station], v: &Violation, factor: f64) {
    let floor = match below_floor(v) {
        true => V_JOINT_FLOOR,
        false => V_FLOOR,
    };
    cap(st, v, v.s, factor, floor);
}

/// Cap the stations of violation `v`'s [`widening`] `w`. These caps stop at the floor
/// speed whatever the violation: a joint's step widened to the stations beside it would
/// have them crawl.
pub(super) fn cap_widened(st: &mut [Station], v: &Violation, w: &Widening) {
    cap(st, v, w.s, w.factor, V_FLOOR);
}

fn cap(st: &mut [Station], v: &Violation, s: (f64, f64), factor: f64, floor: f64) {
    let share = matches!(v.quantity, Quantity::Jerk).then_some(AXIS_SHARE_LEAST);
    super::schedule::cap_stations(st, s, (v.v * factor * CAP_MARGIN, floor), share);
}

/// Violation `v` is one the caps may follow below the floor speed, down to
/// [`V_JOINT_FLOOR`]: a joint's velocity step, in proportion to the speed at the joint (a
/// point: no stretch crawls). A joint passed at the speed its rate jump allows (7.1e-4
/// mm/s) measured C's acceleration 1.48x its limit, the ramp's own term on the side of the
/// fast move added, and the program was refused where its post ran. (An axis's velocity
/// too took a stretch below the floor: 27 of `adversarial.rs`'s 10 000 programs then
/// planned crawls of more than 800 s where they were refused; not kept.)
pub(super) fn below_floor(v: &Violation) -> bool {
    v.kink
}

/// The caps a violation's widening puts on the stations on either side of its stencil.
pub(super) struct Widening {
    pub(super) s: (f64, f64),
    pub(super) factor: f64,
}

/// Where violation `v`'s caps go once widened, and by what factor; None if slowing does
/// not help it.
pub(super) fn widening(st: &[Station], v: &Violation) -> Option<Widening> {
    let factor = v.speed_factor().filter(|f| f.is_finite())?;
    let a = st.partition_point(|x| x.s < v.s.0).saturating_sub(1);
    let b = st.partition_point(|x| x.s <= v.s.1).min(st.len() - 1);
    Some(Widening {
        s: (st[a].s, st[b].s),
        factor,
    })
}

impl Widening {
    /// The caps would hold some station to less than [`CRAWL`] of its ceiling: the path
    /// would crawl over the stretch to it (a station 0.063 mm before a dwell, at 31.5
    /// mm/s, held to 0.0012 mm/s: 52 s).
    fn crawls(&self, st: &[Station], v: &Violation) -> bool {
        let cap = v.v * self.factor * CAP_MARGIN;
        let (a, b) = super::schedule::stations_over(st, self.s);
        st[a..b].iter().any(|x| cap < CRAWL * x.vlim)
    }
}

/// Share of a station's ceiling below which a widened cap counts as a crawl.
const CRAWL: f64 = 0.25;

/// What a violation asks for where widening its caps would make the path crawl, and the
/// caps on the stations its stencil holds changed nothing.
pub(super) enum Remedy {
    /// Its stencil holds a station at the floor speed (a dwell, a joint passed at the
    /// floor), which no cap lowers: what is left of a jerk there is the ramp's own term
    /// (`q_s s'''`), which the path's share of the axes' limits sets ([`lower_share`]).
    Share(Violation),
    /// Its stencil's speed is over the ceilings of the stations it holds (the plan keeps
    /// them; the ramp between them and the next overshoots), as at a joint whose rate jump
    /// passes 3x C's jerk at the speed capped: those ceilings drop by the factor the
    /// violation asks, from where they are.
    Lower(Violation, f64),
}

impl Remedy {
    pub(super) fn for_crawl(st: &[Station], v: &Violation) -> Option<Remedy> {
        let w = widening(st, v)?;
        if !w.crawls(st, v) {
            return None;
        }
        let (a, b) = super::schedule::stations_over(st, v.s);
        let held = &st[a..b];
        if held.iter().any(|x| x.vlim <= V_FLOOR) {
            return (v.quantity == Quantity::Jerk).then_some(Remedy::Share(*v));
        }
        held.iter()
            .any(|x| x.vlim < v.v)
            .then_some(Remedy::Lower(*v, w.factor))
    }

    pub(super) fn apply(&self, st: &mut [Station]) {
        match self {
            Remedy::Share(v) => {
                lower_share(st, v);
            }
            Remedy::Lower(v, factor) => {
                let (a, b) = super::schedule::stations_over(st, v.s);
                for x in &mut st[a..b] {
                    if x.vlim < v.v {
                        x.vlim = (x.vlim * factor * CAP_MARGIN).max(V_FLOOR.min(x.vlim));
                    }
                }
            }
        }
    }
}

/// An axis's jerk over its limit at the slowest feed, in a window that starts at rest (it
/// would be refused): the path's own term `q_s s'''` is what is left, so the stations the
/// stencil holds get a lower share of the axes' limits (the path's jerk and acceleration
/// there), by the ratio the measurement asks for (a `G01` turning the tool 40 degrees
/// within a degree of the vertical: C's rate peaks over 2 um, between the stations, and
/// C's jerk stayed 1.04x its limit at half the share). False where the share would go
/// below [`AXIS_SHARE_FLOOR`], or for any other quantity.
pub(super) fn lower_share(st: &mut [Station], v: &Violation) -> bool {
    if v.quantity != Quantity::Jerk || !(v.value > v.limit && v.limit > 0.0) {
        return false;
    }
    let (a, b) = super::schedule::stations_over(st, v.s);
    let Some(least) = st[a..b].iter().map(|x| f64::from(x.share)).reduce(f64::min) else {
        return false;
    };
    let share = least.min(AXIS_SHARE_LEAST) * v.limit / v.value * CAP_MARGIN;
    if share < AXIS_SHARE_FLOOR {
        return false;
    }
    for x in &mut st[a..b] {
        x.share = x.share.min(share as f32);
    }
    true
}
