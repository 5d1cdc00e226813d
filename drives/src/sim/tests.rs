//! Tests of the simulated drives, driven by a tiny scripted master built on the `wire`
//! encoders. [`Master`] holds the bus and a virtual clock; every call returns the frames the
//! drives sent in answer.

mod bus;
mod faults;
mod homing;
mod io;
mod robustness;
mod sdo;
mod session;
mod spindle;

use super::*;
use crate::wire::heartbeat;
use crate::wire::nmt::NmtCommand;
use crate::wire::pdo::{self, CspFeedback, RPDO1_CSP_MAPPING, TPDO1_CSP_MAPPING};
use crate::wire::sdo::{SdoData, SdoResponse, SdoValue};
use crate::wire::{sdo as wsdo, AbortCode};
use crate::{od, State};

pub const PERIOD: f64 = 0.001;

pub fn node(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

pub fn f(s: &str) -> CanFrame {
    s.parse().unwrap()
}

/// Frames as candump strings, for readable assertions.
pub fn text(frames: &[CanFrame]) -> Vec<String> {
    frames.iter().map(ToString::to_string).collect()
}

pub struct Master {
    pub bus: SimBus,
    pub now: f64,
    /// The SYNC period, [`PERIOD`] unless set otherwise.
    pub period: f64,
}

impl Master {
    pub fn new(nodes: Vec<SimNodeConfig>) -> Self {
        Self::with_period(nodes, PERIOD)
    }

    pub fn with_period(nodes: Vec<SimNodeConfig>, period: f64) -> Self {
        Self {
            bus: SimBus::new(nodes, period),
            now: 0.0,
            period,
        }
    }

    /// Healthy nodes without lag.
    pub fn with_nodes(ids: &[u8]) -> Self {
        Self::new(ids.iter().map(|&n| SimNodeConfig::new(node(n))).collect())
    }

    pub fn send(&mut self, frame: CanFrame) -> Vec<CanFrame> {
        let mut got = Vec::new();
        self.bus.on_frame(&frame, self.now, &mut |f| got.push(f));
        got
    }

    pub fn send_str(&mut self, frame: &str) -> Vec<String> {
        text(&self.send(f(frame)))
    }

    pub fn poll(&mut self) -> Vec<CanFrame> {
        let mut got = Vec::new();
        self.bus.poll(self.now, &mut |f| got.push(f));
        got
    }

    /// Lets `dt` seconds pass, polling every millisecond; returns what was sent meanwhile.
    pub fn wait(&mut self, dt: f64) -> Vec<CanFrame> {
        let end = self.now + dt;
        let mut got = Vec::new();
        while self.now + 1e-9 < end {
            self.now += PERIOD.min(end - self.now);
            got.extend(self.poll());
        }
        got
    }

    pub fn nmt(&mut self, cmd: NmtCommand, target: nmt::Target) -> Vec<CanFrame> {
        self.send(nmt::encode(cmd, target))
    }

    /// One period: the clock advances, the bus is polled, then SYNC is sent. Returns the
    /// frames of both.
    pub fn sync(&mut self) -> Vec<CanFrame> {
        self.now += self.period;
        let mut got = self.poll();
        got.extend(self.send(sync::encode()));
        got
    }

    /// The SDO answer of `n` among `frames`; panics (test only) if there is none.
    fn sdo_answer(n: NodeId, frames: &[CanFrame]) -> SdoResponse {
        let answers: Vec<_> = frames
            .iter()
            .filter_map(|fr| wsdo::decode_response(n, fr).ok())
            .collect();
        assert_eq!(answers.len(), 1, "SDO answers of node {n}: {frames:?}");
        answers[0]
    }

    pub fn sdo_write(
        &mut self,
        n: NodeId,
        index: u16,
        sub: u8,
        value: SdoValue,
    ) -> Result<(), AbortCode> {
        let got = self.send(wsdo::download_request(n, index, sub, value));
        match Self::sdo_answer(n, &got) {
            SdoResponse::DownloadAck { index: i, sub: s } if (i, s) == (index, sub) => Ok(()),
            SdoResponse::Abort {
                index: i,
                sub: s,
                code,
            } if (i, s) == (index, sub) => Err(code),
            other => panic!("unexpected answer to a download: {other:?}"),
        }
    }

    pub fn sdo_read(&mut self, n: NodeId, index: u16, sub: u8) -> Result<SdoData, AbortCode> {
        let got = self.send(wsdo::upload_request(n, index, sub));
        match Self::sdo_answer(n, &got) {
            SdoResponse::Uploaded {
                index: i,
                sub: s,
                data,
            } if (i, s) == (index, sub) => Ok(data),
            SdoResponse::Abort {
                index: i,
                sub: s,
                code,
            } if (i, s) == (index, sub) => Err(code),
            other => panic!("unexpected answer to an upload: {other:?}"),
        }
    }

    pub fn read_u32(&mut self, n: NodeId, index: u16, sub: u8) -> u32 {
        let data = self.sdo_read(n, index, sub).expect("upload");
        let mut bytes = [0; 4];
        bytes[..data.as_bytes().len()].copy_from_slice(data.as_bytes());
        u32::from_le_bytes(bytes)
    }

    /// Power-on: the first poll sends every node's boot-up.
    pub fn power_on(&mut self) -> Vec<CanFrame> {
        self.poll()
    }

    /// docs/canopen.md's PDO mapping procedure, step by step, every step acknowledged.
    pub fn map_csp(&mut self, n: NodeId) {
        self.map_pdos(n, &RPDO1_CSP_MAPPING, &TPDO1_CSP_MAPPING);
    }

    /// The mapping procedure for any mapping, transmission type 1 both ways.
    pub fn map_pdos(&mut self, n: NodeId, rpdo: &[u32], tpdo: &[u32]) {
        let steps = [
            (od::RPDO1_COMMUNICATION, od::RPDO1_MAPPING, rpdo, 0x200),
            (od::TPDO1_COMMUNICATION, od::TPDO1_MAPPING, tpdo, 0x180),
        ];
        for (comm, map, entries, base) in steps {
            let cob_id = u32::from(n.cob_id(base));
            let invalid = cob_id | od::PDO_COB_ID_INVALID;
            self.sdo_write(n, comm, 1, SdoValue::U32(invalid)).unwrap();
            self.sdo_write(n, map, 0, SdoValue::U8(0)).unwrap();
            for (sub, &entry) in (1..).zip(entries) {
                self.sdo_write(n, map, sub, SdoValue::U32(entry)).unwrap();
            }
            self.sdo_write(n, map, 0, SdoValue::U8(entries.len() as u8))
                .unwrap();
            self.sdo_write(n, comm, 2, SdoValue::U8(od::TRANSMISSION_EVERY_SYNC))
                .unwrap();
            self.sdo_write(n, comm, 1, SdoValue::U32(cob_id)).unwrap();
        }
    }

    /// Boots, selects CSP, maps the PDOs as docs/canopen.md says and starts every node.
    pub fn operational(&mut self, ids: &[u8]) {
        self.power_on();
        for &id in ids {
            let n = node(id);
            self.sdo_write(n, od::MODES_OF_OPERATION, 0, SdoValue::I8(8))
                .unwrap();
            self.map_csp(n);
        }
        self.nmt(NmtCommand::Start, nmt::Target::All);
    }

    /// Sends each node's RPDO, then SYNC; returns the TPDOs decoded, by node.
    pub fn cycle(&mut self, commands: &[(u8, u16, i32)]) -> Vec<(u8, CspFeedback)> {
        for &(id, controlword, target) in commands {
            self.send(pdo::rpdo1_csp(node(id), controlword, target));
        }
        self.sync()
            .iter()
            .filter_map(|fr| pdo::decode_tpdo1_csp(fr).ok())
            .map(|(n, fb)| (n.get(), fb))
            .collect()
    }

    /// Controlwords 0x06, 0x07, 0x0F by RPDO + SYNC with the target at the node's current
    /// position; returns the statuswords seen after each.
    pub fn enable(&mut self, id: u8) -> Vec<u16> {
        let (_, _, actual) = self.bus.node_state(node(id)).unwrap();
        [0x06, 0x07, 0x0F]
            .into_iter()
            .map(|cw| {
                let fb = self.cycle(&[(id, cw, actual)]);
                let (_, fb) = fb.into_iter().find(|(n, _)| *n == id).expect("a TPDO");
                fb.statusword
            })
            .collect()
    }

    pub fn drive_state(&self, id: u8) -> State {
        self.bus.node_state(node(id)).unwrap().1
    }

    /// A drive's actual position, counts.
    pub fn drive_state_position(&self, id: u8) -> i32 {
        self.bus.node_state(node(id)).unwrap().2
    }
}

/// Decodes the heartbeats among `frames` as `(node, state)`.
pub fn heartbeats(frames: &[CanFrame]) -> Vec<(u8, heartbeat::NmtState)> {
    frames
        .iter()
        .filter_map(|fr| heartbeat::decode(fr).ok())
        .map(|(n, s)| (n.get(), s))
        .collect()
}
