//! Object dictionary entries this master reads or writes (CiA-301 and CiA-402), as named in
//! docs/canopen.md. Indices only; the SDO codec takes them with a sub-index and a value.
#![forbid(unsafe_code)]

/// Device type (u32): profile number in bits 0..15 (402 drive, 401 I/O module).
pub const DEVICE_TYPE: u16 = 0x1000;
/// Heartbeat consumer time (u32 per sub-index: `node << 16 | ms`).
pub const HEARTBEAT_CONSUMER: u16 = 0x1016;
/// Heartbeat producer time (u16, ms).
pub const HEARTBEAT_PRODUCER: u16 = 0x1017;
/// RPDO1 communication parameter (sub 1 COB-ID, bit 31 = invalid; sub 2 transmission type).
pub const RPDO1_COMMUNICATION: u16 = 0x1400;
/// RPDO1 mapping parameter (sub 0 count, sub 1.. entries).
pub const RPDO1_MAPPING: u16 = 0x1600;
/// TPDO1 communication parameter.
pub const TPDO1_COMMUNICATION: u16 = 0x1800;
/// TPDO1 mapping parameter.
pub const TPDO1_MAPPING: u16 = 0x1A00;
/// Bit 31 of a PDO COB-ID entry: the PDO is disabled.
pub const PDO_COB_ID_INVALID: u32 = 1 << 31;
/// Transmission type: synchronous, every SYNC.
pub const TRANSMISSION_EVERY_SYNC: u8 = 1;

/// Controlword (u16).
pub const CONTROLWORD: u16 = 0x6040;
/// Statusword (u16).
pub const STATUSWORD: u16 = 0x6041;
/// Modes of operation (i8).
pub const MODES_OF_OPERATION: u16 = 0x6060;
/// Modes of operation display (i8).
pub const MODES_OF_OPERATION_DISPLAY: u16 = 0x6061;
/// Position actual value (i32).
pub const POSITION_ACTUAL: u16 = 0x6064;
/// Following error window (u32).
pub const FOLLOWING_ERROR_WINDOW: u16 = 0x6065;
/// Following error time out (u16, ms).
pub const FOLLOWING_ERROR_TIMEOUT: u16 = 0x6066;
/// Quick stop option code (i16).
pub const QUICK_STOP_OPTION: u16 = 0x605A;
/// Fault reaction option code (i16).
pub const FAULT_REACTION_OPTION: u16 = 0x605E;
/// Software position limit: sub 1 min, sub 2 max (i32, counts).
pub const SOFTWARE_POSITION_LIMIT: u16 = 0x607D;
/// Home offset (i32, counts): the position the home point becomes.
pub const HOME_OFFSET: u16 = 0x607C;
/// Homing method (i8).
pub const HOMING_METHOD: u16 = 0x6098;
/// Homing speeds: sub 1 while searching for the switch, sub 2 for the index (u32).
pub const HOMING_SPEEDS: u16 = 0x6099;
/// Homing acceleration (u32).
pub const HOMING_ACCELERATION: u16 = 0x609A;
/// Supported drive modes (u32): bit 2 profile velocity, bit 5 homing, bit 7 CSP.
pub const SUPPORTED_DRIVE_MODES: u16 = 0x6502;
/// Target position (i32).
pub const TARGET_POSITION: u16 = 0x607A;
/// Velocity actual value (i32, velocity units).
pub const VELOCITY_ACTUAL: u16 = 0x606C;
/// Velocity window (u16, velocity units): profile velocity mode's "target reached" band.
pub const VELOCITY_WINDOW: u16 = 0x606D;
/// Velocity window time (u16, ms): how long the velocity must stay in the window.
pub const VELOCITY_WINDOW_TIME: u16 = 0x606E;
/// Profile acceleration (u32, velocity units per second).
pub const PROFILE_ACCELERATION: u16 = 0x6083;
/// Profile deceleration (u32, velocity units per second).
pub const PROFILE_DECELERATION: u16 = 0x6084;
/// Quick stop deceleration (u32, velocity units per second).
pub const QUICK_STOP_DECELERATION: u16 = 0x6085;
/// Target velocity (i32, velocity units).
pub const TARGET_VELOCITY: u16 = 0x60FF;
/// Interpolation time period: sub 1 value (u8), sub 2 exponent (i8); period = value * 10^exp s.
pub const INTERPOLATION_TIME_PERIOD: u16 = 0x60C2;

/// Modes of operation value of cyclic synchronous position mode.
pub const MODE_CSP: i8 = 8;
/// Modes of operation value of profile velocity mode (the spindle).
pub const MODE_PV: i8 = 3;
/// Modes of operation value of homing mode.
pub const MODE_HOMING: i8 = 6;

/// CiA-401 digital inputs, 8 per sub-index (sub 0 count, sub 1 inputs 1..8, u8).
pub const DIGITAL_INPUTS: u16 = 0x6000;
/// CiA-401 digital outputs, 8 per sub-index (sub 0 count, sub 1 outputs 1..8, u8).
pub const DIGITAL_OUTPUTS: u16 = 0x6200;
