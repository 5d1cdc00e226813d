//! One simulated drive: its NMT state, SDO server, PDOs, motor model and injected faults.
//! The behaviour is described in the [module docs](super); [`SimBus`](super::SimBus) routes
//! frames and time to it.

use super::dictionary::{Dictionary, ERROR_REGISTER};
use super::{Faults, NodeCounters, Record, SimNodeConfig};
use crate::cia402::{DriveModel, State, Statusword};
use crate::frame::CanFrame;
use crate::od;
use crate::wire::emcy::{self, Emcy};
use crate::wire::heartbeat::{self, NmtState};
use crate::wire::nmt::NmtCommand;
use crate::wire::pdo::PdoKind;
use crate::wire::sdo::{self, SdoData, SdoRequest};
use crate::wire::{cob, AbortCode, DecodeError, NodeId};

/// Error register (0x1001) while the drive is faulted: bit 0 (generic, set with any error)
/// and bit 7 (manufacturer specific).
pub const FAULT_ERROR_REGISTER: u8 = 0x81;

/// Values received in an RPDO, split per mapped entry: `(index, sub, raw)`.
type RpdoValues = Vec<(u16, u8, u32)>;

/// One simulated node.
#[derive(Debug)]
pub struct SimNode {
    node: NodeId,
    lag_s: f64,
    faults: Faults,
    /// `BootUp` while initialising (until the next poll sends the boot-up message).
    nmt: NmtState,
    dict: Dictionary,
    drive: DriveModel,
    /// Motor position, counts; reported rounded.
    position: f64,
    /// Where the motor moves during the current SYNC period.
    demand: f64,
    following_error: bool,
    /// RPDO values received since the last SYNC (synchronous transmission types).
    pending: Option<RpdoValues>,
    heartbeat_due: Option<f64>,
    fault_fired: bool,
    /// SYNCs since NMT start, for TPDO transmission types 2..=240.
    syncs_operational: u64,
    last_tpdo: Option<CanFrame>,
    /// The last SYNC count seen, for `silent_from_sync`.
    last_sync: u64,
    /// Frames this node tried to send, for `drop_every`.
    attempts: u64,
    counters: NodeCounters,
}

impl SimNode {
    /// A node at power-on: initialising, its boot-up message due at the next poll.
    pub fn new(config: SimNodeConfig) -> Self {
        let position = f64::from(config.initial_position);
        let mut node = Self {
            node: config.node,
            lag_s: config.lag_s,
            faults: config.faults,
            nmt: NmtState::BootUp,
            dict: Dictionary::new(config.node),
            drive: DriveModel::new(),
            position,
            demand: position,
            following_error: false,
            pending: None,
            heartbeat_due: None,
            fault_fired: false,
            syncs_operational: 0,
            last_tpdo: None,
            attempts: 0,
            last_sync: 0,
            counters: NodeCounters::default(),
        };
        node.dict
            .set(od::TARGET_POSITION, 0, config.initial_position as u32);
        node.publish();
        node
    }

    pub fn id(&self) -> NodeId {
        self.node
    }

    pub fn state(&self) -> (NmtState, State, i32) {
        (self.nmt, self.drive.state(), self.actual())
    }

    pub fn counters(&self) -> NodeCounters {
        self.counters
    }

    fn actual(&self) -> i32 {
        self.position.round() as i32 // saturates; the position is always finite
    }

    fn booted(&self) -> bool {
        self.nmt != NmtState::BootUp
    }

    /// Sends `frame` unless `drop_every` or `silent_from_sync` drops it.
    fn emit(&mut self, frame: CanFrame, out: &mut dyn FnMut(CanFrame)) {
        self.attempts += 1;
        let silent = self
            .faults
            .silent_from_sync
            .is_some_and(|s| self.last_sync >= s);
        match self.faults.drop_every {
            _ if silent => self.counters.dropped += 1,
            Some(n) if n > 0 && self.attempts % u64::from(n) == 0 => self.counters.dropped += 1,
            _ => out(frame),
        }
    }

