//! The limits checked on the setpoints themselves, as the drives will receive them.
//!
//! The planner's ceilings (`crate::plan`) come from stations along the path; a peak of
//! curvature, of an axis derivative or of the C rate near the vertical tool can fall between
//! two stations. So the plan is not trusted: [`check`] runs the interpolator over the whole
//! plan at the machine period, exactly as `dnurbs simulate` and the real-time thread do, and
//! measures every axis on the setpoints it produces, by finite differences at the period:
//!
//! * velocity `(q[k] - q[k-1]) / Ts`, acceleration `(q[k] - 2 q[k-1] + q[k-2]) / Ts^2` and
//!   jerk `(q[k] - 3 q[k-1] + 3 q[k-2] - q[k-3]) / Ts^3` of every axis against its limit. The
//!   drives hold the start before the first setpoint and the end after the last, so the
//!   sequence is padded with copies of both; a step at the start or end counts.
//!   Jerk is not limited over a junction whose joint path is not G2-continuous (a corner
//!   or a change of curvature between blocks): there the velocity or the acceleration
//!   changes direction within one period by design (the corner policy in `crate::plan`).
//!   At such a junction the acceleration is also measured on the stencil centred on the
//!   junction itself, its worst phase ([`corner`]): a hold or an override shifts the phase at
//!   which the drives' setpoints meet a corner, and the limit must hold at any phase. And
//!   the jerk is measured on each side of it, on the four setpoints that end on the
//!   junction and the four that start there: the bound between phases ([`reserve`]) needs
//!   the jerk within its limit up to the corner, and a step of a joint at the junction
//!   (which no speed makes small) shows there. Where the jerk changes fast from one
//!   stencil to the next, it is also measured between the plan's phases ([`phases`]): a
//!   hold shifts the phase, and a feature passed within a period shows a different jerk at
//!   another.
//! * chord error: the largest distance of the cutter path between two setpoints from the
//!   straight chord between them (the drives interpolate linearly), measured at the quarter
//!   points of a curve's parameter interval and at every segment junction the chord spans.
//! * travel: every setpoint of every axis within the machine's travel.
//!
//! What it finds drives the planner (`crate::plan::plan` lowers the speed where a limit is
//! broken and plans again) and, where slowing cannot help, the refusal of the program.

use crate::config::PlanConfig;
use crate::interp::{Interpolator, Method};
use crate::profile::FeedProfile;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::limits::{reserve, Margins};
use nc_geom::scurve::Phase;
use nc_geom::segment::Path;
use sample::{sample, Ctx, Sample};
use stencil::{check_travel, check_window};
use trace::{TraceMark, MARK_EVERY};

/// What a limit bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    Velocity,
    Acceleration,
    Jerk,
    Chord,
    Travel,
    /// The rotary axes change solution within one period for the same tool axis: the
    /// other tilt sign with C half a turn on, or C a whole turn on. The kinematics does that
    /// only where following the tool on would leave a rotary travel; no feed can fix it.
    Branch,
}

impl Quantity {
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Velocity => "velocity",
            Quantity::Acceleration => "acceleration",
            Quantity::Jerk => "jerk",
            Quantity::Chord => "chord error",
            Quantity::Travel => "travel",
            Quantity::Branch => "rotary branch",
        }
    }

    /// How the quantity scales with the path speed: v^n (travel does not).
    pub fn speed_power(self) -> Option<i32> {
        match self {
            Quantity::Velocity => Some(1),
            Quantity::Acceleration | Quantity::Chord => Some(2),
            Quantity::Jerk => Some(3),
            Quantity::Travel | Quantity::Branch => None,
        }
    }
}

/// One broken limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Violation {
    pub quantity: Quantity,
    /// Joint index (X Y Z tilt C); 5 for the chord error of the cutter path.
    pub axis: usize,
    /// Cycle of the newest setpoint in the stencil, and its time (s).
    pub cycle: u64,
    pub t: f64,
    /// Segment of the newest setpoint.
    pub segment: usize,
    /// Path positions the stencil spans.
    pub s: (f64, f64),
    /// Highest planned path speed over the stencil.
    pub v: f64,
    /// The measured value and its limit (absolute; radians for rotary axes).
    pub value: f64,
    pub limit: f64,
    /// For [`Quantity::Branch`]: (tilt, C) before and after the change, radians.
    pub rotary: [[f64; 2]; 2],
    /// The acceleration of a kink at its worst phase ([`corner`]): the velocity jump, so
    /// the value, grows linearly with the speed `v` at the junction.
    pub kink: bool,
}

impl Violation {
    /// Factor by which the path speed must drop for this limit to hold, if slowing helps.
    pub fn speed_factor(&self) -> Option<f64> {
        let n = if self.kink {
            1
        } else {
            self.quantity.speed_power()?
        };
        Some((self.limit / self.value).powf(1.0 / f64::from(n)))
    }
}

/// The result of [`check`]: the margins, and at most one violation per cycle (the worst).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Checked {
    pub margins: Margins,
    pub violations: Vec<Violation>,
}

/// Relative slack for rounding: a value within it of the limit holds.
const SLACK: f64 = 1e-9;

