//! Homing mode (6) of the simulated drive: the methods a machine builder uses most, on a
//! motor with a home switch and an encoder index ([`HomeHardware`]).
//!
//! The controlword's bit 4 starts homing (its rising edge, in Operation enabled, in mode 6)
//! and clearing it interrupts it. The method (0x6098), the speeds (0x6099:01 while searching
//! for the switch, :02 while searching for the index, counts/s), the acceleration (0x609A,
//! counts/s²) and the home offset (0x607C) are read at the start. Methods:
//!
//! - 35 and 37: the current position is the home position, at once.
//! - 19: the home switch is active on the positive side of its edge: from the inactive side
//!   the motor moves positive until it turns active, from the active side negative until it
//!   turns inactive; the home position is the edge.
//! - 21: the same with the switch active on the negative side.
//! - 3 (5): as 19 (21), then on at the index speed toward the switch's inactive side
//!   to the first index pulse; the home position is the pulse.
//!
//! At the home position the position actual value becomes the home offset (the motor is
//! re-referenced where it passed that point) and the motor decelerates to rest. A search that
//! travels farther than [`HomeHardware::search_limit`] without finding its switch or pulse
//! (a switch that is not wired) ends in a homing error, the motor decelerating to rest.
//! Statusword in mode 6 (CiA-402): bit 12 homing attained, bit 13 homing error, bit 10 the
//! motor at rest after either (or interrupted).

use super::motor::{Demand, Motor, Ramp};
use crate::od;

/// Controlword bit 4 in homing mode: start.
pub const START: u16 = 1 << 4;
/// Statusword bits in homing mode.
pub const TARGET_REACHED: u16 = 1 << 10;
pub const ATTAINED: u16 = 1 << 12;
pub const ERROR: u16 = 1 << 13;
/// The methods the drive offers (0x6098 refuses others).
pub const METHODS: [i8; 6] = [3, 5, 19, 21, 35, 37];

/// The home switch and the index of a simulated motor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HomeHardware {
    /// Where the home switch changes state (counts), or `None` if none is wired.
    pub switch: Option<i32>,
    /// Counts between two index pulses (one motor turn).
    pub index_pitch: u32,
    /// Where one index pulse is; the others every `index_pitch` from it.
    pub index_at: i32,
    /// Farthest a search goes before it is a homing error, counts.
    pub search_limit: u32,
}

impl Default for HomeHardware {
    /// A switch at 0, an index pulse at 0 and every 10 000 counts, searches of at most
    /// 2 000 000 counts.
    fn default() -> Self {
        HomeHardware {
            switch: Some(0),
            index_pitch: 10_000,
            index_at: 0,
            search_limit: 2_000_000,
        }
    }
}

/// How a homing ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum End {
    Attained,
    Error,
    Interrupted,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    /// Not homing (never started, or ended: `end`).
    Idle,
    /// Moving in `dir` (+1/-1) for the switch edge; started at `from`.
    Switch {
        dir: f64,
        from: f64,
        active_side: f64,
    },
    /// Moving in `dir` for the next index pulse; started at `from`.
    Index { dir: f64, from: f64 },
    /// Decelerating to rest after the end.
    Stopping,
}

/// The homing procedure of one drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homing {
    hw: HomeHardware,
    phase: Phase,
    end: Option<End>,
    method: i8,
    /// The home offset 0x607C at the start: the position the home point becomes.
    offset: i32,
    acc: f64,
    switch_speed: f64,
    index_speed: f64,
    /// Controlword bit 4 at the last look.
    start_bit: bool,
    /// The position at the last look (for crossings).
    last: f64,
}

impl Homing {
    pub fn new(hw: HomeHardware) -> Self {
        Homing {
            hw,
            phase: Phase::Idle,
            end: None,
            method: 0,
            offset: 0,
            acc: 0.0,
            switch_speed: 0.0,
            index_speed: 0.0,
            start_bit: false,
            last: 0.0,
        }
    }

    /// After the SYNC's process data took effect, in mode 6: what the motor does during the
    /// next period. `enabled`: Operation enabled. `dict_value` reads the dictionary.
    pub fn settle(
        &mut self,
        enabled: bool,
        controlword: u16,
        dict_value: impl Fn(u16, u8) -> u32,
        motor: &mut Motor,
    ) -> Demand {
        let start = controlword & START != 0;
        let rising = start && !self.start_bit;
        self.start_bit = start;
        let p = motor.position();
        let searching = matches!(self.phase, Phase::Switch { .. } | Phase::Index { .. });
        if !enabled {
            if searching {
                self.end = Some(End::Interrupted);
            }
            self.phase = Phase::Idle;
            self.last = p;
            return Demand::Position(p);
        }
        if rising {
            self.begin(&dict_value, motor);
        } else if !start && searching {
            self.finish(End::Interrupted);
        }
        let p = motor.position();
        match self.phase {
            Phase::Switch {
                dir,
                from,
                active_side,
            } => self.search_switch(dir, from, active_side, p, motor),
            Phase::Index { dir, from } => self.search_index(dir, from, p, motor),
            Phase::Stopping | Phase::Idle => {}
        }
        self.last = motor.position();
        match self.phase {
            Phase::Switch { dir, .. } => self.velocity(dir * self.switch_speed),
            Phase::Index { dir, .. } => self.velocity(dir * self.index_speed),
            Phase::Stopping => {
                if motor.velocity_units() == 0 {
                    self.phase = Phase::Idle;
                    motor.stop();
                    Demand::Position(motor.position())
                } else {
                    self.velocity(0.0)
                }
            }
            Phase::Idle => Demand::Position(motor.position()),
        }
    }

