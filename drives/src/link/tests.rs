//! The links against each other and the socketpair.

use super::*;
use socketcan::{CanSocket, EmbeddedFrame, Id, Socket, StandardId};

fn f(s: &str) -> CanFrame {
    s.parse().expect("test vector")
}

#[test]
fn frames_cross_the_in_process_link_unchanged() {
    let (mut master, mut drives) = SocketLink::pair().unwrap();
    assert_eq!(drives.recv(), Ok(None));
    for v in [
        "000#0100",
        "080#",
        "605#2B40600006000000",
        "201#0F00A0860100",
        "7FF#0102030405060708",
    ] {
        assert_eq!(master.send(&f(v)), Ok(Sent::Queued));
    }
    for v in [
        "000#0100",
        "080#",
        "605#2B40600006000000",
        "201#0F00A0860100",
        "7FF#0102030405060708",
    ] {
        assert_eq!(drives.recv(), Ok(Some(f(v))));
    }
    assert_eq!(drives.recv(), Ok(None));
    assert_eq!(drives.send(&f("701#05")), Ok(Sent::Queued));
    assert_eq!(master.recv(), Ok(Some(f("701#05"))));
}

#[test]
fn a_full_queue_is_counted_not_fatal() {
    let (mut master, _drives) = SocketLink::pair().unwrap();
    let frame = f("080#");
    let mut sent = 0u64;
    // The socket buffer holds a few hundred frames; the rest are dropped and counted.
    for _ in 0..100_000 {
        if master.send(&frame) == Ok(Sent::Queued) {
            sent += 1;
        }
    }
    assert!(
        sent > 0 && master.dropped() > 0,
        "sent {sent}, dropped {}",
        master.dropped()
    );
    assert_eq!(sent + master.dropped(), 100_000);
}

#[test]
fn batches_cross_the_socketpair_unchanged_and_skip_what_canopen_does_not_use() {
    use nix::sys::socket::{socketpair, AddressFamily, SockFlag, SockType};
    let (a, b) = socketpair(
        AddressFamily::Unix,
        SockType::SeqPacket,
        None,
        SockFlag::SOCK_CLOEXEC,
    )
    .unwrap();
    // One end through socketcan directly, to send what SocketLink never sends.
    let raw = CanSocket::from(a);
    let mut link = SocketLink::from_fd(b).unwrap();
    let mut out = [f("080#"); 8];
    assert_eq!(link.recv_all(&mut out), Ok(0));
    let rtr = socketcan::CanFrame::new_remote(StandardId::new(0x181).unwrap(), 0).unwrap();
    let ext = socketcan::CanFrame::new(socketcan::ExtendedId::new(0x1234).unwrap(), &[1]).unwrap();
    let data = |v: &str| {
        let c = f(v);
        socketcan::CanFrame::new(StandardId::new(c.id()).unwrap(), c.data()).unwrap()
    };
    for fr in [
        data("181#3712A0860100"),
        rtr,
        data("701#05"),
        ext,
        data("081#0000"),
    ] {
        raw.write_frame(&fr).unwrap();
    }
    assert_eq!(link.recv_all(&mut out), Ok(3));
    assert_eq!(
        out[..3],
        [f("181#3712A0860100"), f("701#05"), f("081#0000")]
    );
    assert_eq!(link.skipped(), 2);
    // A batch sent in one call arrives whole and in order, and more than BATCH frames
    // are split across calls.
    let batch: Vec<CanFrame> = (0..BATCH as u16 + 7)
        .map(|i| CanFrame::new(0x200 + (i % 16), &i.to_le_bytes()).unwrap())
        .collect();
    assert_eq!(link.send_all(&batch), Ok(0));
    for want in &batch {
        let got = raw.read_frame().unwrap();
        assert_eq!(got.id(), Id::Standard(StandardId::new(want.id()).unwrap()));
        assert_eq!(got.data(), want.data());
    }
}

#[test]
fn a_full_queue_drops_and_counts_the_rest_of_a_batch() {
    let (mut master, mut drives) = SocketLink::pair().unwrap();
    let batch = [f("201#0F00A0860100"); 6];
    let mut queued = 0usize;
    let mut dropped = 0usize;
    for _ in 0..20_000 {
        let d = master.send_all(&batch).unwrap();
        dropped += d;
        queued += batch.len() - d;
    }
    assert!(
        queued > 0 && dropped > 0,
        "queued {queued}, dropped {dropped}"
    );
    assert_eq!(master.dropped() as usize, dropped);
    // Exactly the queued ones arrive.
    let mut out = [f("080#"); 64];
    let mut got = 0;
    loop {
        let n = drives.recv_all(&mut out).unwrap();
        if n == 0 {
            break;
        }
        got += n;
    }
    assert_eq!(got, queued);
}

