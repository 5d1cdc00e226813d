//! Canned cycles `G73 G81 G82 G83 G85 G86 G89` as LinuxCNC runs them, expanded into the
//! straight moves, dwells and spindle actions they stand for ([`Parser::cycle`]).
//!
//! In the active plane (`G17`: the cycle axis is Z, the hole at X Y; `G18`: Y, at Z X;
//! `G19`: X, at Y Z), for each of `L` repeats: a rapid in the plane to the hole (first up to
//! `R` if the tool is below it), a rapid down to `R`, then the cycle's own moves, and a
//! retract to the clearance level: `R` under `G99`, the level where the cycle started under
//! `G98`. `R`, the depth (the cycle axis's word), `P` (dwell, s) and `Q` (peck) are modal
//! while the cycle is: a later line with only a hole position repeats it there. Under `G91`
//! `R` is measured from the starting level, the depth from `R`, and the hole position is an
//! increment, applied at each repeat. The moves are those LinuxCNC's interpreter makes
//! (`interp_cycles.cc`), checked by the conformance suite against it.

use crate::error::{Context, ParseError, ParseErrorKind};
use crate::line::Line;
use crate::modal::MM_PER_INCH;
use crate::parser::Parser;
use crate::vocab::{Cycle, Motion};
use nc_geom::program::{ActionKind, Spindle, SrcPos};

/// How far `G73`/`G83` back off before the next peck (LinuxCNC's `G83_RAPID_DELTA`, 0.010 in).
const PECK_CLEARANCE_IN: f64 = 0.010;

/// Letters a cycle line may carry (besides `G M F S T N`): the plane's two axes and the
/// cycle axis, `R L P Q`.
const CYCLE_LETTERS: &str = "GMFSTXYZRLPQ@^";

/// Most moves the canned cycle of one line may make (its `L` repeats times its pecks): a
/// line's moves are built before the planner takes them, so they are bounded.
pub const MAX_CYCLE_MOVES: usize = 100_000;

