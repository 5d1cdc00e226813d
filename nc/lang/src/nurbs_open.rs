//! Opening a `G06.2`/`G06.5` block on its first line and closing it into a block
//! (`nurbs.rs` reads the lines between).

use super::error::{ParseError, ParseErrorKind};
use super::line::Line;
use super::nurbs::{Frame, OpenNurbs};
use super::parser::{normalise, Parser};
use crate::vocab::Motion;
use nc_geom::program::{Block, NurbsBlock, NurbsKind, Orientation, SrcPos};

impl Parser<'_> {
    /// Opens a `G06.2` / `G06.5` block on its first line.
    pub(super) fn open_nurbs(
        &mut self,
        line: &Line<'_>,
        motion: Motion,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        if motion == Motion::G065 && !self.setup.rotary_axes {
            let what = "a G06.5 block (its second curve turns the tool)";
            return Err(ParseErrorKind::NoRotaryAxes { what }.at(pos));
        }
        if self.modal.incremental {
            return Err(ParseErrorKind::NurbsIncremental { motion }.at(pos));
        }
        let Some(here) = self.here else {
            return Err(ParseErrorKind::NurbsBeforeStart { motion }.at(pos));
        };
        let frame = Frame {
            scale: self.modal.scale(),
            offset: self.modal.offset,
        };
        let tooling = self.tooling();
        self.open = Some(OpenNurbs::open(
            line,
            (motion, pos),
            here,
            self.feed,
            frame,
            tooling,
        )?);
        Ok(())
    }

    pub(super) fn close(&mut self, block: NurbsBlock) {
        self.here = block.ctrl.last().copied().or(self.here);
        if block.kind == NurbsKind::G065 {
            if let (Some(xyz), Some(uvw)) = (block.ctrl.last(), block.tool_ctrl.last()) {
                // Never zero: control points keep at least MIN_TOOL_OFFSET_MM from their tool point.
                if let Some(v) = normalise([uvw[0] - xyz[0], uvw[1] - xyz[1], uvw[2] - xyz[2]]) {
                    self.orientation = Orientation::Vector(v);
                    self.orientation_given = true;
                }
            }
        }
        self.just_closed = Some((block.pos, block.knots.len()));
        self.blocks.push(Block::Nurbs(block));
    }
}
