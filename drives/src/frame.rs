//! A classic CAN 2.0A data frame (11-bit identifier, 0..=8 data bytes) and its text form.
//!
//! The text form is the compact `ID#DATA` notation that `candump -L` prints after the
//! interface name and that `cansend` accepts: `701#05`, `000#0100`, `080#`,
//! `605#2B40600006000000`. The identifier is exactly three hex digits, the data an even
//! number of hex digits (at most 16); both are case-insensitive when parsed and printed in
//! upper case. `cansend`'s optional `.` between data bytes (`605#2B.40.60`) is accepted.
//! Extended (29-bit) identifiers, remote frames (`123#R`) and CAN FD (`123##1...`) are not
//! used by this project and parse to errors rather than being approximated.
//!
//! # Invariants
//! The fields are private so that every `CanFrame` holds `id <= 0x7FF`, `len <= 8` and zero
//! bytes past `len`. Derived equality therefore compares exactly what is on the wire, and no
//! accessor can panic.
#![forbid(unsafe_code)]

use core::fmt;
use core::str::FromStr;

/// Largest 11-bit identifier.
pub const MAX_ID: u16 = 0x7FF;
/// Most data bytes in a classic CAN frame.
pub const MAX_LEN: usize = 8;

/// A classic CAN data frame with an 11-bit identifier.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct CanFrame {
    id: u16,
    len: u8,
    data: [u8; MAX_LEN],
}

impl CanFrame {
    /// A frame with identifier `id` and a copy of `data`; `None` if `id > 0x7FF` or
    /// `data.len() > 8`.
    pub fn new(id: u16, data: &[u8]) -> Option<Self> {
        if id > MAX_ID || data.len() > MAX_LEN {
            return None;
        }
        let mut buf = [0; MAX_LEN];
        buf.get_mut(..data.len())?.copy_from_slice(data);
        Some(Self {
            id,
            len: data.len() as u8, // <= 8, checked above
            data: buf,
        })
    }

    /// Infallible constructor for the encoders, whose identifiers are built from a valid
    /// node id. The length is checked at compile time; the identifier is masked to 11 bits
    /// (a no-op for every caller in this crate).
    pub(crate) fn from_array<const N: usize>(id: u16, data: [u8; N]) -> Self {
        const { assert!(N <= MAX_LEN) };
        let mut buf = [0; MAX_LEN];
        for (dst, src) in buf.iter_mut().zip(data) {
            *dst = src;
        }
        Self {
            id: id & MAX_ID,
            len: N as u8,
            data: buf,
        }
    }

    /// The 11-bit identifier (the CANopen COB-ID).
    pub const fn id(&self) -> u16 {
        self.id
    }

    /// Number of data bytes (the DLC), 0..=8.
    pub const fn len(&self) -> usize {
        self.len as usize
    }

    /// `true` for a frame without data (SYNC, for instance).
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The data bytes.
    pub fn data(&self) -> &[u8] {
        // `len <= 8` is an invariant of the type; `get` keeps this panic-free regardless.
        self.data.get(..self.len()).unwrap_or(&self.data)
    }

    /// The whole 8-byte buffer; bytes past [`len`](Self::len) are zero. Decoders that have
    /// checked the length read fixed positions from it without slice indexing.
    pub const fn raw_data(&self) -> [u8; MAX_LEN] {
        self.data
    }

    /// Parses the frame out of one line of `candump -L` output,
    /// `(1436509052.249713) vcan0 701#05`, by taking its last whitespace-separated field;
    /// a bare `701#05` is accepted too.
    pub fn from_log_line(line: &str) -> Result<Self, ParseFrameError> {
        line.split_whitespace()
            .next_back()
            .ok_or(ParseFrameError::Separator)?
            .parse()
    }
}

/// Why a string is not a compact candump frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParseFrameError {
    #[error("missing '#' between identifier and data")]
    Separator,
    #[error("the identifier must be 3 hex digits")]
    Id,
    #[error("identifier 0x{0:03X} does not fit in 11 bits")]
    IdRange(u16),
    #[error("29-bit identifiers are not supported")]
    ExtendedId,
    #[error("remote frames are not supported")]
    Remote,
    #[error("CAN FD frames are not supported")]
    Fd,
    #[error("invalid data: expected pairs of hex digits, optionally separated by '.'")]
    Data,
    #[error("more than 8 data bytes")]
    TooLong,
}

impl FromStr for CanFrame {
    type Err = ParseFrameError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (id_text, data_text) = s.split_once('#').ok_or(ParseFrameError::Separator)?;
        let id = match id_text.len() {
            3 => parse_hex_u16(id_text).ok_or(ParseFrameError::Id)?,
            8 if id_text.bytes().all(|b| hex_value(b).is_some()) => {
                return Err(ParseFrameError::ExtendedId)
            }
            _ => return Err(ParseFrameError::Id),
        };
        if id > MAX_ID {
            return Err(ParseFrameError::IdRange(id));
        }
        if data_text.starts_with('#') {
            return Err(ParseFrameError::Fd);
        }
        if data_text.starts_with(['R', 'r']) {
            return Err(ParseFrameError::Remote);
        }
        let mut buf = [0u8; MAX_LEN];
        let mut len = 0;
        let mut high: Option<u8> = None;
        for b in data_text.bytes() {
            if b == b'.' {
                if high.is_some() {
                    return Err(ParseFrameError::Data);
                }
                continue;
            }
            let nibble = hex_value(b).ok_or(ParseFrameError::Data)?;
            match high.take() {
                None => high = Some(nibble),
                Some(h) => {
                    *buf.get_mut(len).ok_or(ParseFrameError::TooLong)? = h << 4 | nibble;
                    len += 1;
                }
            }
        }
        if high.is_some() {
            return Err(ParseFrameError::Data);
        }
        Self::new(id, buf.get(..len).unwrap_or_default()).ok_or(ParseFrameError::TooLong)
    }
}

