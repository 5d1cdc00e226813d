//! Simulated CANopen slaves, the slave side of the bus, sans-I/O, for `dnurbs sim-drives`
//! and for testing the master without hardware: CiA-402 drives (the axes in cyclic
//! synchronous position and homing modes, the spindle in profile velocity mode) and CiA-401 digital I/O
//! modules (the coolant valves).
//!
//! A [`SimBus`] plays every configured node. It is pure: frames from the master go in through
//! [`SimBus::on_frame`], time through `now_s` arguments and [`SimBus::poll`], and frames to
//! the master come out through a closure; the process that runs it owns the socket. It is not
//! real-time code (it allocates), but no input makes it panic: malformed frames are ignored
//! or answered with the SDO abort the standard names.
//!
//! # Every node
//!
//! A node is a drive ([`Profile::Drive`], the default) or an I/O module ([`Profile::Io`],
//! [`SimNodeConfig::io`]); both have the same CiA-301 services:
//!
//! * **NMT.** At power-on a node is initialising; its boot-up message `0x700+node [00]` goes
//!   out at the next [`SimBus::poll`], and it enters pre-operational. Reset node and reset
//!   communication (0x81/0x82, to the node or to all) restore the defaults of the
//!   communication objects (0x1000..=0x1FFF), reset node those of the application objects
//!   too and restarts the application (see [Drives](#drives) and [I/O modules](#io-modules));
//!   the node is initialising again until the next poll sends a new boot-up. Start, stop and
//!   enter pre-operational switch the state. An initialising node ignores every frame.
//!   Heartbeats `0x700+node [state]` are sent every 0x1017 ms (0, the default, is off) from
//!   [`SimBus::poll`], the first one period after 0x1017 is written.
//! * **SDO server**, expedited transfers only, on 0x600+node -> 0x580+node, in
//!   pre-operational and operational (a stopped node does not answer). Requests that are not
//!   8 bytes long are ignored; segmented, block and unknown command specifiers are answered
//!   with 0x05040001.
//! * **PDOs**, in operational only. An RPDO on the COB-ID of 0x1400 sub 1 (while valid) is
//!   split per the *current* mapping of 0x1600 into the mapped objects; a frame whose length
//!   is not the mapping's is ignored and counted ([`NodeCounters::rpdo_length_errors`]).
//!   With a synchronous transmission type (0..=240) the values take effect at the next SYNC,
//!   with 0xFE/0xFF at once. At each SYNC (0x080, with or without counter), in this order: a
//!   drive's motor advances one period and its automatic transitions run; an injected fault
//!   fires; the pending RPDO values take effect (a controlword goes to
//!   [`DriveModel::apply`](crate::DriveModel::apply)); a drive decides what its motor does
//!   during the next period; the values the node produces (statusword, actual values,
//!   inputs) are updated. Then TPDO1 (while valid) carries the mapped objects' values:
//!   every n-th SYNC for transmission type n in 1..=240, at a SYNC where they changed for 0,
//!   0xFE and 0xFF. A [`Record`] of every SYNC in operational is kept, whether the TPDO is
//!   sent or not.
//!
//! # Drives
//!
//! * **Modes.** 0x6060 accepts 8 (cyclic synchronous position, CSP), 3 (profile
//!   velocity, PV) and 6 (homing, below); 0x6061 shows the value written; 0x6502 (supported
//!   drive modes) says 0xA4. In mode 0, the default, nothing moves.
//! * **Homing** (0x6061 = 6): methods 35/37 (the current position), 19 and 21 (the home
//!   switch, active on the positive or the negative side of its edge), 3 and 5 (the switch,
//!   then the index pulse), on the motor's [`HomeHardware`] (a switch at 0 and an index
//!   every 10 000 counts by default; a switch that is not wired is a homing error once the
//!   search has gone `search_limit` counts). 0x6098 refuses other methods. Started by the
//!   controlword's bit 4 in Operation enabled, interrupted by clearing it; statusword bits 12
//!   (attained), 13 (error) and 10 (at rest after either); the home point becomes 0x607C.
//!   The procedure is in `homing.rs`.
//!   Reset node restarts the state machine (Switch on disabled after the boot-up) and stops
//!   the motor where it stands, which becomes the target position.
//! * **Motor in CSP** (and modes other than 3): a first-order lag with time constant
//!   `lag_s`, advanced by `period_s` per SYNC: `actual += (demand - actual) * (1 -
//!   exp(-period_s / lag_s))`, the demand being the target that took effect at the previous
//!   SYNC (so with `lag_s = 0` the actual position equals the previous SYNC's target).
//!   Outside Operation enabled in mode 8 the demand is where the motor stands (so leaving
//!   mode 3 while turning stops the motor at once, a simplification). The velocity actual
//!   0x606C is the last period's distance over `period_s`, rounded. 0x60C2 is stored, not
//!   used: the motor runs on the `period_s` given to [`SimBus::new`].
//! * **Motor in PV** (0x6061 = 3): the velocity `v` (units/s) ramps toward a demand for
//!   `period_s` per SYNC, as the exact continuous profile: `|v|` grows at 0x6083 and shrinks
//!   at the deceleration below; a reversal (or a demand of 0) decelerates to 0 first, then
//!   accelerates; once at the demand `v` stays there. An acceleration or deceleration of 0
//!   does not limit the ramp: the velocity steps to the demand at the start of the period.
//!   The demand, fixed at the previous SYNC: in Operation enabled 0x60FF, decelerating at
//!   0x6084; in Quick stop active, Fault reaction active and Fault 0 at 0x6085 (a real
//!   drive's quick stop and fault reaction); in any other state 0 at 0x6084 (a disabled
//!   motor coasts; the simulation decelerates it at the profile deceleration instead).
//!   0x606C is `v` rounded (saturating); 0x6064 integrates `v` exactly (counts, the fraction
//!   kept internally), wrapping like an `i32` counter.
//! * **Statusword** (0x6041): [`DriveModel::statusword`](crate::DriveModel::statusword) with
//!   the bits of the mode. CSP (0x6060 = 8): bit 12 (target followed) in Operation enabled,
//!   bit 13 (following error) when `|0x607A - 0x6064| > 0x6065` at the SYNC (0x6065 = 0, the
//!   default, switches it off). PV (3): bit 10 (target reached) in Operation enabled once
//!   `|0x606C - 0x60FF| <= 0x606D` has held at every SYNC for 0x606E ms, counted in SYNC
//!   periods (the n-th SYNC after the first one in the window has held it `n * period_s`;
//!   with 0x606E = 0 the bit is set at the first); bit 12 (speed = 0) whenever 0x606C is 0,
//!   in every state. Mode 0: neither.
//!
//! # I/O modules
//!
//! A CiA-401 module has no CiA-402 state machine, no motor and none of the 0x6040.. objects.
//!
//! * **Outputs** 0x6200:01 (bit 0 = output 1) are set by RPDO1 (with a synchronous
//!   transmission type at the next SYNC, as a drive's) or by SDO (at once). The **inputs**
//!   0x6000:01 are wired back from the outputs, as the valves' position switches would
//!   report: they equal the outputs in effect at every moment, so the TPDO1 of the SYNC at
//!   which new outputs take effect already carries them.
//! * NMT stop switches the outputs to 0 (CiA-401's default error behaviour: outputs to their
//!   error value, 0); they stay 0 until written again. Reset node restores the default, 0,
//!   and clears an injected fault. Pre-operational keeps the outputs as they are.
//! * Its [`Record`]s have the outputs, the inputs and a statusword of 0;
//!   [`SimBus::io_outputs`] reads the outputs in effect, and [`SimBus::node_state`] (a
//!   drive's) is `None` for a module: use [`SimBus::nmt_state`].
//!
//! # Object dictionary
//!
//! Every node has the communication area; `node` is the node id.
//!
//! | index  | sub  | type | access | default                 | notes                                  |
//! |--------|------|------|--------|-------------------------|----------------------------------------|
//! | 0x1000 | 0    | U32  | ro     | 0x00020192, 0x00030191  | device type: CiA-402 servo drive; CiA-401 digital inputs and outputs |
//! | 0x1001 | 0    | U8   | ro     | 0                       | error register: 0x81 while faulted     |
//! | 0x1017 | 0    | U16  | rw     | 0                       | heartbeat producer time, ms            |
//! | 0x1400 | 0    | U8   | ro     | 2                       | RPDO1 communication                    |
//! |        | 1    | U32  | rw     | 0x200+node              | COB-ID, bit 31 = invalid               |
//! |        | 2    | U8   | rw     | 0xFF                    | transmission type                      |
//! | 0x1600 | 0    | U8   | rw     | 1                       | RPDO1 mapping: number of entries       |
//! |        | 1..8 | U32  | rw     | see below, 0...         | `index << 16 \| sub << 8 \| bits`        |
//! | 0x1800 | 0..2 |      |        | 2, 0x180+node, 0xFF     | TPDO1 communication, as 0x1400         |
//! | 0x1A00 | 0..8 |      |        | 1, see below, 0...      | TPDO1 mapping, as 0x1600               |
//!
//! A drive's default mapping entries are 0x60400010 (RPDO1: controlword) and 0x60410010
//! (TPDO1: statusword); its application objects (defaults restored by reset node):
//!
//! | index  | sub  | type | access | default                 | notes                                  |
//! |--------|------|------|--------|-------------------------|----------------------------------------|
//! | 0x6040 | 0    | U16  | rw     | 0                       | controlword; an SDO write applies it   |
//! | 0x6041 | 0    | U16  | ro     |                         | statusword                             |
//! | 0x6060 | 0    | I8   | rw     | 0                       | modes of operation: 8 (CSP), 3 (PV)    |
//! | 0x6061 | 0    | I8   | ro     | 0                       | modes of operation display = 0x6060    |
//! | 0x6064 | 0    | I32  | ro     | `initial_position`      | position actual value, counts          |
//! | 0x6065 | 0    | U32  | rw     | 0                       | following error window, 0 = off        |
//! | 0x606C | 0    | I32  | ro     | 0                       | velocity actual value, units/s         |
//! | 0x606D | 0    | U16  | rw     | 10                      | velocity window, units/s               |
//! | 0x606E | 0    | U16  | rw     | 0                       | velocity window time, ms               |
//! | 0x607A | 0    | I32  | rw     | position at (re)set     | target position, counts                |
//! | 0x6083 | 0    | U32  | rw     | 10000                   | profile acceleration, units/s², 0 = unlimited |
//! | 0x6084 | 0    | U32  | rw     | 10000                   | profile deceleration, units/s², 0 = unlimited |
//! | 0x6085 | 0    | U32  | rw     | 20000                   | quick stop deceleration, units/s², 0 = unlimited |
//! | 0x60C2 | 0..2 | U8, U8, I8 | ro, rw, rw | 2, 1, -3   | interpolation time period (1 ms)       |
//! | 0x60FF | 0    | I32  | rw     | 0                       | target velocity, units/s               |
//!
//! An I/O module's default mapping entries are 0x62000108 (RPDO1: outputs) and 0x60000108
//! (TPDO1: inputs); its application objects:
//!
//! | index  | sub  | type | access | default                 | notes                                  |
//! |--------|------|------|--------|-------------------------|----------------------------------------|
//! | 0x6000 | 0    | U8   | ro     | 1                       | digital inputs, 8 per sub-index        |
//! |        | 1    | U8   | ro     | 0                       | inputs 1..8 = the outputs in effect    |
//! | 0x6200 | 0    | U8   | ro     | 1                       | digital outputs, 8 per sub-index       |
//! |        | 1    | U8   | rw     | 0                       | outputs 1..8, bit 0 = output 1         |
//!
//! SDO aborts, the same for both, checked in this order: unknown index 0x06020000; unknown
//! sub-index 0x06090011; write to a read-only entry 0x06010002; data length not the type's (a
//! download without size indication counts as 4 bytes) 0x06070010; then per entry: 0x6060
//! other than 3 or 8 0x06090030; a mapping entry or count written while the PDO is valid,
//! or an entry while the count is not 0 (CiA-301's procedure: disable, count 0, entries,
//! count), 0x06010000; an entry that is not one of the direction's mappable objects with
//! its exact bit length, or a count enabling such an entry, 0x06040041 (a drive's RPDO
//! 0x6040, 0x607A, 0x60FF, TPDO 0x6041, 0x6064, 0x606C; an I/O module's RPDO 0x6200:01,
//! TPDO 0x6000:01); a count above 8 0x06090030; more than 64 mapped bits 0x06040042; a
//! valid COB-ID that is not 11 bits, is restricted by CiA-301 (or 0x080, the SYNC) or
//! differs from the current valid one 0x06090030; a transmission type of 241..=253
//! 0x06090030.
//!
//! # Faults ([`Faults`])
//!
//! * `fault_at_sync: Some(n)`: at SYNC `n` (counted by the bus from 1) the node faults
//!   once. A drive: [`DriveModel::inject_fault`](crate::DriveModel::inject_fault) (Fault
//!   reaction active in that SYNC's statusword, Fault from the next), EMCY `0x080+node` with
//!   error code 0x8611 (following error) and error register 0x81 (generic + manufacturer).
//!   The motor then stands still whatever the target in CSP, and decelerates to 0 at 0x6085
//!   in PV (a real drive's fault reaction). A fault reset (controlword bit 7 edge) clears it
//!   with EMCY 0x0000. An I/O module: EMCY with error code 0x5000 (device hardware) and
//!   error register 0x81; its outputs are forced to 0 and held there until reset node
//!   (RPDO and SDO writes are taken but 0x6200:01 reads 0), so its inputs read 0; there is
//!   no other way to clear the fault. EMCY is sent in pre-operational and operational only;
//!   a stopped node faults silently.
//! * `heartbeat_stops_at: Some(n)`: no heartbeat once the bus has seen `n` SYNCs.
//! * `never_boots`: the node stays initialising: no boot-up, no answers, no PDOs, no EMCY.
//! * `drop_every: Some(n)`: every n-th frame the node would send is lost (counted in
//!   [`NodeCounters::dropped`]); `Some(0)` drops nothing.
//! * `silent_from_sync: Some(n)`: from SYNC `n` on every frame the node would send is lost
//!   (counted in [`NodeCounters::dropped`]).
//! * `estop_chain`: an I/O module's input wired to an e-stop chain ([`EStopChain`]): it
//!   reads 1 while the chain is closed, 0 while it is open (a button pressed).
#![forbid(unsafe_code)]

