//! Stations: the samples of the path the planner's ceilings live on (step 1 and 3 of
//! [`super`]), made one segment at a time as segments arrive ([`Sampler`]), so that a
//! program can be planned while it is read.

use super::{CAP_MARGIN, V_JOINT_FLOOR};
use crate::config::PlanConfig;
use nalgebra::Vector3;
use nc_geom::kinematics::{Joints, MachineKinematics};
use nc_geom::limits::V_FLOOR;
use nc_geom::segment::{Geometry, Segment, Tooling};

/// Of each axis's acceleration and jerk, the share a section plans to. The rest is left
/// for what the stations do not see: the path between them, and the parameter update's
/// drift from the planned feed, which the setpoint check would otherwise catch and cap.
pub(super) const AXIS_SHARE: f64 = 0.9;

/// The least share of an axis's acceleration and jerk the path terms get, however much of
/// it the curvature terms would take (the setpoint check lowers the ceilings where that is
/// too much), unless the check lowered the station's own share below it.
pub(super) const AXIS_SHARE_LEAST: f64 = 0.5;

/// The lowest a station's share goes where an axis's jerk stays over its limit at the
/// slowest feed ([`super::window`]): a path jerk and acceleration of a thousandth of what
/// the axes allow at their rates there.
pub(super) const AXIS_SHARE_FLOOR: f64 = 1e-3;

/// A sample of the path used by the planner.
#[derive(Clone, Copy, Debug)]
pub(super) struct Station {
    pub(super) s: f64,
    pub(super) vlim: f64,
    /// The joints' derivatives by path length on the way in and on the way out: the same
    /// but at a joint of two segments, where `before` is the first's end and `after` the
    /// second's start.
    pub(super) before: Rates,
    pub(super) after: Rates,
    /// Of each axis's acceleration and jerk, the share the sections that hold this station
    /// plan to (`limits`): lowered to half where the setpoint check finds a jerk over its
    /// limit.
    pub(super) share: f32,
}

/// |dq_j/ds|, |d2q_j/ds2| and |d3q_j/ds3| of each joint at a station, on one segment
/// (single precision, rounded up: bounds, and a window holds many stations).
#[derive(Clone, Copy, Debug)]
pub(super) struct Rates {
    d1: [f32; 5],
    d2: [f32; 5],
    d3: [f32; 5],
}

/// `x >= 0` in single precision, not below it.
fn up(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x {
        // The next f32 up (x >= 0 here).
        f32::from_bits(y.to_bits() + 1)
    } else {
        y
    }
}

impl Rates {
    pub(super) fn new(d1: [f64; 5], d2: [f64; 5], d3: [f64; 5]) -> Rates {
        Rates {
            d1: d1.map(|x| up(x.abs())),
            d2: d2.map(|x| up(x.abs())),
            d3: d3.map(|x| up(x.abs())),
        }
    }

    pub(super) fn d1(&self, j: usize) -> f64 {
        self.d1[j] as f64
    }

    pub(super) fn d2(&self, j: usize) -> f64 {
        self.d2[j] as f64
    }

    pub(super) fn d3(&self, j: usize) -> f64 {
        self.d3[j] as f64
    }

    /// Whether the joints' rates change here (else the curvature terms are zero).
    pub(super) fn curving(&self) -> bool {
        self.d2.iter().chain(&self.d3).any(|&x| x > 0.0)
    }

    /// Each derivative's larger magnitude of the two.
    pub(super) fn max(&self, other: &Rates) -> Rates {
        let m = |a: [f32; 5], b: [f32; 5]| core::array::from_fn(|j| a[j].max(b[j]));
        Rates {
            d1: m(self.d1, other.d1),
            d2: m(self.d2, other.d2),
            d3: m(self.d3, other.d3),
        }
    }
}

impl Station {
    /// The larger of the two sides' rates of joint `j`.
    pub(super) fn d1(&self, j: usize) -> f64 {
        self.before.d1(j).max(self.after.d1(j))
    }
}

