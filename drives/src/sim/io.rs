//! The application of a simulated CiA-401 digital I/O module (the coolant valves): eight
//! outputs 0x6200:01 and eight inputs 0x6000:01 wired back from them, as the valves'
//! position switches would report (see the [module docs](super)).

use super::dictionary::Dictionary;
use super::drive::emcy_of;
use super::tables::ERROR_REGISTER;
use super::FAULT_ERROR_REGISTER;
use crate::od;
use crate::wire::emcy::Emcy;
use crate::wire::heartbeat::NmtState;

/// EMCY error code of the I/O module's injected fault: 0x5000, device hardware.
pub const IO_FAULT_ERROR_CODE: u16 = 0x5000;

/// A CiA-401 module. The outputs live in the dictionary (0x6200:01); the module itself only
/// remembers whether it faulted.
#[derive(Debug, Default)]
pub struct Io {
    /// The injected fault, latched until reset node: outputs held at 0.
    faulted: bool,
}

impl Io {
    /// The outputs in effect.
    pub fn outputs(dict: &Dictionary) -> u8 {
        dict.get(od::DIGITAL_OUTPUTS, 1) as u8
    }

    /// Reset node: the fault is cleared (the outputs' default, 0, is already restored).
    pub fn reset(&mut self) {
        self.faulted = false;
    }

    /// The node entered `state`: stopped switches the outputs off.
    pub fn nmt(&mut self, state: NmtState, dict: &mut Dictionary) {
        if state == NmtState::Stopped {
            dict.set(od::DIGITAL_OUTPUTS, 1, 0);
        }
    }

    /// The injected fault: EMCY 0x5000, outputs forced to 0 until reset node.
    pub fn fault(&mut self) -> Emcy {
        self.faulted = true;
        emcy_of(IO_FAULT_ERROR_CODE, FAULT_ERROR_REGISTER)
    }

    /// Writes what the module produces into the dictionary: the outputs held at 0 while
    /// faulted, the inputs equal to the outputs, the error register.
    pub fn publish(&self, dict: &mut Dictionary) {
        if self.faulted {
            dict.set(od::DIGITAL_OUTPUTS, 1, 0);
        }
        let outputs = Self::outputs(dict);
        let register = if self.faulted {
            FAULT_ERROR_REGISTER
        } else {
            0
        };
        dict.set(od::DIGITAL_INPUTS, 1, outputs.into());
        dict.set(ERROR_REGISTER, 0, register.into());
    }

    /// `(target, actual, statusword)` of a [`Record`](super::Record): outputs, inputs, 0.
    pub fn record(dict: &Dictionary) -> (i32, i32, u16) {
        let inputs = dict.get(od::DIGITAL_INPUTS, 1) as u8;
        (Self::outputs(dict).into(), inputs.into(), 0)
    }
}
