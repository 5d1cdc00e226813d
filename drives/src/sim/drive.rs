//! The application of a simulated CiA-402 drive: device control ([`DriveModel`]), the modes
//! CSP (8), profile velocity (3) and homing (6, [`super::homing`]), the motor and the
//! statusword. The node
//! ([`SimNode`](super::node::SimNode)) calls it at the points of a SYNC the
//! [module docs](super) describe.

use super::dictionary::Dictionary;
use super::homing::{HomeHardware, Homing};
use super::motor::{Demand, Motor, Ramp};
use super::tables::ERROR_REGISTER;
use super::FAULT_ERROR_REGISTER;
use crate::cia402::{DriveModel, State, Statusword};
use crate::od;
use crate::wire::emcy::{self, Emcy};

/// Statusword bit 12 in profile velocity mode: speed = 0.
const SPEED_ZERO: u16 = 1 << 12;

/// A CiA-402 drive.
#[derive(Debug)]
pub struct Drive {
    model: DriveModel,
    motor: Motor,
    lag_s: f64,
    /// CSP: `|demand - 0x6064| > 0x6065` for longer than 0x6066 ms.
    following_error: bool,
    /// CSP: SYNCs in a row with the error over the window.
    over_window: u64,
    /// PV: SYNCs since the velocity entered the window (0 at the first), `None` outside.
    in_window: Option<u64>,
    /// PV: it has stayed there for 0x606E ms.
    target_reached: bool,
    homing: Homing,
}

impl Drive {
    /// At power-on, at `initial_position`, which becomes the target position too.
    pub fn new(
        lag_s: f64,
        initial_position: i32,
        home: HomeHardware,
        dict: &mut Dictionary,
    ) -> Self {
        dict.set(od::TARGET_POSITION, 0, initial_position as u32);
        Self {
            model: DriveModel::new(),
            motor: Motor::new(f64::from(initial_position)),
            lag_s,
            following_error: false,
            over_window: 0,
            in_window: None,
            target_reached: false,
            homing: Homing::new(home),
        }
    }

    pub fn state(&self) -> State {
        self.model.state()
    }

    pub fn position(&self) -> i32 {
        self.motor.position_counts()
    }

    /// The self-test is done (transition 1).
    pub fn boot(&mut self) {
        self.model.tick();
    }

    /// Reset node: the state machine restarts and the motor stops where it stands, which
    /// becomes the target position (the dictionary's defaults are already restored).
    pub fn reset(&mut self, dict: &mut Dictionary) {
        self.model = DriveModel::new();
        self.motor.stop();
        self.following_error = false;
        self.over_window = 0;
        self.in_window = None;
        self.target_reached = false;
        self.homing = Homing::new(self.homing.hardware());
        dict.set(od::TARGET_POSITION, 0, self.position() as u32);
    }

    /// An SDO write or an RPDO stored `index`: a controlword takes effect. Leaving Fault
    /// announces the error reset (EMCY 0x0000).
    pub fn written(&mut self, index: u16, dict: &Dictionary) -> Option<Emcy> {
        if index != od::CONTROLWORD {
            return None;
        }
        let was = self.model.state();
        self.model.apply(dict.get(od::CONTROLWORD, 0) as u16);
        (was == State::Fault && self.model.state() != State::Fault).then(|| emcy_of(0x0000, 0))
    }

    /// The start of a SYNC: the motor runs the period that ended, then the automatic
    /// transitions.
    pub fn advance(&mut self, period_s: f64) {
        self.motor.advance(period_s, self.lag_s);
        self.model.tick();
    }

    /// The injected fault: Fault reaction active, EMCY 0x8611 (following error).
    pub fn fault(&mut self) -> Emcy {
        self.model.inject_fault();
        emcy_of(emcy::FOLLOWING_ERROR, FAULT_ERROR_REGISTER)
    }