mod dictionary;
mod drive;
mod homing;
mod io;
mod lockstep;
mod motor;
mod node;
mod tables;
#[cfg(test)]
mod tests;
mod thread;

use std::io::{self as stdio, Write};

use crate::cia402;
use crate::frame::CanFrame;
use crate::wire::heartbeat::NmtState;
use crate::wire::nmt::{self, Target};
use crate::wire::{cob, sync, NodeId};

pub use homing::{HomeHardware, METHODS as HOMING_METHODS};
pub use io::IO_FAULT_ERROR_CODE;
pub use lockstep::Lockstep;
pub use tables::{DEVICE_TYPE_IO, DEVICE_TYPE_SERVO};
pub use thread::SimThread;

use node::SimNode;

/// Error register (0x1001) while a node is faulted: bit 0 (generic, set with any error)
/// and bit 7 (manufacturer specific).
pub const FAULT_ERROR_REGISTER: u8 = 0x81;

/// What a simulated node is, beyond CiA-301.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Profile {
    /// A CiA-402 drive: an axis in CSP or a spindle in profile velocity mode.
    #[default]
    Drive,
    /// A CiA-401 module with 8 digital outputs and 8 digital inputs wired back from them.
    Io,
}

/// One simulated node.
#[derive(Clone, Debug, PartialEq)]
pub struct SimNodeConfig {
    pub node: NodeId,
    pub profile: Profile,
    /// First-order lag of the motor model in CSP: actual position moves toward the target
    /// with this time constant (s); 0 = actual equals the target of the previous SYNC.
    /// Drives only.
    pub lag_s: f64,
    /// Position at power-on, counts. Drives only.
    pub initial_position: i32,
    /// The home switch and the index homing mode finds. Drives only.
    pub home: HomeHardware,
    pub faults: Faults,
}

