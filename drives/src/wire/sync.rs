//! SYNC (CiA-301 7.2.5): COB-ID 0x080, no data, or one counter byte 1..=240 when the
//! producer's counter overflow value (0x1019) is set. This project sends it without a
//! counter; the decoder accepts both forms.

use super::{check_len, cob, DecodeError};
use crate::frame::CanFrame;

/// Largest SYNC counter value (CiA-301 object 0x1019).
pub const MAX_COUNTER: u8 = 240;

/// A SYNC frame without counter: `080#`.
pub fn encode() -> CanFrame {
    CanFrame::from_array(cob::SYNC, [])
}

/// A SYNC frame with `counter` (1..=240); `None` outside that range.
pub fn encode_with_counter(counter: u8) -> Option<CanFrame> {
    (1..=MAX_COUNTER)
        .contains(&counter)
        .then(|| CanFrame::from_array(cob::SYNC, [counter]))
}

/// Decodes a SYNC frame into its counter, if it carries one.
pub fn decode(frame: &CanFrame) -> Result<Option<u8>, DecodeError> {
    if frame.id() != cob::SYNC {
        return Err(DecodeError::CobId {
            id: frame.id(),
            service: "SYNC",
        });
    }
    check_len(frame, 0, 1)?;
    match frame.data().first() {
        None => Ok(None),
        Some(&counter) if (1..=MAX_COUNTER).contains(&counter) => Ok(Some(counter)),
        Some(&counter) => Err(DecodeError::SyncCounter { counter }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::frame;

    #[test]
    fn encodes_and_decodes() {
        assert_eq!(encode().to_string(), "080#");
        assert_eq!(decode(&frame("080#")), Ok(None));
        assert_eq!(encode_with_counter(1).unwrap().to_string(), "080#01");
        assert_eq!(encode_with_counter(240).unwrap().to_string(), "080#F0");
        assert_eq!(decode(&frame("080#F0")), Ok(Some(240)));
        assert_eq!(encode_with_counter(0), None);
        assert_eq!(encode_with_counter(241), None);
    }

    #[test]
    fn rejects_malformed_frames() {
        assert_eq!(
            decode(&frame("081#")),
            Err(DecodeError::CobId {
                id: 0x81,
                service: "SYNC"
            })
        );
        assert_eq!(
            decode(&frame("080#0102")),
            Err(DecodeError::Length {
                id: 0x80,
                len: 2,
                min: 0,
                max: 1
            })
        );
        assert_eq!(
            decode(&frame("080#00")),
            Err(DecodeError::SyncCounter { counter: 0 })
        );
        assert_eq!(
            decode(&frame("080#F1")),
            Err(DecodeError::SyncCounter { counter: 241 })
        );
    }
}
