//! The object dictionaries of the simulated devices, as data: the communication area every
//! profile shares, and one table of application objects per [`Profile`](super::Profile)
//! (the tables in the [module docs](super)). [`Dictionary`](super::dictionary::Dictionary)
//! holds the values and applies the access rules to whichever table it is given.

use super::Profile;
use crate::od;
use crate::wire::cob;
use crate::wire::pdo::PdoKind;

/// CiA-402 device type of a servo drive (0x1000): profile 402, "servo drive" type bits.
pub const DEVICE_TYPE_SERVO: u32 = 0x0002_0192;
/// CiA-401 device type of an I/O module with digital inputs and outputs (0x1000): profile
/// 401, type bits 0x0003 (digital input + digital output).
pub const DEVICE_TYPE_IO: u32 = 0x0003_0191;
/// Object 0x1001.
pub const ERROR_REGISTER: u16 = 0x1001;

/// The data type of an entry; the value is kept as its raw bits, zero-extended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
}

impl Kind {
    pub const fn bytes(self) -> u8 {
        match self {
            Kind::U8 | Kind::I8 => 1,
            Kind::U16 | Kind::I16 => 2,
            Kind::U32 | Kind::I32 => 4,
        }
    }

    pub const fn bits(self) -> u8 {
        self.bytes() * 8
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Ro,
    Rw,
}

/// A default value; some depend on the node id or on the profile.
#[derive(Clone, Copy, Debug)]
pub enum Init {
    Value(u32),
    /// A COB-ID: the base plus the node id.
    PlusNode(u16),
    /// The profile's [`Table::device_type`].
    DeviceType,
    /// The profile's default first mapping entry of PDO 1 of this direction.
    FirstMapped(PdoKind),
}

/// One entry (index and sub-index) of an object dictionary.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    pub index: u16,
    pub sub: u8,
    pub kind: Kind,
    pub access: Access,
    pub default: Init,
    /// The PDO direction that may map this entry (with its exact bit length), if any.
    pub pdo: Option<PdoKind>,
}

const fn entry(index: u16, sub: u8, kind: Kind, access: Access, default: u32) -> Entry {
    Entry {
        index,
        sub,
        kind,
        access,
        default: Init::Value(default),
        pdo: None,
    }
}

const fn init(index: u16, sub: u8, kind: Kind, access: Access, default: Init) -> Entry {
    Entry {
        index,
        sub,
        kind,
        access,
        default,
        pdo: None,
    }
}

impl Entry {
    /// The same entry, mappable into PDOs of `kind`.
    const fn map(self, kind: PdoKind) -> Entry {
        Entry {
            pdo: Some(kind),
            ..self
        }
    }
}

/// What a profile puts into its dictionary beyond the shared communication area.
#[derive(Debug)]
pub struct Table {
    /// 0x1000.
    pub device_type: u32,
    /// The default mapping of RPDO1 (0x1600, one entry).
    pub rpdo1: u32,
    /// The default mapping of TPDO1 (0x1A00, one entry).
    pub tpdo1: u32,
    /// The application objects (0x6000 and up), sorted by index and sub-index.
    pub application: &'static [Entry],
}

impl Table {
    pub fn of(profile: Profile) -> &'static Table {
        match profile {
            Profile::Drive => &DRIVE,
            Profile::Io => &IO,
        }
    }

    /// The default value of `e` on `node`.
    pub fn default_value(&self, e: &Entry, node: crate::wire::NodeId) -> u32 {
        match e.default {
            Init::Value(v) => v,
            Init::PlusNode(base) => u32::from(node.cob_id(base)),
            Init::DeviceType => self.device_type,
            Init::FirstMapped(PdoKind::Rpdo) => self.rpdo1,
            Init::FirstMapped(PdoKind::Tpdo) => self.tpdo1,
        }
    }
}

use Access::{Ro, Rw};
use Kind::{I16, I32, I8, U16, U32, U8};
use PdoKind::{Rpdo, Tpdo};

/// Entries of the communication area.
pub const COMMUNICATION_LEN: usize = 27;

/// The communication area (0x1000..=0x1FFF) of every profile, sorted. PDO 1's mapping has
/// one entry by default, the profile's.
#[rustfmt::skip]
pub const COMMUNICATION: [Entry; COMMUNICATION_LEN] = [
    init(od::DEVICE_TYPE, 0, U32, Ro, Init::DeviceType),
    entry(ERROR_REGISTER, 0, U8, Ro, 0),
    entry(od::HEARTBEAT_PRODUCER, 0, U16, Rw, 0),
    entry(od::RPDO1_COMMUNICATION, 0, U8, Ro, 2),
    init(od::RPDO1_COMMUNICATION, 1, U32, Rw, Init::PlusNode(cob::RPDO[0])),
    entry(od::RPDO1_COMMUNICATION, 2, U8, Rw, 0xFF),
    entry(od::RPDO1_MAPPING, 0, U8, Rw, 1),
    init(od::RPDO1_MAPPING, 1, U32, Rw, Init::FirstMapped(Rpdo)),
    entry(od::RPDO1_MAPPING, 2, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 3, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 4, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 5, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 6, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 7, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 8, U32, Rw, 0),
    entry(od::TPDO1_COMMUNICATION, 0, U8, Ro, 2),
    init(od::TPDO1_COMMUNICATION, 1, U32, Rw, Init::PlusNode(cob::TPDO[0])),
    entry(od::TPDO1_COMMUNICATION, 2, U8, Rw, 0xFF),
    entry(od::TPDO1_MAPPING, 0, U8, Rw, 1),
    init(od::TPDO1_MAPPING, 1, U32, Rw, Init::FirstMapped(Tpdo)),
    entry(od::TPDO1_MAPPING, 2, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 3, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 4, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 5, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 6, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 7, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 8, U32, Rw, 0),
];

