//! CAN buses and the CiA-402 drive behind each axis (`[[bus]]`, `[axes.*.drive]`), and the
//! worst-case bus load that decides whether a machine file is accepted.
//!
//! Bus load (docs/canopen.md): a standard CAN frame with n data bytes takes at most
//! `55 + 10 n` bits on the wire with worst-case bit stuffing and the interframe space
//! (`47 + 8 n` without stuffing). Each cycle a bus carries one SYNC (0 bytes), per drive
//! (the axes' and the spindle's) one RPDO (controlword + target, 6 bytes) and one TPDO
//! (statusword + actual, 6 bytes), and per I/O module (the coolant's) one RPDO (outputs,
//! 1 byte) and one TPDO (inputs, 1 byte).
//! vcan has no bit timing, so the project computes the load itself.

/// Default `bitrate`, bit/s.
pub const DEFAULT_BITRATE: u32 = 1_000_000;
/// Default `max_load`, fraction of the bitrate.
pub const DEFAULT_MAX_LOAD: f64 = 0.70;
/// Bytes of the cyclic RPDO (0x6040 + 0x607A) and TPDO (0x6041 + 0x6064).
pub const PDO_BYTES: u32 = 6;
/// Bytes of an I/O module's cyclic RPDO (0x6200:01) and TPDO (0x6000:01).
pub const IO_PDO_BYTES: u32 = 1;

/// Worst-case bits of one standard frame with `n` data bytes, stuffing and IFS included.
pub const fn frame_bits(n: u32) -> u32 {
    55 + 10 * n
}

/// What one bus carries each cycle besides the SYNC.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Nodes {
    /// CiA-402 drives: the axes' and the spindle's.
    pub drives: u32,
    /// CiA-401 I/O modules.
    pub io: u32,
}

/// Worst-case bits per cycle on a bus: SYNC, and an RPDO and a TPDO per node.
pub const fn cycle_bits(nodes: Nodes) -> u32 {
    frame_bits(0)
        + nodes.drives * 2 * frame_bits(PDO_BYTES)
        + nodes.io * 2 * frame_bits(IO_PDO_BYTES)
}

/// Fraction of the bus's capacity used per cycle.
pub fn load(nodes: Nodes, bitrate: u32, period_s: f64) -> f64 {
    f64::from(cycle_bits(nodes)) / (f64::from(bitrate) * period_s)
}

/// `n` drives and no I/O module.
pub const fn drives(n: u32) -> Nodes {
    Nodes { drives: n, io: 0 }
}

/// One CAN bus.
#[derive(Clone, Debug, PartialEq)]
pub struct Bus {
    /// The name axes refer to.
    pub name: String,
    /// SocketCAN interface name (at most 15 bytes).
    pub interface: String,
    /// bit/s, 10 000..=1 000 000.
    pub bitrate: u32,
    /// Highest accepted worst-case load, in (0, 1].
    pub max_load: f64,
}

/// The drive behind one axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Drive {
    /// Joint index: 0 X, 1 Y, 2 Z, 3 tilt (A/B), 4 C.
    pub axis: usize,
    /// Index into [`crate::Machine::buses`].
    pub bus: usize,
    /// CANopen node id, 1..=127, unique on its bus.
    pub node: u8,
    /// Drive counts per mm or per degree, 1e-6..=1e9.
    pub counts_per_unit: f64,
    /// +1 or -1: the drive's positive direction against the axis's.
    pub sign: i8,
    /// Counts at axis position 0.
    pub offset: i32,
    /// What the drive guards by itself, written in set-up.
    pub guard: Guard,
    /// How the axis is homed (`[axes.*.home]`); `None` when the file says nothing.
    pub home: Option<Home>,
}

/// How an axis finds its zero (`[axes.*.home]`): CiA-402 homing by the drive, or an
/// absolute encoder that needs none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Home {
    pub method: HomeMethod,
    /// The axis position (mm or degrees) of the home point: the switch's edge, the index
    /// pulse, or where the axis stands for [`HomeMethod::Current`].
    pub position: f64,
    /// Speeds while searching for the switch and for the index pulse, axis units/s.
    pub search_velocity: f64,
    pub latch_velocity: f64,
    /// Axis units/s².
    pub acceleration: f64,
    /// Axes home in rising order of this; equal values home together.
    pub sequence: u8,
}

/// The homing methods an axis may name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HomeMethod {
    /// Where the axis stands is the home position (CiA-402 method 37).
    Current,
    /// The home switch's edge, the switch active on the `positive` (else negative) side
    /// of it in axis direction (methods 19/21).
    Switch { positive: bool },
    /// The switch, then the first index pulse toward its inactive side (methods 3/5).
    SwitchIndex { positive: bool },
    /// An absolute encoder: the drive's position is trusted, no homing.
    Absolute,
}