/// The most any plan the planner accepts can reach: the shares of the axes' velocity and
/// acceleration that [`reserve`] leaves, the whole jerk and chord tolerance (with the
/// check's rounding slack). A plan streamed to the real-time thread is bounded by it before
/// it is whole.
pub fn ceiling(cfg: &PlanConfig) -> Margins {
    let share = |f: fn((f64, f64)) -> f64| -> [f64; 5] {
        core::array::from_fn(|j| f(reserve(&cfg.axes[j], cfg.period)) * (1.0 + SLACK))
    };
    Margins {
        velocity: share(|r| r.0),
        acceleration: share(|r| r.1),
        jerk: [1.0 + SLACK; 5],
        chord: 1.0 + SLACK,
        cycles: 0,
    }
}

/// Most periods a plan may take (24 h at 1 ms): a longer plan is refused, so neither the
/// check nor `dnurbs simulate` ever stops short of the program's end.
pub const MAX_CYCLES: u64 = 86_400_000;

/// Run the interpolator over `profile` at the period and measure every limit on its
/// setpoints. `smooth[k]` tells whether the junction at the start of segment k is
/// G2-continuous in the joints (from [`smooth_junctions`]).
pub fn check(
    path: &Path,
    profile: &FeedProfile,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    smooth: &[bool],
) -> Checked {
    check_from(path, profile, kin, cfg, smooth, None).0
}

/// As [`check`], and where `earlier` is given, start from its last mark before the first
/// phase in which `profile` differs from it: up to there the interpolator computes the same
/// setpoints, so their measurements (margins and violations) are taken over. Returns the
/// trace for the next round.
pub fn check_from(
    path: &Path,
    profile: &FeedProfile,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    smooth: &[bool],
    earlier: Option<Earlier>,
) -> (Checked, Trace) {
    check_marked(path, profile, kin, cfg, smooth, earlier, MARK_EVERY)
}

/// [`check_from`] with a mark every `every` periods.
fn check_marked(
    path: &Path,
    profile: &FeedProfile,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    smooth: &[bool],
    earlier: Option<Earlier>,
    every: u64,
) -> (Checked, Trace) {
    let ctx = Ctx {
        path,
        profile,
        kin,
        cfg,
        smooth,
    };
    let mut out = Checked::default();
    let mut trace = Trace::default();
    let ts = cfg.period;
    let mut ip = Interpolator::new(path, profile, *kin, cfg.rotary, Method::ArcLength, ts, 0.0);
    let mut cursor = 0;
    // The last four samples, newest last; padded with the start pose (the drives are there).
    let first = sample(&ip.step(), 0, profile, &mut cursor);
    let mut win = [first; 4];
    // The two setpoints before the window's oldest (the jerk of the stencils before).
    let mut older = [first; 2];
    // Padding past the end: three more copies of the last setpoint.
    let mut tail = 0;
    let mut done = first.cycle == 0 && path.segments.is_empty();
    out.margins.cycles = 1;
    check_travel(&first, cfg, &mut out);
    if let Some(e) = earlier {
        let now = profile.phases.get(e.offset..).unwrap_or(&[]);
        let same = e.phases.iter().zip(now).take_while(|(a, b)| a == b).count();
        let t0 = |p: &[Phase]| p.get(same).map_or(f64::INFINITY, |x| x.t0);
        let changed = t0(e.phases).min(t0(now));
        // The mark's own and earlier setpoints were computed before the change.
        let usable = e
            .trace
            .marks
            .iter()
            .take_while(|m| (m.win[3].t + ts) < changed)
            .count();
        if let Some(m) = usable.checked_sub(1).map(|i| &e.trace.marks[i]) {
            ip.resume(&m.ip);
            win = m.win;
            older = m.older;
            cursor = m.cursor;
            out.margins = m.margins;
            out.violations = e.checked.violations[..m.violations].to_vec();
            trace.marks = e.trace.marks[..usable].to_vec();
        }
    }
    while tail < 3 {
        let next = if done {
            tail += 1;
            Sample {
                cycle: win[3].cycle + 1,
                t: win[3].t + ts,
                v: 0.0,
                ..win[3]
            }
        } else {
            let sp = ip.step();
            done = sp.done || sp.cycle >= MAX_CYCLES;
            out.margins.cycles += 1;
            sample(&sp, ip.segment(), profile, &mut cursor)
        };
        older = [older[1], win[0]];
        win = [win[1], win[2], win[3], next];
        check_travel(&next, cfg, &mut out);
        check_window(&win, &older, &ctx, &mut out);
        if !done && next.cycle % every == 0 {
            trace.marks.push(TraceMark {
                ip: ip.mark(),
                win,
                older,
                cursor,
                margins: out.margins,
                violations: out.violations.len(),
            });
        }
    }
    (out, trace)
}

mod chord;
mod corner;
mod junction;
mod phases;
mod sample;
mod stencil;
mod trace;

pub use chord::{chord_foot, dist_to_chord};
pub(crate) use junction::g2;
pub use junction::smooth_junctions;
pub use trace::{Earlier, Trace};
#[cfg(test)]
mod tests;