    /// After the SYNC's process data took effect: what the motor does during the next
    /// period, the following error (CSP) and the velocity window (PV).
    pub fn settle(&mut self, period_s: f64, dict: &Dictionary) {
        let state = self.model.state();
        let enabled = state == State::OperationEnabled;
        let mode = mode(dict);
        // The software position limits 0x607D bound the demand.
        let (lo, hi) = (
            dict.get(od::SOFTWARE_POSITION_LIMIT, 1) as i32,
            dict.get(od::SOFTWARE_POSITION_LIMIT, 2) as i32,
        );
        let target = dict.get(od::TARGET_POSITION, 0) as i32;
        let target = if lo <= hi {
            target.clamp(lo, hi)
        } else {
            target
        };
        let csp = enabled && mode == od::MODE_CSP;
        let demand = if mode == od::MODE_HOMING {
            let cw = dict.get(od::CONTROLWORD, 0) as u16;
            self.homing
                .settle(enabled, cw, |i, s| dict.get(i, s), &mut self.motor)
        } else if mode == od::MODE_PV {
            Demand::Velocity(pv_ramp(state, dict))
        } else if csp {
            Demand::Position(f64::from(target))
        } else {
            Demand::Position(self.motor.position())
        };
        self.motor.set_demand(demand);

        // Following control: off at a window of 0 or 2^32 - 1; reported once the error has
        // stayed over the window for 0x6066 ms (from the SYNC it was first seen at; within a
        // microsecond, as the velocity window).
        let window = dict.get(od::FOLLOWING_ERROR_WINDOW, 0);
        let timeout_ms = f64::from(dict.get(od::FOLLOWING_ERROR_TIMEOUT, 0));
        let error = (i64::from(target) - i64::from(self.position())).unsigned_abs();
        let over = csp && window != 0 && window != u32::MAX && error > u64::from(window);
        self.over_window = if over {
            self.over_window.saturating_add(1)
        } else {
            0
        };
        self.following_error =
            over && (self.over_window - 1) as f64 * period_s * 1000.0 + 1e-3 >= timeout_ms;

        let velocity_target = i64::from(dict.get(od::TARGET_VELOCITY, 0) as i32);
        let error = (velocity_target - i64::from(self.motor.velocity_units())).unsigned_abs();
        let in_window =
            enabled && mode == od::MODE_PV && error <= u64::from(dict.get(od::VELOCITY_WINDOW, 0));
        self.in_window = in_window.then(|| self.in_window.map_or(0, |n| n.saturating_add(1)));
        let window_ms = f64::from(dict.get(od::VELOCITY_WINDOW_TIME, 0));
        self.target_reached = self.in_window.is_some_and(|n| {
            // Within a microsecond, so that 50 periods of 2 ms make 100 ms.
            window_ms == 0.0 || n as f64 * period_s * 1000.0 + 1e-3 >= window_ms
        });
    }

    /// Writes what the drive produces into the dictionary.
    pub fn publish(&self, dict: &mut Dictionary) {
        let state = self.model.state();
        let enabled = state == State::OperationEnabled;
        let mode = mode(dict);
        let mut statusword = self.model.statusword() & !Statusword::TARGET_FOLLOWED;
        if mode == od::MODE_CSP && enabled {
            statusword |= Statusword::TARGET_FOLLOWED;
        }
        if enabled && self.following_error {
            statusword |= Statusword::FOLLOWING_ERROR;
        }
        if mode == od::MODE_HOMING {
            statusword |= self.homing.status(self.motor.velocity_units() == 0);
        }
        if mode == od::MODE_PV {
            if enabled && self.target_reached {
                statusword |= Statusword::TARGET_REACHED;
            }
            if self.motor.velocity_units() == 0 {
                statusword |= SPEED_ZERO;
            }
        }
        let faulted = matches!(state, State::Fault | State::FaultReactionActive);
        let register = if faulted { FAULT_ERROR_REGISTER } else { 0 };
        dict.set(od::STATUSWORD, 0, statusword.into());
        dict.set(od::POSITION_ACTUAL, 0, self.position() as u32);
        dict.set(od::VELOCITY_ACTUAL, 0, self.motor.velocity_units() as u32);
        dict.set(od::MODES_OF_OPERATION_DISPLAY, 0, mode as u8 as u32);
        dict.set(ERROR_REGISTER, 0, register.into());
    }

    /// `(target, actual, statusword)` of a [`Record`](super::Record): positions, or in
    /// profile velocity mode the target velocity and the velocity actual value.
    pub fn record(&self, dict: &Dictionary) -> (i32, i32, u16) {
        let statusword = dict.get(od::STATUSWORD, 0) as u16;
        let (target, actual) = if mode(dict) == od::MODE_PV {
            (od::TARGET_VELOCITY, od::VELOCITY_ACTUAL)
        } else {
            (od::TARGET_POSITION, od::POSITION_ACTUAL)
        };
        let value = |index| dict.get(index, 0) as i32;
        (value(target), value(actual), statusword)
    }
}

/// The velocity ramp of profile velocity mode in `state`: to 0x60FF in Operation enabled;
/// to 0 at the quick-stop deceleration in Quick stop active and after a fault; to 0 at the
/// profile deceleration otherwise (the simulation's stand-in for a coasting motor).
fn pv_ramp(state: State, dict: &Dictionary) -> Ramp {
    let rate = |index| f64::from(dict.get(index, 0));
    let accel = rate(od::PROFILE_ACCELERATION);
    let (target, decel) = match state {
        State::OperationEnabled => (
            f64::from(dict.get(od::TARGET_VELOCITY, 0) as i32),
            rate(od::PROFILE_DECELERATION),
        ),
        State::QuickStopActive | State::FaultReactionActive | State::Fault => {
            (0.0, rate(od::QUICK_STOP_DECELERATION))
        }
        _ => (0.0, rate(od::PROFILE_DECELERATION)),
    };
    Ramp {
        target,
        accel,
        decel,
    }
}

fn mode(dict: &Dictionary) -> i8 {
    dict.get(od::MODES_OF_OPERATION, 0) as u8 as i8
}

/// An EMCY without manufacturer-specific bytes.
pub fn emcy_of(error_code: u16, error_register: u8) -> Emcy {
    Emcy {
        error_code,
        error_register,
        manufacturer: [0; 5],
    }
}
