//! The simulated drive's object dictionary: a fixed table of entries, each value held as the
//! raw bits of its type in a `u32`, and the SDO access rules (see the table and the abort
//! rules in the [module docs](super)).
//!
//! [`Dictionary::download`] is the only way the SDO server changes a value; it checks, in this
//! order: the index exists, the sub-index exists, the entry is writable, the data length is
//! the type's, and then the value rules of the entry (mode, COB-ID, transmission type,
//! mapping). Values the drive itself produces (statusword, position actual, error register,
//! mode display) are written with [`Dictionary::set`], which bypasses the access rules.

use crate::od;
use crate::wire::pdo::PdoKind;
use crate::wire::sdo::SdoData;
use crate::wire::{cob, AbortCode, NodeId};

/// CiA-402 device type of a servo drive (0x1000): profile 402, "servo drive" type bits.
pub const DEVICE_TYPE_SERVO: u32 = 0x0002_0192;
/// Object 0x1000.
pub const DEVICE_TYPE: u16 = 0x1000;
/// Object 0x1001.
pub const ERROR_REGISTER: u16 = 0x1001;
/// The first index of the application area; below it is the communication area, which
/// reset communication restores (reset node restores both).
const APPLICATION_AREA: u16 = 0x2000;
/// Most entries in a PDO mapping object (sub-indices 1..=8).
const MAX_MAPPED: u8 = 8;
/// Most data bits in a classic CAN PDO.
const MAX_PDO_BITS: u32 = 64;

/// The data type of an entry; the value is kept as its raw bits, zero-extended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    U8,
    I8,
    U16,
    U32,
    I32,
}

impl Kind {
    pub const fn bytes(self) -> u8 {
        match self {
            Kind::U8 | Kind::I8 => 1,
            Kind::U16 => 2,
            Kind::U32 | Kind::I32 => 4,
        }
    }