    /// The switch and index it homes on.
    pub fn hardware(&self) -> HomeHardware {
        self.hw
    }

    /// The homing bits of the statusword.
    pub fn status(&self, at_rest: bool) -> u16 {
        let rest = if at_rest && matches!(self.phase, Phase::Idle) {
            TARGET_REACHED
        } else {
            0
        };
        match self.end {
            _ if matches!(self.phase, Phase::Switch { .. } | Phase::Index { .. }) => 0,
            Some(End::Attained) => ATTAINED | rest,
            Some(End::Error) => ERROR | rest,
            Some(End::Interrupted) => rest,
            None => 0,
        }
    }

    fn velocity(&self, v: f64) -> Demand {
        Demand::Velocity(Ramp {
            target: v,
            accel: self.acc,
            decel: self.acc,
        })
    }

    fn begin(&mut self, dict_value: &impl Fn(u16, u8) -> u32, motor: &mut Motor) {
        self.method = dict_value(od::HOMING_METHOD, 0) as u8 as i8;
        self.acc = f64::from(dict_value(od::HOMING_ACCELERATION, 0));
        self.switch_speed = f64::from(dict_value(od::HOMING_SPEEDS, 1));
        self.index_speed = f64::from(dict_value(od::HOMING_SPEEDS, 2));
        self.end = None;
        let p = motor.position();
        self.last = p;
        self.offset = dict_value(od::HOME_OFFSET, 0) as i32;
        let offset = f64::from(self.offset);
        // The switch is active on this side of its edge (+1 or -1).
        let active_side = match self.method {
            3 | 19 => 1.0,
            5 | 21 => -1.0,
            _ => {
                // 35, 37: here is home.
                motor.rebase(offset - p);
                self.finish(End::Attained);
                return;
            }
        };
        if self.switch_speed <= 0.0 || self.acc <= 0.0 {
            self.finish(End::Error);
            return;
        }
        let active = self
            .hw
            .switch
            .is_some_and(|e| (p - f64::from(e)) * active_side >= 0.0);
        let dir = if active { -active_side } else { active_side };
        self.phase = Phase::Switch {
            dir,
            from: p,
            active_side,
        };
    }

    fn finish(&mut self, end: End) {
        self.end = Some(end);
        self.phase = Phase::Stopping;
    }

    /// Too far from where the search began.
    fn too_far(&self, from: f64, p: f64) -> bool {
        (p - from).abs() > f64::from(self.hw.search_limit)
    }

    fn search_switch(&mut self, dir: f64, from: f64, active_side: f64, p: f64, motor: &mut Motor) {
        let crossed = self.hw.switch.map(f64::from).filter(|&e| {
            let (a, b) = (self.last.min(p), self.last.max(p));
            // Crossed in the direction of travel (a start exactly on the edge counts).
            a <= e && e <= b && (p - self.last) * dir > 0.0
        });
        match crossed {
            Some(edge) if matches!(self.method, 19 | 21) => self.home_at(edge, motor),
            Some(_) => {
                // On to the index, toward the switch's inactive side.
                self.phase = Phase::Index {
                    dir: -active_side,
                    from: p,
                };
            }
            None if self.too_far(from, p) => self.finish(End::Error),
            None => {}
        }
    }

    fn search_index(&mut self, dir: f64, from: f64, p: f64, motor: &mut Motor) {
        let pitch = f64::from(self.hw.index_pitch.max(1));
        let at = f64::from(self.hw.index_at);
        // The first pulse strictly beyond the last position, in the direction of travel.
        let k = (self.last - at) / pitch;
        let next = at
            + if dir > 0.0 {
                k.floor() * pitch + pitch
            } else {
                k.ceil() * pitch - pitch
            };
        if (p - next) * dir >= 0.0 {
            self.home_at(next, motor);
        } else if self.too_far(from, p) || self.index_speed <= 0.0 {
            self.finish(End::Error);
        }
    }

    /// The motor passed the home point `at` (raw position): there the position is the home
    /// offset.
    fn home_at(&mut self, at: f64, motor: &mut Motor) {
        let offset = f64::from(self.offset);
        motor.rebase(offset - at);
        self.finish(End::Attained);
    }
}
