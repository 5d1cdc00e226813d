//! A spindle drive in profile velocity mode (0x6060 = 3), configured as the master will:
//! ramps, reversal, quick stop, fault reaction, the velocity window (statusword bit 10),
//! speed = 0 (bit 12), and the dictionary's PV objects. The expected velocities come from
//! the continuous trapezoidal profile, computed here from the ramp parameters, not from the
//! simulation's code.

use super::*;
use crate::wire::emcy;
use crate::wire::heartbeat::NmtState;
use crate::wire::pdo::{RPDO1_PV_MAPPING, TPDO1_PV_MAPPING};

/// The spindle's SYNC period.
const P: f64 = 0.002;
const ID: u8 = 3;

const TARGET_REACHED: u16 = 1 << 10;
const SPEED_ZERO: u16 = 1 << 12;

/// Ramp and window parameters, as the master writes them.
#[derive(Clone, Copy)]
struct Params {
    accel: u32,
    decel: u32,
    quick: u32,
    window: u16,
    window_ms: u16,
}

const PARAMS: Params = Params {
    accel: 8000,
    decel: 10_000,
    quick: 20_000,
    window: 100,
    window_ms: 20,
};

fn spindle(config: SimNodeConfig, params: Params) -> Master {
    let mut m = Master::with_period(vec![config], P);
    m.power_on();
    configure(&mut m, node(ID), params);
    m
}

/// The master's set-up of a spindle, step by step: mode 3 read back, the PV mapping,
/// ramps, window, heartbeat, one read of the velocity, NMT start.
fn configure(m: &mut Master, n: NodeId, p: Params) {
    m.sdo_write(n, od::MODES_OF_OPERATION, 0, SdoValue::I8(3))
        .unwrap();
    let display = m.sdo_read(n, od::MODES_OF_OPERATION_DISPLAY, 0).unwrap();
    assert_eq!(display.to_i8(), Some(3));
    m.map_pdos(n, &RPDO1_PV_MAPPING, &TPDO1_PV_MAPPING);
    for (index, value) in [
        (od::PROFILE_ACCELERATION, p.accel),
        (od::PROFILE_DECELERATION, p.decel),
        (od::QUICK_STOP_DECELERATION, p.quick),
    ] {
        m.sdo_write(n, index, 0, SdoValue::U32(value)).unwrap();
    }
    m.sdo_write(n, od::VELOCITY_WINDOW, 0, SdoValue::U16(p.window))
        .unwrap();
    m.sdo_write(n, od::VELOCITY_WINDOW_TIME, 0, SdoValue::U16(p.window_ms))
        .unwrap();
    m.sdo_write(n, od::HEARTBEAT_PRODUCER, 0, SdoValue::U16(100))
        .unwrap();
    assert_eq!(m.read_u32(n, od::VELOCITY_ACTUAL, 0), 0);
    m.nmt(NmtCommand::Start, nmt::Target::Node(n));
}

/// One cycle: RPDO1 (controlword, target velocity) and SYNC; the TPDO1 as
/// `(statusword, velocity actual)`.
fn step(m: &mut Master, controlword: u16, velocity: i32) -> (u16, i32) {
    let fb = m.cycle(&[(ID, controlword, velocity)]);
    assert_eq!(fb.len(), 1, "one TPDO1 per SYNC");
    (fb[0].1.statusword, fb[0].1.actual)
}

/// Shutdown, Switch on, Enable operation at target velocity 0; then `rest` cycles at rest.
fn enable(m: &mut Master, rest: usize) -> Vec<u16> {
    let mut statuswords: Vec<u16> = [0x06, 0x07, 0x0F]
        .into_iter()
        .map(|cw| step(m, cw, 0).0)
        .collect();
    statuswords.extend((0..rest).map(|_| step(m, 0x0F, 0).0));
    assert_eq!(m.drive_state(ID), State::OperationEnabled);
    statuswords
}

