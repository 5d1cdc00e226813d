//! Homing one axis through CiA-402 homing mode (6) while the master runs its cycle: the
//! drive's parameters and the mode by SDO (one request at a time, each awaited), the start
//! bit (controlword bit 4) in the axis's RPDO, the statusword's homing bits from its TPDO,
//! then cyclic synchronous position again. Sans-I/O and allocation-free: the master calls
//! [`Job::poll`] once a cycle for the frame to send and [`Job::on_sdo`] with each answer
//! (`home.rs` holds the master's side: [`super::Master::home`] and the cycle's part).
//!
//! While an axis homes, the master sends it its own actual position as the target (the
//! drive ignores the target in mode 6), so that when the mode returns to 8 the target is
//! where the drive stands and nothing jumps. The statusword's bit 13 is the homing error in
//! mode 6, not a following error.

use crate::frame::CanFrame;
use crate::od;
use crate::wire::sdo::{self, SdoResponse, SdoValue};
use crate::wire::{AbortCode, NodeId};

/// Statusword bits in homing mode.
const TARGET_REACHED: u16 = 1 << 10;
const ATTAINED: u16 = 1 << 12;
const ERROR: u16 = 1 << 13;
/// Controlword bit 4 in homing mode: start.
pub const START: u16 = 1 << 4;
/// Cycles after the start before the statusword is believed: the first TPDO after the
/// start bit went out answers the SYNC that applied it.
const SETTLE_CYCLES: u32 = 2;
/// Cycles the mode's return to 8 may take after a timeout.
const MODE_BACK_CYCLES: u32 = 100;

/// How to home one axis: the drive's homing parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HomeRequest {
    /// 0x6098 (35 or 37: the current position; 19/21 the home switch; 3/5 the switch and
    /// the index pulse; what the drive offers).
    pub method: i8,
    /// 0x6099:01 and :02, counts/s.
    pub switch_speed: u32,
    pub index_speed: u32,
    /// 0x609A, counts/s².
    pub acceleration: u32,
    /// 0x607C: the position (counts) the home point becomes.
    pub offset: i32,
    /// Cycles the whole homing may take, the SDO exchanges included.
    pub timeout_cycles: u32,
}

/// Where an axis's homing is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HomingState {
    /// Never asked to home.
    Idle,
    Running,
    /// Homed; back in cyclic synchronous position mode, standing at `position` counts.
    Attained {
        position: i32,
    },
    /// Not homed (the mode set back to 8 where the drive still answered).
    Failed(HomingError),
}

/// Why a homing failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum HomingError {
    #[error("the drive refused 0x{index:04X}:{sub:02X} ({code})")]
    Refused {
        index: u16,
        sub: u8,
        code: AbortCode,
    },
    #[error(
        "homing error (statusword 0x{0:04X}, bit 13): the drive did not find its switch or \
         index pulse"
    )]
    Drive(u16),
    #[error("not homed within {0} cycles")]
    Timeout(u32),
    #[error("interrupted: the drive left Operation enabled or the bus faulted")]
    Interrupted,
    #[error("stopped by the operator before it was homed")]
    Stopped,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    /// Send write `k` of [`writes`] (6 = the mode back to 8).
    Write(usize),
    /// Write `k` sent, its answer awaited.
    Awaiting(usize),
    /// The start bit out since `since` (cycles of the job).
    Homing {
        since: u32,
    },
    Done,
}

/// One axis's homing, from its request to its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Job {
    req: HomeRequest,
    step: Step,
    cycles: u32,
    /// The cycle count past which the job gives up (the request's timeout, then the
    /// mode's return).
    deadline: u32,
    /// How it ended, once the mode is back (or could not be set back).
    outcome: Option<Result<(), HomingError>>,
}

/// The writes before the start, and (index 6) the mode back to CSP.
fn write(req: &HomeRequest, k: usize) -> (u16, u8, SdoValue) {
    match k {
        0 => (od::HOMING_METHOD, 0, SdoValue::I8(req.method)),
        1 => (od::HOMING_SPEEDS, 1, SdoValue::U32(req.switch_speed)),
        2 => (od::HOMING_SPEEDS, 2, SdoValue::U32(req.index_speed)),
        3 => (od::HOMING_ACCELERATION, 0, SdoValue::U32(req.acceleration)),
        4 => (od::HOME_OFFSET, 0, SdoValue::I32(req.offset)),
        5 => (od::MODES_OF_OPERATION, 0, SdoValue::I8(od::MODE_HOMING)),
        _ => (od::MODES_OF_OPERATION, 0, SdoValue::I8(od::MODE_CSP)),
    }
}

