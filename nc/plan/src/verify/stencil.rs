//! The checks over a stencil of four consecutive setpoints: every axis's velocity,
//! acceleration and jerk by finite differences at the period (the jerk only inside
//! G2-continuous stretches; a corner's own stencil in `corner.rs`), the rotary branch, the
//! chord error, the travel; each over its limit a [`Violation`].

use super::chord::chord_error;
use super::corner;
use super::phases;
use super::sample::{crosses_corner, Ctx, Sample};
use super::{Checked, Quantity, Violation, SLACK};
use crate::config::PlanConfig;
use nc_geom::limits::reserve;

pub(super) fn violation(
    q: Quantity,
    axis: usize,
    w: &[Sample],
    value: f64,
    limit: f64,
) -> Violation {
    let last = &w[w.len() - 1];
    Violation {
        quantity: q,
        axis,
        cycle: last.cycle,
        t: last.t,
        segment: last.seg,
        s: (w[0].s, last.s),
        v: w.iter().map(|x| x.v).fold(0.0, f64::max),
        value,
        limit,
        rotary: [[0.0; 2]; 2],
        kink: false,
    }
}

/// Keep the worst violation of a cycle: the one that needs the largest slow-down.
pub(super) fn record(out: &mut Checked, v: Violation) {
    if let Some(last) = out.violations.last_mut() {
        if last.cycle == v.cycle {
            let worse = match (v.speed_factor(), last.speed_factor()) {
                (None, _) => true,
                (Some(_), None) => false,
                (Some(a), Some(b)) => a < b,
            };
            if worse {
                *last = v;
            }
            return;
        }
    }
    out.violations.push(v);
}

pub(super) fn check_travel(x: &Sample, cfg: &PlanConfig, out: &mut Checked) {
    for j in 0..5 {
        let (lo, hi) = cfg.travel[j];
        let q = x.q[j];
        if !(q >= lo - SLACK * lo.abs().max(1.0) && q <= hi + SLACK * hi.abs().max(1.0)) {
            let limit = if q < lo { lo } else { hi };
            record(out, violation(Quantity::Travel, j, &[*x], q, limit));
        }
    }
}

