//! `G28` and `G53`: moves through machine coordinates, which are the workpiece's only through
//! the machine's kinematics (or with the rotary axes at 0).

use super::codes::Code;
use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::moves::check_domain;
use super::nurbs::distance;
use super::parser::Parser;
use crate::vocab::Motion;
use nc_geom::program::{Orientation, SrcPos};

const AXES: [char; 3] = ['X', 'Y', 'Z'];

impl Parser<'_> {
    /// `G53` (a straight move to machine coordinates) and `G28` (a rapid move through the
    /// line's intermediate point to the reference position). Both need the workpiece frame
    /// to be the machine's along the axes they move: see [`Parser::machine_frame`].
    pub(super) fn machine_move(
        &mut self,
        line: &Line<'_>,
        code: Code,
        pos: SrcPos,
    ) -> Result<(), ParseError> {
        let home = matches!(code, Code::Home | Code::Home30);
        // G53 turns the rotary axes too (their machine coordinates are the program's angles).
        let letters = if home { "GMFSTXYZ" } else { "GMFSTXYZABC" };
        line.only(
            &self.extra_letters(line, letters),
            Context::Move(self.mode.unwrap_or(Motion::G00)),
        )?;
        let value = match code {
            Code::Home => 28.0,
            Code::Home30 => 30.0,
            _ => 53.0,
        };
        let rapid = match (home, self.mode) {
            (true, _) | (false, Some(Motion::G00)) => true,
            (false, Some(Motion::G01)) => false,
            (false, _) => return Err(ParseErrorKind::MachineMoveNotLinear { code: value }.at(pos)),
        };
        let given: Vec<usize> = (0..3).filter(|&i| line.get(AXES[i]).is_some()).collect();
        let target = if home {
            let position = if code == Code::Home30 {
                self.setup.g30
            } else {
                self.setup.reference
            };
            let reference = position.ok_or(ParseErrorKind::NoReference { code: value }.at(pos))?;
            let via = self.end_point(line, pos)?;
            if self.here.is_some_and(|h| distance(h, via) > 0.0) {
                let o = self.orientation;
                self.push_linear(line, pos, true, via, o, 0.0);
            }
            reference
        } else {
            let here = self.here_or_reference(line, pos, 'X')?;
            let mut m = here;
            for &i in &given {
                m[i] = line.value(AXES[i]).unwrap_or(0.0) * self.modal.scale();
            }
            m
        };
        let here = self.here_or_reference(line, pos, 'X')?;
        let axes: Vec<usize> = if home && given.is_empty() {
            vec![0, 1, 2]
        } else {
            given
        };
        let length = self.modal.tool_length;
        let mut end = here;
        let start = self.orientation;
        let turned = if home { start } else { self.orientation(line)? };
        if let (
            Some(kin),
            Orientation::Angles { r1_deg, r2_deg },
            Orientation::Angles {
                r1_deg: e1,
                r2_deg: e2,
            },
        ) = (&self.setup.kinematics, start, turned)
        {
            // Through the machine's kinematics: where the tool tip is in machine coordinates
            // with the table as it stands, the axes given moved there, and back into the
            // workpiece frame with the table as the line leaves it.
            use nalgebra::Vector3;
            use nc_geom::kinematics::Kinematics;
            let (a, c) = (r1_deg.to_radians(), r2_deg.to_radians());
            let mut m = kin.place(&Vector3::from(here), a, c);
            for &i in &axes {
                m[i] = target[i] - if i == 2 { length } else { 0.0 };
            }
            let p = kin.unplace(&m, e1.to_radians(), e2.to_radians());
            for (i, e) in end.iter_mut().enumerate() {
                *e = check_domain(AXES[i], p[i], pos)?;
            }
        } else {
            for &i in &axes {
                if !self.machine_frame(i) || turned != start {
                    let kind = ParseErrorKind::MachineMoveRotated {
                        code: value,
                        axis: AXES[i],
                    };
                    return Err(kind.at(pos));
                }
                let l = if i == 2 { length } else { 0.0 };
                end[i] = check_domain(AXES[i], target[i] - l, pos)?;
            }
        }
        let feed = if rapid {
            0.0
        } else {
            self.move_feed(line, Motion::G01, pos, distance(here, end))?
        };
        self.orientation_given |= line.first_of("ABC").is_some();
        self.push_linear(line, pos, rapid, end, turned, feed);
        Ok(())
    }

    /// Whether machine coordinate `axis` equals the workpiece's here: always before any
    /// orientation is programmed and with both angles 0; only Z with a vertical tool (the
    /// table may be turned about Z).
    fn machine_frame(&self, axis: usize) -> bool {
        if !self.orientation_given {
            return true;
        }
        match self.orientation {
            Orientation::Angles { r1_deg, r2_deg } => r1_deg == 0.0 && (r2_deg == 0.0 || axis == 2),
            Orientation::Vector(v) => axis == 2 && v[0] == 0.0 && v[1] == 0.0,
        }
    }
}