    fn emit_emcy(&mut self, error_code: u16, error_register: u8, out: &mut dyn FnMut(CanFrame)) {
        // EMCY is a pre-operational and operational service.
        if matches!(self.nmt, NmtState::PreOperational | NmtState::Operational) {
            let e = Emcy {
                error_code,
                error_register,
                manufacturer: [0; 5],
            };
            self.emit(emcy::encode(self.node, &e), out);
        }
    }

    /// Time passed: the delayed boot-up message, heartbeats.
    pub fn poll(&mut self, now_s: f64, syncs: u64, out: &mut dyn FnMut(CanFrame)) {
        if !self.booted() {
            if !self.faults.never_boots {
                self.nmt = NmtState::PreOperational;
                self.drive.tick(); // self-test done: Switch on disabled
                self.publish();
                self.emit(heartbeat::encode(self.node, NmtState::BootUp), out);
            }
            return;
        }
        let Some(due) = self.heartbeat_due else {
            return;
        };
        if now_s < due {
            return;
        }
        let period = self.heartbeat_period();
        self.heartbeat_due = period.map(|p| if due + p > now_s { due + p } else { now_s + p });
        let silenced = self.faults.heartbeat_stops_at.is_some_and(|n| syncs >= n);
        if !silenced {
            self.emit(heartbeat::encode(self.node, self.nmt), out);
        }
    }

    fn heartbeat_period(&self) -> Option<f64> {
        let ms = self.dict.get(od::HEARTBEAT_PRODUCER, 0);
        (ms > 0).then(|| f64::from(ms) / 1000.0)
    }

    pub fn on_nmt(&mut self, cmd: NmtCommand) {
        if !self.booted() {
            return; // initialising nodes do not take NMT commands
        }
        match cmd {
            NmtCommand::Start => {
                if self.nmt != NmtState::Operational {
                    self.syncs_operational = 0;
                    self.last_tpdo = None;
                }
                self.nmt = NmtState::Operational;
            }
            NmtCommand::Stop => self.nmt = NmtState::Stopped,
            NmtCommand::PreOperational => self.nmt = NmtState::PreOperational,
            NmtCommand::ResetNode => self.reset(true),
            NmtCommand::ResetCommunication => self.reset(false),
        }
        if self.nmt != NmtState::Operational {
            self.pending = None;
        }
    }

    /// Back to initialising with the defaults restored; the application's too for a reset
    /// node, which also restarts the drive state machine. The motor does not move: the
    /// target is set to where it stands.
    fn reset(&mut self, application: bool) {
        self.dict.reset(application);
        if application {
            self.drive = DriveModel::new();
            self.demand = self.position;
            self.following_error = false;
            self.dict.set(od::TARGET_POSITION, 0, self.actual() as u32);
        }
        self.nmt = NmtState::BootUp;
        self.pending = None;
        self.heartbeat_due = None;
        self.publish();
    }

    /// A frame that is neither NMT nor SYNC: an SDO request or an RPDO, if addressed here.
    pub fn on_frame(&mut self, frame: &CanFrame, now_s: f64, out: &mut dyn FnMut(CanFrame)) {
        if frame.id() == self.node.cob_id(cob::SDO_RX) {
            self.on_sdo(frame, now_s, out);
        } else if self.nmt == NmtState::Operational
            && self.dict.pdo(PdoKind::Rpdo).can_id == Some(frame.id())
        {
            self.on_rpdo(frame, out);
        }
    }