impl SimNodeConfig {
    /// A healthy drive without lag at position 0.
    pub fn new(node: NodeId) -> Self {
        Self {
            node,
            profile: Profile::Drive,
            lag_s: 0.0,
            initial_position: 0,
            home: HomeHardware::default(),
            faults: Faults::default(),
        }
    }

    /// A healthy CiA-401 I/O module.
    pub fn io(node: NodeId) -> Self {
        Self {
            profile: Profile::Io,
            ..Self::new(node)
        }
    }
}

/// Faults to inject, as a master sees them (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Faults {
    /// A fault at this SYNC count: a drive's EMCY 0x8611 (following error) and statusword
    /// Fault, an I/O module's EMCY 0x5000 (device hardware) and outputs off.
    pub fault_at_sync: Option<u64>,
    /// Stop producing heartbeats after this SYNC count.
    pub heartbeat_stops_at: Option<u64>,
    /// The node stays silent: no boot-up, no SDO answers, no PDOs.
    pub never_boots: bool,
    /// Drop every n-th frame this node would send.
    pub drop_every: Option<u32>,
    /// From this SYNC count on, drop every frame this node would send (a broken cable or a
    /// dead transceiver): the master must notice missing feedback and heartbeats.
    pub silent_from_sync: Option<u64>,
    /// Writes of this object (index, sub) are acknowledged and not kept: a drive that keeps
    /// its own value, which only reading it back finds.
    pub keeps_object: Option<(u16, u8)>,
    /// An I/O module's input wired to an e-stop chain: that bit of 0x6000:01 reads 1 (the
    /// chain closed) but from SYNC `opens` up to SYNC `closes` (not included), where it
    /// reads 0 (a button pressed, then released).
    pub estop_chain: Option<EStopChain>,
}

