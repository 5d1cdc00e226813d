//! A `G02`/`G03` line: its centre (`I J K`, absolute under `G90.1`, or `R`), its turns
//! (`P`), its end, and the exact NURBS block of the arc (`arc.rs`), or the compensated arc
//! when cutter compensation is on (`comp_parse.rs`).

use super::arc::{self, Centre};
use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use crate::vocab::{Motion, Plane};
use nc_geom::program::{Block, Orientation, SrcPos};

/// Most turns one arc may make (`P`); its control points are bounded further by
/// [`nc_geom::program::MAX_BLOCK_CTRL`].
const MAX_ARC_TURNS: u32 = 10_000;

impl Parser<'_> {
    /// A `G02`/`G03` line (or its modal continuation): a rational quadratic NURBS block.
    pub(super) fn arc_move(
        &mut self,
        line: &Line<'_>,
        motion: Motion,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        line.only(
            &self.extra_letters(line, "GMFSTXYZIJKRABCP@^"),
            Context::Move(motion),
        )?;
        if line.first_of("XYZIJKRABC").is_none() {
            return Ok(());
        }
        // `P`: how many times round (LinuxCNC's multi-turn arcs).
        let turns = match line.get('P') {
            None => 1,
            Some(p) => match p.uint {
                Some(n) if (1..=MAX_ARC_TURNS).contains(&n) => n,
                _ => return Err(ParseErrorKind::ArcTurns { value: p.value }.at(p.pos)),
            },
        };
        if !self.modal.inverse_time && self.feed.is_none() {
            return Err(self.no_feed(motion).at(pos));
        }
        self.comp_curve_allowed(motion, pos)?;
        let plane = self.modal.plane;
        if plane != Plane::Xy {
            // A turn about Z tilts a ZX or YZ arc out of its plane.
            self.rotation_forbids("an arc in G18 or G19", pos)?;
        }
        let (a, b, _) = plane.axes();
        let centre = match line.get('R') {
            Some(r) => {
                if let Some(w) = line.first_of("IJK") {
                    let kind = ParseErrorKind::ArcCentreAndRadius {
                        motion,
                        letter: w.letter,
                    };
                    return Err(kind.at(w.pos));
                }
                Centre::Radius(r.value * self.modal.scale())
            }
            None => {
                // Every offset word outside the plane, even after one in it (`I0 J3 K0` in
                // G17 is refused, as LinuxCNC refuses it).
                let outside = ['I', 'J', 'K']
                    .into_iter()
                    .filter(|&l| l != Plane::offset_letter(a) && l != Plane::offset_letter(b))
                    .filter_map(|l| line.get(l))
                    .min_by_key(|w| (w.pos.line, w.pos.col));
                if let Some(w) = outside {
                    let kind = ParseErrorKind::ArcOffsetOutOfPlane {
                        letter: w.letter,
                        plane,
                    };
                    return Err(kind.at(w.pos));
                }
                let off = |i| {
                    line.value(Plane::offset_letter(i))
                        .map(|v| v * self.modal.scale())
                };
                match (off(a), off(b)) {
                    (None, None) => {
                        return Err(ParseErrorKind::ArcWithoutCentre { motion, plane }.at(pos));
                    }
                    (Some(i), Some(j)) if self.modal.arc_absolute => {
                        // G90.1: the centre's coordinates (work offset applied); made
                        // offsets from the start below.
                        if self.rotated() {
                            let c = self.to_work([i, j, 0.0]);
                            Centre::Offsets(c[0], c[1])
                        } else {
                            Centre::Offsets(i + self.modal.offset[a], j + self.modal.offset[b])
                        }
                    }
                    (i, _) if self.modal.arc_absolute => {
                        let letter = Plane::offset_letter(if i.is_none() { a } else { b });
                        let kind = ParseErrorKind::MissingWord {
                            letter,
                            context: Context::Move(motion),
                        };
                        return Err(kind.at(pos));
                    }
                    (i, j) => {
                        // Offsets are a vector: turned with the coordinate system (G17).
                        let [i, j] = self.turn([i.unwrap_or(0.0), j.unwrap_or(0.0)]);
                        Centre::Offsets(i, j)
                    }
                }
            }
        };
        let end = self.end_point(line, pos)?;
        // Angle words turn the tool along the arc (I J K are the centre here, never a
        // tool axis).
        let turn_to = match line.first_of("ABC") {
            Some(_) => Some(self.angles(line)?),
            None => None,
        };
        let start = self.comp.base().or(self.here).unwrap_or(end);
        let centre = match centre {
            Centre::Offsets(ca, cb) if self.modal.arc_absolute => {
                let at = |i: usize| start.get(i).copied().unwrap_or(0.0);
                Centre::Offsets(ca - at(a), cb - at(b))
            }
            c => c,
        };
        let net = arc::arc(
            start,
            end,
            plane,
            (motion == Motion::G02, turns),
            centre,
            arc::ArcTol::for_units(self.modal.inch),
        )
        .map_err(|kind| kind.at(pos))?;
        let length = (net.radius * net.sweep.abs()).hypot(rise(start, end, plane));
        let feed_mm_min = self.move_feed(line, motion, pos, length)?;
        if self.comp.compensating().is_some() {
            if let Some(w) = line.first_of("ABC") {
                return self.comp_unsupported("a tool-axis word", w.pos);
            }
            if let Some(w) = line.get('P').filter(|_| turns > 1) {
                return self.comp_unsupported("an arc of more than one turn (P)", w.pos);
            }
            if self.modal.inverse_time {
                return self.comp_unsupported("G93 inverse-time feed", pos);
            }
            let clockwise = motion == Motion::G02;
            return self.comp_arc(line, pos, clockwise, (end, net.centre), feed_mm_min);
        }
        let tooling = self.tooling();
        self.here = Some(end);
        if let Some((r1_deg, r2_deg)) = turn_to {
            self.orientation = Orientation::Angles { r1_deg, r2_deg };
            self.orientation_given = true;
        }
        let block = net.into_block((pos, line.n), feed_mm_min, tooling, turn_to);
        self.blocks.push(Block::Nurbs(block));
        Ok(())
    }
}

/// The change of the normal axis along an arc.
fn rise(start: [f64; 3], end: [f64; 3], plane: Plane) -> f64 {
    let (_, _, n) = plane.axes();
    end.get(n).copied().unwrap_or(0.0) - start.get(n).copied().unwrap_or(0.0)
}
