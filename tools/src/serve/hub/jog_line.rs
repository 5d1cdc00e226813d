//! Jogging along a line of X Y Z through the controller: the workpiece's X, Y or Z at the
//! table's angles, or the tool axis, the rotary axes still (`nc_follow::jog_line`).

use super::answer::JOG_DEFAULT_SHARE;
use super::{Asker, Hub, JogKey, Waiting};
use crate::serve::protocol::{Axis, Frame};
use crate::serve::state::{Command, State};
use crate::serve::work;
use nc_follow::jog_line::{tool_direction, workpiece_direction};
use rt_loop::life::Order;

impl Hub<'_> {
    pub(super) fn line_jog(
        &mut self,
        who: Asker,
        axis: Axis,
        frame: Frame,
        positive: bool,
        step: Option<f64>,
        speed: Option<f64>,
    ) -> Result<Option<State>, String> {
        let axes = self.status.axes();
        let (tilt, c) = (axes[3].to_radians(), axes[4].to_radians());
        let kin = &self.setup.kin;
        let sign = if positive { 1.0 } else { -1.0 };
        let d = match (frame, axis) {
            (Frame::Tool, _) => tool_direction(kin, tilt, c),
            (_, Axis::X) => workpiece_direction(kin, [1.0, 0.0, 0.0], tilt, c),
            (_, Axis::Y) => workpiece_direction(kin, [0.0, 1.0, 0.0], tilt, c),
            _ => workpiece_direction(kin, [0.0, 0.0, 1.0], tilt, c),
        };
        let dir = d.map(|x| sign * x);
        let mut limits = [nc_follow::jog::JogLimits {
            velocity: 0.0,
            acceleration: 0.0,
            jerk: 0.0,
            min: 0.0,
            max: 0.0,
        }; 3];
        for (j, l) in limits.iter_mut().enumerate() {
            let Some(drive) = self.drives[j].first() else {
                return Err(format!(
                    "jog {frame:?}: this machine has no {} axis to move",
                    self.setup.axis_names[j]
                ));
            };
            *l = work::jog_limits(&self.setup.limits[j], &drive.drive, self.homed[j]);
        }
        // The default speed: a tenth of the slowest linear axis's velocity.
        let vmax = limits
            .iter()
            .map(|l| l.velocity)
            .fold(f64::INFINITY, f64::min);
        let speed = speed.unwrap_or(vmax * JOG_DEFAULT_SHARE);
        let key = JogKey {
            frame,
            joint: match axis {
                Axis::X => 0,
                Axis::Y => 1,
                _ => 2,
            },
            positive,
            continuous: step.is_none(),
            client: who.client,
        };
        let order = Order::LineJog {
            dir,
            limits,
            distance: step,
            speed,
        };
        if self.ctl.state() == State::Jog
            && step.is_none()
            && self.jog.is_some_and(|k| {
                k.continuous && k.frame == frame && k.joint == key.joint && k.positive == positive
            })
        {
            self.send(order);
            self.jog = Some(key);
            return Ok(Some(State::Jog));
        }
        let mut next = self.ctl;
        next.command(Command::Jog).map_err(|e| e.to_string())?;
        self.send(order);
        self.waiting = Some((who, Waiting::Jog(next, key)));
        Ok(None)
    }
}