    pub const fn bits(self) -> u8 {
        self.bytes() * 8
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Access {
    Ro,
    Rw,
}

/// A default value; some depend on the node id.
#[derive(Clone, Copy, Debug)]
enum Init {
    Value(u32),
    PlusNode(u16),
}

#[derive(Clone, Copy, Debug)]
struct Entry {
    index: u16,
    sub: u8,
    kind: Kind,
    access: Access,
    default: Init,
}

const fn entry(index: u16, sub: u8, kind: Kind, access: Access, default: u32) -> Entry {
    Entry {
        index,
        sub,
        kind,
        access,
        default: Init::Value(default),
    }
}

const fn cob_entry(index: u16, base: u16) -> Entry {
    Entry {
        index,
        sub: 1,
        kind: Kind::U32,
        access: Access::Rw,
        default: Init::PlusNode(base),
    }
}

use Access::{Ro, Rw};
use Kind::{I32, I8, U16, U32, U8};

const TABLE_LEN: usize = 37;

/// The object dictionary, sorted by index and sub-index (the table in the module docs).
/// The default PDO mappings are CiA-402's predefined ones: RPDO1 maps the controlword,
/// TPDO1 the statusword.
#[rustfmt::skip]
const TABLE: [Entry; TABLE_LEN] = [
    entry(DEVICE_TYPE, 0, U32, Ro, DEVICE_TYPE_SERVO),
    entry(ERROR_REGISTER, 0, U8, Ro, 0),
    entry(od::HEARTBEAT_PRODUCER, 0, U16, Rw, 0),
    entry(od::RPDO1_COMMUNICATION, 0, U8, Ro, 2),
    cob_entry(od::RPDO1_COMMUNICATION, cob::RPDO[0]),
    entry(od::RPDO1_COMMUNICATION, 2, U8, Rw, 0xFF),
    entry(od::RPDO1_MAPPING, 0, U8, Rw, 1),
    entry(od::RPDO1_MAPPING, 1, U32, Rw, 0x6040_0010),
    entry(od::RPDO1_MAPPING, 2, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 3, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 4, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 5, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 6, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 7, U32, Rw, 0),
    entry(od::RPDO1_MAPPING, 8, U32, Rw, 0),
    entry(od::TPDO1_COMMUNICATION, 0, U8, Ro, 2),
    cob_entry(od::TPDO1_COMMUNICATION, cob::TPDO[0]),
    entry(od::TPDO1_COMMUNICATION, 2, U8, Rw, 0xFF),
    entry(od::TPDO1_MAPPING, 0, U8, Rw, 1),
    entry(od::TPDO1_MAPPING, 1, U32, Rw, 0x6041_0010),
    entry(od::TPDO1_MAPPING, 2, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 3, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 4, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 5, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 6, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 7, U32, Rw, 0),
    entry(od::TPDO1_MAPPING, 8, U32, Rw, 0),
    entry(od::CONTROLWORD, 0, U16, Rw, 0),
    entry(od::STATUSWORD, 0, U16, Ro, 0),
    entry(od::MODES_OF_OPERATION, 0, I8, Rw, 0),
    entry(od::MODES_OF_OPERATION_DISPLAY, 0, I8, Ro, 0),
    entry(od::POSITION_ACTUAL, 0, I32, Ro, 0),
    entry(od::FOLLOWING_ERROR_WINDOW, 0, U32, Rw, 0),
    entry(od::TARGET_POSITION, 0, I32, Rw, 0),
    entry(od::INTERPOLATION_TIME_PERIOD, 0, U8, Ro, 2),
    entry(od::INTERPOLATION_TIME_PERIOD, 1, U8, Rw, 1),
    entry(od::INTERPOLATION_TIME_PERIOD, 2, I8, Rw, (-3i8) as u8 as u32),
];

/// The communication and mapping objects of one PDO direction.
const fn pdo_objects(kind: PdoKind) -> (u16, u16) {
    match kind {
        PdoKind::Rpdo => (od::RPDO1_COMMUNICATION, od::RPDO1_MAPPING),
        PdoKind::Tpdo => (od::TPDO1_COMMUNICATION, od::TPDO1_MAPPING),
    }
}

/// The objects a PDO of `kind` may map (docs/canopen.md's CSP layout).
fn mappable(kind: PdoKind, index: u16, sub: u8) -> bool {
    let objects: [u16; 2] = match kind {
        PdoKind::Rpdo => [od::CONTROLWORD, od::TARGET_POSITION],
        PdoKind::Tpdo => [od::STATUSWORD, od::POSITION_ACTUAL],
    };
    sub == 0 && objects.contains(&index)
}

/// CAN identifiers a PDO may not use (CiA-301 table 43, restricted CAN-IDs), plus 0x080,
/// which is this bus's SYNC.
fn restricted_can_id(id: u32) -> bool {
    matches!(id, 0x000..=0x080 | 0x101..=0x180 | 0x581..=0x5FF | 0x601..=0x67F | 0x6E0..=0x7FF)
}

/// A PDO's configuration, read from the dictionary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PdoConfig {
    /// The 11-bit CAN identifier; `None` while the PDO is invalid (COB-ID bit 31).
    pub can_id: Option<u16>,
    pub transmission_type: u8,
    /// Mapped `(index, sub, kind)`, the first `count` entries.
    mapped: [(u16, u8, Kind); MAX_MAPPED as usize],
    count: usize,
}

impl PdoConfig {
    pub fn entries(&self) -> &[(u16, u8, Kind)] {
        self.mapped.get(..self.count).unwrap_or_default()
    }

    /// Data bytes of the mapped objects.
    pub fn len(&self) -> usize {
        self.entries()
            .iter()
            .map(|e| usize::from(e.2.bytes()))
            .sum()
    }
}

/// One node's object dictionary.
#[derive(Clone, Debug)]
pub struct Dictionary {
    node: NodeId,
    values: [u32; TABLE_LEN],
}

impl Dictionary {
    /// Every entry at its default.
    pub fn new(node: NodeId) -> Self {
        let mut dict = Self {
            node,
            values: [0; TABLE_LEN],
        };
        dict.reset(true);
        dict
    }

