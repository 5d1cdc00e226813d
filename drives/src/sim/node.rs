//! One simulated node: its NMT state, SDO server, PDOs and injected faults, the same for
//! every profile, and its application: a [`Drive`] or an [`Io`] module. The behaviour is
//! described in the [module docs](super); [`SimBus`](super::SimBus) routes frames and time
//! to it.

use super::dictionary::Dictionary;
use super::drive::Drive;
use super::io::Io;
use super::tables::Table;
use super::{Faults, NodeCounters, Profile, Record, SimNodeConfig};
use crate::cia402::State;
use crate::frame::CanFrame;
use crate::od;
use crate::wire::emcy::{self, Emcy};
use crate::wire::heartbeat::{self, NmtState};
use crate::wire::nmt::NmtCommand;
use crate::wire::pdo::PdoKind;
use crate::wire::sdo::{self, SdoData, SdoRequest};
use crate::wire::{cob, AbortCode, DecodeError, NodeId};

/// Values received in an RPDO, split per mapped entry: `(index, sub, raw)`.
type RpdoValues = Vec<(u16, u8, u32)>;

/// What the node is beyond CiA-301.
#[derive(Debug)]
enum App {
    Drive(Drive),
    Io(Io),
}

/// One simulated node.
#[derive(Debug)]
pub struct SimNode {
    node: NodeId,
    faults: Faults,
    /// `BootUp` while initialising (until the next poll sends the boot-up message).
    nmt: NmtState,
    dict: Dictionary,
    app: App,
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
        let mut dict = Dictionary::new(config.node, Table::of(config.profile));
        let app = match config.profile {
            Profile::Drive => App::Drive(Drive::new(
                config.lag_s,
                config.initial_position,
                config.home,
                &mut dict,
            )),
            Profile::Io => App::Io(Io::default()),
        };
        let mut node = Self {
            node: config.node,
            faults: config.faults,
            nmt: NmtState::BootUp,
            dict,
            app,
            pending: None,
            heartbeat_due: None,
            fault_fired: false,
            syncs_operational: 0,
            last_tpdo: None,
            attempts: 0,
            last_sync: 0,
            counters: NodeCounters::default(),
        };
        node.publish();
        node
    }

    pub fn id(&self) -> NodeId {
        self.node
    }

    pub fn nmt_state(&self) -> NmtState {
        self.nmt
    }

    /// A drive's NMT state, drive state and position; `None` for an I/O module.
    pub fn drive_state(&self) -> Option<(NmtState, State, i32)> {
        match &self.app {
            App::Drive(d) => Some((self.nmt, d.state(), d.position())),
            App::Io(_) => None,
        }
    }

    /// An I/O module's outputs in effect; `None` for a drive.
    pub fn object(&self, index: u16, sub: u8) -> Option<u32> {
        self.dict
            .upload(index, sub)
            .ok()
            .map(|_| self.dict.get(index, sub))
    }

    pub fn io_outputs(&self) -> Option<u8> {
        match self.app {
            App::Io(_) => Some(Io::outputs(&self.dict)),
            App::Drive(_) => None,
        }
    }

    pub fn counters(&self) -> NodeCounters {
        self.counters
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

    fn emit_emcy(&mut self, e: Option<Emcy>, out: &mut dyn FnMut(CanFrame)) {
        // EMCY is a pre-operational and operational service.
        let active = matches!(self.nmt, NmtState::PreOperational | NmtState::Operational);
        if let Some(e) = e.filter(|_| active) {
            self.emit(emcy::encode(self.node, &e), out);
        }
    }

    /// Time passed: the delayed boot-up message, heartbeats.
    pub fn poll(&mut self, now_s: f64, syncs: u64, out: &mut dyn FnMut(CanFrame)) {
        if !self.booted() {
            if !self.faults.never_boots {
                self.nmt = NmtState::PreOperational;
                if let App::Drive(d) = &mut self.app {
                    d.boot(); // self-test done: Switch on disabled
                }
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
        if let App::Io(io) = &mut self.app {
            io.nmt(self.nmt, &mut self.dict);
            self.publish();
        }
    }

    /// Back to initialising with the defaults restored; the application's too for a reset
    /// node, which also resets the application (see [`Drive::reset`], [`Io::reset`]).
    fn reset(&mut self, application: bool) {
        self.dict.reset(application);
        if application {
            match &mut self.app {
                App::Drive(d) => d.reset(&mut self.dict),
                App::Io(io) => io.reset(),
            }
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
        if self.faults.keeps_object == Some((index, sub)) {
            return Ok(());
        }
        self.dict.download(index, sub, data)?;
        self.written(index, out);
        match index {
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

    /// Stores received process data into the mapped objects, each taking effect.
    fn store(&mut self, values: &[(u16, u8, u32)], out: &mut dyn FnMut(CanFrame)) {
        for &(index, sub, raw) in values {
            self.dict.set(index, sub, raw);
            self.written(index, out);
        }
    }

    /// `index` was written by SDO or RPDO: the application reacts (a drive applies a
    /// controlword), perhaps with an EMCY.
    fn written(&mut self, index: u16, out: &mut dyn FnMut(CanFrame)) {
        if let App::Drive(d) = &mut self.app {
            let e = d.written(index, &self.dict);
            self.emit_emcy(e, out);
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
        if let App::Drive(d) = &mut self.app {
            d.advance(period_s);
        }
        if self.faults.fault_at_sync == Some(count) && !self.fault_fired {
            self.fault_fired = true;
            let e = match &mut self.app {
                App::Drive(d) => d.fault(),
                App::Io(io) => io.fault(),
            };
            self.emit_emcy(Some(e), out);
        }
        let operational = self.nmt == NmtState::Operational;
        if let Some(values) = self.pending.take().filter(|_| operational) {
            self.store(&values, out);
        }
        if let App::Drive(d) = &mut self.app {
            d.settle(period_s, &self.dict);
        }
        self.publish();
        if operational {
            self.syncs_operational += 1;
            self.send_tpdo(out);
            let (target_counts, actual_counts, statusword) = match &self.app {
                App::Drive(d) => d.record(&self.dict),
                App::Io(_) => Io::record(&self.dict),
            };
            records.push(Record {
                sync: count,
                node: self.node.get(),
                target_counts,
                actual_counts,
                statusword,
            });
        }
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

    /// Writes the values the application produces into the dictionary.
    fn publish(&mut self) {
        match &self.app {
            App::Drive(d) => d.publish(&mut self.dict),
            App::Io(io) => io.publish(&mut self.dict),
        }
        if let (App::Io(_), Some(chain)) = (&self.app, self.faults.estop_chain) {
            let inputs = self.dict.get(od::DIGITAL_INPUTS, 1);
            let bit = 1 << (chain.bit & 7);
            let inputs = if chain.closed(self.last_sync) {
                inputs | bit
            } else {
                inputs & !bit
            };
            self.dict.set(od::DIGITAL_INPUTS, 1, inputs);
        }
    }
}