/// The checks over the stencil `w`; `older` are the two setpoints before `w[0]` (oldest
/// first), for the jerk of the two stencils before ([`phases`]).
pub(super) fn check_window(w: &[Sample; 4], older: &[Sample; 2], ctx: &Ctx, out: &mut Checked) {
    let cfg = ctx.cfg;
    let (ts, m) = (cfg.period, &mut out.margins);
    let mut found: Option<Violation> = None;
    let keep = |v: Violation, found: &mut Option<Violation>| {
        let worse = match (
            found.as_ref().and_then(Violation::speed_factor),
            v.speed_factor(),
        ) {
            (_, None) => true,
            (None, Some(_)) => found.is_none(),
            (Some(a), Some(b)) => b < a,
        };
        if worse {
            *found = Some(v);
        }
    };
    let jerk_ok = !crosses_corner(w, ctx.smooth);
    // The jerk between the plan's phases, where it changes fast from one stencil to the
    // next or peaks between them.
    let between = phases::measure(w, older, ctx);
    let kink = if w[1].seg < w[2].seg {
        corner::stencil(w, ctx)
    } else {
        None
    };
    for (j, ax) in cfg.axes.iter().enumerate() {
        let (q0, q1, q2, q3) = (w[0].q[j], w[1].q[j], w[2].q[j], w[3].q[j]);
        let vel = ((q3 - q2) / ts).abs();
        let acc = ((q3 - 2.0 * q2 + q1) / (ts * ts)).abs();
        let (v_share, a_share) = reserve(ax, ts);
        let (vel_limit, acc_limit) = (ax.velocity * v_share, ax.acceleration * a_share);
        let jerk_limit = ax.planned_jerk(ts);
        let jerk = ((q3 - 3.0 * q2 + 3.0 * q1 - q0) / (ts * ts * ts)).abs();
        m.velocity[j] = m.velocity[j].max(vel / ax.velocity);
        m.acceleration[j] = m.acceleration[j].max(acc / ax.acceleration);
        if vel > vel_limit * (1.0 + SLACK) || vel.is_nan() {
            keep(
                violation(Quantity::Velocity, j, &w[2..], vel, vel_limit),
                &mut found,
            );
        }
        if acc > acc_limit * (1.0 + SLACK) || acc.is_nan() {
            keep(
                violation(Quantity::Acceleration, j, &w[1..], acc, acc_limit),
                &mut found,
            );
        }
        if let Some(c) = &kink {
            let [k0, k1, k2] = &c.q;
            let acc = ((k2[j] - 2.0 * k1[j] + k0[j]) / (ts * ts)).abs();
            m.acceleration[j] = m.acceleration[j].max(acc / ax.acceleration);
            if acc > acc_limit * (1.0 + SLACK) || acc.is_nan() {
                // The speed at the junction sets the jump: lower it there.
                let v = Violation {
                    s: (c.s, c.s),
                    v: c.v,
                    kink: true,
                    ..violation(Quantity::Acceleration, j, &w[1..], acc, acc_limit)
                };
                keep(v, &mut found);
            }
            for side in c.sides.iter().flatten() {
                let [k0, k1, k2, k3] = side.q.map(|x| x[j]);
                let jerk = ((k3 - 3.0 * k2 + 3.0 * k1 - k0) / (ts * ts * ts)).abs();
                m.jerk[j] = m.jerk[j].max(jerk / jerk_limit);
                if jerk > jerk_limit * (1.0 + SLACK) || jerk.is_nan() {
                    let v = Violation {
                        s: side.s,
                        v: side.v,
                        ..violation(Quantity::Jerk, j, w, jerk, jerk_limit)
                    };
                    keep(v, &mut found);
                }
            }
        }
        // The aligned stencil's jerk where it lies inside a stretch, and the jerk between
        // phases where it was measured (up to a corner the stencil crosses).
        let aligned = if jerk_ok { jerk } else { 0.0 };
        if let Some(jerk) = between
            .map(|b| b[j].max(aligned))
            .or(jerk_ok.then_some(jerk))
        {
            m.jerk[j] = m.jerk[j].max(jerk / jerk_limit);
            if jerk > jerk_limit * (1.0 + SLACK) || jerk.is_nan() {
                keep(
                    violation(Quantity::Jerk, j, w, jerk, jerk_limit),
                    &mut found,
                );
            }
        }
    }
    if let Some(v) = branch_change(w) {
        keep(v, &mut found);
    }
    let chord = chord_error(&w[2], &w[3], ctx.path);
    m.chord = m.chord.max(chord / cfg.chord_tol);
    if chord > cfg.chord_tol * (1.0 + SLACK) || chord.is_nan() {
        keep(
            violation(Quantity::Chord, 5, &w[2..], chord, cfg.chord_tol),
            &mut found,
        );
    }
    if let Some(v) = found {
        record(out, v);
    }
}

/// A change of rotary solution between the two newest setpoints (see [`Quantity::Branch`]).
/// A tool passing near the vertical swings C fast but continuously, with the tilt near zero;
/// it never steps C by exactly half a turn at a tilt of its own, nor by whole turns.
pub(super) fn branch_change(w: &[Sample; 4]) -> Option<Violation> {
    use core::f64::consts::{PI, TAU};
    let (a, b) = (&w[2].q, &w[3].q);
    let (t0, t1, dc) = (a[3], b[3], b[4] - a[4]);
    let near = |x: f64, y: f64| (x - y).abs() < 1e-3;
    let flip = t0 * t1 < 0.0 && t0.abs() > 1e-3 && t1.abs() > 1e-3 && near(dc.abs(), PI);
    let wrap = dc.abs() > PI && near((dc / TAU).round() * TAU, dc) && near(t0, t1);
    (flip || wrap).then(|| Violation {
        rotary: [[t0, a[4]], [t1, b[4]]],
        ..violation(Quantity::Branch, 4, &w[2..], dc.abs(), 0.0)
    })
}
