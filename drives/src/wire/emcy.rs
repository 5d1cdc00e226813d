//! Emergency messages (CiA-301 7.2.7): COB-ID 0x080 + node (0x080 itself is SYNC), eight
//! bytes: error code (u16 LE), error register (object 0x1001), five manufacturer-specific
//! bytes. An error code of 0x0000 announces that the error is gone ("error reset").
//!
//! The error code's high byte names its class (CiA-301 table 21); [`ErrorClass`] decodes it
//! and [`Emcy`]'s `Display` names the class and, for the few codes this project reacts to,
//! the code itself (CiA-402 adds 0x8611, following error).

use core::fmt;

use super::{check_len, cob, node_of, DecodeError, NodeId};
use crate::frame::CanFrame;

/// The contents of an EMCY frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Emcy {
    pub error_code: u16,
    /// Object 0x1001: bit 0 generic, 1 current, 2 voltage, 3 temperature, 4 communication,
    /// 5 device profile, 7 manufacturer.
    pub error_register: u8,
    pub manufacturer: [u8; 5],
}

/// Error code of a following error (CiA-402).
pub const FOLLOWING_ERROR: u16 = 0x8611;

/// The class of an EMCY error code, from its high byte (CiA-301 table 21).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorClass {
    /// 0x00xx: error reset or no error.
    NoError,
    /// 0x10xx.
    Generic,
    /// 0x2xxx.
    Current,
    /// 0x3xxx.
    Voltage,
    /// 0x4xxx.
    Temperature,
    /// 0x5xxx.
    DeviceHardware,
    /// 0x6xxx.
    DeviceSoftware,
    /// 0x7xxx.
    AdditionalModules,
    /// 0x8xxx, including communication (0x81xx), protocol (0x82xx) and, in CiA-402,
    /// following error (0x8611).
    Monitoring,
    /// 0x9xxx.
    External,
    /// 0xF0xx.
    AdditionalFunctions,
    /// 0xFFxx.
    DeviceSpecific,
    /// A high byte CiA-301 does not assign.
    Reserved,
}

impl ErrorClass {
    pub const fn of(error_code: u16) -> Self {
        match error_code >> 8 {
            0x00 => Self::NoError,
            0x10..=0x1F => Self::Generic,
            0x20..=0x2F => Self::Current,
            0x30..=0x3F => Self::Voltage,
            0x40..=0x4F => Self::Temperature,
            0x50..=0x5F => Self::DeviceHardware,
            0x60..=0x6F => Self::DeviceSoftware,
            0x70..=0x7F => Self::AdditionalModules,
            0x80..=0x8F => Self::Monitoring,
            0x90..=0x9F => Self::External,
            0xF0 => Self::AdditionalFunctions,
            0xFF => Self::DeviceSpecific,
            _ => Self::Reserved,
        }
    }

    pub const fn name(self) -> &'static str {
        match self {
            Self::NoError => "error reset or no error",
            Self::Generic => "generic error",
            Self::Current => "current",
            Self::Voltage => "voltage",
            Self::Temperature => "temperature",
            Self::DeviceHardware => "device hardware",
            Self::DeviceSoftware => "device software",
            Self::AdditionalModules => "additional modules",
            Self::Monitoring => "monitoring",
            Self::External => "external error",
            Self::AdditionalFunctions => "additional functions",
            Self::DeviceSpecific => "device specific",
            Self::Reserved => "reserved error class",
        }
    }
}

/// The meaning of the individual codes worth naming (CiA-301 communication errors and the
/// CiA-402 following error); `None` for the rest, which [`ErrorClass`] still classifies.
pub const fn code_name(error_code: u16) -> Option<&'static str> {
    match error_code {
        0x8110 => Some("CAN overrun, objects lost"),
        0x8120 => Some("CAN in error passive mode"),
        0x8130 => Some("life guard or heartbeat error"),
        0x8140 => Some("recovered from bus off"),
        0x8150 => Some("CAN-ID collision"),
        0x8210 => Some("PDO not processed due to length error"),
        0x8220 => Some("PDO length exceeded"),
        0x8240 => Some("unexpected SYNC data length"),
        0x8250 => Some("RPDO timeout"),
        FOLLOWING_ERROR => Some("following error"),
        _ => None,
    }
}

impl Emcy {
    pub const fn class(&self) -> ErrorClass {
        ErrorClass::of(self.error_code)
    }
}