/// The velocity `t` seconds after a ramp starting at `v0` toward `target` began: |v|
/// shrinks at `decel` (through 0 first when reversing) and grows at `accel`.
fn profile(v0: f64, target: f64, accel: f64, decel: f64, t: f64) -> f64 {
    if v0 != 0.0 && v0.signum() != target.signum() {
        let stop = v0.abs() / decel;
        if t <= stop {
            return v0 - v0.signum() * decel * t;
        }
        return profile(0.0, target, accel, decel, t - stop);
    }
    let rate = if target.abs() > v0.abs() {
        accel
    } else {
        decel
    };
    let v = v0 + (target - v0).signum() * rate * t;
    if (target - v0) * (target - v) <= 0.0 {
        target
    } else {
        v
    }
}

/// Runs `cycles` at `(controlword, velocity)`; the TPDO1s, the first being the SYNC at
/// which the command takes effect.
fn run(m: &mut Master, cycles: usize, controlword: u16, velocity: i32) -> Vec<(u16, i32)> {
    (0..cycles)
        .map(|_| step(m, controlword, velocity))
        .collect()
}

#[test]
fn pv_ramps_up_at_the_profile_acceleration() {
    let mut m = spindle(SimNodeConfig::new(node(ID)), PARAMS);
    let statuswords = enable(&mut m, 20);
    assert_eq!(
        &statuswords[..3],
        [0x1221, 0x1233, 0x1237],
        "ready, switched on, enabled; speed = 0 throughout"
    );
    assert_eq!(
        statuswords[3..].last().map(|s| s & TARGET_REACHED),
        Some(TARGET_REACHED),
        "at rest on target 0 for 20 ms"
    );

    let skip = m.bus.records().len();
    let start_sync = m.bus.syncs() + 1;
    let fb = run(&mut m, 800, 0x0F, 12_000);
    for (k, &(_, v)) in fb.iter().enumerate() {
        let expected = (8000.0 * k as f64 * P).min(12_000.0);
        assert!(
            (f64::from(v) - expected).abs() <= 1.0,
            "SYNC +{k}: {v}, not {expected}"
        );
    }
    let reached = fb.iter().position(|&(_, v)| v == 12_000).unwrap();
    let time = reached as f64 * P;
    assert!(
        (time - 1.5).abs() <= P + 1e-9,
        "12000 reached after {time} s"
    );

    // Bit 10: clear from the new target on, set once the velocity has been within 100 of
    // it for 20 ms (10 periods), and then on.
    let first_in = fb
        .iter()
        .position(|&(_, v)| (v - 12_000).abs() <= 100)
        .unwrap();
    assert_eq!(first_in, 744, "11904 is the first velocity in the window");
    for (k, &(sw, _)) in fb.iter().enumerate() {
        let expected = if k >= first_in + 10 {
            TARGET_REACHED
        } else {
            0
        };
        assert_eq!(sw & TARGET_REACHED, expected, "bit 10 at SYNC +{k}");
        let zero = if k == 0 { SPEED_ZERO } else { 0 };
        assert_eq!(sw & SPEED_ZERO, zero, "bit 12 at SYNC +{k}");
        assert_eq!(sw & 0x6F, 0x27, "Operation enabled");
    }

    // The records carry the velocities; the position integrates them: 9000 counts of ramp
    // (1.5 s at a mean of 6000), then 12000 per second.
    let records = &m.bus.records()[skip..];
    assert_eq!(records.len(), 800);
    for (k, r) in records.iter().enumerate() {
        assert_eq!(r.sync, start_sync + k as u64);
        assert_eq!((r.target_counts, r.actual_counts), (12_000, fb[k].1));
        assert_eq!(r.statusword, fb[k].0);
    }
    let position = 9000.0 + 12_000.0 * (799.0 * P - 1.5);
    let (_, _, actual) = m.bus.node_state(node(ID)).unwrap();
    assert!((f64::from(actual) - position).abs() <= 1.0, "{actual}");
    assert_eq!(m.read_u32(node(ID), od::POSITION_ACTUAL, 0) as i32, actual);
}

