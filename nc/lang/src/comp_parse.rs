//! The parser's side of cutter radius compensation: turning it on and off from a line's
//! `G40`/`G41`/`G42`/`G41.1`/`G42.1` and `D`, the words and modes it does not allow, and the
//! blocks and actions the compensation releases (`comp.rs` holds and decides them).

use super::arc::{self, Centre};
use super::codes::Code;
use super::comp::{Active, CompError, Meta, Queued, Side};
use super::error::{ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::{tool_number, Parser};
use crate::vocab::{Motion, Plane};
use nc_geom::program::{Block, LinearMove, SrcPos};

impl CompError {
    fn kind(self) -> ParseErrorKind {
        match self {
            CompError::EntryTooShort { length, radius } => {
                ParseErrorKind::CompensationEntryTooShort { length, radius }
            }
            CompError::ToolTooBig { arc_radius, radius } => {
                ParseErrorKind::CompensationToolTooBig { arc_radius, radius }
            }
            CompError::Gouge(what) => ParseErrorKind::CompensationGouge { what },
            CompError::Internal(what) => ParseErrorKind::CompensationInternal { what },
        }
    }
}

impl Parser<'_> {
    /// Whether `G41`/`G42` is in effect (with any radius): the modes it forbids stay
    /// forbidden even when the radius is 0, as in LinuxCNC.
    pub(super) fn comp_on(&self) -> bool {
        self.comp.active.is_some()
    }

    /// Refuses `what` while compensation is on.
    pub(super) fn comp_forbids(&self, what: &'static str, pos: SrcPos) -> Result<(), ParseError> {
        if self.comp_on() {
            return Err(ParseErrorKind::CompensationForbids { what }.at(pos));
        }
        Ok(())
    }

    /// Refuses what dnurbs does not compensate (LinuxCNC does) while compensation is on.
    pub(super) fn comp_unsupported(
        &self,
        what: &'static str,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        if self.comp_on() {
            return Err(ParseErrorKind::CompensationUnsupported { what }.at(pos));
        }
        Ok(())
    }

    /// Refuses a mode change compensation does not allow (LinuxCNC's rules), or does not
    /// support in dnurbs.
    pub(super) fn comp_allows(&self, code: Code, pos: SrcPos) -> Result<(), ParseError> {
        match code {
            Code::Plane(p) if p != self.modal.plane => self.comp_forbids("a plane change", pos),
            Code::Inch(i) if i != self.modal.inch => self.comp_forbids("a change of units", pos),
            Code::WorkOffset(i) if i != self.modal.work => {
                self.comp_forbids("a change of work offset", pos)
            }
            Code::Blend(_) => self.comp_forbids("a path-control mode (G61/G64)", pos),
            Code::InverseTime(true) => self.comp_unsupported("G93 inverse-time feed", pos),
            _ => Ok(()),
        }
    }

    /// A line's `G40`/`G41`/`G42`/`G41.1`/`G42.1` and its `D` word.
    pub(super) fn radius_comp(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let code = line.code_of_group(6);
        if let (Some(d), false) = (
            line.get('D'),
            matches!(code, Some((Code::RadiusComp { .. }, _))),
        ) {
            return Err(ParseErrorKind::DWithoutCompensation.at(d.pos));
        }
        match code {
            Some((Code::CompensationOff, pos)) => {
                let programmed = self.comp.off().map_err(|e| e.kind().at(pos))?;
                self.emit_comp();
                if let Some(p) = programmed {
                    // LinuxCNC's rule: the next move starts from the programmed point.
                    self.here = Some(p);
                }
                Ok(())
            }
            Some((Code::RadiusComp { side, direct }, pos)) => {
                self.comp_start(line, side, direct, pos)
            }
            _ => Ok(()),
        }
    }

    fn comp_start(
        &mut self,
        line: &Line<'_>,
        side: Side,
        direct: bool,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        let code = match (side, direct) {
            (Side::Left, false) => 41.0,
            (Side::Left, true) => 41.1,
            (Side::Right, false) => 42.0,
            (Side::Right, true) => 42.1,
        };
        if self.modal.plane != Plane::Xy {
            let plane = self.modal.plane;
            return Err(ParseErrorKind::CompensationPlane { code, plane }.at(pos));
        }
        if self.comp_on() {
            return Err(ParseErrorKind::CompensationTwice { code }.at(pos));
        }
        let d = line.get('D');
        let diameter = if direct {
            let d = d.ok_or(ParseErrorKind::CompensationWithoutD { code }.at(pos))?;
            d.value * self.modal.scale()
        } else {
            let tool = match d {
                Some(w) => Some(tool_number(w)?),
                None => self.modal.loaded,
            };
            match tool {
                None | Some(0) => 0.0,
                Some(t) => match self.diameters.get(&t) {
                    Some(&dia) => dia,
                    None if self.tools.contains_key(&t) => 0.0,
                    None => {
                        let at = d.map_or(pos, |w| w.pos);
                        return Err(ParseErrorKind::UnknownTool { tool: t }.at(at));
                    }
                },
            }
        };
        let radius = diameter / 2.0;
        let here = self.here.unwrap_or([0.0; 3]);
        self.comp.active = Some(Active {
            side: if radius < 0.0 { side.other() } else { side },
            radius: radius.abs(),
            scale: self.modal.scale(),
            first: true,
            programmed: here,
            current: here,
        });
        Ok(())
    }

    /// What a compensated move carries: its line, feed, orientation and tooling.
    fn comp_meta(&mut self, line: &Line<'_>, pos: SrcPos, feed_mm_min: f64) -> Meta {
        Meta {
            pos,
            n: line.n,
            feed_mm_min,
            orientation: self.orientation,
            tooling: self.tooling(),
        }
    }

    /// A compensated line to the programmed point `end`, where the compensation moves the
    /// tool; `false` when it does not (off, or radius 0: the move is an ordinary one).
    pub(super) fn comp_linear(
        &mut self,
        line: &Line<'_>,
        pos: SrcPos,
        rapid: bool,
        end: [f64; 3],
        feed_mm_min: f64,
    ) -> Result<bool, ParseError> {
        if self.comp.compensating().is_none() {
            return Ok(false);
        }
        let meta = self.comp_meta(line, pos, feed_mm_min);
        self.comp
            .straight(rapid, end, meta)
            .map_err(|e| e.kind().at(pos))?;
        self.emit_comp();
        self.here = self.comp.active.map(|a| a.current);
        Ok(true)
    }

    /// A compensated arc to the programmed point `end` about the programmed `centre`.
    pub(super) fn comp_arc(
        &mut self,
        line: &Line<'_>,
        pos: SrcPos,
        clockwise: bool,
        (end, centre): ([f64; 3], [f64; 3]),
        feed_mm_min: f64,
    ) -> Result<(), ParseError> {
        let meta = self.comp_meta(line, pos, feed_mm_min);
        let tol = arc::ArcTol::for_units(self.modal.inch).radius_mm;
        self.comp
            .arc(!clockwise, end, [centre[0], centre[1]], meta, tol)
            .map_err(|e| e.kind().at(pos))?;
        self.emit_comp();
        self.here = self.comp.active.map(|a| a.current);
        Ok(())
    }

    /// Releases the held moves where they are (before a stop, at the program end).
    pub(super) fn comp_flush(&mut self, pos: SrcPos) -> Result<(), ParseError> {
        self.comp.flush_here().map_err(|e| e.kind().at(pos))?;
        self.emit_comp();
        Ok(())
    }

    /// Turns what the compensation released into blocks and actions, in order.
    pub(super) fn emit_comp(&mut self) {
        let out = core::mem::take(&mut self.comp.out);
        for (q, start) in out {
            match q {
                Queued::Action(pos, kind) => self.act_now(pos, kind),
                Queued::Line {
                    rapid, end, meta, ..
                } => self.blocks.push(Block::Linear(LinearMove {
                    pos: meta.pos,
                    n: meta.n,
                    rapid,
                    end,
                    orientation: meta.orientation,
                    feed_mm_min: meta.feed_mm_min,
                    inverse_time: false,
                    tooling: meta.tooling,
                })),
                Queued::Arc {
                    end,
                    centre,
                    ccw,
                    meta,
                    ..
                } => {
                    let offsets = Centre::Offsets(centre[0] - start[0], centre[1] - start[1]);
                    let tol = arc::ArcTol::for_units(self.modal.inch);
                    match arc::arc(start, end, Plane::Xy, (!ccw, 1), offsets, tol) {
                        Ok(net) => {
                            let block = net.into_block(
                                (meta.pos, meta.n),
                                meta.feed_mm_min,
                                meta.tooling,
                                None,
                            );
                            self.blocks.push(Block::Nurbs(block));
                        }
                        Err(kind) => self.comp_error = Some(kind.at(meta.pos)),
                    }
                }
            }
        }
    }

    /// Refuses a curve right after `G40`.
    pub(super) fn comp_curve_allowed(&self, motion: Motion, pos: SrcPos) -> Result<(), ParseError> {
        if self.comp.arc_not_allowed {
            return Err(ParseErrorKind::ArcAfterCompensation { motion }.at(pos));
        }
        Ok(())
    }
}