fn joint_derivatives(q: &[Joints], h: f64, i: usize) -> ([f64; 5], [f64; 5]) {
    let n = q.len();
    let (a, b, c) = if i == 0 {
        (0, 1, 2.min(n - 1))
    } else if i + 1 == n {
        (n.saturating_sub(3), n - 2, n - 1)
    } else {
        (i - 1, i, i + 1)
    };
    let mut d1 = [0.0; 5];
    let mut d2 = [0.0; 5];
    for j in 0..5 {
        d1[j] = if i == 0 {
            (q[b][j] - q[a][j]) / h
        } else if i + 1 == n {
            (q[c][j] - q[b][j]) / h
        } else {
            (q[c][j] - q[a][j]) / (2.0 * h)
        };
        d2[j] = if c > b && b > a {
            (q[c][j] - 2.0 * q[b][j] + q[a][j]) / (h * h)
        } else {
            0.0
        };
    }
    (d1, d2)
}

fn curvature(seg: &Segment, s: f64) -> f64 {
    match &seg.geometry {
        Geometry::Line { .. } => 0.0,
        Geometry::Nurbs { curve, table } => {
            let d = curve.cutter(table.u_of_s(curve, s), 2);
            let sp = d.d1.norm();
            if sp < 1e-12 {
                0.0
            } else {
                d.d1.cross(&d.d2).norm() / (sp * sp * sp)
            }
        }
    }
}

/// The cutter path's unit tangent at a segment's start or end, if it has one.
fn end_tangent(seg: &Segment, at_end: bool) -> Option<Vector3<f64>> {
    let d = match &seg.geometry {
        Geometry::Line { from, to } => to - from,
        Geometry::Nurbs { curve, table } => {
            let s = if at_end { seg.length } else { 0.0 };
            curve.cutter(table.u_of_s(curve, s), 1).d1
        }
    };
    let n = d.norm();
    (n > 1e-12 && n.is_finite()).then(|| d / n)
}

/// Highest speed at which a junction whose cutter path turns from `t0` to `t1` keeps the
/// chord error within `tol` whatever the sampling phase: a chord of one period's travel
/// `L = v Ts` that straddles the corner passes it at most `(L / 2) sin(phi / 2)` away
/// (phi the turn, reached with the corner midway), so the corner's speed is at most
/// `2 tol / (Ts sin(phi / 2))`, with [`CORNER_CHORD_SHARE`] of it taken. The setpoint check
/// measures the chord at the plan's actual phase; a cap found from that phase alone would
/// move with every change of the plan's timing before it, and the replanning rounds would
/// chase it from corner to corner along a long program.
fn corner_chord_speed(t0: &Vector3<f64>, t1: &Vector3<f64>, tol: f64, ts: f64) -> f64 {
    let half = 0.5 * t0.dot(t1).clamp(-1.0, 1.0).acos();
    let sin = half.sin();
    if sin <= 1e-12 {
        f64::INFINITY
    } else {
        CORNER_CHORD_SHARE * 2.0 * tol / (ts * sin)
    }
}

/// Share of the chord tolerance a corner's speed is planned for: the chord straddling a
/// corner is one period's travel only at a steady speed.
const CORNER_CHORD_SHARE: f64 = 0.97;

/// Whether every joint moves at a constant rate along `seg`: a line with a fixed tool axis
/// (the rotary joints stand still, and the linear ones follow the line rotated).
fn constant_rates(seg: &Segment) -> bool {
    matches!(
        (&seg.geometry, &seg.tooling),
        (Geometry::Line { .. }, Tooling::Fixed(_))
    )
}

/// Halvings of the station spacing over which [`end_rates`] follows a segment's ends.
const END_HALVINGS: i32 = 10;

/// A segment's joint rate dq/ds at one of its ends.
struct EndRate {
    /// At the end itself (the finest one-sided difference), signed.
    at: [f64; 5],
    /// The largest magnitude met from the station spacing down to the finest step.
    peak: [f64; 5],
}