#[test]
fn reversing_decelerates_to_zero_then_accelerates() {
    // 30000/s does not divide the 4000 into whole periods: the zero crossing falls
    // between two SYNCs.
    let params = Params {
        decel: 30_000,
        ..PARAMS
    };
    let mut m = spindle(SimNodeConfig::new(node(ID)), params);
    enable(&mut m, 0);
    let fb = run(&mut m, 300, 0x0F, 4000);
    assert_eq!(fb[250].1, 4000, "8000/s: 0.5 s to 4000");
    let fb = run(&mut m, 400, 0x0F, -4000);
    for (k, &(sw, v)) in fb.iter().enumerate() {
        let expected = profile(4000.0, -4000.0, 8000.0, 30_000.0, k as f64 * P);
        assert!(
            (f64::from(v) - expected).abs() <= 1.0,
            "SYNC +{k}: {v}, not {expected}"
        );
        assert_eq!(sw & SPEED_ZERO != 0, v == 0, "bit 12 at SYNC +{k} ({v})");
    }
    // 4000/30000 s down, then 0.5 s up: -4000 at 0.6333 s, SYNC +317.
    let reached = fb.iter().position(|&(_, v)| v == -4000).unwrap();
    assert_eq!(reached, 317);
    // The position integrates both ramps: 0.5 s up to 4000 and 0.1 s at 4000 (300 periods)
    // forward, then down to 0, up to -4000 and 399 periods in all.
    let stop = 4000.0 / 30_000.0;
    let forward = 4000.0 * 0.5 / 2.0 + 4000.0 * (300.0 * P - 0.5);
    let back = 4000.0 * stop / 2.0 - 4000.0 * 0.5 / 2.0 - 4000.0 * (399.0 * P - stop - 0.5);
    let (_, _, position) = m.bus.node_state(node(ID)).unwrap();
    let expected = forward + back;
    assert!(
        (f64::from(position) - expected).abs() <= 1.0,
        "{position} vs {expected}"
    );
}

#[test]
fn quick_stop_decelerates_at_0x6085_and_disable_at_0x6084() {
    let params = Params {
        decel: 12_000,
        quick: 24_000,
        ..PARAMS
    };
    let mut m = spindle(SimNodeConfig::new(node(ID)), params);
    enable(&mut m, 0);
    run(&mut m, 400, 0x0F, 6000);
    // Quick stop (0x02) with the target still 6000: 48 per period down to 0.
    let fb = run(&mut m, 140, 0x02, 6000);
    assert_eq!(m.drive_state(ID), State::QuickStopActive);
    for (k, &(sw, v)) in fb.iter().enumerate() {
        assert_eq!(v, (6000 - 48 * k as i32).max(0), "SYNC +{k}");
        assert_eq!(sw & 0x6F, 0x07, "Quick stop active");
        assert_eq!(sw & TARGET_REACHED, 0, "only in Operation enabled");
    }
    assert_eq!(fb[125].0 & SPEED_ZERO, SPEED_ZERO);

    // Back to Operation enabled (16), up to 6000 again, then Disable operation (0x07):
    // Switched on, down at the profile deceleration, 24 per period.
    run(&mut m, 400, 0x0F, 6000);
    let fb = run(&mut m, 260, 0x07, 6000);
    assert_eq!(m.drive_state(ID), State::SwitchedOn);
    for (k, &(_, v)) in fb.iter().enumerate() {
        assert_eq!(v, (6000 - 24 * k as i32).max(0), "SYNC +{k}");
    }
}

#[test]
fn a_fault_decelerates_at_the_quick_stop_deceleration() {
    let config = SimNodeConfig {
        faults: Faults {
            fault_at_sync: Some(400),
            ..Faults::default()
        },
        ..SimNodeConfig::new(node(ID))
    };
    let mut m = spindle(config, PARAMS);
    enable(&mut m, 0);
    run(&mut m, 396, 0x0F, 3000);
    assert_eq!(m.bus.syncs(), 399);
    let got = m.cycle(&[]);
    assert_eq!(got.len(), 1);
    let frames = m.send(pdo::rpdo1_csp(node(ID), 0x0F, 3000));
    assert!(frames.is_empty());
    // SYNC 401 and on: Fault; 40 per period (20000/s) down from 3000.
    let mut velocities = Vec::new();
    for _ in 0..100 {
        let got = m.sync();
        let (_, fb) = pdo::decode_tpdo1_csp(got.last().unwrap()).unwrap();
        assert_eq!(fb.statusword & 0x4F, 0x08, "Fault");
        velocities.push(fb.actual);
    }
    for (k, v) in velocities.iter().enumerate() {
        assert_eq!(*v, (3000 - 40 * (k as i32 + 1)).max(0), "SYNC {}", 401 + k);
    }
    assert_eq!(m.read_u32(node(ID), 0x1001, 0), 0x81);
}

