//! Jerk-limited velocity changes: the building block of the feed profile.
//!
//! A change from v0 to v1 starts and ends at zero acceleration and uses jerk +-J and at most
//! acceleration A: three phases (jerk, constant acceleration, jerk) when |dv| >= A^2/J, two
//! otherwise (the acceleration peaks at sqrt(|dv| J)). The velocity curve is point-symmetric
//! about its midpoint, so the distance covered is exactly `(v0 + v1) / 2 * T`.

/// One piece of the feed profile with constant jerk. Time and path position are absolute.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Phase {
    pub t0: f64,
    pub dur: f64,
    pub s0: f64,
    pub v0: f64,
    pub a0: f64,
    pub j: f64,
}

/// Path position, velocity and acceleration at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    pub s: f64,
    pub v: f64,
    pub a: f64,
}

impl Phase {
    /// State at `tau` seconds into the phase (not clamped).
    pub fn at(&self, tau: f64) -> Motion {
        Motion {
            s: self.s0 + tau * (self.v0 + tau * (self.a0 / 2.0 + tau * self.j / 6.0)),
            v: self.v0 + tau * (self.a0 + tau * self.j / 2.0),
            a: self.a0 + tau * self.j,
        }
    }

    pub fn end(&self) -> Motion {
        self.at(self.dur)
    }
}

/// Duration of a jerk-limited velocity change by `dv` (sign ignored).
pub fn change_time(dv: f64, a: f64, j: f64) -> f64 {
    let dv = dv.abs();
    if dv >= a * a / j {
        dv / a + a / j
    } else {
        2.0 * (dv / j).sqrt()
    }
}

/// Distance covered by a jerk-limited change from `v0` to `v1`.
pub fn change_dist(v0: f64, v1: f64, a: f64, j: f64) -> f64 {
    0.5 * (v0 + v1) * change_time(v1 - v0, a, j)
}

/// Highest speed from which `v_end` can be reached within `dist` (or, symmetrically, the
/// highest speed reachable from `v_end` within `dist`).
///
/// In closed form: a change by `x < a^2 / j` never reaches the acceleration limit and covers
/// `(2 v_end + x) sqrt(x / j)`, a cubic in `y = sqrt(x)` with one real root (Cardano); a
/// larger change covers `(2 v_end + x) (x / a + a / j) / 2`, a quadratic in `x`. The root is
/// then lowered by ulps until its change fits, so the result never needs more than `dist`.
pub fn reachable(v_end: f64, dist: f64, a: f64, j: f64) -> f64 {
    if dist <= 0.0 {
        return v_end;
    }
    if !(dist.is_finite() && v_end.is_finite() && a > 0.0 && j > 0.0 && (a * a / j).is_finite()) {
        return reachable_bisect(v_end, dist, a, j);
    }
    let knee = a * a / j;
    let x = if dist <= (2.0 * v_end + knee) * a / j {
        // y^3 + p y = q.
        let (p, q) = (2.0 * v_end, dist * j.sqrt());
        let r = (0.25 * q * q + p * p * p / 27.0).sqrt();
        let mut y = (0.5 * q + r).cbrt() - (r - 0.5 * q).cbrt();
        // Cardano cancels where p dominates; Newton restores the digits.
        for _ in 0..3 {
            let f = y * y * y + p * y - q;
            let df = 3.0 * y * y + p;
            if df > 0.0 {
                y -= f / df;
            }
        }
        (y * y).min(knee)
    } else {
        // x^2 + b x + c = 0, c < 0: the positive root, without cancellation.
        let b = knee + 2.0 * v_end;
        let c = 2.0 * a * (v_end * a / j - dist);
        -2.0 * c / (b + (b * b - 4.0 * c).sqrt())
    };
    let mut x = x.max(0.0);
    for k in 0..64 {
        if change_dist(v_end + x, v_end, a, j) <= dist {
            return v_end + x;
        }
        x *= 1.0 - f64::EPSILON * f64::from(1u32 << (k / 2).min(30));
    }
    reachable_bisect(v_end, dist, a, j)
}