impl Drive {
    /// The CiA-402 homing method (0x6098) for this drive, its sign applied; `None` for an
    /// absolute encoder.
    pub fn homing_method(&self, m: HomeMethod) -> Option<i8> {
        let drive_positive = |positive: bool| positive == (self.sign > 0);
        match m {
            HomeMethod::Current => Some(37),
            HomeMethod::Switch { positive } => Some(if drive_positive(positive) { 19 } else { 21 }),
            HomeMethod::SwitchIndex { positive } => {
                Some(if drive_positive(positive) { 3 } else { 5 })
            }
            HomeMethod::Absolute => None,
        }
    }
}

/// What an axis drive is told to guard by itself (`[axes.*.drive]`), so that it stops even
/// if the controller dies: following error, stop reactions; its software position limits
/// are the axis's travel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Guard {
    /// Following error the drive tolerates, axis units (mm or degrees); None: off.
    pub following_error: Option<f64>,
    /// How long the error may stay over it, ms (0x6066).
    pub following_error_timeout_ms: u16,
    /// Quick-stop option code 0x605A and fault-reaction option code 0x605E (CiA-402).
    pub quick_stop_option: i16,
    pub fault_reaction_option: i16,
}

impl Guard {
    /// Default time the following error may stay over its window, ms.
    pub const TIMEOUT_MS: u16 = 10;
    /// Default following error: the distance at the axis's velocity limit in this time, s.
    pub const FOLLOWING_TIME_S: f64 = 0.02;
    /// Default option codes: the quick-stop ramp, then switch on disabled (0x605A = 2); the
    /// quick-stop ramp on a fault (0x605E = 2).
    pub const QUICK_STOP_OPTION: i16 = 2;
    pub const FAULT_REACTION_OPTION: i16 = 2;
}

impl Default for Guard {
    /// Following control off, the default option codes.
    fn default() -> Self {
        Guard {
            following_error: None,
            following_error_timeout_ms: Guard::TIMEOUT_MS,
            quick_stop_option: Guard::QUICK_STOP_OPTION,
            fault_reaction_option: Guard::FAULT_REACTION_OPTION,
        }
    }
}

impl Drive {
    /// Counts for an axis position (mm or degrees), `None` if they do not fit an i32.
    pub fn counts(&self, position: f64) -> Option<i32> {
        let c = (position * self.counts_per_unit * f64::from(self.sign)).round()
            + f64::from(self.offset);
        (c.is_finite() && c >= f64::from(i32::MIN) && c <= f64::from(i32::MAX)).then_some(c as i32)
    }

    /// Axis position (mm or degrees) for drive counts.
    pub fn position(&self, counts: i32) -> f64 {
        (f64::from(counts) - f64::from(self.offset)) / (self.counts_per_unit * f64::from(self.sign))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_bus_load_example() {
        // 5 axes: one SYNC + 5 RPDO(6 B) + 5 TPDO(6 B) = 55 + 10 * 115 = 1205 bits.
        assert_eq!(frame_bits(0), 55);
        assert_eq!(frame_bits(6), 115);
        assert_eq!(cycle_bits(drives(5)), 1205);
        assert!((load(drives(5), 1_000_000, 0.002) - 0.6025).abs() < 1e-12);
        assert!((load(drives(5), 1_000_000, 0.001) - 1.205).abs() < 1e-12);
        // A spindle drive and a coolant I/O module: 55 + 230 + 2 * (55 + 10) = 415 bits.
        assert_eq!(cycle_bits(Nodes { drives: 1, io: 1 }), 415);
    }

    #[test]
    fn counts_round_trip_and_refuse_overflow() {
        let d = Drive {
            axis: 0,
            bus: 0,
            node: 1,
            counts_per_unit: 10_000.0,
            sign: -1,
            offset: 500,
            guard: Guard::default(),
            home: None,
        };
        assert_eq!(d.counts(1.5), Some(-14_500));
        assert!((d.position(-14_500) - 1.5).abs() < 1e-12);
        assert_eq!(d.counts(1e6), None);
        assert_eq!(d.counts(f64::NAN), None);
    }

    #[test]
    fn a_drive_turned_the_other_way_finds_its_switch_on_the_other_side() {
        let mut d = Drive {
            axis: 0,
            bus: 0,
            node: 1,
            counts_per_unit: 1.0,
            sign: 1,
            offset: 0,
            guard: Guard::default(),
            home: None,
        };
        let sw = |positive| HomeMethod::Switch { positive };
        let idx = |positive| HomeMethod::SwitchIndex { positive };
        assert_eq!(d.homing_method(sw(true)), Some(19));
        assert_eq!(d.homing_method(sw(false)), Some(21));
        assert_eq!(d.homing_method(idx(true)), Some(3));
        assert_eq!(d.homing_method(HomeMethod::Current), Some(37));
        assert_eq!(d.homing_method(HomeMethod::Absolute), None);
        d.sign = -1;
        assert_eq!(d.homing_method(sw(true)), Some(21));
        assert_eq!(d.homing_method(idx(false)), Some(3));
    }
}
