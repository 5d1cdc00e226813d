//! SDO abort codes (CiA-301 7.2.4.3.17, table 22), re-exported as [`super::sdo::AbortCode`].
//!
//! The table is written once, in the macro call below, and generates the enum, both
//! conversions and the descriptions, so the three cannot drift apart.

use core::fmt;
use core::hash::{Hash, Hasher};

macro_rules! abort_codes {
    ($($name:ident = $code:literal, $text:literal;)*) => {
        /// An SDO abort code: the standard CiA-301 codes by name, anything else in
        /// [`AbortCode::Other`]. Equality and hashing compare the numeric code, so
        /// `Other(0x0602_0000) == ObjectDoesNotExist`; [`AbortCode::from_u32`] always returns
        /// the named variant.
        #[derive(Clone, Copy, Debug)]
        pub enum AbortCode {
            $(#[doc = $text] $name,)*
            /// A manufacturer-specific or unknown code.
            Other(u32),
        }

        impl AbortCode {
            pub const fn from_u32(code: u32) -> Self {
                match code {
                    $($code => Self::$name,)*
                    other => Self::Other(other),
                }
            }

            pub const fn as_u32(self) -> u32 {
                match self {
                    $(Self::$name => $code,)*
                    Self::Other(code) => code,
                }
            }

            /// The standard meaning in words, or "unknown abort code" for
            /// [`AbortCode::Other`] values outside the standard table.
            pub const fn description(self) -> &'static str {
                match Self::from_u32(self.as_u32()) {
                    $(Self::$name => $text,)*
                    Self::Other(_) => "unknown abort code",
                }
            }
        }
    };
}

abort_codes! {
    ToggleBitNotAlternated = 0x0503_0000, "toggle bit not alternated";
    TimedOut = 0x0504_0000, "SDO protocol timed out";
    InvalidCommandSpecifier = 0x0504_0001, "client/server command specifier not valid or unknown";
    InvalidBlockSize = 0x0504_0002, "invalid block size (block mode only)";
    InvalidSequenceNumber = 0x0504_0003, "invalid sequence number (block mode only)";
    CrcError = 0x0504_0004, "CRC error (block mode only)";
    OutOfMemory = 0x0504_0005, "out of memory";
    UnsupportedAccess = 0x0601_0000, "unsupported access to an object";
    ReadWriteOnly = 0x0601_0001, "attempt to read a write only object";
    WriteReadOnly = 0x0601_0002, "attempt to write a read only object";
    ObjectDoesNotExist = 0x0602_0000, "object does not exist in the object dictionary";
    CannotMapToPdo = 0x0604_0041, "object cannot be mapped to the PDO";
    PdoLengthExceeded = 0x0604_0042, "the number and length of the objects to be mapped would exceed the PDO length";
    ParameterIncompatibility = 0x0604_0043, "general parameter incompatibility reason";
    InternalIncompatibility = 0x0604_0047, "general internal incompatibility in the device";
    HardwareError = 0x0606_0000, "access failed due to a hardware error";
    LengthMismatch = 0x0607_0010, "data type does not match, length of service parameter does not match";
    LengthTooHigh = 0x0607_0012, "data type does not match, length of service parameter too high";
    LengthTooLow = 0x0607_0013, "data type does not match, length of service parameter too low";
    SubIndexDoesNotExist = 0x0609_0011, "sub-index does not exist";
    ValueRangeExceeded = 0x0609_0030, "invalid value for parameter: value range exceeded (download only)";
    ValueTooHigh = 0x0609_0031, "value of parameter written too high (download only)";
    ValueTooLow = 0x0609_0032, "value of parameter written too low (download only)";
    MaxLessThanMin = 0x0609_0036, "maximum value is less than minimum value";
    SdoConnectionUnavailable = 0x060A_0023, "resource not available: SDO connection";
    GeneralError = 0x0800_0000, "general error";
    CannotStore = 0x0800_0020, "data cannot be transferred or stored to the application";
    CannotStoreLocalControl = 0x0800_0021, "data cannot be transferred or stored to the application because of local control";
    CannotStoreDeviceState = 0x0800_0022, "data cannot be transferred or stored to the application because of the present device state";
    NoObjectDictionary = 0x0800_0023, "object dictionary dynamic generation fails or no object dictionary is present";
    NoDataAvailable = 0x0800_0024, "no data available";
}

impl PartialEq for AbortCode {
    fn eq(&self, other: &Self) -> bool {
        self.as_u32() == other.as_u32()
    }
}

impl Eq for AbortCode {}

impl Hash for AbortCode {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.as_u32().hash(state);
    }
}

impl From<u32> for AbortCode {
    fn from(code: u32) -> Self {
        Self::from_u32(code)
    }
}

impl From<AbortCode> for u32 {
    fn from(code: AbortCode) -> Self {
        code.as_u32()
    }
}

/// `0x06020000: object does not exist in the object dictionary`.
impl fmt::Display for AbortCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "0x{:08X}: {}", self.as_u32(), self.description())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_displays() {
        for code in [
            0x0503_0000,
            0x0602_0000,
            0x0609_0011,
            0x0800_0022,
            0x1234_5678,
        ] {
            assert_eq!(AbortCode::from_u32(code).as_u32(), code);
        }
        assert_eq!(
            AbortCode::from_u32(0x0602_0000),
            AbortCode::ObjectDoesNotExist
        );
        assert_eq!(
            AbortCode::ObjectDoesNotExist.to_string(),
            "0x06020000: object does not exist in the object dictionary"
        );
        assert_eq!(
            AbortCode::from_u32(0x0504_0001).to_string(),
            "0x05040001: client/server command specifier not valid or unknown"
        );
        assert_eq!(
            AbortCode::from_u32(0xDEAD_BEEF).to_string(),
            "0xDEADBEEF: unknown abort code"
        );
    }

    #[test]
    fn other_with_a_standard_code_equals_the_named_variant() {
        assert_eq!(AbortCode::Other(0x0606_0000), AbortCode::HardwareError);
        assert_eq!(
            AbortCode::Other(0x0606_0000).description(),
            "access failed due to a hardware error"
        );
        assert_ne!(AbortCode::Other(1), AbortCode::Other(2));
    }
}
