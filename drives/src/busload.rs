//! CAN bus load of the cyclic traffic, computed because vcan has no bit timing to measure it.
//!
//! A classic data frame with an 11-bit identifier and `n` data bytes has 47 + 8n bits
//! including the 3-bit interframe space: SOF 1, identifier 11, RTR 1, IDE 1, r0 1, DLC 4,
//! data 8n, CRC 15, CRC delimiter 1, ACK slot 1, ACK delimiter 1, EOF 7, IFS 3. Bit stuffing
//! applies from SOF to the end of the CRC (34 + 8n bits) and adds at most one bit per four
//! after the first, floor((34 + 8n - 1) / 4) = 8 + 2n, so the worst case is 55 + 10n
//! (design.md section 2; the tests check the identity for every n).
//!
//! Each cycle carries one SYNC (no data), and per axis one RPDO1 and one TPDO1 of six bytes:
//! 55 + 230 k bits for k axes. Five axes: 1205 bits, 60.25 % of 1 Mbit/s at 2 ms and 120.5 %
//! at 1 ms, which does not fit (design.md rounds these to 60 % and 120 %).
#![forbid(unsafe_code)]

use core::time::Duration;

use crate::wire::pdo::CSP_PDO_LEN;

/// Worst-case length in bits, with bit stuffing and interframe space, of a standard frame
/// with `data_len` data bytes.
pub const fn frame_bits_worst_case(data_len: u8) -> u32 {
    55 + 10 * data_len as u32
}

/// Length in bits without stuffing, with interframe space.
pub const fn frame_bits_unstuffed(data_len: u8) -> u32 {
    47 + 8 * data_len as u32
}

/// Worst-case bits per cycle for `axes` drives in CSP: one SYNC, and an RPDO1 and a TPDO1
/// of six bytes per axis.
pub const fn csp_cycle_bits(axes: u32) -> u64 {
    let per_axis = 2 * frame_bits_worst_case(CSP_PDO_LEN) as u64;
    frame_bits_worst_case(0) as u64 + per_axis * axes as u64
}

/// Fraction of the bus time (1.0 = 100 %) that `bits` per `period` take at `bitrate` bit/s.
/// Infinite for a zero bitrate or period (NaN if `bits` is zero too); never panics.
pub fn load(bits: u64, bitrate: u32, period: Duration) -> f64 {
    bits as f64 / (f64::from(bitrate) * period.as_secs_f64())
}

/// [`load`] of [`csp_cycle_bits`]`(axes)`.
pub fn csp_load(axes: u32, bitrate: u32, period: Duration) -> f64 {
    load(csp_cycle_bits(axes), bitrate, period)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stuffed_worst_case_matches_the_bit_count() {
        for n in 0..=8u8 {
            let stuffable = 34 + 8 * u32::from(n);
            let stuff_bits = (stuffable - 1) / 4;
            assert_eq!(
                frame_bits_unstuffed(n) + stuff_bits,
                frame_bits_worst_case(n)
            );
        }
        assert_eq!(frame_bits_worst_case(0), 55);
        assert_eq!(frame_bits_worst_case(6), 115);
        assert_eq!(frame_bits_worst_case(8), 135);
        assert_eq!(frame_bits_unstuffed(8), 111);
    }

    #[test]
    fn five_axes_as_in_design_md() {
        assert_eq!(csp_cycle_bits(5), 1205);
        assert_eq!(csp_cycle_bits(0), 55);
        let at_2ms = csp_load(5, 1_000_000, Duration::from_millis(2));
        let at_1ms = csp_load(5, 1_000_000, Duration::from_millis(1));
        assert!((at_2ms - 0.6025).abs() < 1e-12, "{at_2ms}");
        assert!((at_1ms - 1.205).abs() < 1e-12, "{at_1ms}");
        assert!((csp_load(5, 500_000, Duration::from_millis(4)) - 0.6025).abs() < 1e-12);
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        assert_eq!(load(1205, 0, Duration::from_millis(1)), f64::INFINITY);
        assert_eq!(load(1205, 1_000_000, Duration::ZERO), f64::INFINITY);
        assert!(load(0, 0, Duration::ZERO).is_nan());
        assert_eq!(csp_cycle_bits(u32::MAX), 55 + 230 * u64::from(u32::MAX));
    }
}
