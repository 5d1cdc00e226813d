//! The geometry of compensated moves: where a line or an arc puts the tool centre, and what
//! it does to the corner with the held move before it (LinuxCNC's `convert_straight_comp1/2`
//! and `convert_arc_comp1/2`, reproduced so that dnurbs's path is `rs274`'s).
//!
//! Angles follow LinuxCNC: `theta` is the direction from the programmed corner to the tool,
//! `alpha` the new move's direction, and `beta` the turn between the two tangents, normalised
//! so that `0..pi` is convex (the tool on the outside) and anything beyond the tolerance
//! either way is concave.

use super::comp::{find_turn, Active, Comp, CompError, Meta, Queued, Side, CORNER_TOL_RAD};
use core::f64::consts::{FRAC_PI_2, PI, TAU};

fn polar(o: [f64; 2], r: f64, angle: f64) -> [f64; 2] {
    [o[0] + r * angle.cos(), o[1] + r * angle.sin()]
}

fn dir(from: [f64; 2], to: [f64; 2]) -> f64 {
    (to[1] - from[1]).atan2(to[0] - from[0])
}

fn xy(p: [f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

fn with_z(p: [f64; 2], z: f64) -> [f64; 3] {
    [p[0], p[1], z]
}

/// The held arc at the front of the queue, if the front is an arc.
fn front_arc(queue: &[Queued]) -> Option<([f64; 3], [f64; 2], bool)> {
    match queue.first() {
        Some(Queued::Arc {
            end, centre, ccw, ..
        }) => Some((*end, *centre, *ccw)),
        _ => None,
    }
}

impl Comp {
    fn state(&self) -> Result<Active, CompError> {
        self.compensating()
            .ok_or(CompError::Internal("no compensation in effect"))
    }

    /// A compensated `G00`/`G01` to the programmed point `p` (mm).
    pub(crate) fn straight(
        &mut self,
        rapid: bool,
        p: [f64; 3],
        meta: Meta,
    ) -> Result<(), CompError> {
        let mut a = self.state()?;
        let (r, c) = (a.radius, a.current);
        if a.first {
            let length = (p[0] - c[0]).hypot(p[1] - c[1]);
            if length <= r {
                return Err(CompError::EntryTooShort { length, radius: r });
            }
            let turn = if a.side == Side::Left {
                FRAC_PI_2
            } else {
                -FRAC_PI_2
            };
            let alpha = dir(xy(c), xy(p)) + turn;
            let end = with_z(polar(xy(p), r, alpha), p[2]);
            self.released_end = c;
            self.endpoint = Some(xy(c));
            self.queue.push(Queued::Line {
                rapid,
                dir: [alpha.cos(), alpha.sin()],
                end,
                meta,
            });
            a.first = false;
            a.current = end;
            a.programmed = p;
            self.active = Some(a);
            return Ok(());
        }
        let op = a.programmed;
        if p[0] == op[0] && p[1] == op[1] {
            // No XY motion: the tool keeps its XY, and the move is held with the corner.
            let end = [c[0], c[1], p[2]];
            self.queue.push(Queued::Line {
                rapid,
                dir: [0.0, 0.0],
                end,
                meta,
            });
            a.current = end;
            a.programmed = p;
            self.active = Some(a);
            return Ok(());
        }
        let mut theta = dir(xy(op), xy(c));
        let mut alpha = dir(xy(op), xy(p));
        let (beta, gamma) = match a.side {
            Side::Left => {
                if theta < alpha {
                    theta += TAU;
                }
                (theta - alpha - FRAC_PI_2, FRAC_PI_2)
            }
            Side::Right => {
                if alpha < theta {
                    alpha += TAU;
                }
                (alpha - theta - FRAC_PI_2, -FRAC_PI_2)
            }
        };
        let end = polar(xy(p), r, alpha + gamma);
        let mid = polar(xy(op), r, alpha + gamma);
        let small = CORNER_TOL_RAD;
        let front = front_arc(&self.queue);
        // Going over the round top of an "h" the tool could stay right two ways: it stays
        // above (LinuxCNC's choice), which makes the corner concave.
        let h_shape =
            beta > PI - small && front.is_some_and(|(_, _, ccw)| (a.side == Side::Right) == ccw);
        let concave = beta < -small || beta > PI + small || h_shape;
        if !concave && beta > small {
            // Convex: the held move ends as it is, an arc (or, for a rapid, a line) about the
            // programmed corner takes the tool round it.
            self.move_ends_and_release(xy(c))?;
            let corner = if rapid {
                Queued::Line {
                    rapid: true,
                    dir: [0.0, 0.0],
                    end: with_z(mid, c[2]),
                    meta: meta.clone(),
                }
            } else {
                Queued::Arc {
                    sweep: 0.0,
                    end: with_z(mid, c[2]),
                    centre: xy(op),
                    ccw: a.side == Side::Right,
                    meta: meta.clone(),
                }
            };
            self.queue.push(corner);
            self.release();
            self.endpoint = Some(mid);
        } else if concave {
            let meet = match front {
                None => {
                    // line -> line: back along the held line to where the offsets meet.
                    let half = (beta + PI) / 2.0;
                    if half == 0.0 {
                        return Err(CompError::Gouge("a zero-degree inside corner"));
                    }
                    polar(xy(c), r / half.tan(), theta + gamma)
                }
                Some((prev_end, centre, prev_ccw)) => {
                    // arc -> line: where the held (compensated) arc meets the new offset line.
                    let old_r = (centre[1] - prev_end[1]).hypot(centre[0] - prev_end[0]);
                    let base = dir(xy(op), xy(p));
                    let th = if prev_ccw {
                        base + FRAC_PI_2
                    } else {
                        base - FRAC_PI_2
                    };
                    let phi = dir(xy(op), centre);
                    let inside = a.side.inside(prev_ccw);
                    let uncomp = if inside { old_r + r } else { old_r - r };
                    let d = uncomp * (th - phi).cos();
                    let l = if inside { d - r } else { d + r } / old_r;
                    if !(-1.0..=1.0).contains(&l) {
                        return Err(CompError::Gouge(
                            "the corner from an arc to a line is too tight for the tool",
                        ));
                    }
                    let turn = if inside == prev_ccw {
                        -l.acos()
                    } else {
                        l.acos()
                    };
                    polar(centre, old_r, turn + th + PI)
                }
            };
            self.move_ends_and_release(meet)?;
        } else {
            // Straight on (or tangent from an arc): nothing to adjust.
            self.release();
            self.endpoint = Some(xy(c));
        }
        let meta = if !concave && beta > small {
            meta.without_wait()
        } else {
            meta
        };
        let end = with_z(end, p[2]);
        self.queue.push(Queued::Line {
            rapid,
            dir: [p[0] - op[0], p[1] - op[1]],
            end,
            meta,
        });
        a.current = end;
        a.programmed = p;
        self.active = Some(a);
        Ok(())
    }

    /// A compensated `G02`/`G03` to the programmed point `p` about the programmed `centre`
    /// (both mm, the centre found from the programmed start as an uncompensated arc's).
    /// `radius_tol_mm`: how far the start and end radii of the compensated arc may differ.
    pub(crate) fn arc(
        &mut self,
        ccw: bool,
        p: [f64; 3],
        centre: [f64; 2],
        meta: Meta,
        radius_tol_mm: f64,
    ) -> Result<(), CompError> {
        let mut a = self.state()?;
        let (r, c) = (a.radius, a.current);
        let inside = a.side.inside(ccw);
        let arc_radius = (centre[0] - p[0]).hypot(centre[1] - p[1]);
        if inside && arc_radius <= r {
            return Err(CompError::ToolTooBig {
                arc_radius,
                radius: r,
            });
        }
        let gamma = if inside {
            dir(xy(p), centre)
        } else {
            dir(centre, xy(p))
        };
        let new_end = polar(xy(p), r, gamma);
        if a.first {
            let length = (p[0] - c[0]).hypot(p[1] - c[1]);
            if length <= r {
                return Err(CompError::EntryTooShort { length, radius: r });
            }
            // The arc from the tool to the offset end: same side of the chord as the
            // programmed centre, its centre moved so that both ends are on one circle.
            let half = (c[0] - new_end[0]).hypot(c[1] - new_end[1]) / 2.0;
            let ab = dir(new_end, centre);
            let angle = dir(new_end, xy(c)) - ab;
            if angle.cos().abs() < 1e-6 {
                return Err(CompError::ToolTooBig {
                    arc_radius,
                    radius: r,
                });
            }
            let moved = polar(new_end, half / angle.cos(), ab);
            let (re, rs) = (
                (moved[0] - new_end[0]).hypot(moved[1] - new_end[1]),
                (moved[0] - c[0]).hypot(moved[1] - c[1]),
            );
            if (re - rs).abs() > radius_tol_mm {
                return Err(CompError::Internal("the entry arc's radii differ"));
            }
            self.released_end = c;
            self.queue.push(Queued::Arc {
                sweep: find_turn(xy(c), moved, ccw, new_end),
                end: with_z(new_end, p[2]),
                centre: moved,
                ccw,
                meta,
            });
            a.first = false;
            a.programmed = p;
            a.current = with_z(new_end, p[2]);
            self.active = Some(a);
            return Ok(());
        }
        let op = a.programmed;
        let theta = dir(xy(op), xy(c))
            + if a.side == Side::Left {
                -FRAC_PI_2
            } else {
                FRAC_PI_2
            };
        let mut delta = dir(xy(op), centre);
        let alpha = if ccw {
            delta - FRAC_PI_2
        } else {
            delta + FRAC_PI_2
        };
        let beta = if a.side == Side::Left {
            theta - alpha
        } else {
            alpha - theta
        };
        let beta = if beta > 1.5 * PI {
            beta - TAU
        } else if beta < -FRAC_PI_2 {
            beta + TAU
        } else {
            beta
        };
        if !inside {
            delta += PI;
        }
        let small = CORNER_TOL_RAD;
        let sweep = find_turn(xy(op), centre, ccw, xy(p));
        let main = |meta: Meta| Queued::Arc {
            sweep,
            end: with_z(new_end, p[2]),
            centre,
            ccw,
            meta,
        };
        if beta < -small || beta > PI + small || ((beta - PI).abs() < small && !inside) {
            // Concave: the held moves end where they meet this arc's offset.
            let meet = match front_arc(&self.queue) {
                None => {
                    // line -> arc
                    let cy = arc_radius * (beta - FRAC_PI_2).sin();
                    let (dist, toward) = if inside {
                        (arc_radius - r, cy + r)
                    } else {
                        (arc_radius + r, cy - r)
                    };
                    let l = toward / dist;
                    if !(-1.0..=1.0).contains(&l) {
                        return Err(CompError::Gouge(
                            "an arc in a concave corner cannot be reached by the tool",
                        ));
                    }
                    let angle = match (inside, ccw) {
                        (true, true) => theta + l.asin(),
                        (true, false) => theta - l.asin(),
                        (false, true) => theta + PI - l.asin(),
                        (false, false) => theta + PI + l.asin(),
                    };
                    polar(centre, dist, angle)
                }
                Some((prev_end, prev_centre, prev_ccw)) => {
                    // arc -> arc
                    let old_r = (prev_centre[1] - prev_end[1]).hypot(prev_centre[0] - prev_end[0]);
                    let new_r = if inside {
                        arc_radius - r
                    } else {
                        arc_radius + r
                    };
                    let cc = (prev_centre[1] - centre[1]).hypot(prev_centre[0] - centre[0]);
                    if old_r == 0.0 || cc == 0.0 {
                        return Err(CompError::Gouge(
                            "two arcs about the same centre meet in a corner",
                        ));
                    }
                    let cos = (old_r * old_r + cc * cc - new_r * new_r) / (2.0 * old_r * cc);
                    if !(-1.0..=1.0).contains(&cos) {
                        return Err(CompError::Gouge(
                            "the corner from an arc to an arc is too tight for the tool",
                        ));
                    }
                    let pullback = cos.acos();
                    let cc_dir = dir(prev_centre, centre);
                    let towards = a.side.inside(prev_ccw) == ccw;
                    let d = if towards {
                        cc_dir + pullback
                    } else {
                        cc_dir - pullback
                    };
                    polar(prev_centre, old_r, d)
                }
            };
            self.move_ends_and_release(meet)?;
            self.queue.push(main(meta));
        } else if beta > small {
            // Convex: an arc about the programmed corner, then this arc.
            let mid = polar(xy(op), r, delta);
            self.release();
            self.queue.push(Queued::Arc {
                sweep: 0.0,
                end: with_z(mid, c[2]),
                centre: xy(op),
                ccw: a.side == Side::Right,
                meta: meta.clone(),
            });
            self.release();
            self.endpoint = Some(mid);
            self.queue.push(main(meta.without_wait()));
        } else {
            self.release();
            self.endpoint = Some(xy(c));
            self.queue.push(main(meta));
        }
        a.programmed = p;
        a.current = with_z(new_end, p[2]);
        self.active = Some(a);
        Ok(())
    }
}