#[test]
fn the_fault_sends_its_emcy_at_the_sync() {
    let config = SimNodeConfig {
        faults: Faults {
            fault_at_sync: Some(5),
            ..Faults::default()
        },
        ..SimNodeConfig::new(node(ID))
    };
    let mut m = spindle(config, PARAMS);
    enable(&mut m, 1);
    let got = m.sync();
    let (n, e) = got.iter().find_map(|fr| emcy::decode(fr).ok()).unwrap();
    assert_eq!(
        (n, e.error_code, e.error_register),
        (node(ID), 0x8611, 0x81)
    );
}

#[test]
fn zero_ramps_step_and_the_position_wraps() {
    let params = Params {
        accel: 0,
        decel: 0,
        ..PARAMS
    };
    let config = SimNodeConfig {
        initial_position: i32::MAX - 100,
        ..SimNodeConfig::new(node(ID))
    };
    let mut m = spindle(config, params);
    enable(&mut m, 0);
    let fb = run(&mut m, 3, 0x0F, 100_000);
    assert_eq!(
        fb.iter().map(|f| f.1).collect::<Vec<_>>(),
        [0, 100_000, 100_000]
    );
    // Two periods of 200 counts past i32::MAX - 100.
    assert_eq!(m.bus.node_state(node(ID)).unwrap().2, i32::MIN + 299);
    let fb = run(&mut m, 2, 0x0F, -5);
    assert_eq!((fb[0].1, fb[1].1), (100_000, -5), "and back at once");
}

#[test]
fn pv_objects_in_the_dictionary() {
    let mut m = Master::with_period(vec![SimNodeConfig::new(node(ID))], P);
    m.power_on();
    let n = node(ID);
    let defaults: [(u16, usize, u32); 7] = [
        (od::VELOCITY_ACTUAL, 4, 0),
        (od::VELOCITY_WINDOW, 2, 10),
        (od::VELOCITY_WINDOW_TIME, 2, 0),
        (od::PROFILE_ACCELERATION, 4, 10_000),
        (od::PROFILE_DECELERATION, 4, 10_000),
        (od::QUICK_STOP_DECELERATION, 4, 20_000),
        (od::TARGET_VELOCITY, 4, 0),
    ];
    let check_defaults = |m: &mut Master| {
        for (index, len, value) in defaults {
            let data = m.sdo_read(n, index, 0).unwrap();
            assert_eq!(data.as_bytes().len(), len, "{index:04X}");
            assert_eq!(m.read_u32(n, index, 0), value, "{index:04X}");
        }
    };
    check_defaults(&mut m);

    // Mode 3 is taken and shown; 1 (profile position) is not, nor is the display changed.
    m.sdo_write(n, od::MODES_OF_OPERATION, 0, SdoValue::I8(3))
        .unwrap();
    assert_eq!(m.read_u32(n, od::MODES_OF_OPERATION_DISPLAY, 0), 3);
    let write = |m: &mut Master, index, sub, value| m.sdo_write(n, index, sub, value);
    assert_eq!(
        write(&mut m, od::MODES_OF_OPERATION, 0, SdoValue::I8(1)),
        Err(AbortCode::ValueRangeExceeded)
    );
    assert_eq!(m.read_u32(n, od::MODES_OF_OPERATION_DISPLAY, 0), 3);
    // Velocity actual is read-only; the window is 16 bits, the target 32.
    assert_eq!(
        write(&mut m, od::VELOCITY_ACTUAL, 0, SdoValue::I32(5)),
        Err(AbortCode::WriteReadOnly)
    );
    assert_eq!(
        write(&mut m, od::VELOCITY_WINDOW, 0, SdoValue::U32(5)),
        Err(AbortCode::LengthMismatch)
    );
    assert_eq!(
        write(&mut m, od::TARGET_VELOCITY, 1, SdoValue::I32(5)),
        Err(AbortCode::SubIndexDoesNotExist)
    );
    write(&mut m, od::TARGET_VELOCITY, 0, SdoValue::I32(-7)).unwrap();
    assert_eq!(m.read_u32(n, od::TARGET_VELOCITY, 0) as i32, -7);
    write(&mut m, od::PROFILE_ACCELERATION, 0, SdoValue::U32(1)).unwrap();

    // Mapping: velocity actual only into the TPDO, target velocity only into the RPDO,
    // each with 32 bits; the target position stays mappable next to the PV objects.
    write(&mut m, 0x1400, 1, SdoValue::U32(0x8000_0203)).unwrap();
    write(&mut m, 0x1600, 0, SdoValue::U8(0)).unwrap();
    for entry in [0x606C_0020, 0x60FF_0010, 0x6083_0020, 0x606D_0010] {
        assert_eq!(
            write(&mut m, 0x1600, 1, SdoValue::U32(entry)),
            Err(AbortCode::CannotMapToPdo),
            "RPDO {entry:08X}"
        );
    }
    for (sub, entry) in [(1, 0x60FF_0020), (2, 0x607A_0020)] {
        write(&mut m, 0x1600, sub, SdoValue::U32(entry)).unwrap();
    }
    write(&mut m, 0x1600, 0, SdoValue::U8(2)).unwrap();
    write(&mut m, 0x1800, 1, SdoValue::U32(0x8000_0183)).unwrap();
    write(&mut m, 0x1A00, 0, SdoValue::U8(0)).unwrap();
    for entry in [0x60FF_0020, 0x606C_0010] {
        assert_eq!(
            write(&mut m, 0x1A00, 1, SdoValue::U32(entry)),
            Err(AbortCode::CannotMapToPdo),
            "TPDO {entry:08X}"
        );
    }
    write(&mut m, 0x1A00, 1, SdoValue::U32(0x606C_0020)).unwrap();

    // Reset node restores the application's defaults.
    m.send_str("000#8103");
    m.poll();
    check_defaults(&mut m);
    assert_eq!(m.read_u32(n, od::MODES_OF_OPERATION_DISPLAY, 0), 0);
    assert_eq!(m.bus.nmt_state(n), Some(NmtState::PreOperational));
}

