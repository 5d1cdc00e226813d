//! The protocol layer must not touch the heap: a counting global allocator watches 100 000
//! cycles of a five-axis CSP bus simulated with the pure codecs (master sequencer and
//! drive models exchanging SYNC, RPDO1 and TPDO1 frames), plus SDO, NMT, heartbeat and EMCY
//! traffic, malformed frames, candump parsing and the `Display` of every error, written into
//! a stack buffer. It must see zero allocations, reallocations and frees.
//!
//! This file is its own test binary (with a single test), so no other test's allocations are
//! counted. The allocator is `test_support::CountingAlloc`, counting this test's thread only:
//! measured under `stress-ng --cpu 4`, counting every thread also caught the test
//! harness's own allocations (4 of them) when the run grew slow.

use core::fmt::Write;
use drives::wire::{self, emcy, heartbeat, nmt, pdo, sdo, sync, Received};
use drives::{classify, CanFrame, DriveModel, Goal, NodeId, Sequencer, State};

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

/// A `fmt::Write` into a fixed buffer that drops what does not fit.
struct StackText {
    buf: [u8; 256],
    len: usize,
}

impl Write for StackText {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        for (dst, src) in self.buf.iter_mut().skip(self.len).zip(s.bytes()) {
            *dst = src;
            self.len += 1;
        }
        Ok(())
    }
}

const AXES: usize = 5;
const CYCLES: u32 = 100_000;

/// One bus cycle: the master's SYNC and RPDOs, then the drives' TPDOs. Returns how many
/// drives report Operation enabled.
fn cycle(
    nodes: &[NodeId; AXES],
    seqs: &mut [Sequencer; AXES],
    drives: &mut [DriveModel; AXES],
    states: &mut [State; AXES],
    goal: Goal,
    t: u32,
) -> usize {
    let mut bus = [sync::encode(); 1 + 2 * AXES];
    for (i, node) in nodes.iter().enumerate() {
        let cw = seqs[i].step(states[i], goal);
        bus[1 + i] = pdo::rpdo1_csp(*node, cw.0, t as i32);
    }
    for i in 0..AXES {
        let rx = bus[1 + i];
        let (node, cmd) = pdo::decode_rpdo1_csp(&rx).expect("own RPDO");
        let sw = drives[i].apply(cmd.controlword);
        bus[1 + AXES + i] = pdo::tpdo1_csp(node, sw, cmd.target);
    }
    let mut enabled = 0;
    for frame in &bus {
        match classify(frame) {
            Received::Sync => assert_eq!(sync::decode(frame), Ok(None)),
            Received::Tpdo { n: 1, node } => {
                let (_, fb) = pdo::decode_tpdo1_csp(frame).expect("own TPDO");
                let i = usize::from(node.get() - 1);
                states[i] = State::from_statusword(fb.statusword).expect("valid statusword");
                enabled += usize::from(states[i] == State::OperationEnabled);
            }
            Received::Rpdo { n: 1, .. } => {}
            other => panic!("unexpected {other:?}"),
        }
    }
    enabled
}

fn other_services(node: NodeId, text: &mut StackText) {
    let f = sdo::download_request(node, 0x6060, 0, sdo::SdoValue::I8(8));
    let req = sdo::decode_request(node, &f).expect("own request");
    let sdo::SdoRequest::Download { index, sub, .. } = req else {
        panic!("download expected")
    };
    let ack = sdo::download_ack(node, index, sub);
    assert!(sdo::decode_response(node, &ack).is_ok());
    let data = sdo::SdoValue::U16(0x0237).data();
    let up = sdo::upload_response(node, 0x6041, 0, data);
    assert!(sdo::decode_response(node, &up).is_ok());
    let ab = sdo::abort(node, 0x2000, 0, wire::AbortCode::ObjectDoesNotExist);
    if let Ok(sdo::SdoResponse::Abort { code, .. }) = sdo::decode_response(node, &ab) {
        write!(text, "{code}").expect("stack text");
    }
    let f = nmt::encode(nmt::NmtCommand::Start, nmt::Target::All);
    assert!(nmt::decode(&f).is_ok());
    assert!(heartbeat::decode(&heartbeat::encode(node, heartbeat::NmtState::Operational)).is_ok());
    let e = emcy::Emcy {
        error_code: emcy::FOLLOWING_ERROR,
        error_register: 0x20,
        manufacturer: [0; 5],
    };
    write!(
        text,
        "{}",
        emcy::decode(&emcy::encode(node, &e)).expect("own EMCY").1
    )
    .expect("stack text");
    for s in [
        "585#4141600004000000",
        "185#3712",
        "705#85",
        "000#0305",
        "080#00",
    ] {
        let f: CanFrame = s.parse().expect("vector parses");
        write!(text, "{f}").expect("stack text");
        let err = match classify(&f) {
            Received::SdoResponse { node } => sdo::decode_response(node, &f).err(),
            Received::Tpdo { .. } => pdo::decode_tpdo1_csp(&f).err(),
            Received::Heartbeat { .. } => heartbeat::decode(&f).err(),
            Received::Nmt => nmt::decode(&f).err(),
            Received::Sync => sync::decode(&f).err(),
            _ => None,
        };
        write!(text, "{}", err.expect("malformed vector")).expect("stack text");
    }
    let bad = "7G1#05".parse::<CanFrame>().expect_err("bad id");
    write!(text, "{bad}").expect("stack text");
}

#[test]
fn protocol_layer_never_allocates() {
    let nodes: [NodeId; AXES] = core::array::from_fn(|i| NodeId::new(i as u8 + 1).expect("1..=5"));
    let mut seqs = [Sequencer::new(); AXES];
    let mut drives = [DriveModel::new(); AXES];
    let mut states = [State::NotReadyToSwitchOn; AXES];
    let mut text = StackText {
        buf: [0; 256],
        len: 0,
    };
    let mut enabled_cycles = 0u32;

    test_support::arm_this_thread();
    for t in 0..CYCLES {
        if t == CYCLES / 2 {
            drives[2].inject_fault();
        }
        for drive in &mut drives {
            drive.tick(); // self-test done, fault reaction done
        }
        let goal = if t < CYCLES - 10 {
            Goal::Enabled
        } else {
            Goal::Disabled
        };
        if cycle(&nodes, &mut seqs, &mut drives, &mut states, goal, t) == AXES {
            enabled_cycles += 1;
        }
        if t % 1000 == 0 {
            text.len = 0;
            other_services(nodes[t as usize % AXES], &mut text);
        }
    }
    let events = test_support::disarm_this_thread();

    assert_eq!(events, 0, "heap events in the protocol layer");
    assert!(
        enabled_cycles > CYCLES - 100,
        "{enabled_cycles} cycles fully enabled"
    );
    assert!(
        states.iter().all(|s| *s == State::SwitchOnDisabled),
        "{states:?}"
    );
    assert!(text.len > 0);
}
