//! The parameters the modal state gives the interpreter ([`State`] for the parser): the
//! position `#5420`.. and `#<_x>`.., the tool `#5400`.., the work offsets `#5220`..
//! `#5221`.., the `G92` offset `#5210`.., the reference position `#5161`.., and the modes
//! `#<_metric>`, `#<_motion_mode>`, ... as LinuxCNC names and numbers them. Positions and
//! the tool length are in the program's units (G20/G21 in effect), positions in the active
//! coordinate system, as LinuxCNC's `#5420` reads; the stored offsets and positions
//! (`#5161`.., `#5211`.., `#5221`..) are in the machine's units, mm, as LinuxCNC keeps them.
//! All of them are read-only: the offsets, the reference and the tools come from the machine
//! file, the `G92` offset from `G92`.

use crate::codes::LengthComp;
use crate::interp::State;
use crate::interp_error::InterpError;
use crate::name::Name;
use crate::parser::Parser;
use crate::vocab::{Motion, Plane};
use nc_geom::program::Orientation;

impl Parser<'_> {
    /// The position in program coordinates: axis `i` (0..3 X Y Z, 3..6 A B C).
    fn position(&self, i: usize, name: &str) -> Result<f64, InterpError> {
        let unknown = || InterpError::PositionUnknown {
            name: Name::new(name),
        };
        if i < 3 {
            let here = self.here.or_else(|| {
                self.setup
                    .reference
                    .map(|r| [r[0], r[1], r[2] - self.modal.tool_length])
            });
            let here = here.ok_or_else(unknown)?;
            if self.rotated() {
                let p = self.to_program(here);
                return Ok(p.get(i).copied().unwrap_or(0.0) / self.modal.scale());
            }
            return Ok((here[i] - self.modal.offset[i]) / self.modal.scale());
        }
        match self.orientation {
            // In program coordinates: the G92 offset taken off the machine's angles.
            Orientation::Angles { r1_deg, r2_deg } => Ok(match (i, self.rotary) {
                (5, _) => r2_deg - self.modal.g92_rot[1],
                (3, Some(('A', _)) | None) | (4, Some(('B', _))) => r1_deg - self.modal.g92_rot[0],
                _ => 0.0,
            }),
            Orientation::Vector([0.0, 0.0, 1.0]) => Ok(match (i, self.rotary) {
                (5, _) => -self.modal.g92_rot[1],
                (3, Some(('A', _)) | None) | (4, Some(('B', _))) => -self.modal.g92_rot[0],
                _ => 0.0,
            }),
            Orientation::Vector(_) => Err(unknown()),
        }
    }

    /// Work offset `k` (0: G54), axis `i`, in program units.
    fn offset(&self, k: usize, i: usize) -> f64 {
        let o = self
            .work_offsets
            .get(k)
            .copied()
            .flatten()
            .unwrap_or([0.0; 3]);
        o.get(i).copied().unwrap_or(0.0)
    }

    fn motion_mode(&self) -> f64 {
        match self.mode {
            None => 800.0,
            Some(Motion::G00) => 0.0,
            Some(Motion::G01) => 10.0,
            Some(Motion::G02) => 20.0,
            Some(Motion::G03) => 30.0,
            Some(Motion::G062 | Motion::G065) => 10.0,
            Some(Motion::G05) => 50.0,
            Some(Motion::G051) => 51.0,
            Some(Motion::G052) => 52.0,
            Some(Motion::G053) => 53.0,
            Some(Motion::Cycle(c)) => 10.0 * c.code(),
        }
    }
}

fn flag(b: bool) -> f64 {
    f64::from(u8::from(b))
}