    fn on_sdo(&mut self, frame: &CanFrame, now_s: f64, out: &mut dyn FnMut(CanFrame)) {
        if !matches!(self.nmt, NmtState::PreOperational | NmtState::Operational) {
            return;
        }
        let node = self.node;
        let reply = match sdo::decode_request(node, frame) {
            Ok(SdoRequest::Upload { index, sub }) => match self.dict.upload(index, sub) {
                Ok(data) => sdo::upload_response(node, index, sub, data),
                Err(code) => sdo::abort(node, index, sub, code),
            },
            Ok(SdoRequest::Download { index, sub, data }) => {
                match self.download(index, sub, data, now_s, out) {
                    Ok(()) => sdo::download_ack(node, index, sub),
                    Err(code) => sdo::abort(node, index, sub, code),
                }
            }
            // A client's abort needs no answer; frames of the wrong length are not SDOs.
            Ok(SdoRequest::Abort { .. })
            | Err(DecodeError::Length { .. } | DecodeError::CobId { .. }) => return,
            Err(_) => {
                let [_, il, ih, sub, ..] = frame.raw_data();
                let index = u16::from_le_bytes([il, ih]);
                sdo::abort(node, index, sub, AbortCode::InvalidCommandSpecifier)
            }
        };
        self.emit(reply, out);
    }

    fn download(
        &mut self,
        index: u16,
        sub: u8,
        data: SdoData,
        now_s: f64,
        out: &mut dyn FnMut(CanFrame),
    ) -> Result<(), AbortCode> {
        self.dict.download(index, sub, data)?;
        match index {
            od::CONTROLWORD => {
                let cw = self.dict.get(od::CONTROLWORD, 0) as u16;
                self.apply_controlword(cw, out);
            }
            od::HEARTBEAT_PRODUCER => {
                self.heartbeat_due = self.heartbeat_period().map(|p| now_s + p);
            }
            od::RPDO1_COMMUNICATION | od::RPDO1_MAPPING => self.pending = None,
            _ => {}
        }
        self.publish();
        Ok(())
    }

    /// An RPDO on this node's valid RPDO1 COB-ID, in operational: split per the current
    /// mapping; synchronous types take effect at the next SYNC, 0xFE/0xFF at once.
    fn on_rpdo(&mut self, frame: &CanFrame, out: &mut dyn FnMut(CanFrame)) {
        let config = self.dict.pdo(PdoKind::Rpdo);
        if frame.len() != config.len() {
            self.counters.rpdo_length_errors += 1;
            return;
        }
        let mut values = RpdoValues::with_capacity(config.entries().len());
        let mut bytes = frame.data().iter().copied();
        for &(index, sub, kind) in config.entries() {
            let mut raw = [0; 4];
            for (dst, src) in raw.iter_mut().zip(bytes.by_ref().take(kind.bytes().into())) {
                *dst = src;
            }
            values.push((index, sub, u32::from_le_bytes(raw)));
        }
        if config.transmission_type <= 240 {
            self.pending = Some(values);
        } else {
            self.store(&values, out);
            self.publish();
        }
    }

    /// Stores received process data into the mapped objects; a controlword takes effect.
    fn store(&mut self, values: &[(u16, u8, u32)], out: &mut dyn FnMut(CanFrame)) {
        for &(index, sub, raw) in values {
            self.dict.set(index, sub, raw);
            if index == od::CONTROLWORD {
                self.apply_controlword(raw as u16, out);
            }
        }
    }

    /// Applies a controlword; leaving Fault announces the error reset (EMCY 0x0000).
    fn apply_controlword(&mut self, controlword: u16, out: &mut dyn FnMut(CanFrame)) {
        let was = self.drive.state();
        self.drive.apply(controlword);
        if was == State::Fault && self.drive.state() != State::Fault {
            self.emit_emcy(0x0000, 0, out);
        }
    }