#[test]
fn the_master_sequence_as_candump_vectors() {
    let mut m = spindle(SimNodeConfig::new(node(ID)), PARAMS);
    assert_eq!(m.send_str("203#060000000000"), Vec::<String>::new());
    assert_eq!(m.send_str("080#"), ["183#211200000000"]);
    m.send_str("203#070000000000");
    assert_eq!(m.send_str("080#"), ["183#331200000000"]);
    // Enable operation with 1000 units/s: 16 per period from the next SYNC.
    m.send_str("203#0F00E8030000");
    assert_eq!(m.send_str("080#"), ["183#371200000000"]);
    m.send_str("203#0F00E8030000");
    assert_eq!(m.send_str("080#"), ["183#370210000000"]);
}

#[test]
fn absurd_pv_parameters_do_not_panic() {
    let extremes = Params {
        accel: u32::MAX,
        decel: 1,
        quick: 0,
        window: u16::MAX,
        window_ms: u16::MAX,
    };
    for period in [f64::NAN, -0.001, 0.0, 1e-300, f64::INFINITY, f64::MAX] {
        for params in [PARAMS, extremes] {
            let config = SimNodeConfig {
                initial_position: i32::MIN,
                ..SimNodeConfig::new(node(ID))
            };
            let mut m = Master {
                bus: SimBus::new(vec![config], period),
                now: 0.0,
                period: PERIOD,
            };
            m.power_on();
            configure(&mut m, node(ID), params);
            enable(&mut m, 0);
            for k in 0..30 {
                let v = [i32::MAX, i32::MIN, 0][k % 3];
                let cw = [0x0F, 0x02, 0x0F, 0x07, 0x0F][k % 5];
                m.cycle(&[(ID, cw, v)]);
            }
            m.sdo_write(node(ID), od::MODES_OF_OPERATION, 0, SdoValue::I8(8))
                .unwrap();
            m.cycle(&[(ID, 0x0F, i32::MAX)]);
        }
    }
}