#[test]
fn the_memory_link_carries_frames_in_order_and_counts_a_full_queue() {
    let (mut master, mut drives) = MemLink::pair(4);
    assert_eq!(drives.recv(), Ok(None));
    let seq = [
        "000#0100",
        "080#",
        "605#2B40600006000000",
        "201#0F00A0860100",
    ];
    for v in seq {
        assert_eq!(master.send(&f(v)), Ok(Sent::Queued));
    }
    assert_eq!(master.send(&f("7FF#01")), Ok(Sent::Dropped));
    assert_eq!(master.dropped(), 1);
    for v in seq {
        assert_eq!(drives.recv(), Ok(Some(f(v))));
    }
    assert_eq!(drives.recv(), Ok(None));
    assert_eq!(drives.send(&f("701#05")), Ok(Sent::Queued));
    assert_eq!(master.recv(), Ok(Some(f("701#05"))));
    // Across threads, every frame arrives once and in order.
    let (mut a, mut b) = MemLink::pair(16);
    let sender = std::thread::spawn(move || {
        for i in 0..10_000u32 {
            let frame = CanFrame::new(0x201, &i.to_le_bytes()).expect("valid frame");
            while a.send(&frame) != Ok(Sent::Queued) {
                std::thread::yield_now();
            }
        }
        a
    });
    let mut next = 0u32;
    while next < 10_000 {
        match b.recv() {
            Ok(Some(fr)) => {
                assert_eq!(fr.data(), &next.to_le_bytes());
                next += 1;
            }
            Ok(None) => std::thread::yield_now(),
            Err(e) => panic!("{e}"),
        }
    }
    sender.join().expect("the sending thread finishes");
}

#[test]
fn a_closed_memory_peer_is_an_error() {
    let (mut master, mut drives) = MemLink::pair(4);
    assert_eq!(drives.send(&f("701#05")), Ok(Sent::Queued));
    drop(drives);
    assert_eq!(master.send(&f("080#")), Err(LinkError::Closed));
    // What was sent before the peer left can still be read, then the link reports it.
    assert_eq!(master.recv(), Ok(Some(f("701#05"))));
    assert_eq!(master.recv(), Err(LinkError::Closed));
}

#[test]
fn a_closed_peer_is_an_error() {
    let (mut master, drives) = SocketLink::pair().unwrap();
    drop(drives);
    // Said at once, both ways (the assertion used to accept "nothing received" too).
    assert_eq!(master.recv(), Err(LinkError::Closed));
    assert_eq!(master.send(&f("080#")), Err(LinkError::Closed));
}