/// [`reachable`] by bisection on [`change_dist`], for the inputs the closed form does not
/// take, and as its reference in the tests.
pub fn reachable_bisect(v_end: f64, dist: f64, a: f64, j: f64) -> f64 {
    if dist <= 0.0 {
        return v_end;
    }
    // change_dist >= dv * T / 2 bounds dv by sqrt(2 a d) or (d^2 j)^(1/3).
    let mut hi = v_end + (2.0 * a * dist).sqrt().max((dist * dist * j).cbrt()) + 1e-9;
    let mut lo = v_end;
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if change_dist(mid, v_end, a, j) <= dist {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Append the phases of a change from `start` (with zero acceleration) to `v1`. Returns the
/// state at its end (acceleration zero again).
pub fn push_change(
    out: &mut Vec<Phase>,
    t0: f64,
    start: Motion,
    v1: f64,
    a: f64,
    j: f64,
) -> (f64, Motion) {
    let dv = v1 - start.v;
    if dv == 0.0 {
        return (t0, start);
    }
    let sign = dv.signum();
    let (t_jerk, t_const) = if dv.abs() >= a * a / j {
        (a / j, dv.abs() / a - a / j)
    } else {
        ((dv.abs() / j).sqrt(), 0.0)
    };
    let mut t = t0;
    let mut m = Motion { a: 0.0, ..start };
    for (dur, jerk) in [(t_jerk, sign * j), (t_const, 0.0), (t_jerk, -sign * j)] {
        if dur <= 0.0 {
            continue;
        }
        let ph = Phase {
            t0: t,
            dur,
            s0: m.s,
            v0: m.v,
            a0: m.a,
            j: jerk,
        };
        out.push(ph);
        m = ph.end();
        t += dur;
    }
    // Remove rounding: the change ends exactly at v1 with zero acceleration.
    m.v = v1;
    m.a = 0.0;
    (t, m)
}

/// The acceleration and jerk limits of a section's two speed changes: the one from its
/// start and the one into its end (each ramp may be allowed more than the section as a
/// whole where the path it covers allows more, see the planner's `section_ramps`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ramps {
    pub start: (f64, f64),
    pub end: (f64, f64),
}

impl Ramps {
    /// The same limits for both.
    pub fn both(limits: (f64, f64)) -> Ramps {
        Ramps {
            start: limits,
            end: limits,
        }
    }
}

/// Append the phases of one section from `va` to `vb` over `len` starting at time `t0` and
/// position `s0`: accelerate, cruise at the highest speed up to `vmax` that fits, decelerate,
/// with the ramps' acceleration and jerk limits. Returns the end time.
pub fn push_section(
    out: &mut Vec<Phase>,
    t0: f64,
    s0: f64,
    (va, vb): (f64, f64),
    len: f64,
    vmax: f64,
    ramps: Ramps,
) -> f64 {
    let ((a0, j0), (a1, j1)) = (ramps.start, ramps.end);
    let lo = va.max(vb);
    let fits = |vc: f64| change_dist(va, vc, a0, j0) + change_dist(vc, vb, a1, j1) <= len;
    let vc = if vmax <= lo {
        lo
    } else if fits(vmax) {
        vmax
    } else {
        let (mut l, mut h) = (lo, vmax);
        for _ in 0..80 {
            let m = 0.5 * (l + h);
            if fits(m) {
                l = m;
            } else {
                h = m;
            }
        }
        l
    };
    let start = Motion {
        s: s0,
        v: va,
        a: 0.0,
    };
    let (t1, m1) = push_change(out, t0, start, vc, a0, j0);
    let d2 = change_dist(vc, vb, a1, j1);
    let cruise = (len - (m1.s - s0) - d2).max(0.0);
    let mut t = t1;
    let mut m = m1;
    if cruise > 0.0 && vc > 0.0 {
        let ph = Phase {
            t0: t,
            dur: cruise / vc,
            s0: m.s,
            v0: vc,
            a0: 0.0,
            j: 0.0,
        };
        out.push(ph);
        t += ph.dur;
        m = ph.end();
    }
    let (t2, _) = push_change(out, t, m, vb, a1, j1);
    t2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn change_reaches_target_with_its_predicted_distance() {
        for &(v0, v1, a, j) in &[
            (0.0, 100.0, 1000.0, 20000.0), // long: constant-acceleration phase
            (50.0, 52.0, 1000.0, 20000.0), // short: triangular acceleration
            (80.0, 10.0, 500.0, 5000.0),
        ] {
            let mut ph = Vec::new();
            let start = Motion {
                s: 3.0,
                v: v0,
                a: 0.0,
            };
            let (t, end) = push_change(&mut ph, 1.0, start, v1, a, j);
            let last = ph.last().unwrap().end();
            assert!((last.v - v1).abs() < 1e-9, "{last:?}");
            assert!(last.a.abs() < 1e-9);
            assert!((t - 1.0 - change_time(v1 - v0, a, j)).abs() < 1e-12);
            assert!((last.s - 3.0 - change_dist(v0, v1, a, j)).abs() < 1e-9);
            assert_eq!(end.v, v1);
            // Limits hold at every phase boundary (extrema of a are at boundaries).
            for p in &ph {
                assert!(p.a0.abs() <= a * (1.0 + 1e-12) && p.end().a.abs() <= a * (1.0 + 1e-12));
                assert!(p.j.abs() <= j);
            }
        }
    }

    #[test]
    fn reachable_inverts_change_dist() {
        let (a, j) = (1000.0, 20000.0);
        for &d in &[0.001, 0.1, 5.0, 200.0] {
            let v = reachable(20.0, d, a, j);
            assert!(
                (change_dist(v, 20.0, a, j) - d).abs() < 1e-9 * d.max(1.0),
                "d={d}"
            );
        }
        assert_eq!(reachable(7.0, 0.0, a, j), 7.0);
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(20_000))]
        /// The closed form against the bisection it replaced, over 12 decades of every input:
        /// never more than the distance, and the same speed to 1e-12.
        #[test]
        fn reachable_in_closed_form_is_the_bisections_speed(
            v in -6.0f64..4.0, d in -9.0f64..4.0, a in -3.0f64..6.0, j in -3.0f64..8.0,
            zero in proptest::bool::weighted(0.1),
        ) {
            let v_end = if zero { 0.0 } else { 10f64.powf(v) };
            let (dist, a, j) = (10f64.powf(d), 10f64.powf(a), 10f64.powf(j));
            let fast = reachable(v_end, dist, a, j);
            let slow = reachable_bisect(v_end, dist, a, j);
            proptest::prop_assert!(change_dist(fast, v_end, a, j) <= dist);
            proptest::prop_assert!(
                (fast - slow).abs() <= 1e-12 * fast.max(1e-9),
                "v_end {v_end} dist {dist} a {a} j {j}: {fast} against {slow}"
            );
        }
    }
}