/// An e-stop chain on an input of a simulated I/O module ([`Faults::estop_chain`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EStopChain {
    /// The input bit, 0..=7.
    pub bit: u8,
    pub opens: Option<u64>,
    pub closes: Option<u64>,
}

impl EStopChain {
    /// The chain is closed at SYNC `sync`.
    pub fn closed(&self, sync: u64) -> bool {
        let opened = self.opens.is_some_and(|o| sync >= o);
        let closed_again = self.closes.is_some_and(|c| sync >= c);
        !opened || closed_again
    }
}

/// One node at one SYNC in operational: the target that took effect and what the node
/// reported (whether or not its TPDO was sent). The columns depend on what the node is:
///
/// | node                          | `target_counts`       | `actual_counts`         | `statusword` |
/// |-------------------------------|-----------------------|-------------------------|--------------|
/// | drive, 0x6061 other than 3    | target position 0x607A| position actual 0x6064  | 0x6041       |
/// | drive, profile velocity (3)   | target velocity 0x60FF| velocity actual 0x606C  | 0x6041       |
/// | I/O module                    | outputs 0x6200:01     | inputs 0x6000:01        | 0            |
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Record {
    pub sync: u64,
    pub node: u8,
    pub target_counts: i32,
    pub actual_counts: i32,
    pub statusword: u16,
}

