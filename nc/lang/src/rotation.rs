//! A rotated coordinate system (`G10 L2 P<n> R<deg>`): LinuxCNC turns a work offset's X Y
//! about its origin, so a program point `p` goes to `R(p + g92) + work` (its canon's order:
//! the `G92` offset, the rotation, the work offset). Each of G54..G59 keeps its own rotation;
//! selecting one selects it.
//!
//! dnurbs applies it to straight moves, `G02`/`G03` in `G17` (end, centre offsets as
//! vectors, absolute centres as points), the `G28`/`G30` intermediate point and the
//! position parameters; what it does not turn (canned cycles, polar coordinates, splines,
//! NURBS blocks, arcs in `G18`/`G19`, `G92`, `G10 L20`) is refused while a rotation is in
//! effect, with its column.

use super::error::{ParseError, ParseErrorKind};
use super::parser::Parser;
use nc_geom::program::SrcPos;

impl Parser<'_> {
    /// The XY rotation of the work offset in effect, degrees.
    fn rotation_deg(&self) -> f64 {
        self.rotations
            .get(usize::from(self.modal.work))
            .copied()
            .unwrap_or(0.0)
    }

    /// Whether the work offset in effect is rotated.
    pub(super) fn rotated(&self) -> bool {
        self.rotation_deg() != 0.0
    }

    /// Refuses `what` in a rotated coordinate system.
    pub(super) fn rotation_forbids(
        &self,
        what: &'static str,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        if self.rotated() {
            let deg = self.rotation_deg();
            return Err(ParseErrorKind::NotRotated { what, deg }.at(pos));
        }
        Ok(())
    }

    /// A vector of the program's XY turned into the workpiece frame.
    pub(super) fn turn(&self, v: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.rotation_deg().to_radians().sin_cos();
        [c * v[0] - s * v[1], s * v[0] + c * v[1]]
    }

    /// A program point (mm, its units applied) in the workpiece frame.
    pub(super) fn to_work(&self, p: [f64; 3]) -> [f64; 3] {
        let g = self.modal.g92;
        let work: [f64; 3] = std::array::from_fn(|i| self.modal.offset[i] - g[i]);
        let xy = self.turn([p[0] + g[0], p[1] + g[1]]);
        [
            xy[0] + work[0],
            xy[1] + work[1],
            p[2] + self.modal.offset[2],
        ]
    }

    /// A workpiece-frame point as the program sees it (mm).
    pub(super) fn to_program(&self, w: [f64; 3]) -> [f64; 3] {
        let g = self.modal.g92;
        let work: [f64; 3] = std::array::from_fn(|i| self.modal.offset[i] - g[i]);
        let (s, c) = self.rotation_deg().to_radians().sin_cos();
        let (x, y) = (w[0] - work[0], w[1] - work[1]);
        [
            c * x + s * y - g[0],
            -s * x + c * y - g[1],
            w[2] - self.modal.offset[2],
        ]
    }
}
