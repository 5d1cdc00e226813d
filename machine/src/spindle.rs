//! The spindle and coolant hardware (`[spindle]`, `[coolant]`): a CiA-402 drive in profile
//! velocity mode, and the digital outputs of a CiA-401 I/O module that switch the coolant
//! valves. Both sit on a `[[bus]]` with the axes' drives; node ids are unique per bus.
//!
//! A machine without them still runs programs that use `S`, `M03`..`M05`, `M07`..`M09`:
//! the words are reported in the run's summary and do nothing. A simulated machine (no
//! `[[bus]]`) may have them without a bus: `simulate` then checks `S` against `max_rpm` and
//! times the spindle's ramps.

/// Where a device is: its bus (index into [`crate::Machine::buses`]) and CANopen node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusNode {
    pub bus: usize,
    pub node: u8,
}

/// The spindle drive.
#[derive(Clone, Debug, PartialEq)]
pub struct Spindle {
    /// Its drive on the bus; `None` on a simulated machine.
    pub at: Option<BusNode>,
    /// Highest programmable speed, rpm: an `S` above it is refused with its line.
    pub max_rpm: f64,
    /// Ramp up and down (0x6083, 0x6084), rpm/s.
    pub acceleration_rpm_s: f64,
    /// Quick-stop ramp (0x6085), rpm/s.
    pub quick_stop_rpm_s: f64,
    /// Drive velocity units (0x60FF, 0x606C) per rpm.
    pub units_per_rpm: f64,
    /// +1 or -1: the drive's positive direction against `M03` (clockwise).
    pub sign: i8,
    /// The spindle is at speed within this many rpm of the command (0x606D).
    pub at_speed_window_rpm: f64,
    /// Motion that waits for the speed waits at most this long, s; then the run stops.
    pub at_speed_timeout_s: f64,
}

impl Spindle {
    /// Its node, if it is on bus `bus`.
    pub fn on_bus(&self, bus: usize) -> Option<u8> {
        self.at.filter(|a| a.bus == bus).map(|a| a.node)
    }

    /// Drive velocity units for a signed speed (rpm; `M04` negative). Saturates; the
    /// machine file guarantees `max_rpm` fits.
    pub fn velocity(&self, rpm: f64) -> i32 {
        let v = (rpm * self.units_per_rpm * f64::from(self.sign)).round();
        if v.is_nan() {
            0
        } else {
            v.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
        }
    }

    /// Speed (rpm, signed as programmed) for drive velocity units.
    pub fn rpm(&self, velocity: i32) -> f64 {
        f64::from(velocity) / (self.units_per_rpm * f64::from(self.sign))
    }

    /// The at-speed window in drive velocity units (0x606D, u16).
    pub fn window_units(&self) -> u16 {
        (self.at_speed_window_rpm * self.units_per_rpm)
            .round()
            .clamp(0.0, f64::from(u16::MAX)) as u16
    }

    /// A ramp in rpm/s as drive units per second (0x6083..0x6085, u32).
    pub fn ramp_units(&self, rpm_s: f64) -> u32 {
        (rpm_s * self.units_per_rpm)
            .round()
            .clamp(1.0, f64::from(u32::MAX)) as u32
    }
}

/// The coolant valves.
#[derive(Clone, Debug, PartialEq)]
pub struct Coolant {
    /// Its I/O module on the bus; `None` on a simulated machine.
    pub at: Option<BusNode>,
    /// Output 1..=8 switched by `M07`, if the machine has mist.
    pub mist_output: Option<u8>,
    /// Output 1..=8 switched by `M08`, if the machine has flood.
    pub flood_output: Option<u8>,
}

impl Coolant {
    /// Its node, if it is on bus `bus`.
    pub fn on_bus(&self, bus: usize) -> Option<u8> {
        self.at.filter(|a| a.bus == bus).map(|a| a.node)
    }

    /// The byte written to 0x6200:01 (bit 0 = output 1). Real-time thread: an output
    /// outside 1..=8 (which the machine file refuses) switches nothing, it does not panic.
    pub fn outputs(&self, mist: bool, flood: bool) -> u8 {
        let bit = |on: bool, out: Option<u8>| match out {
            Some(n) if on => 1u8.checked_shl(u32::from(n).wrapping_sub(1)).unwrap_or(0),
            _ => 0,
        };
        bit(mist, self.mist_output) | bit(flood, self.flood_output)
    }
}