impl State for Parser<'_> {
    fn computed(&self, n: u32) -> Option<Result<f64, InterpError>> {
        let scale = self.modal.scale();
        Some(Ok(match n {
            // The stored positions and offsets are in the machine's units (LinuxCNC's rule),
            // and a dnurbs machine's are mm, whatever the program's.
            5161..=5169 => {
                let i = (n - 5161) as usize;
                let r = self.setup.reference.unwrap_or([0.0; 3]);
                r.get(i).copied().unwrap_or(0.0)
            }
            5181..=5189 => {
                let i = (n - 5181) as usize;
                let r = self.setup.g30.unwrap_or([0.0; 3]);
                r.get(i).copied().unwrap_or(0.0)
            }
            5399 => return Some(Err(InterpError::InputUnknown)),
            5210 => flag(self.modal.g92 != [0.0; 3] || self.modal.g92_rot != [0.0; 2]),
            5211..=5213 => {
                let i = (n - 5211) as usize;
                self.modal.g92_saved.get(i).copied().unwrap_or(0.0)
            }
            // A B C: the tilting axis is the program's letter (A before any).
            5214 | 5215 => match (n, self.rotary) {
                (5214, Some(('A', _)) | None) | (5215, Some(('B', _))) => {
                    self.modal.g92_rot_saved[0]
                }
                _ => 0.0,
            },
            5216 => self.modal.g92_rot_saved[1],
            5217..=5219 => 0.0,
            5220 => f64::from(self.modal.work) + 1.0,
            5221..=5390 if (n - 5221) % 20 < 10 => {
                let k = ((n - 5221) / 20) as usize;
                let i = ((n - 5221) % 20) as usize;
                match (k, i) {
                    (6.., _) => 0.0,
                    // #5230, #5250, ..: the rotation (G10 L2 R), degrees.
                    (k, 9) => self.rotations.get(k).copied().unwrap_or(0.0),
                    (k, i) => self.offset(k, i),
                }
            }
            5400 => f64::from(self.modal.loaded.unwrap_or(0)),
            5401..=5413 => match n {
                5403 => self.modal.tool_length / scale,
                _ => 0.0,
            },
            5420..=5425 => return Some(self.position((n - 5420) as usize, "5420..5425")),
            5426..=5428 => 0.0,
            _ => return None,
        }))
    }

    fn predefined(&self, name: &str) -> Option<Result<f64, InterpError>> {
        let m = &self.modal;
        let axis = |i: usize| Some(self.position(i, name));
        Some(Ok(match name {
            "_x" => return axis(0),
            "_y" => return axis(1),
            "_z" => return axis(2),
            "_a" => return axis(3),
            "_b" => return axis(4),
            "_c" => return axis(5),
            "_u" | "_v" | "_w" => 0.0,
            "_motion_mode" => self.motion_mode(),
            "_plane" => match m.plane {
                Plane::Xy => 170.0,
                Plane::Zx => 180.0,
                Plane::Yz => 190.0,
            },
            "_ccomp" => 400.0,
            "_metric" => flag(!m.inch),
            "_imperial" => flag(m.inch),
            "_absolute" => flag(!m.incremental),
            "_incremental" => flag(m.incremental),
            "_inverse_time" => flag(m.inverse_time),
            "_units_per_minute" => flag(!m.inverse_time),
            "_units_per_rev" => 0.0,
            "_coord_system" => 540.0 + 10.0 * f64::from(m.work),
            "_tool_offset" => flag(m.comp != LengthComp::Off && m.tool_length != 0.0),
            "_feed" => self.feed.map_or(0.0, |f| f / m.scale()),
            "_rpm" => m.rpm,
            "_current_tool" => f64::from(m.loaded.unwrap_or(0)),
            "_selected_tool" => f64::from(m.selected.unwrap_or(0)),
            "_metric_machine" => 1.0,
            "_retract_r_plane" => flag(m.cycle.retract_to_r),
            "_retract_old_z" => flag(!m.cycle.retract_to_r),
            "_ijk_absolute_mode" => flag(m.arc_absolute),
            _ => return None,
        }))
    }

    fn ended(&self) -> bool {
        self.end().is_some()
    }

    fn level(&mut self, level: usize) {
        self.at_level(level);
    }
}
