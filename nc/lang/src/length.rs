//! `G43 H`, `G43.4 H`, `G49`: the tool length in effect. Where the length changes, the
//! machine stays where it is and the tool tip's coordinates change by the difference, as in
//! LinuxCNC (the next move takes the tip to the programmed point).

use super::codes::{Code, LengthComp, StopCode};
use super::error::{Context, ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::{tool_number, Parser};
use crate::vocab::Motion;
use nc_geom::program::{Orientation, SrcPos};

impl Parser<'_> {
    /// `G43 H` / `G43.4 H` / `G49`: the new tool length. On a line without X Y Z the tool
    /// tip's coordinates change so that the machine stays where it is.
    pub(super) fn length_comp(
        &mut self,
        line: &Line<'_>,
        comp: LengthComp,
        pos: SrcPos,
        motion: Option<Motion>,
    ) -> Result<(), ParseError> {
        let scale = self.modal.scale();
        let length = match comp {
            LengthComp::Off => 0.0,
            LengthComp::Dynamic => {
                let z = line.get('Z').ok_or(
                    ParseErrorKind::MissingWord {
                        letter: 'Z',
                        context: Context::LengthComp,
                    }
                    .at(pos),
                )?;
                z.value * scale
            }
            LengthComp::Added => match (line.get('H'), line.get('Z')) {
                (Some(h), _) => {
                    let tool = tool_number(h)?;
                    let add = match (tool, self.tools.get(&tool)) {
                        (0, _) => 0.0,
                        (_, Some(l)) => *l,
                        (_, None) => return Err(ParseErrorKind::UnknownTool { tool }.at(pos)),
                    };
                    self.modal.tool_length + add
                }
                (None, Some(z)) => self.modal.tool_length + z.value * scale,
                (None, None) => {
                    let kind = ParseErrorKind::MissingWord {
                        letter: 'H',
                        context: Context::LengthComp,
                    };
                    return Err(kind.at(pos));
                }
            },
            LengthComp::Length | LengthComp::Rtcp => {
                // Without H, the tool in the spindle (LinuxCNC's rule): the one an `M06` on
                // this line loads (it comes first), else the one loaded; none is tool 0.
                let changing = matches!(
                    line.code_of_group(11),
                    Some((Code::Stop(StopCode::ToolChange), _))
                );
                let loaded = if changing {
                    match line.get('T') {
                        Some(t) => Some(tool_number(t)?),
                        None => self.modal.selected,
                    }
                } else {
                    self.modal.loaded
                };
                let tool = match (line.get('H'), loaded) {
                    (Some(h), _) => tool_number(h)?,
                    (None, Some(t)) => t,
                    (None, None) => 0,
                };
                match (tool, self.tools.get(&tool)) {
                    (0, _) => 0.0,
                    (_, Some(l)) => *l,
                    (_, None) => return Err(ParseErrorKind::UnknownTool { tool }.at(pos)),
                }
            }
        };
        self.modal.comp = match comp {
            // Offsets on top of the mode in effect (G43.4 stays G43.4).
            LengthComp::Dynamic | LengthComp::Added if self.modal.comp == LengthComp::Rtcp => {
                LengthComp::Rtcp
            }
            LengthComp::Dynamic | LengthComp::Added => LengthComp::Length,
            c => c,
        };
        let from = self.modal.tool_length;
        if length == from {
            return Ok(());
        }
        if let Some(
            m @ (Motion::G02
            | Motion::G03
            | Motion::G062
            | Motion::G065
            | Motion::G05
            | Motion::G051
            | Motion::G052),
        ) = motion
        {
            let kind = ParseErrorKind::LengthChangeOnCurve {
                motion: m,
                from,
                to: length,
            };
            return Err(kind.at(pos));
        }
        if let Some(here) = &mut self.here {
            let t = match self.orientation {
                // LinuxCNC's tool-centre-point kinematics (a machine's `tcp-on` code) keep
                // the tool length an offset of the program's Z, as its interpreter does.
                _ if self.modal.tcp_on => [0.0, 0.0, 1.0],
                Orientation::Vector(v) => v,
                Orientation::Angles { r1_deg, r2_deg } if r1_deg == 0.0 && r2_deg == 0.0 => {
                    [0.0, 0.0, 1.0]
                }
                Orientation::Angles { r1_deg, r2_deg } => match &self.setup.kinematics {
                    Some(kin) => {
                        use nc_geom::kinematics::Kinematics;
                        let t = kin.tool_axis(r1_deg.to_radians(), r2_deg.to_radians());
                        [t.x, t.y, t.z]
                    }
                    None => return Err(ParseErrorKind::LengthChangeTilted.at(pos)),
                },
            };
            for (h, t) in here.iter_mut().zip(t) {
                *h += (from - length) * t;
            }
        }
        self.modal.tool_length = length;
        Ok(())
    }
}