/// A CiA-402 drive (CSP, profile velocity and homing). The default PDO mappings are CiA-402's
/// predefined ones: RPDO1 maps the controlword, TPDO1 the statusword.
#[rustfmt::skip]
static DRIVE: Table = Table {
    device_type: DEVICE_TYPE_SERVO,
    rpdo1: 0x6040_0010,
    tpdo1: 0x6041_0010,
    application: &[
        entry(od::CONTROLWORD, 0, U16, Rw, 0).map(Rpdo),
        entry(od::STATUSWORD, 0, U16, Ro, 0).map(Tpdo),
        entry(od::QUICK_STOP_OPTION, 0, I16, Rw, 2),
        entry(od::FAULT_REACTION_OPTION, 0, I16, Rw, 2),
        entry(od::MODES_OF_OPERATION, 0, I8, Rw, 0),
        entry(od::MODES_OF_OPERATION_DISPLAY, 0, I8, Ro, 0),
        entry(od::POSITION_ACTUAL, 0, I32, Ro, 0).map(Tpdo),
        entry(od::FOLLOWING_ERROR_WINDOW, 0, U32, Rw, 0),
        entry(od::FOLLOWING_ERROR_TIMEOUT, 0, U16, Rw, 0),
        entry(od::VELOCITY_ACTUAL, 0, I32, Ro, 0).map(Tpdo),
        entry(od::VELOCITY_WINDOW, 0, U16, Rw, 10),
        entry(od::VELOCITY_WINDOW_TIME, 0, U16, Rw, 0),
        entry(od::TARGET_POSITION, 0, I32, Rw, 0).map(Rpdo),
        entry(od::HOME_OFFSET, 0, I32, Rw, 0),
        entry(od::SOFTWARE_POSITION_LIMIT, 0, U8, Ro, 2),
        entry(od::SOFTWARE_POSITION_LIMIT, 1, I32, Rw, i32::MIN as u32),
        entry(od::SOFTWARE_POSITION_LIMIT, 2, I32, Rw, i32::MAX as u32),
        entry(od::PROFILE_ACCELERATION, 0, U32, Rw, 10_000),
        entry(od::PROFILE_DECELERATION, 0, U32, Rw, 10_000),
        entry(od::QUICK_STOP_DECELERATION, 0, U32, Rw, 20_000),
        entry(od::HOMING_METHOD, 0, I8, Rw, 35),
        entry(od::HOMING_SPEEDS, 0, U8, Ro, 2),
        entry(od::HOMING_SPEEDS, 1, U32, Rw, 20_000),
        entry(od::HOMING_SPEEDS, 2, U32, Rw, 2_000),
        entry(od::HOMING_ACCELERATION, 0, U32, Rw, 100_000),
        entry(od::INTERPOLATION_TIME_PERIOD, 0, U8, Ro, 2),
        entry(od::INTERPOLATION_TIME_PERIOD, 1, U8, Rw, 1),
        entry(od::INTERPOLATION_TIME_PERIOD, 2, I8, Rw, (-3i8) as u8 as u32),
        entry(od::TARGET_VELOCITY, 0, I32, Rw, 0).map(Rpdo),
        entry(od::SUPPORTED_DRIVE_MODES, 0, U32, Ro, 0xA4),
    ],
};

/// A CiA-401 module with 8 digital inputs and 8 digital outputs; PDO 1 maps them by default.
#[rustfmt::skip]
static IO: Table = Table {
    device_type: DEVICE_TYPE_IO,
    rpdo1: 0x6200_0108,
    tpdo1: 0x6000_0108,
    application: &[
        entry(od::DIGITAL_INPUTS, 0, U8, Ro, 1),
        entry(od::DIGITAL_INPUTS, 1, U8, Ro, 0).map(Tpdo),
        entry(od::DIGITAL_OUTPUTS, 0, U8, Ro, 1),
        entry(od::DIGITAL_OUTPUTS, 1, U8, Rw, 0).map(Rpdo),
    ],
};

#[cfg(test)]
mod tests {
    use super::*;

    /// Lookups stop at the first match: every table must be sorted without duplicates, and
    /// the application area must start above the communication area.
    #[test]
    fn tables_are_sorted() {
        for profile in [Profile::Drive, Profile::Io] {
            let all: Vec<(u16, u8)> = COMMUNICATION
                .iter()
                .chain(Table::of(profile).application)
                .map(|e| (e.index, e.sub))
                .collect();
            assert!(all.windows(2).all(|w| w[0] < w[1]), "{profile:?}");
        }
    }
}