/// The joint rates at a segment's start and end, by one-sided differences over steps from
/// the station spacing `h` down to `h / 2^END_HALVINGS`. A rate that peaks at an end (the
/// tool axis leaving or reaching the vertical of an A/C table turns C fastest there) can be
/// narrower than the stations, and a kink's velocity jump is the rate at the end itself.
/// Along a [`constant_rates`] segment the station spacing is exact.
fn end_rates(
    seg: &Segment,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    q: &[Joints],
    h: f64,
) -> (EndRate, EndRate) {
    let n = q.len() - 1;
    let grid = |i: usize, dir: f64| -> [f64; 5] {
        let (a, b) = if dir > 0.0 { (i, i + 1) } else { (i - 1, i) };
        core::array::from_fn(|j| (q[b][j] - q[a][j]) / h)
    };
    let exact = constant_rates(seg);
    let one = |from: &Joints, s: f64, dir: f64, coarse: [f64; 5]| {
        let mut r = EndRate {
            at: coarse,
            peak: coarse.map(f64::abs),
        };
        if exact {
            return r;
        }
        for m in 1..=END_HALVINGS {
            let step = h * 0.5f64.powi(m);
            let j = seg.pose(s + dir * step).joints(kin, from, &cfg.rotary);
            for k in 0..5 {
                let d = dir * (j[k] - from[k]) / step;
                r.at[k] = d;
                r.peak[k] = r.peak[k].max(d.abs());
            }
        }
        r
    };
    (
        one(&q[0], 0.0, 1.0, grid(0, 1.0)),
        one(&q[n], seg.length, -1.0, grid(n, -1.0)),
    )
}

/// Most stations on one segment.
const MOST_STATIONS: usize = 4096;
/// A segment is sampled this many times as densely where its stations do not resolve a
/// rotary axis's rate ([`unresolved`]), and again while they do not (up to
/// [`MOST_STATIONS`]: a rate that grows like one over the distance to a block's end on the
/// vertical is never resolved). Sampled eight times as densely once, the block of
/// [`unresolved`]'s example still had the path crawl at 0.4 mm/min over its last
/// interval, 0.0095 mm, for 1.5 s.
const REFINE: usize = 8;
/// Factor by which a rotary axis's rate may change from one interval between stations to
/// the next before the stations count as not resolving it.
const UNRESOLVED: f64 = 8.0;
/// Rates below this (rad per path unit) are not looked at: at 50 mm/s, 0.5 rad/s.
const RATE_SEEN: f64 = 0.01;

/// Samples `q`, `h` apart, do not resolve a rotary axis's rate: over one interval it is
/// more than [`UNRESOLVED`] times what it is over the next (or the one before), and over
/// [`RATE_SEEN`]. A tool coming onto the vertical turns C like one over its tilt: stations
/// a period of travel apart saw C's rate go 0.0014, 0.117, then 27 rad/mm at the block's
/// end, a cap on the interval before the end held all of it, and the path crawled over
/// its 0.076 mm at 0.4 mm/min for 11.4 s (`compressed_posts.rs`).
fn unresolved(q: &[Joints], h: f64) -> bool {
    let rate = |i: usize, j: usize| ((q[i + 1][j] - q[i][j]) / h).abs();
    (1..q.len().saturating_sub(1)).any(|i| {
        (3..5).any(|j| {
            let (a, b) = (rate(i - 1, j), rate(i, j));
            a.max(b) > RATE_SEEN && a.max(b) > UNRESOLVED * a.min(b)
        })
    })
}

fn max_abs(a: [f64; 5], b: [f64; 5]) -> [f64; 5] {
    core::array::from_fn(|j| a[j].abs().max(b[j]))
}

/// Samples segments in path order: what it carries from one to the next is the joints at
/// the last one's end, its joint rate there, whether it turned the tool only, and its end
/// tangent (for the corner with the next).
pub(super) struct Sampler {
    prev: Joints,
    /// Where the next segment starts.
    s0: f64,
    prev_end: Option<([f64; 5], bool)>,
    /// The last segment's end tangent, if it has one and moves the cutter.
    prev_tangent: Option<Vector3<f64>>,
}

