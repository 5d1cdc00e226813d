//! The moves of a line: `G00`/`G01` (and their modal continuation), `G02`/`G03` arcs,
//! `G28`/`G53` moves through machine coordinates, and the opening of a NURBS block.
//!
//! Coordinates are resolved here: program units to mm (`G20`), incremental to absolute
//! (`G91`), program zero to the workpiece frame (the work offset). The workpiece frame is the
//! machine frame with the rotary axes at 0; positions are the tool tip (the tool length lives
//! in [`MoveTooling`](nc_geom::program::MoveTooling) and is added by the machine's Z axis).

use super::codes::{Code, LengthComp};
use super::error::{Context, ParseError, ParseErrorKind};
use super::line::{Line, MOVE_WORDS};
use super::nurbs::distance;
use super::parser::{normalise, Parser};
use super::word::word_limit;
use crate::vocab::Motion;
use crate::vocab::Plane;
use nc_geom::program::{Block, LinearMove, Orientation, SrcPos};

const AXES: [char; 3] = ['X', 'Y', 'Z'];

impl Parser<'_> {
    /// The motion of a line that is not a dwell.
    pub(super) fn motion(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        if let (Some(w), false) = (line.first_of("@^"), self.modal.plane == Plane::Xy) {
            return Err(ParseErrorKind::PolarPlane { letter: w.letter }.at(w.pos));
        }
        if let Some((Code::CoordOffset(kind), pos)) = line.code_of_group(1) {
            self.comp_forbids("G92", pos)?;
            self.rotation_forbids("G92", pos)?;
            return self.coord_offset(line, kind, pos);
        }
        if let Some((Code::SetTable, pos)) = line.code_of_group(1) {
            return self.set_table(line, pos);
        }
        if let Some((Code::LengthComp(c @ (LengthComp::Dynamic | LengthComp::Added)), _)) =
            line.code_of_group(7)
        {
            // The Z word is the offset's, not a move's.
            if let (Some((motion, at)), Some(_)) = (line.motion, line.get('Z')) {
                let code = if c == LengthComp::Dynamic { 43.1 } else { 43.2 };
                return Err(ParseErrorKind::AxisWordsTwice { code, motion }.at(at));
            }
            if line.get('Z').is_some() {
                return line.only(&self.extra_letters(line, "GMFSTZ"), Context::LengthComp);
            }
        }
        if let Some((code @ (Code::Home | Code::Home30 | Code::MachineCoords), pos)) =
            line.code_of_group(1)
        {
            if let Some((m, _)) = line.motion {
                self.mode = Some(m);
            }
            let what = if code == Code::MachineCoords {
                "G53"
            } else {
                "G28/G30"
            };
            self.comp_forbids(what, pos)?;
            return self.machine_move(line, code, pos);
        }
        match line.motion {
            Some((motion @ (Motion::G062 | Motion::G065), pos)) => {
                self.comp_unsupported("a NURBS block", pos)?;
                self.rotation_forbids("a NURBS block", pos)?;
                self.comp_curve_allowed(motion, pos)?;
                self.open_nurbs(line, motion, pos)
            }
            Some((motion, pos)) => {
                self.mode = Some(motion);
                self.modal_move(line, motion, pos)
            }
            None => match line.first_of(MOVE_WORDS) {
                Some(w) => {
                    let Some(motion) = self.mode else {
                        return Err(ParseErrorKind::NoMotionMode { letter: w.letter }.at(w.pos));
                    };
                    self.modal_move(line, motion, line.first)
                }
                None => line.only(&self.extra_letters(line, "GMFST"), Context::NoMotion),
            },
        }
    }

    fn modal_move(
        &mut self,
        line: &Line<'_>,
        motion: Motion,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        if let Motion::Cycle(c) = motion {
            self.comp_forbids("a canned cycle", pos)?;
            self.rotation_forbids("a canned cycle", pos)?;
            return self.cycle(line, c, pos);
        }
        self.end_cycle();
        if motion != Motion::G052 && motion != Motion::G053 {
            self.g52_unclosed(pos)?;
        }
        if matches!(
            motion,
            Motion::G05 | Motion::G051 | Motion::G052 | Motion::G053
        ) {
            self.comp_forbids("a spline (G05, G05.1, G05.2)", pos)?;
            self.rotation_forbids("a spline (G05, G05.1, G05.2)", pos)?;
            self.comp_curve_allowed(motion, pos)?;
        }
        match motion {
            Motion::G052 => self.g52_point(line, pos),
            Motion::G053 => self.g52_close(line, pos),
            Motion::G02 | Motion::G03 => self.arc_move(line, motion, pos),
            Motion::G05 | Motion::G051 => self.spline(line, motion, pos),
            _ => self.linear(line, motion, pos),
        }
    }

    /// `base` plus `H` on a tool-length line, `P` on a `G64` line and `D` on a
    /// compensation line.
    pub(super) fn extra_letters(&self, line: &Line<'_>, base: &str) -> String {
        let mut s = base.to_owned();
        if matches!(line.code_of_group(6), Some((Code::RadiusComp { .. }, _))) {
            s.push('D');
        }
        if line.code_of_group(7).is_some() {
            s.push('H');
        }
        if matches!(line.code_of_group(10), Some((Code::Blend(true), _))) {
            // G64 P (path tolerance) Q (naive-CAM tolerance): read by `blend_words`.
            s.push_str("PQ");
        }
        if matches!(line.code_of_group(1), Some((Code::Dwell, _))) {
            s.push('P');
        }
        if let Some((Code::Io(io), _)) = line.code_of_group(16) {
            s.push_str(io.letters());
        }
        s
    }

    /// The feed of a feed move (mm/min): the modal feed, or under `G93` the line's `F` (1/min)
    /// times the move's length (mm, or degrees for a move that only turns the tool).
    pub(super) fn move_feed(
        &self,
        line: &Line<'_>,
        motion: Motion,
        pos: SrcPos,
        length: f64,
    ) -> Result<f64, ParseError> {
        if self.modal.inverse_time {
            let f = line
                .get('F')
                .ok_or(ParseErrorKind::InverseTimeWithoutFeed { motion }.at(pos))?;
            return Ok(f.value * length);
        }
        self.feed.ok_or(self.no_feed(motion).at(pos))
    }

    /// The current position, starting at the reference position if the program has none
    /// yet (`missing` names the axis the line left out, for the error without one).
    pub(crate) fn here_or_reference(
        &mut self,
        line: &Line<'_>,
        pos: SrcPos,
        missing: char,
    ) -> Result<[f64; 3], ParseError> {
        if let Some(here) = self.here {
            return Ok(here);
        }
        let Some(r) = self.setup.reference else {
            return Err(ParseErrorKind::MissingStartAxis { axis: missing }.at(pos));
        };
        let end = [r[0], r[1], r[2] - self.modal.tool_length];
        let tooling = self.tooling();
        self.from_reference = Some(self.drained + self.blocks.len());
        self.blocks.push(Block::Linear(LinearMove {
            pos,
            n: line.n,
            rapid: true,
            end,
            orientation: self.orientation,
            feed_mm_min: 0.0,
            inverse_time: false,
            tooling,
        }));
        self.here = Some(end);
        Ok(end)
    }

    /// The end point of a move: each given axis resolved (units, G91, work offset), the
    /// others kept.
    pub(super) fn end_point(
        &mut self,
        line: &Line<'_>,
        pos: SrcPos,
    ) -> Result<[f64; 3], ParseError> {
        let missing = AXES.into_iter().find(|a| line.get(*a).is_none());
        // Under cutter compensation, from the programmed point (the tool is beside it).
        let base = self.comp.base().or(self.here);
        let here = match (base, missing, self.modal.incremental) {
            (Some(h), _, _) => Some(h),
            (None, None, false) => None,
            (None, m, _) => Some(self.here_or_reference(line, pos, m.unwrap_or('X'))?),
        };
        if self.rotated() {
            if let Some(w) = line.first_of("@^") {
                return self
                    .rotation_forbids("polar coordinates", w.pos)
                    .map(|()| [0.0; 3]);
            }
            // In the program's (unturned) frame, then turned into the workpiece's.
            let prev = here.map(|h| self.to_program(h)).unwrap_or([0.0; 3]);
            let mut p = prev;
            for (i, axis) in AXES.into_iter().enumerate() {
                if let Some(w) = line.get(axis) {
                    let v = w.value * self.modal.scale();
                    p[i] = if self.modal.incremental {
                        prev[i] + v
                    } else {
                        v
                    };
                }
            }
            let end = self.to_work(p);
            for (i, axis) in AXES.into_iter().enumerate() {
                if let Some(w) = line.get(axis) {
                    check_domain(axis, end[i], w.pos)?;
                }
            }
            return Ok(end);
        }
        let mut end = [0.0; 3];
        for (i, axis) in AXES.into_iter().enumerate() {
            let prev = here.map(|h| h[i]).unwrap_or(0.0);
            end[i] = match line.get(axis) {
                None => prev,
                Some(w) => {
                    let v = w.value * self.modal.scale();
                    let v = if self.modal.incremental {
                        prev + v
                    } else {
                        v + self.modal.offset[i]
                    };
                    check_domain(axis, v, w.pos)?
                }
            };
        }
        if let Some(w) = line.first_of("@^") {
            self.polar(line, w.pos, &mut end)?;
        }
        Ok(end)
    }

    /// A G00/G01 line, or a line continuing that modal motion; `pos` is the block's position.
    fn linear(&mut self, line: &Line<'_>, motion: Motion, pos: SrcPos) -> Result<(), ParseError> {
        line.only(
            &self.extra_letters(line, "GMFSTXYZABCIJK@^"),
            Context::Move(motion),
        )?;
        if line.first_of("XYZABCIJK@^").is_none() {
            return Ok(()); // `G01 F500`: sets the mode, moves nothing
        }
        let rapid = motion == Motion::G00;
        if !rapid && !self.modal.inverse_time && self.feed.is_none() {
            return Err(self.no_feed(motion).at(pos));
        }
        let start = self.here;
        let end = self.end_point(line, pos)?;
        let orientation = self.orientation(line)?;
        let from = self.here.or(start).unwrap_or(end);
        let feed_mm_min = if rapid {
            self.feed.unwrap_or(0.0)
        } else {
            let mm = distance(from, end);
            let length = if mm > 1e-9 {
                mm
            } else {
                turn_deg(self.orientation, orientation)
            };
            self.move_feed(line, motion, pos, length)?
        };
        self.comp.arc_not_allowed = false;
        if self.comp.compensating().is_some() {
            if let Some(w) = line.first_of("ABCIJK") {
                return self.comp_unsupported("a tool-axis word", w.pos);
            }
            if self.modal.inverse_time {
                return self.comp_unsupported("G93 inverse-time feed", pos);
            }
        }
        if self.comp_linear(line, pos, rapid, end, feed_mm_min)? {
            return Ok(());
        }
        self.orientation_given |= line.first_of("ABCIJK").is_some();
        self.push_linear(line, pos, rapid, end, orientation, feed_mm_min);
        Ok(())
    }

    pub(crate) fn push_linear(
        &mut self,
        line: &Line<'_>,
        pos: SrcPos,
        rapid: bool,
        end: [f64; 3],
        orientation: Orientation,
        feed_mm_min: f64,
    ) {
        let tooling = self.tooling();
        self.here = Some(end);
        self.orientation = orientation;
        self.blocks.push(Block::Linear(LinearMove {
            pos,
            n: line.n,
            rapid,
            end,
            orientation,
            feed_mm_min,
            inverse_time: !rapid && self.modal.inverse_time,
            tooling,
        }));
    }

    /// The orientation at the end of a linear move (modal values resolved).
    pub(super) fn orientation(&mut self, line: &Line<'_>) -> Result<Orientation, ParseError> {
        let angle = line.first_of("ABC");
        let vector = line.first_of("IJK");
        match (angle, vector) {
            (Some(a), Some(v)) => {
                let later = if a.pos > v.pos { a.pos } else { v.pos };
                let kind = ParseErrorKind::MixedOrientation {
                    angle: a.letter,
                    vector: v.letter,
                };
                Err(kind.at(later))
            }
            (None, Some(given)) => {
                let mut ijk = [0.0; 3];
                for (slot, letter) in ijk.iter_mut().zip(['I', 'J', 'K']) {
                    let missing = ParseErrorKind::IncompleteVector {
                        given: given.letter,
                        missing: letter,
                    };
                    *slot = line.value(letter).ok_or(missing.at(given.pos))?;
                }
                let zero = ParseErrorKind::ZeroVector { ijk }.at(given.pos);
                let v = normalise(ijk).ok_or(zero)?;
                if !self.setup.rotary_axes && v != [0.0, 0.0, 1.0] {
                    let what = "a tool vector other than I0 J0 K1";
                    return Err(ParseErrorKind::NoRotaryAxes { what }.at(given.pos));
                }
                Ok(Orientation::Vector(v))
            }
            (Some(_), None) => self
                .angles(line)
                .map(|(r1_deg, r2_deg)| Orientation::Angles { r1_deg, r2_deg }),
            (None, None) => Ok(self.orientation),
        }
    }

    /// The rotary angles of a line with angle words (`G91`: added to the previous ones).
    pub(super) fn angles(&mut self, line: &Line<'_>) -> Result<(f64, f64), ParseError> {
        let r1 = match (line.get('A'), line.get('B')) {
            (Some(a), Some(b)) => {
                let kind = ParseErrorKind::MixedRotaryAxes {
                    letter: 'B',
                    first: 'A',
                    first_pos: a.pos,
                };
                return Err(kind.at(b.pos));
            }
            (r1, None) | (None, r1) => r1,
        };
        if let Some(w) = r1 {
            self.rotary_letter(w)?;
        }
        let r2 = line.get('C');
        let (prev1, prev2) = match self.orientation {
            Orientation::Angles { r1_deg, r2_deg } => (r1_deg, r2_deg),
            // The implicit vertical tool is A0 C0 (B0 C0) on the machines dnurbs drives.
            Orientation::Vector(_) if !self.orientation_given => (0.0, 0.0),
            Orientation::Vector(_) => match (r1, r2) {
                (Some(given), None) | (None, Some(given)) => {
                    let kind = ParseErrorKind::PartialAngles {
                        given: given.letter,
                    };
                    return Err(kind.at(given.pos));
                }
                _ => (0.0, 0.0),
            },
        };
        let inc = self.modal.incremental;
        // Absolute angles are the program's: the G92 offset makes them the machine's.
        let [off1, off2] = self.modal.g92_rot;
        let resolve =
            |w: Option<super::word::Word>, prev: f64, off: f64| -> Result<f64, ParseError> {
                match w {
                    None => Ok(prev),
                    Some(w) if inc => check_domain(w.letter, prev + w.value, w.pos),
                    Some(w) if off != 0.0 => check_domain(w.letter, w.value + off, w.pos),
                    Some(w) => Ok(w.value),
                }
            };
        Ok((resolve(r1, prev1, off1)?, resolve(r2, prev2, off2)?))
    }

    /// The program's tilting-axis letter is `w`'s (a program uses A or B, not both).
    pub(super) fn rotary_letter(&mut self, w: super::word::Word) -> Result<(), ParseError> {
        match self.rotary {
            Some((first, first_pos)) if first != w.letter => {
                let kind = ParseErrorKind::MixedRotaryAxes {
                    letter: w.letter,
                    first,
                    first_pos,
                };
                Err(kind.at(w.pos))
            }
            Some(_) => Ok(()),
            None => {
                self.rotary = Some((w.letter, w.pos));
                Ok(())
            }
        }
    }
}

/// A resolved coordinate must stay within the word's domain (offsets and G91 can push a
/// valid word outside it).
pub(crate) fn check_domain(letter: char, value: f64, pos: SrcPos) -> Result<f64, ParseError> {
    let max = word_limit(letter);
    if value.abs() <= max {
        Ok(value)
    } else {
        Err(ParseErrorKind::OutsideDomain { letter, value, max }.at(pos))
    }
}

/// Degrees the tool turns between two orientations (for G93 on moves that only turn it):
/// the angle between vectors, or the larger angle change.
fn turn_deg(from: Orientation, to: Orientation) -> f64 {
    match (from, to) {
        (Orientation::Vector(a), Orientation::Vector(b)) => {
            let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            dot.clamp(-1.0, 1.0).acos().to_degrees()
        }
        (
            Orientation::Angles {
                r1_deg: a1,
                r2_deg: a2,
            },
            Orientation::Angles {
                r1_deg: b1,
                r2_deg: b2,
            },
        ) => (b1 - a1).abs().max((b2 - a2).abs()),
        _ => 0.0,
    }
}