/// `EMCY 0x8611 (monitoring: following error), error register 0x20`.
impl fmt::Display for Emcy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "EMCY 0x{:04X} ({}", self.error_code, self.class().name())?;
        if let Some(name) = code_name(self.error_code) {
            write!(f, ": {name}")?;
        }
        write!(f, "), error register 0x{:02X}", self.error_register)
    }
}

/// The EMCY frame of `node`.
pub fn encode(node: NodeId, emcy: &Emcy) -> CanFrame {
    let [c0, c1] = emcy.error_code.to_le_bytes();
    let [m0, m1, m2, m3, m4] = emcy.manufacturer;
    let data = [c0, c1, emcy.error_register, m0, m1, m2, m3, m4];
    CanFrame::from_array(node.cob_id(cob::EMCY), data)
}

/// Decodes an EMCY frame into the producing node and its contents.
pub fn decode(frame: &CanFrame) -> Result<(NodeId, Emcy), DecodeError> {
    let node = node_of(frame, cob::EMCY, "an EMCY")?;
    check_len(frame, 8, 8)?;
    let [c0, c1, error_register, m0, m1, m2, m3, m4] = frame.raw_data();
    let emcy = Emcy {
        error_code: u16::from_le_bytes([c0, c1]),
        error_register,
        manufacturer: [m0, m1, m2, m3, m4],
    };
    Ok((node, emcy))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{frame, node};

    #[test]
    fn encodes_the_candump_vectors() {
        let cases = [
            (5, 0x8611, 0x20, [0; 5], "085#1186200000000000"),
            (1, 0x0000, 0x00, [0; 5], "081#0000000000000000"),
            (127, 0x2310, 0x03, [1, 2, 3, 4, 5], "0FF#1023030102030405"),
        ];
        for (n, error_code, error_register, manufacturer, s) in cases {
            let emcy = Emcy {
                error_code,
                error_register,
                manufacturer,
            };
            assert_eq!(encode(node(n), &emcy).to_string(), s);
            assert_eq!(decode(&frame(s)), Ok((node(n), emcy)), "{s}");
        }
    }

    #[test]
    fn displays_class_and_known_codes() {
        let show = |s| decode(&frame(s)).unwrap().1.to_string();
        assert_eq!(
            show("085#1186200000000000"),
            "EMCY 0x8611 (monitoring: following error), error register 0x20"
        );
        assert_eq!(
            show("085#3081110000000000"),
            "EMCY 0x8130 (monitoring: life guard or heartbeat error), error register 0x11"
        );
        assert_eq!(
            show("085#1023030000000000"),
            "EMCY 0x2310 (current), error register 0x03"
        );
        assert_eq!(
            show("085#0000000000000000"),
            "EMCY 0x0000 (error reset or no error), error register 0x00"
        );
    }

    #[test]
    fn classes_by_high_byte() {
        let cases = [
            (0x0000, ErrorClass::NoError),
            (0x1000, ErrorClass::Generic),
            (0x2310, ErrorClass::Current),
            (0x3210, ErrorClass::Voltage),
            (0x4310, ErrorClass::Temperature),
            (0x5530, ErrorClass::DeviceHardware),
            (0x6320, ErrorClass::DeviceSoftware),
            (0x7121, ErrorClass::AdditionalModules),
            (0x8611, ErrorClass::Monitoring),
            (0x9000, ErrorClass::External),
            (0xF001, ErrorClass::AdditionalFunctions),
            (0xFF42, ErrorClass::DeviceSpecific),
            (0x0100, ErrorClass::Reserved),
            (0xA000, ErrorClass::Reserved),
            (0xF100, ErrorClass::Reserved),
        ];
        for (code, class) in cases {
            assert_eq!(ErrorClass::of(code), class, "0x{code:04X}");
        }
    }

    #[test]
    fn rejects_malformed_frames() {
        let cob = |id| DecodeError::CobId {
            id,
            service: "an EMCY",
        };
        let len = |id, len| DecodeError::Length {
            id,
            len,
            min: 8,
            max: 8,
        };
        let cases = [
            ("080#1186200000000000", cob(0x080)),
            ("100#1186200000000000", cob(0x100)),
            ("185#1186200000000000", cob(0x185)),
            ("085#118620", len(0x085, 3)),
            ("085#", len(0x085, 0)),
        ];
        for (s, e) in cases {
            assert_eq!(decode(&frame(s)), Err(e), "{s}");
        }
    }
}