/// What a node ignored or lost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NodeCounters {
    /// RPDOs whose length did not match the current mapping.
    pub rpdo_length_errors: u64,
    /// Frames lost to [`Faults::drop_every`].
    pub dropped: u64,
}

/// Every simulated node on one bus.
#[derive(Debug)]
pub struct SimBus {
    nodes: Vec<SimNode>,
    period_s: f64,
    syncs: u64,
    records: Vec<Record>,
}

impl SimBus {
    /// The nodes at power-on. A node id configured twice is kept once (the first).
    pub fn new(nodes: Vec<SimNodeConfig>, period_s: f64) -> SimBus {
        let mut sims: Vec<SimNode> = Vec::with_capacity(nodes.len());
        for config in nodes {
            if sims.iter().all(|n| n.id() != config.node) {
                sims.push(SimNode::new(config));
            }
        }
        SimBus {
            nodes: sims,
            period_s,
            syncs: 0,
            records: Vec::new(),
        }
    }

    /// A frame arrived from the bus (from the master).
    pub fn on_frame(&mut self, frame: &CanFrame, now_s: f64, out: &mut dyn FnMut(CanFrame)) {
        match frame.id() {
            cob::NMT => {
                let Ok((cmd, target)) = nmt::decode(frame) else {
                    return;
                };
                for node in &mut self.nodes {
                    if target == Target::All || target == Target::Node(node.id()) {
                        node.on_nmt(cmd);
                    }
                }
            }
            cob::SYNC => {
                if sync::decode(frame).is_err() {
                    return;
                }
                self.syncs += 1;
                for node in &mut self.nodes {
                    node.on_sync(self.syncs, self.period_s, &mut self.records, out);
                }
            }
            _ => {
                for node in &mut self.nodes {
                    node.on_frame(frame, now_s, out);
                }
            }
        }
    }