impl Parser<'_> {
    /// A line of canned cycle `cycle` (its code, or the modal cycle with a hole position).
    pub(crate) fn cycle(
        &mut self,
        line: &Line<'_>,
        cycle: Cycle,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        let motion = Motion::Cycle(cycle);
        line.only(CYCLE_LETTERS, Context::Move(motion))?;
        if self.modal.inverse_time {
            return Err(ParseErrorKind::CycleInverseTime { cycle }.at(pos));
        }
        let feed = self
            .feed
            .filter(|f| *f > 0.0)
            .ok_or(self.no_feed(motion).at(pos))?;
        let (a, b, n) = self.modal.plane.axes();
        let letter = |i: usize| ['X', 'Y', 'Z'][i];
        let entering = self.modal.cycle.active != Some(cycle);
        // The sticky words: required when the cycle starts.
        let word = |l: char, state: f64, needed: bool| -> Result<f64, ParseError> {
            match line.get(l) {
                Some(w) => Ok(w.value),
                None if !entering || !needed => Ok(state),
                None => Err(ParseErrorKind::MissingWord {
                    letter: l,
                    context: Context::Move(motion),
                }
                .at(pos)),
            }
        };
        let st = self.modal.cycle;
        let r_word = word('R', st.r, true)?;
        let depth_word = word(letter(n), st.depth, true)?;
        let dwell = word('P', st.p, cycle.dwells())?;
        let peck = word('Q', st.q, cycle.pecks())?;
        let repeats = match line.get('L') {
            None => 1,
            Some(l) => match l.uint {
                Some(0) | None => {
                    return Err(ParseErrorKind::BadRepeat { value: l.value }.at(l.pos))
                }
                Some(k) => k,
            },
        };
        if cycle.pecks() && peck <= 0.0 {
            let at = line.get('Q').map_or(pos, |w| w.pos);
            return Err(ParseErrorKind::BadPeck { value: peck }.at(at));
        }
        if cycle.dwells() && !(0.0..=crate::rules::MAX_DWELL_S).contains(&dwell) {
            let at = line.get('P').map_or(pos, |w| w.pos);
            return Err(ParseErrorKind::BadDwell { value: dwell }.at(at));
        }
        let spindle = self.modal.spindle;
        if cycle == Cycle::G86 && spindle == Spindle::Off {
            return Err(ParseErrorKind::CycleSpindleOff { cycle }.at(pos));
        }
        let here_mm = self.here_or_reference(line, pos, letter(a))?;
        // LinuxCNC computes a cycle in the program's units (the pecks' loop compares depths
        // so computed): so does this, converting each point to workpiece mm as it is moved to.
        let scale = self.modal.scale();
        let off = self.modal.offset;
        let here: [f64; 3] = core::array::from_fn(|i| (here_mm[i] - off[i]) / scale);
        let initial = *self.modal.cycle.initial.get_or_insert(here[n]);
        let mut level = initial;
        let (mut pa, mut pb) = (here[a], here[b]);
        let (mut da, mut db) = (0.0, 0.0);
        // Polar words (G17 only, checked with the motion): in G91 a radius and an angle
        // added each repeat, in G90 the hole's radius and angle (LinuxCNC's rules).
        let (polar_r, polar_t) = (line.value('@'), line.value('^').map(f64::to_radians));
        let (mut dr, mut dt) = (0.0, 0.0);
        let (r, bottom) = if self.modal.incremental {
            da = line.value(letter(a)).unwrap_or(0.0);
            db = line.value(letter(b)).unwrap_or(0.0);
            (dr, dt) = (polar_r.unwrap_or(0.0), polar_t.unwrap_or(0.0));
            let r = r_word + initial;
            (r, r + depth_word)
        } else if polar_r.is_some() || polar_t.is_some() {
            let radius = polar_r.unwrap_or_else(|| pb.hypot(pa));
            let theta = polar_t.unwrap_or_else(|| pb.atan2(pa));
            (pa, pb) = (radius * theta.cos(), radius * theta.sin());
            (r_word, depth_word)
        } else {
            pa = line.value(letter(a)).unwrap_or(pa);
            pb = line.value(letter(b)).unwrap_or(pb);
            (r_word, depth_word)
        };
        if r < bottom {
            let at = line.get('R').map_or(pos, |w| w.pos);
            let kind = ParseErrorKind::CycleRBelowDepth {
                r: r * scale + off[n],
                depth: bottom * scale + off[n],
            };
            return Err(kind.at(at));
        }
        // A point of the cycle (program units) in workpiece mm.
        let point = |u: f64, v: f64, w: f64| {
            let mut p = [0.0; 3];
            p[a] = u * scale + off[a];
            p[b] = v * scale + off[b];
            p[n] = w * scale + off[n];
            p
        };
        let mut current = here[n];
        if level < r {
            // Below R: straight up to it first.
            self.cycle_move(line, pos, true, point(here[a], here[b], r), feed)?;
            level = r;
            current = r;
        }
        let clear = if self.modal.cycle.retract_to_r {
            r
        } else {
            level
        };
        let back = PECK_CLEARANCE_IN * MM_PER_INCH / scale;
        self.cycle_moves = 0;
        for k in 0..repeats {
            pa += da;
            pb += db;
            for (step, turn) in [(dr, 0.0), (0.0, dt)] {
                if step == 0.0 && turn == 0.0 {
                    continue;
                }
                if pa == 0.0 && pb == 0.0 {
                    return Err(ParseErrorKind::PolarAtOrigin { incremental: true }.at(pos));
                }
                let (radius, theta) = (pb.hypot(pa) + step, pb.atan2(pa) + turn);
                (pa, pb) = (radius * theta.cos(), radius * theta.sin());
            }
            if k == 0 && current > r {
                self.cycle_move(line, pos, true, point(pa, pb, current), feed)?;
                self.cycle_move(line, pos, true, point(pa, pb, r), feed)?;
            } else {
                self.cycle_move(line, pos, true, point(pa, pb, clear), feed)?;
                if clear > r {
                    self.cycle_move(line, pos, true, point(pa, pb, r), feed)?;
                }
            }
            let at = |w: f64| point(pa, pb, w);
            match cycle {
                Cycle::G73 | Cycle::G83 => {
                    let mut depth = r - peck;
                    while depth > bottom {
                        self.cycle_move(line, pos, false, at(depth), feed)?;
                        if cycle == Cycle::G83 {
                            self.cycle_move(line, pos, true, at(r), feed)?;
                        }
                        self.cycle_move(line, pos, true, at(depth + back), feed)?;
                        depth -= peck;
                    }
                    self.cycle_move(line, pos, false, at(bottom), feed)?;
                    self.cycle_move(line, pos, true, at(clear), feed)?;
                }
                Cycle::G81 => {
                    self.cycle_move(line, pos, false, at(bottom), feed)?;
                    self.cycle_move(line, pos, true, at(clear), feed)?;
                }
                Cycle::G82 => {
                    self.cycle_move(line, pos, false, at(bottom), feed)?;
                    self.cycle_dwell(pos, dwell);
                    self.cycle_move(line, pos, true, at(clear), feed)?;
                }
                Cycle::G85 => {
                    self.cycle_move(line, pos, false, at(bottom), feed)?;
                    self.cycle_move(line, pos, false, at(r), feed)?;
                    self.cycle_move(line, pos, true, at(clear), feed)?;
                }
                Cycle::G86 => {
                    self.cycle_move(line, pos, false, at(bottom), feed)?;
                    self.cycle_dwell(pos, dwell);
                    let rpm = self.modal.rpm;
                    self.act(
                        pos,
                        ActionKind::Spindle {
                            dir: Spindle::Off,
                            rpm,
                        },
                    );
                    self.cycle_move(line, pos, true, at(clear), feed)?;
                    self.act(pos, ActionKind::Spindle { dir: spindle, rpm });
                }
                Cycle::G89 => {
                    self.cycle_move(line, pos, false, at(bottom), feed)?;
                    self.cycle_dwell(pos, dwell);
                    self.cycle_move(line, pos, false, at(clear), feed)?;
                }
            }
        }
        let c = &mut self.modal.cycle;
        c.r = r_word;
        c.depth = depth_word;
        c.p = dwell;
        c.q = peck;
        c.active = Some(cycle);
        self.mode = Some(motion);
        Ok(())
    }

    /// One straight move of a cycle (the tool's orientation as it is).
    fn cycle_move(
        &mut self,
        line: &Line<'_>,
        pos: SrcPos,
        rapid: bool,
        end: [f64; 3],
        feed: f64,
    ) -> Result<(), ParseError> {
        for (i, v) in end.iter().enumerate() {
            crate::moves::check_domain(['X', 'Y', 'Z'][i], *v, pos)?;
        }
        // One line's moves are built before the planner takes them: bounded.
        self.cycle_moves += 1;
        if self.cycle_moves > MAX_CYCLE_MOVES {
            let kind = ParseErrorKind::CycleTooLong {
                max: MAX_CYCLE_MOVES,
            };
            return Err(kind.at(pos));
        }
        let orientation = self.orientation;
        self.push_linear(
            line,
            pos,
            rapid,
            end,
            orientation,
            if rapid {
                self.feed.unwrap_or(0.0)
            } else {
                feed
            },
        );
        Ok(())
    }

    fn cycle_dwell(&mut self, pos: SrcPos, seconds: f64) {
        self.wait.dwell_s += seconds;
        self.act(pos, ActionKind::Dwell { seconds });
    }

    /// `G80`, or a motion that is no cycle: the cycle's starting level is forgotten.
    pub(crate) fn end_cycle(&mut self) {
        self.modal.cycle.initial = None;
        self.modal.cycle.active = None;
    }
}
