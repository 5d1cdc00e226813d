//! A simulated node's object dictionary: the entries of its profile's
//! [`Table`](super::tables::Table), each value held as the raw bits of its type in a `u32`,
//! and the SDO access rules, the same for every profile (see the tables and the abort rules
//! in the [module docs](super)).
//!
//! [`Dictionary::download`] is the only way the SDO server changes a value; it checks, in this
//! order: the index exists, the sub-index exists, the entry is writable, the data length is
//! the type's, and then the value rules of the entry (mode, COB-ID, transmission type,
//! mapping). Values the device itself produces (statusword, actual values, error register,
//! mode display, inputs) are written with [`Dictionary::set`], which bypasses the access
//! rules.

use crate::od;
use crate::wire::pdo::PdoKind;
use crate::wire::sdo::SdoData;
use crate::wire::{AbortCode, NodeId};

use super::tables::{Access, Entry, Kind, Table, COMMUNICATION, COMMUNICATION_LEN};

/// The first index of the application area; below it is the communication area, which
/// reset communication restores (reset node restores both).
const APPLICATION_AREA: u16 = 0x2000;
/// Most entries in a PDO mapping object (sub-indices 1..=8).
const MAX_MAPPED: u8 = 8;
/// Most data bits in a classic CAN PDO.
const MAX_PDO_BITS: u32 = 64;

/// The communication and mapping objects of one PDO direction.
const fn pdo_objects(kind: PdoKind) -> (u16, u16) {
    match kind {
        PdoKind::Rpdo => (od::RPDO1_COMMUNICATION, od::RPDO1_MAPPING),
        PdoKind::Tpdo => (od::TPDO1_COMMUNICATION, od::TPDO1_MAPPING),
    }
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

/// One node's object dictionary: the shared communication area and its profile's table.
#[derive(Clone, Debug)]
pub struct Dictionary {
    node: NodeId,
    table: &'static Table,
    /// One value per entry, the communication area's first.
    values: Vec<u32>,
}

impl Dictionary {
    /// Every entry of `table` at its default.
    pub fn new(node: NodeId, table: &'static Table) -> Self {
        let mut dict = Self {
            node,
            table,
            values: vec![0; COMMUNICATION_LEN + table.application.len()],
        };
        dict.reset(true);
        dict
    }

    /// The entries, in the order of `values`.
    fn entries(&self) -> impl Iterator<Item = &'static Entry> {
        entries(self.table)
    }

    fn entry(&self, i: usize) -> Option<&'static Entry> {
        match i.checked_sub(COMMUNICATION_LEN) {
            None => COMMUNICATION.get(i),
            Some(j) => self.table.application.get(j),
        }
    }

    /// Restores the defaults of the communication area, and of the application area too if
    /// `application`.
    pub fn reset(&mut self, application: bool) {
        let (table, node) = (self.table, self.node);
        for (value, e) in self.values.iter_mut().zip(entries(table)) {
            if application || e.index < APPLICATION_AREA {
                *value = table.default_value(e, node);
            }
        }
    }

    fn position(&self, index: u16, sub: u8) -> Result<usize, AbortCode> {
        match self
            .entries()
            .position(|e| e.index == index && e.sub == sub)
        {
            Some(i) => Ok(i),
            None if self.entries().any(|e| e.index == index) => {
                Err(AbortCode::SubIndexDoesNotExist)
            }
            None => Err(AbortCode::ObjectDoesNotExist),
        }
    }

    /// The raw value of `index:sub`; 0 for an entry that does not exist.
    pub fn get(&self, index: u16, sub: u8) -> u32 {
        self.position(index, sub)
            .ok()
            .and_then(|i| self.values.get(i))
            .copied()
            .unwrap_or(0)
    }

    /// Stores a value the device produces, without the SDO access rules. The value is cut to
    /// the entry's type; a missing entry is ignored.
    pub fn set(&mut self, index: u16, sub: u8, raw: u32) {
        if let Ok(i) = self.position(index, sub) {
            if let (Some(e), Some(value)) = (self.entry(i), self.values.get_mut(i)) {
                *value = truncate(raw, e.kind);
            }
        }
    }

    /// SDO upload: the value's bytes, or the abort code.
    pub fn upload(&self, index: u16, sub: u8) -> Result<SdoData, AbortCode> {
        let i = self.position(index, sub)?;
        let (Some(e), Some(value)) = (self.entry(i), self.values.get(i)) else {
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
        let i = self.position(index, sub)?;
        let Some(e) = self.entry(i) else {
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
        let mode = raw as u8 as i8;
        if index == od::MODES_OF_OPERATION
            && ![od::MODE_CSP, od::MODE_PV, od::MODE_HOMING].contains(&mode)
        {
            return Err(AbortCode::ValueRangeExceeded);
        }
        if index == od::HOMING_METHOD && !super::homing::METHODS.contains(&mode) {
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
            return self
                .decode_mapping(kind, raw)
                .map(|_| ())
                .ok_or(AbortCode::CannotMapToPdo);
        }
        if raw > u32::from(MAX_MAPPED) {
            return Err(AbortCode::ValueRangeExceeded);
        }
        let mut bits = 0;
        for s in 1..=raw as u8 {
            let (_, _, k) = self
                .decode_mapping(kind, self.get(map, s))
                .ok_or(AbortCode::CannotMapToPdo)?;
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
            if let Some(e) = self.decode_mapping(kind, self.get(map, sub)) {
                *slot = e;
                config.count += 1;
            }
        }
        config
    }

    /// A mapping entry's `(index, sub, kind)` if it names an entry PDOs of `kind` may map,
    /// with the entry's exact bit length.
    fn decode_mapping(&self, kind: PdoKind, entry: u32) -> Option<(u16, u8, Kind)> {
        let [bits, sub, index_lo, index_hi] = entry.to_le_bytes();
        let index = u16::from_le_bytes([index_lo, index_hi]);
        let e = self.entry(self.position(index, sub).ok()?)?;
        (e.pdo == Some(kind) && e.kind.bits() == bits).then_some((index, sub, e.kind))
    }
}

/// The entries of a node with `table`: the communication area's, then the application's.
fn entries(table: &'static Table) -> impl Iterator<Item = &'static Entry> {
    COMMUNICATION.iter().chain(table.application)
}

/// Synchronous (0..=240) or event-driven (0xFE, 0xFF); RTR-only types are not supported.
fn check_transmission_type(raw: u32) -> Result<(), AbortCode> {
    match raw {
        0..=240 | 0xFE | 0xFF => Ok(()),
        _ => Err(AbortCode::ValueRangeExceeded),
    }
}

fn truncate(raw: u32, kind: Kind) -> u32 {
    match kind.bytes() {
        1 => raw & 0xFF,
        2 => raw & 0xFFFF,
        _ => raw,
    }
}