    /// Restores the defaults of the communication area, and of the application area too if
    /// `application`.
    pub fn reset(&mut self, application: bool) {
        for (value, e) in self.values.iter_mut().zip(TABLE.iter()) {
            if application || e.index < APPLICATION_AREA {
                *value = match e.default {
                    Init::Value(v) => v,
                    Init::PlusNode(base) => u32::from(self.node.cob_id(base)),
                };
            }
        }
    }

    fn position(index: u16, sub: u8) -> Result<usize, AbortCode> {
        match TABLE.iter().position(|e| e.index == index && e.sub == sub) {
            Some(i) => Ok(i),
            None if TABLE.iter().any(|e| e.index == index) => Err(AbortCode::SubIndexDoesNotExist),
            None => Err(AbortCode::ObjectDoesNotExist),
        }
    }

    /// The raw value of `index:sub`; 0 for an entry that does not exist.
    pub fn get(&self, index: u16, sub: u8) -> u32 {
        Self::position(index, sub)
            .ok()
            .and_then(|i| self.values.get(i))
            .copied()
            .unwrap_or(0)
    }

    /// Stores a value the drive produces, without the SDO access rules. The value is cut to
    /// the entry's type; a missing entry is ignored.
    pub fn set(&mut self, index: u16, sub: u8, raw: u32) {
        if let Ok(i) = Self::position(index, sub) {
            if let (Some(value), Some(e)) = (self.values.get_mut(i), TABLE.get(i)) {
                *value = truncate(raw, e.kind);
            }
        }
    }

    /// SDO upload: the value's bytes, or the abort code.
    pub fn upload(&self, index: u16, sub: u8) -> Result<SdoData, AbortCode> {
        let i = Self::position(index, sub)?;
        let (Some(e), Some(value)) = (TABLE.get(i), self.values.get(i)) else {
            return Err(AbortCode::ObjectDoesNotExist);
        };
        let bytes = value.to_le_bytes();
        bytes
            .get(..usize::from(e.kind.bytes()))
            .and_then(SdoData::new)
            .ok_or(AbortCode::GeneralError)
    }

    /// SDO download: checks the access rules, then stores the value.
    pub fn download(&mut self, index: u16, sub: u8, data: SdoData) -> Result<(), AbortCode> {
        let i = Self::position(index, sub)?;
        let Some(e) = TABLE.get(i) else {
            return Err(AbortCode::ObjectDoesNotExist);
        };
        if e.access == Access::Ro {
            return Err(AbortCode::WriteReadOnly);
        }
        if data.as_bytes().len() != usize::from(e.kind.bytes()) {
            return Err(AbortCode::LengthMismatch);
        }
        let mut bytes = [0; 4];
        for (dst, src) in bytes.iter_mut().zip(data.as_bytes()) {
            *dst = *src;
        }
        let raw = u32::from_le_bytes(bytes);
        self.check_value(index, sub, raw)?;
        self.set(index, sub, raw);
        if index == od::MODES_OF_OPERATION {
            self.set(od::MODES_OF_OPERATION_DISPLAY, 0, raw);
        }
        Ok(())
    }

    /// The value rules of writable entries beyond type and length.
    fn check_value(&self, index: u16, sub: u8, raw: u32) -> Result<(), AbortCode> {
        if index == od::MODES_OF_OPERATION && raw as u8 as i8 != od::MODE_CSP {
            return Err(AbortCode::ValueRangeExceeded);
        }
        for kind in [PdoKind::Rpdo, PdoKind::Tpdo] {
            match pdo_objects(kind) {
                (comm, _) if index == comm && sub == 1 => return self.check_cob_id(kind, raw),
                (comm, _) if index == comm => return check_transmission_type(raw),
                (_, map) if index == map => return self.check_mapping(kind, sub, raw),
                _ => {}
            }
        }
        Ok(())
    }