fn hex_value(b: u8) -> Option<u8> {
    match b {
        b'0'..=b'9' => Some(b - b'0'),
        b'a'..=b'f' => Some(b - b'a' + 10),
        b'A'..=b'F' => Some(b - b'A' + 10),
        _ => None,
    }
}

/// Up to four hex digits, nothing else (no sign, no prefix).
fn parse_hex_u16(s: &str) -> Option<u16> {
    if s.is_empty() || s.len() > 4 {
        return None;
    }
    s.bytes()
        .try_fold(0u16, |acc, b| Some(acc << 4 | u16::from(hex_value(b)?)))
}

impl fmt::Display for CanFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:03X}#", self.id)?;
        self.data().iter().try_for_each(|b| write!(f, "{b:02X}"))
    }
}

/// Debug shows the candump form, which is what test failures should be compared with.
impl fmt::Debug for CanFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "CanFrame({self})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_prints_the_candump_vectors() {
        for s in [
            "701#05",
            "000#0100",
            "080#",
            "605#2B40600006000000",
            "7FF#0102030405060708",
        ] {
            let f: CanFrame = s.parse().unwrap();
            assert_eq!(f.to_string(), s);
        }
        let f: CanFrame = "605#2B40600006000000".parse().unwrap();
        assert_eq!(f.id(), 0x605);
        assert_eq!(f.data(), [0x2B, 0x40, 0x60, 0x00, 0x06, 0x00, 0x00, 0x00]);
        let sync: CanFrame = "080#".parse().unwrap();
        assert!(sync.is_empty());
        assert_eq!(sync.data(), [] as [u8; 0]);
    }

    #[test]
    fn parsing_is_case_insensitive_and_accepts_cansend_dots() {
        let f: CanFrame = "5a1#4b.41.60.00".parse().unwrap();
        assert_eq!(f, CanFrame::new(0x5A1, &[0x4B, 0x41, 0x60, 0x00]).unwrap());
        assert_eq!(f.to_string(), "5A1#4B416000");
    }

    #[test]
    fn parses_candump_log_lines() {
        let f = CanFrame::from_log_line("(1436509052.249713) vcan0 701#05\n").unwrap();
        assert_eq!(f, CanFrame::new(0x701, &[0x05]).unwrap());
        assert_eq!(
            CanFrame::from_log_line("  "),
            Err(ParseFrameError::Separator)
        );
    }

    #[test]
    fn rejects_malformed_text() {
        let cases = [
            ("70105", ParseFrameError::Separator),
            ("", ParseFrameError::Separator),
            ("71#05", ParseFrameError::Id),
            ("0701#05", ParseFrameError::Id),
            ("7G1#05", ParseFrameError::Id),
            ("+01#05", ParseFrameError::Id),
            ("7é#05", ParseFrameError::Id),
            ("1234567é#05", ParseFrameError::Id),
            ("701#0é", ParseFrameError::Data),
            ("800#", ParseFrameError::IdRange(0x800)),
            ("FFF#00", ParseFrameError::IdRange(0xFFF)),
            ("12345678#00", ParseFrameError::ExtendedId),
            ("123#R", ParseFrameError::Remote),
            ("123##1001122", ParseFrameError::Fd),
            ("701#5", ParseFrameError::Data),
            ("701#0Z", ParseFrameError::Data),
            ("701#0.5", ParseFrameError::Data),
            ("701# 05", ParseFrameError::Data),
            ("701#010203040506070809", ParseFrameError::TooLong),
        ];
        for (s, e) in cases {
            assert_eq!(s.parse::<CanFrame>(), Err(e), "{s:?}");
        }
    }

    /// Random strings over the characters that matter: parsing never panics, and what parses
    /// prints back to something that parses to the same frame.
    #[test]
    fn parsing_never_panics() {
        const ALPHABET: [char; 12] = ['0', '7', 'a', 'F', '1', 'g', '#', '.', 'R', 'é', ' ', 'f'];
        let mut state = 0x9E37_79B9_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as usize
        };
        let mut text = String::new();
        let mut parsed = 0;
        for _ in 0..50_000 {
            text.clear();
            let len = next() % 24;
            let structured = next() % 2 == 0;
            for k in 0..len {
                let c = match (structured, k) {
                    (true, 3) => '#',
                    (true, 0..3) => ALPHABET[next() % 5],
                    _ => ALPHABET[next() % ALPHABET.len()],
                };
                text.push(c);
            }
            if let Ok(f) = text.parse::<CanFrame>() {
                assert_eq!(f.to_string().parse(), Ok(f), "{text:?}");
                parsed += 1;
            }
        }
        assert!(parsed > 100, "only {parsed} random strings parsed");
    }

    #[test]
    fn new_checks_id_and_length() {
        assert!(CanFrame::new(0x7FF, &[0; 8]).is_some());
        assert_eq!(CanFrame::new(0x800, &[]), None);
        assert_eq!(CanFrame::new(0x100, &[0; 9]), None);
        let f = CanFrame::new(0x181, &[1, 2]).unwrap();
        assert_eq!(f.raw_data(), [1, 2, 0, 0, 0, 0, 0, 0]);
        assert_eq!(f.len(), 2);
        assert_eq!(format!("{f:?}"), "CanFrame(181#0102)");
    }
}