impl Sampler {
    /// Starting at the program's start joints.
    pub(super) fn new(start_joints: Joints) -> Self {
        Sampler {
            prev: start_joints,
            s0: 0.0,
            prev_end: None,
            prev_tangent: None,
        }
    }

    /// Sample `seg`, the segment after the last one given: its stations go to `out` and the
    /// index of its first station (the joint with the previous segment, whose ceiling takes
    /// both sides' limits) to `starts`. `smooth`: the joint is G2-continuous (the setpoint
    /// check measures jerk across it).
    pub(super) fn push(
        &mut self,
        seg: &Segment,
        smooth: bool,
        kin: &MachineKinematics,
        cfg: &PlanConfig,
        out: &mut Vec<Station>,
        starts: &mut Vec<usize>,
    ) {
        // A line with a fixed tool axis moves every joint at a constant rate, so its ceiling
        // is the same all along: its two ends and a midpoint say all there is (a dense CAM
        // program of such moves would otherwise carry 16 stations a move).
        let lines = constant_rates(seg);
        let fewest = if lines { 2 } else { 16 };
        let mut n = ((seg.length / (seg.feed.max(V_FLOOR) * cfg.period)).ceil() as usize)
            .clamp(fewest, MOST_STATIONS);
        let sample = |n: usize| {
            let h = seg.length / n as f64;
            let mut prev = self.prev;
            let q: Vec<Joints> = (0..=n)
                .map(|i| {
                    prev = seg.pose(h * i as f64).joints(kin, &prev, &cfg.rotary);
                    prev
                })
                .collect();
            (q, prev, h)
        };
        let (mut q, mut prev, mut h) = sample(n);
        while !lines && n < MOST_STATIONS && unresolved(&q, h) {
            n = (n * REFINE).min(MOST_STATIONS);
            (q, prev, h) = sample(n);
        }
        self.prev = prev;
        let (start_rate, end_rate) = end_rates(seg, kin, cfg, &q, h);
        // |d2q/ds2| at each station, and |d3q/ds3| from its change to the neighbours' (for
        // the curvature terms of the axes' acceleration and jerk, `super::limits`): zero
        // along a line whose joints move at constant rates (not the differences' rounding).
        let d2s: Vec<[f64; 5]> = (0..=n)
            .map(|i| match lines {
                true => [0.0; 5],
                false => joint_derivatives(&q, h, i).1,
            })
            .collect();
        let curving = |i: usize| -> ([f64; 5], [f64; 5]) {
            let d3 = core::array::from_fn(|j| {
                let before = i
                    .checked_sub(1)
                    .map_or(0.0, |p| (d2s[i][j] - d2s[p][j]).abs());
                let after = d2s.get(i + 1).map_or(0.0, |x| (x[j] - d2s[i][j]).abs());
                before.max(after) / h
            });
            (d2s[i], d3)
        };
        let mut last_d1 = [0.0; 5];
        let tangent = (!seg.rotary_only)
            .then(|| end_tangent(seg, false))
            .flatten();
        for i in 0..=n {
            // The last station is the joint: exactly where the next segment starts (h n
            // can differ from the length in the last bit, and a cap at the joint would then
            // fall on the station before it too).
            let s_loc = if i == n { seg.length } else { h * i as f64 };
            let (d1, d2) = joint_derivatives(&q, h, i);
            // At the segment's ends: the rate at the end itself (what jumps at a joint) and
            // the largest on the way there (what bounds the section's limits).
            let (d1, peak) = match i {
                0 => (start_rate.at, max_abs(d1, start_rate.peak)),
                _ if i == n => (end_rate.at, max_abs(d1, end_rate.peak)),
                _ => (d1, d1.map(f64::abs)),
            };
            if i == n {
                last_d1 = d1;
            }
            let mut v = seg.feed.min(1e9);
            let kappa = curvature(seg, s_loc);
            if kappa > 1e-12 {
                let rho = 1.0 / kappa;
                let d = cfg.chord_tol.min(rho);
                v = v.min(2.0 * (2.0 * rho * d - d * d).sqrt() / cfg.period);
                v = v.min((cfg.path_acc / kappa).sqrt());
            }
            for (j, ax) in cfg.axes.iter().enumerate() {
                if peak[j] > 1e-15 {
                    v = v.min(ax.velocity / peak[j]);
                }
                if d2[j].abs() > 1e-15 {
                    v = v.min((ax.acceleration / (2.0 * d2[j].abs())).sqrt());
                }
            }
            let (d2_rates, d3_rates) = curving(i);
            let rates = Rates::new(peak, d2_rates, d3_rates);
            let st = Station {
                s: self.s0 + s_loc,
                vlim: v.max(V_FLOOR),
                before: rates,
                after: rates,
                share: AXIS_SHARE as f32,
            };
            if i == 0 {
                if let (Some(last), Some((pd1, prev_rotary))) = (out.last_mut(), self.prev_end) {
                    // The joint with the previous segment: one station, both sides' limits
                    // (and each side's rates for the section on that side).
                    let mut vc = last.vlim.min(st.vlim);
                    if prev_rotary != seg.rotary_only || seg.stop {
                        // Path units change (mm <-> degrees), the tangent kinks inside a
                        // NURBS block, or the move waits: stop between (at the floor speed,
                        // below; a wait at rest).
                        vc = 0.0;
                    }
                    if let (Some(t0), Some(t1)) = (self.prev_tangent, tangent) {
                        vc = vc.min(corner_chord_speed(&t0, &t1, cfg.chord_tol, cfg.period));
                    }
                    // An axis's rate jumps here: it takes the jump in one period, at the
                    // speed the joint is passed at. Where that speed is below the floor
                    // (C next to the vertical: 13 600 deg/mm where a G01 turned the tool
                    // off 0.58 degrees of tilt, after a plunge), the joint is passed at it,
                    // with the check's reserve and the caps' margin, since no cap goes
                    // below the floor: at the floor C's acceleration was 7.8x its limit,
                    // and the program was refused where its moves are feasible from rest.
                    let mut v_jump = f64::INFINITY;
                    for (j, ax) in cfg.axes.iter().enumerate() {
                        let jump = (d1[j] - pd1[j]).abs();
                        if jump > 1e-9 {
                            let v = ax.acceleration * cfg.period / jump;
                            vc = vc.min(v);
                            let (_, share) = nc_geom::limits::reserve(ax, cfg.period);
                            v_jump = v_jump.min(v * share * CAP_MARGIN);
                        }
                    }
                    if smooth {
                        // The setpoints' jerk across the joint mixes both sides' rates.
                        let both = last.before.max(&st.after);
                        (last.before, last.after) = (both, both);
                    } else {
                        last.after = st.after;
                    }
                    last.vlim = if seg.waits() {
                        // A dwell, the operator's resume or the spindle: the path rests here.
                        // Arriving and leaving at the floor speed stepped each axis's velocity
                        // by its rate times that speed: C's by 0.47 deg/s where a move turned
                        // it 474 deg/mm, 5.9x its jerk over one period (`tests/waits.rs`).
                        0.0
                    } else if vc >= V_FLOOR {
                        vc
                    } else if v_jump < V_FLOOR {
                        v_jump.max(V_JOINT_FLOOR)
                    } else {
                        V_FLOOR
                    };
                    starts.push(out.len() - 1);
                    continue;
                }
                starts.push(out.len());
            }
            out.push(st);
        }
        self.prev_end = Some((last_d1, seg.rotary_only));
        self.prev_tangent = (!seg.rotary_only).then(|| end_tangent(seg, true)).flatten();
        self.s0 += seg.length;
    }
}