    /// SYNC number `count` (1-based, counted by the bus).
    pub fn on_sync(
        &mut self,
        count: u64,
        period_s: f64,
        records: &mut Vec<Record>,
        out: &mut dyn FnMut(CanFrame),
    ) {
        self.last_sync = count;
        if !self.booted() {
            return;
        }
        self.advance(period_s);
        self.drive.tick();
        if self.faults.fault_at_sync == Some(count) && !self.fault_fired {
            self.fault_fired = true;
            self.drive.inject_fault();
            self.emit_emcy(emcy::FOLLOWING_ERROR, FAULT_ERROR_REGISTER, out);
        }
        let operational = self.nmt == NmtState::Operational;
        if let Some(values) = self.pending.take().filter(|_| operational) {
            self.store(&values, out);
        }
        let target = self.dict.get(od::TARGET_POSITION, 0) as i32;
        let csp = self.drive.state() == State::OperationEnabled && self.mode() == od::MODE_CSP;
        self.demand = if csp {
            f64::from(target)
        } else {
            self.position
        };
        let window = self.dict.get(od::FOLLOWING_ERROR_WINDOW, 0);
        let error = (i64::from(target) - i64::from(self.actual())).unsigned_abs();
        self.following_error = csp && window != 0 && error > u64::from(window);
        self.publish();
        if operational {
            self.syncs_operational += 1;
            self.send_tpdo(out);
            records.push(Record {
                sync: count,
                node: self.node.get(),
                target_counts: target,
                actual_counts: self.actual(),
                statusword: self.dict.get(od::STATUSWORD, 0) as u16,
            });
        }
    }

    /// One SYNC period of the first-order lag toward the demand.
    fn advance(&mut self, period_s: f64) {
        let alpha = if self.lag_s > 0.0 {
            1.0 - (-period_s / self.lag_s).exp()
        } else {
            1.0
        };
        let alpha = if alpha.is_finite() {
            alpha.clamp(0.0, 1.0)
        } else {
            1.0
        };
        self.position += (self.demand - self.position) * alpha;
    }

    /// TPDO1, if valid: every n-th SYNC for transmission types 1..=240; for 0, 0xFE and 0xFF
    /// (acyclic, event-driven) at a SYNC where the mapped values changed.
    fn send_tpdo(&mut self, out: &mut dyn FnMut(CanFrame)) {
        let config = self.dict.pdo(PdoKind::Tpdo);
        let Some(id) = config.can_id else {
            return;
        };
        let mut data = Vec::with_capacity(8);
        for &(index, sub, kind) in config.entries() {
            let raw = self.dict.get(index, sub).to_le_bytes();
            data.extend(raw.iter().take(kind.bytes().into()));
        }
        let Some(frame) = CanFrame::new(id, &data) else {
            return;
        };
        let due = match config.transmission_type {
            n @ 1..=240 => self.syncs_operational % u64::from(n) == 0,
            _ => self.last_tpdo != Some(frame),
        };
        if due {
            self.last_tpdo = Some(frame);
            self.emit(frame, out);
        }
    }

    fn mode(&self) -> i8 {
        self.dict.get(od::MODES_OF_OPERATION, 0) as u8 as i8
    }

    /// Writes the values the drive produces into the dictionary.
    fn publish(&mut self) {
        let mut statusword = self.drive.statusword();
        let enabled = self.drive.state() == State::OperationEnabled;
        if self.mode() != od::MODE_CSP {
            statusword &= !Statusword::TARGET_FOLLOWED;
        }
        if enabled && self.following_error {
            statusword |= Statusword::FOLLOWING_ERROR;
        }
        let faulted = matches!(
            self.drive.state(),
            State::Fault | State::FaultReactionActive
        );
        let mode = self.dict.get(od::MODES_OF_OPERATION, 0);
        self.dict.set(od::STATUSWORD, 0, statusword.into());
        self.dict.set(od::POSITION_ACTUAL, 0, self.actual() as u32);
        self.dict.set(od::MODES_OF_OPERATION_DISPLAY, 0, mode);
        let register = if faulted { FAULT_ERROR_REGISTER } else { 0 };
        self.dict.set(ERROR_REGISTER, 0, register.into());
    }
}