const MODE_BACK: usize = 6;

impl Job {
    pub fn new(req: HomeRequest) -> Self {
        Job {
            req,
            step: Step::Write(0),
            cycles: 0,
            deadline: req.timeout_cycles,
            outcome: None,
        }
    }

    /// One cycle: the SDO request to send, if one is due. `statusword` and `actual` are
    /// the node's latest.
    pub fn poll(&mut self, node: NodeId, statusword: u16) -> Option<CanFrame> {
        if self.step == Step::Done {
            return None;
        }
        self.cycles = self.cycles.saturating_add(1);
        if self.cycles > self.deadline {
            let timeout = Err(HomingError::Timeout(self.req.timeout_cycles));
            if self.homing_mode() && self.outcome.is_none() {
                // Perhaps in mode 6: set it back, within a short allowance of its own.
                self.outcome = Some(timeout);
                self.step = Step::Write(MODE_BACK);
                self.deadline = self.cycles.saturating_add(MODE_BACK_CYCLES);
            } else {
                self.end(self.outcome.unwrap_or(timeout));
                return None;
            }
        }
        match self.step {
            Step::Write(k) => {
                self.step = Step::Awaiting(k);
                let (index, sub, value) = write(&self.req, k);
                Some(sdo::download_request(node, index, sub, value))
            }
            Step::Homing { since } if self.cycles > since + SETTLE_CYCLES => {
                if statusword & ERROR != 0 {
                    self.outcome = Some(Err(HomingError::Drive(statusword)));
                    self.step = Step::Write(MODE_BACK);
                } else if statusword & (ATTAINED | TARGET_REACHED) == ATTAINED | TARGET_REACHED {
                    self.outcome = Some(Ok(()));
                    self.step = Step::Write(MODE_BACK);
                }
                None
            }
            _ => None,
        }
    }

    /// An SDO answer from the node.
    pub fn on_sdo(&mut self, answer: SdoResponse) {
        let Step::Awaiting(k) = self.step else {
            return;
        };
        let (index, sub, _) = write(&self.req, k);
        match answer {
            SdoResponse::DownloadAck { index: i, sub: s } if (i, s) == (index, sub) => {
                self.step = match k {
                    MODE_BACK => Step::Done,
                    5 => Step::Homing { since: self.cycles },
                    _ => Step::Write(k + 1),
                };
                if self.step == Step::Done && self.outcome.is_none() {
                    self.outcome = Some(Ok(()));
                }
            }
            SdoResponse::Abort {
                index: i,
                sub: s,
                code,
            } if (i, s) == (index, sub) => {
                let refused = HomingError::Refused { index, sub, code };
                if k == MODE_BACK || k == 5 {
                    // Mode 6 refused (still in 8), or 8 refused: nothing more to undo.
                    self.end(Err(self.outcome.and_then(Result::err).unwrap_or(refused)));
                } else {
                    self.end(Err(refused));
                }
            }
            _ => {}
        }
    }

    /// The start bit belongs in the controlword this cycle.
    pub fn start_bit(&self) -> bool {
        matches!(self.step, Step::Homing { .. })
    }

    /// The drive is in (or being switched to) homing mode: its bit 13 is no following
    /// error.
    pub fn homing_mode(&self) -> bool {
        matches!(
            self.step,
            Step::Awaiting(5)
                | Step::Homing { .. }
                | Step::Write(MODE_BACK)
                | Step::Awaiting(MODE_BACK)
        )
    }

    /// Stopped from outside (a fault, the drive disabled): no more frames.
    pub fn interrupt(&mut self) {
        if self.step != Step::Done {
            self.end(Err(HomingError::Interrupted));
        }
    }

    /// The operator's stop: the start bit drops (the drive halts its search) and the mode
    /// is set back to cyclic synchronous position; not homed. Before the drive is in
    /// homing mode, it simply ends.
    pub fn cancel(&mut self) {
        if self.step == Step::Done || self.outcome.is_some() {
            return;
        }
        if self.homing_mode() {
            self.outcome = Some(Err(HomingError::Stopped));
            self.step = Step::Write(MODE_BACK);
            self.deadline = self.cycles.saturating_add(MODE_BACK_CYCLES);
        } else {
            self.end(Err(HomingError::Stopped));
        }
    }

    /// How it ended, once it has: `Ok` homed, else why not.
    pub fn outcome(&self) -> Option<Result<(), HomingError>> {
        (self.step == Step::Done).then_some(self.outcome?)
    }

    fn end(&mut self, r: Result<(), HomingError>) {
        self.outcome = Some(r);
        self.step = Step::Done;
    }
}