    /// A valid COB-ID must be a free 11-bit identifier, and cannot change while valid.
    fn check_cob_id(&self, kind: PdoKind, raw: u32) -> Result<(), AbortCode> {
        if raw & od::PDO_COB_ID_INVALID != 0 {
            return Ok(());
        }
        let id = raw & 0x3FFF_FFFF; // bit 30 (no RTR) is accepted either way
        if id > 0x7FF || restricted_can_id(id) {
            return Err(AbortCode::ValueRangeExceeded);
        }
        match self.pdo(kind).can_id {
            Some(current) if u32::from(current) != id => Err(AbortCode::ValueRangeExceeded),
            _ => Ok(()),
        }
    }

    /// Mapping changes need the PDO invalid; entries need the count at 0 (CiA-301's
    /// procedure). A count is checked against the entries it enables.
    fn check_mapping(&self, kind: PdoKind, sub: u8, raw: u32) -> Result<(), AbortCode> {
        let (_, map) = pdo_objects(kind);
        if self.pdo(kind).can_id.is_some() {
            return Err(AbortCode::UnsupportedAccess);
        }
        if sub != 0 {
            if self.get(map, 0) != 0 {
                return Err(AbortCode::UnsupportedAccess);
            }
            return decode_mapping(kind, raw)
                .map(|_| ())
                .ok_or(AbortCode::CannotMapToPdo);
        }
        if raw > u32::from(MAX_MAPPED) {
            return Err(AbortCode::ValueRangeExceeded);
        }
        let mut bits = 0;
        for s in 1..=raw as u8 {
            let (_, _, k) =
                decode_mapping(kind, self.get(map, s)).ok_or(AbortCode::CannotMapToPdo)?;
            bits += u32::from(k.bits());
        }
        if bits > MAX_PDO_BITS {
            return Err(AbortCode::PdoLengthExceeded);
        }
        Ok(())
    }

    /// The current configuration of PDO 1 of `kind`.
    pub fn pdo(&self, kind: PdoKind) -> PdoConfig {
        let (comm, map) = pdo_objects(kind);
        let cob_id = self.get(comm, 1);
        let mut config = PdoConfig {
            can_id: (cob_id & od::PDO_COB_ID_INVALID == 0).then_some((cob_id & 0x7FF) as u16),
            transmission_type: self.get(comm, 2) as u8,
            mapped: [(0, 0, Kind::U8); MAX_MAPPED as usize],
            count: 0,
        };
        let count = self.get(map, 0).min(u32::from(MAX_MAPPED)) as u8;
        for (slot, sub) in config.mapped.iter_mut().zip(1..=count) {
            // Entries were checked when the count was written.
            if let Some(e) = decode_mapping(kind, self.get(map, sub)) {
                *slot = e;
                config.count += 1;
            }
        }
        config
    }
}

/// Synchronous (0..=240) or event-driven (0xFE, 0xFF); RTR-only types are not supported.
fn check_transmission_type(raw: u32) -> Result<(), AbortCode> {
    match raw {
        0..=240 | 0xFE | 0xFF => Ok(()),
        _ => Err(AbortCode::ValueRangeExceeded),
    }
}

/// A mapping entry's `(index, sub, kind)` if it names an object `kind` may map, with the
/// object's exact bit length.
fn decode_mapping(kind: PdoKind, entry: u32) -> Option<(u16, u8, Kind)> {
    let [bits, sub, index_lo, index_hi] = entry.to_le_bytes();
    let index = u16::from_le_bytes([index_lo, index_hi]);
    if !mappable(kind, index, sub) {
        return None;
    }
    let i = Dictionary::position(index, sub).ok()?;
    let e = TABLE.get(i)?;
    (e.kind.bits() == bits).then_some((index, sub, e.kind))
}

fn truncate(raw: u32, kind: Kind) -> u32 {
    match kind.bytes() {
        1 => raw & 0xFF,
        2 => raw & 0xFFFF,
        _ => raw,
    }
}
