//! The drive's own protections ([`Protections`]), written in set-up and read back, so that
//! a drive stops by itself even if the controller dies: the following-error window 0x6065
//! and its time 0x6066, the quick-stop option code 0x605A, the fault-reaction option code
//! 0x605E, and the software position limits 0x607D:01/02.

use super::{Session, SetupError, SetupErrorKind};
use crate::link::CanLink;
use crate::master::Clock;
use crate::od;
use crate::wire::sdo::SdoValue;
use crate::wire::NodeId;

/// What an axis drive is told to guard by itself (drive units: counts, ms).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Protections {
    /// Following-error window 0x6065 (counts) and its time 0x6066 (ms): the drive reports a
    /// following error (statusword bit 13) when the error stays over it that long.
    pub following_window: u32,
    pub following_timeout_ms: u16,
    /// Quick-stop option code 0x605A (CiA-402: 2 = quick-stop ramp, then switch on
    /// disabled).
    pub quick_stop_option: i16,
    /// Fault-reaction option code 0x605E (2 = quick-stop ramp).
    pub fault_reaction_option: i16,
    /// Software position limits 0x607D:01 (min) and :02 (max), counts; None leaves the
    /// drive's own (an endless axis).
    pub position_limits: Option<(i32, i32)>,
}

/// Following control off (CiA-402: a window of 2^32 - 1).
pub const FOLLOWING_OFF: u32 = u32::MAX;

impl Default for Protections {
    /// No following control, the quick-stop ramp on a quick stop and on a fault, the
    /// drive's own position limits: what [`super::configure`] gives every axis drive.
    fn default() -> Self {
        Protections {
            following_window: FOLLOWING_OFF,
            following_timeout_ms: 0,
            quick_stop_option: 2,
            fault_reaction_option: 2,
            position_limits: None,
        }
    }
}

impl<L: CanLink, C: Clock> Session<'_, L, C> {
    /// Writes each protection and reads it back: a drive that keeps another value is a
    /// set-up error naming the object.
    pub(super) fn protections(&mut self, node: NodeId, p: &Protections) -> Result<(), SetupError> {
        let mut objects = vec![
            (
                od::FOLLOWING_ERROR_WINDOW,
                0,
                SdoValue::U32(p.following_window),
            ),
            (
                od::FOLLOWING_ERROR_TIMEOUT,
                0,
                SdoValue::U16(p.following_timeout_ms),
            ),
            (od::QUICK_STOP_OPTION, 0, SdoValue::I16(p.quick_stop_option)),
            (
                od::FAULT_REACTION_OPTION,
                0,
                SdoValue::I16(p.fault_reaction_option),
            ),
        ];
        if let Some((min, max)) = p.position_limits {
            objects.push((od::SOFTWARE_POSITION_LIMIT, 1, SdoValue::I32(min)));
            objects.push((od::SOFTWARE_POSITION_LIMIT, 2, SdoValue::I32(max)));
        }
        for (index, sub, value) in objects {
            self.write(node, index, sub, value)?;
            let got = self.read_i32(node, index, sub)?;
            let (expected, got) = match value {
                SdoValue::U32(v) => (i64::from(v), i64::from(got as u32)),
                SdoValue::U16(v) => (i64::from(v), i64::from(got as u16)),
                SdoValue::I16(v) => (i64::from(v), i64::from(got)),
                SdoValue::I32(v) => (i64::from(v), i64::from(got)),
                SdoValue::U8(v) => (i64::from(v), i64::from(got as u8)),
                SdoValue::I8(v) => (i64::from(v), i64::from(got)),
            };
            if got != expected {
                return Err(SetupError {
                    node: node.get(),
                    object: Some((index, sub)),
                    kind: SetupErrorKind::Mismatch { expected, got },
                });
            }
        }
        Ok(())
    }
}