/// Two sockets on the real vcan0 of the PREEMPT_RT guest (tests/vcan/run): the kernel's
/// loopback hands every frame one socket sends to the other.
#[test]
#[ignore = "needs a SocketCAN interface: run by tests/vcan/run in the PREEMPT_RT guest"]
fn vcan_link_round_trip_on_a_real_interface() {
    let iface = std::env::var("DNURBS_VCAN").unwrap_or_else(|_| "vcan0".into());
    let mut a = SocketLink::open(&iface).expect("open the vcan interface");
    let mut b = SocketLink::open(&iface).expect("open the vcan interface twice");
    let seq = [
        "000#8200",
        "701#00",
        "601#2F60600008000000",
        "581#6060600000000000",
        "080#",
        "201#0F00A0860100",
        "181#3712A0860100",
    ];
    for v in seq {
        assert_eq!(a.send(&f(v)), Ok(Sent::Queued));
    }
    let mut got = Vec::new();
    for _ in 0..1000 {
        if let Ok(Some(fr)) = b.recv() {
            got.push(fr);
            if got.len() == seq.len() {
                break;
            }
        } else {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }
    assert_eq!(got, seq.map(f));
    // The same through the batched calls (sendmmsg / recvmmsg), as the master uses them.
    assert_eq!(a.send_all(&seq.map(f)), Ok(0));
    let mut buf = [f("080#"); 16];
    let mut got = Vec::new();
    for _ in 0..1000 {
        let n = b.recv_all(&mut buf).unwrap();
        got.extend_from_slice(&buf[..n]);
        if got.len() >= seq.len() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    assert_eq!(got, seq.map(f));
    // The sender does not receive its own frames (CAN_RAW_RECV_OWN_MSGS is off).
    assert_eq!(a.recv(), Ok(None));
    assert_eq!(a.recv_all(&mut buf), Ok(0));
}

/// An error frame as the kernel writes it: the flag and classes in the id, details in data.
fn error_frame(class: u32, crtl: u8) -> (u32, [u8; 8]) {
    (CAN_ERR_FLAG | class, [0, crtl, 0, 0, 0, 0, 0, 0])
}

#[test]
fn error_frames_are_counted_by_kind_and_data_frames_pass() {
    use super::errors::*;
    let (a, b) = SocketLink::pair().unwrap();
    let mut link = b;
    let send = |frames: &[super::mmsg::RawFrame]| {
        super::mmsg::sendmmsg(std::os::fd::AsRawFd::as_raw_fd(&a), frames).unwrap()
    };
    let raw = |(id, data): (u32, [u8; 8])| super::mmsg::RawFrame::raw(id, data);
    let frames = [
        raw(error_frame(ERR_CRTL, CRTL_TX_WARNING)),
        super::mmsg::RawFrame::from(&f("181#3712A0860100")),
        raw(error_frame(ERR_CRTL, CRTL_RX_PASSIVE | CRTL_RX_OVERFLOW)),
        raw(error_frame(ERR_BUSOFF | ERR_RESTARTED, 0)),
        raw(error_frame(ERR_TX_TIMEOUT, 0)),
        raw(error_frame(ERR_LOSTARB, 0)),
        raw(error_frame(ERR_PROT | ERR_BUSERROR, 0)),
        raw(error_frame(ERR_ACK, 0)),
        // An extended frame whose id has the bus-off bit: skipped, not an error.
        raw((0x8000_0040, [0; 8])),
    ];
    assert_eq!(send(&frames), frames.len());
    let mut out = [f("080#"); 16];
    assert_eq!(link.recv_all(&mut out), Ok(1));
    assert_eq!(out[0], f("181#3712A0860100"));
    let e = link.errors();
    assert_eq!(
        e,
        BusErrors {
            warning: 1,
            passive: 1,
            bus_off: 1,
            restarted: 1,
            tx_timeout: 1,
            lost_arbitration: 1,
            protocol: 2,
            overflow: 1,
        }
    );
    assert_eq!(e.total(), 9);
    assert_eq!(link.skipped(), 1);
    // The one-frame receive counts them the same way.
    let more = [raw(error_frame(ERR_BUSOFF, 0))];
    assert_eq!(send(&more), 1);
    assert_eq!(link.recv(), Ok(None));
    assert_eq!(link.errors().bus_off, 2);
    assert_eq!(link.errors().since(&e).bus_off, 1);
    assert_eq!(link.errors().since(&e).total(), 1);
}

#[test]
fn the_memory_link_meets_injected_faults_as_a_socket_would() {
    use super::errors::*;
    let (mut master, mut drives) = MemLink::pair(8);
    let faults = master.faults();
    let (id, data) = error_frame(ERR_CRTL, CRTL_TX_PASSIVE);
    faults.error_frame(id, data);
    assert_eq!(master.errors().passive, 1);
    assert_eq!(
        drives.errors().passive,
        1,
        "one interface: both ends see it"
    );
    faults.set_tx_full(true);
    assert_eq!(master.send(&f("080#")), Ok(Sent::Dropped));
    assert_eq!(master.send_all(&[f("080#"), f("080#")]), Ok(2));
    assert_eq!(master.dropped(), 3);
    faults.set_tx_full(false);
    assert_eq!(master.send(&f("080#")), Ok(Sent::Queued));
    faults.set_down(true);
    let down = Err(LinkError::Down(nix::libc::ENETDOWN));
    assert_eq!(master.send(&f("080#")), down);
    assert_eq!(drives.recv(), down.map(|_| None));
    assert_eq!(
        LinkError::Down(nix::libc::ENETDOWN).to_string(),
        "CAN interface down (ENETDOWN)"
    );
    faults.set_down(false);
    assert_eq!(drives.recv(), Ok(Some(f("080#"))));
}

#[test]
fn a_down_or_vanished_interface_is_told_apart_from_other_errors() {
    assert_eq!(
        LinkError::from_errno(nix::libc::ENETDOWN),
        LinkError::Down(nix::libc::ENETDOWN)
    );
    assert_eq!(
        LinkError::from_errno(nix::libc::ENODEV),
        LinkError::Down(nix::libc::ENODEV)
    );
    assert_eq!(
        LinkError::from_errno(nix::libc::EIO),
        LinkError::Os(nix::libc::EIO)
    );
    let io = std::io::Error::from_raw_os_error(nix::libc::ENETDOWN);
    assert_eq!(
        LinkError::from_io(&io),
        LinkError::Down(nix::libc::ENETDOWN)
    );
}