    /// Time passed: heartbeats, delayed boot-up messages.
    pub fn poll(&mut self, now_s: f64, out: &mut dyn FnMut(CanFrame)) {
        for node in &mut self.nodes {
            node.poll(now_s, self.syncs, out);
        }
    }

    /// SYNCs seen so far.
    pub fn syncs(&self) -> u64 {
        self.syncs
    }

    pub fn records(&self) -> &[Record] {
        &self.records
    }

    /// Hands the records over and starts a new list (for a long-running simulation that
    /// writes them out as it goes).
    pub fn take_records(&mut self) -> Vec<Record> {
        std::mem::take(&mut self.records)
    }

    /// The records as CSV with the header `sync,node,target_counts,actual_counts,statusword`,
    /// all columns decimal.
    pub fn write_records(&self, w: &mut impl Write) -> stdio::Result<()> {
        writeln!(w, "sync,node,target_counts,actual_counts,statusword")?;
        for r in &self.records {
            writeln!(
                w,
                "{},{},{},{},{}",
                r.sync, r.node, r.target_counts, r.actual_counts, r.statusword
            )?;
        }
        Ok(())
    }

    /// A drive's NMT state ([`NmtState::BootUp`] while initialising), drive state and actual
    /// position; `None` for a node that is not simulated and for an I/O module, which has
    /// no drive state (see [`SimBus::nmt_state`] and [`SimBus::io_outputs`]).
    pub fn node_state(&self, node: NodeId) -> Option<(NmtState, cia402::State, i32)> {
        self.node(node).and_then(SimNode::drive_state)
    }

    /// Any node's NMT state ([`NmtState::BootUp`] while initialising); `None` for a node
    /// that is not simulated.
    pub fn nmt_state(&self, node: NodeId) -> Option<NmtState> {
        self.node(node).map(SimNode::nmt_state)
    }

    /// An I/O module's outputs in effect (0x6200:01, bit 0 = output 1; its inputs read the
    /// same); `None` for a node that is not simulated and for a drive.
    pub fn io_outputs(&self, node: NodeId) -> Option<u8> {
        self.node(node).and_then(SimNode::io_outputs)
    }

    /// Object `index:sub` of a node's dictionary (raw bits); `None` for a node that is not
    /// simulated or an object it does not have.
    pub fn object(&self, node: NodeId, index: u16, sub: u8) -> Option<u32> {
        self.node(node).and_then(|n| n.object(index, sub))
    }

    /// What a node ignored or lost.
    pub fn counters(&self, node: NodeId) -> Option<NodeCounters> {
        self.node(node).map(SimNode::counters)
    }

    fn node(&self, node: NodeId) -> Option<&SimNode> {
        self.nodes.iter().find(|n| n.id() == node)
    }
}
