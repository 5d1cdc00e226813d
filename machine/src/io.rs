//! `[io]` on a machine with a bus ([`BusIo`]): the program's digital outputs and inputs
//! (`M62`..`M65 P<n>`, `M66 P<n>`) as consecutive outputs and inputs of the machine's
//! CiA-401 I/O module, the one that switches the coolant valves when the machine has them.

use crate::spindle::BusNode;

/// Outputs (0x6200:01) and inputs (0x6000:01) of the I/O module: one byte each.
pub const MODULE_BITS: u8 = 8;

/// The program's digital I/O on the module at `at`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusIo {
    pub at: BusNode,
    /// Module output 1..=8 that program output `P0` switches (`P<n>`: `first_output + n`),
    /// and how many program outputs there are.
    pub first_output: u8,
    pub outputs: u8,
    /// Module input 1..=8 that `M66 P0` reads (`P<n>`: `first_input + n`), and how many.
    pub first_input: u8,
    pub inputs: u8,
    /// Module input 1..=8 wired to the machine's normally closed e-stop chain: when it
    /// reads 0 every drive is quick-stopped and disabled (`[io] estop_input`).
    pub estop_input: Option<u8>,
}

impl BusIo {
    /// Whether it is on bus `bus`.
    pub fn on_bus(&self, bus: usize) -> bool {
        self.at.bus == bus
    }

    /// The module's output bits (bit 0 = output 1) for the program's outputs (bit n =
    /// `P<n>`). Real-time thread: an output beyond the module's eight switches nothing.
    pub fn output_byte(&self, program: u64) -> u8 {
        let mut byte = 0u8;
        for n in 0..self.outputs.min(MODULE_BITS) {
            let on = program.checked_shr(u32::from(n)).unwrap_or(0) & 1 == 1;
            let bit = u32::from(self.first_output.saturating_add(n)).wrapping_sub(1);
            if on {
                byte |= 1u8.checked_shl(bit).unwrap_or(0);
            }
        }
        byte
    }

    /// The program's inputs (bit n = `M66 P<n>`) from the module's input byte (bit 0 =
    /// input 1). Real-time thread.
    pub fn program_inputs(&self, module: u8) -> u64 {
        let mut bits = 0u64;
        for n in 0..self.inputs.min(MODULE_BITS) {
            let bit = u32::from(self.first_input.saturating_add(n)).wrapping_sub(1);
            if module.checked_shr(bit).unwrap_or(0) & 1 == 1 {
                bits |= 1 << n;
            }
        }
        bits
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn program_bits_map_to_consecutive_module_bits() {
        let io = BusIo {
            at: BusNode { bus: 0, node: 7 },
            first_output: 3,
            outputs: 4,
            first_input: 5,
            inputs: 2,
            estop_input: None,
        };
        // P0 -> output 3 (bit 2), P3 -> output 6 (bit 5); P4 is none of the machine's.
        assert_eq!(io.output_byte(0b1001), 0b0010_0100);
        assert_eq!(io.output_byte(1 << 4), 0);
        // Input 5 (bit 4) -> P0, input 6 (bit 5) -> P1; input 7 is not the program's.
        assert_eq!(io.program_inputs(0b0011_0000), 0b11);
        assert_eq!(io.program_inputs(0b0100_0000), 0);
    }
}
