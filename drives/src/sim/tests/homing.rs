//! Homing mode (6): each method the simulated drive offers, as a master drives it (SDO for
//! the mode and the parameters, the controlword's bit 4 by RPDO, the statusword by TPDO).

use super::*;
use crate::sim::homing::{ATTAINED, ERROR, START, TARGET_REACHED};

const HOMING_BITS: u16 = ATTAINED | ERROR | TARGET_REACHED;

/// Node 1 at `start`, with `home` hardware, enabled in CSP then switched to homing with
/// `method` and `offset`.
fn ready(start: i32, home: HomeHardware, method: i8, offset: i32) -> Master {
    let mut m = Master::new(vec![SimNodeConfig {
        initial_position: start,
        home,
        ..SimNodeConfig::new(node(1))
    }]);
    m.operational(&[1]);
    m.enable(1);
    let n = node(1);
    m.sdo_write(n, od::MODES_OF_OPERATION, 0, SdoValue::I8(od::MODE_HOMING))
        .unwrap();
    m.sdo_write(n, od::HOMING_METHOD, 0, SdoValue::I8(method))
        .unwrap();
    m.sdo_write(n, od::HOME_OFFSET, 0, SdoValue::I32(offset))
        .unwrap();
    m
}

/// Cycles with `controlword` until the homing bits show an end at rest (at most `max`);
/// returns every (statusword, actual position) seen.
fn home(m: &mut Master, controlword: u16, max: usize) -> Vec<(u16, i32)> {
    let mut seen = Vec::new();
    for _ in 0..max {
        let fb = m.cycle(&[(1, controlword, 0)]);
        let (_, fb) = fb[0];
        seen.push((fb.statusword, fb.actual));
        if fb.statusword & TARGET_REACHED != 0 && fb.statusword & (ATTAINED | ERROR) != 0 {
            break;
        }
    }
    seen
}

fn last(seen: &[(u16, i32)]) -> (u16, i32) {
    *seen.last().expect("cycles ran")
}

const RUN: u16 = 0x0F | START;

#[test]
fn the_drive_offers_homing_and_its_methods() {
    let mut m = Master::with_nodes(&[1]);
    m.power_on();
    let n = node(1);
    assert_eq!(m.read_u32(n, od::SUPPORTED_DRIVE_MODES, 0), 0xA4);
    for method in HOMING_METHODS {
        assert_eq!(
            m.sdo_write(n, od::HOMING_METHOD, 0, SdoValue::I8(method)),
            Ok(())
        );
    }
    for method in [0, 1, 17, 33, -1] {
        assert_eq!(
            m.sdo_write(n, od::HOMING_METHOD, 0, SdoValue::I8(method)),
            Err(AbortCode::ValueRangeExceeded),
            "method {method}"
        );
    }
    assert_eq!(
        m.sdo_write(n, od::MODES_OF_OPERATION, 0, SdoValue::I8(6)),
        Ok(())
    );
    assert_eq!(m.read_u32(n, od::MODES_OF_OPERATION_DISPLAY, 0), 6);
}

#[test]
fn on_the_current_position_the_home_offset_is_there_at_once() {
    for method in [35, 37] {
        let mut m = ready(12_345, HomeHardware::default(), method, -700);
        let seen = home(&mut m, RUN, 10);
        assert!(seen.len() <= 3, "{seen:?}");
        assert_eq!(last(&seen).1, -700, "{seen:?}");
        assert_eq!(last(&seen).0 & HOMING_BITS, ATTAINED | TARGET_REACHED);
        assert_eq!(m.read_u32(node(1), od::POSITION_ACTUAL, 0) as i32, -700);
    }
}

#[test]
fn on_the_home_switch_from_either_side() {
    let hw = HomeHardware::default(); // switch edge at 0, active above it for 19
                                      // Method 19 from the active side moves negative, from the inactive side positive; the
                                      // edge becomes the offset, and the motor stops a little beyond it.
    for (start, method, dir) in [
        (5_000, 19, -1),
        (-5_000, 19, 1),
        (-5_000, 21, 1),
        (5_000, 21, -1),
    ] {
        let mut m = ready(start, hw, method, 1_000);
        let seen = home(&mut m, RUN, 5_000);
        let (sw, at) = last(&seen);
        assert_eq!(
            sw & HOMING_BITS,
            ATTAINED | TARGET_REACHED,
            "{method} from {start}"
        );
        // In progress first (no homing bits), moving toward the switch.
        assert_eq!(seen[1].0 & HOMING_BITS, 0);
        assert!(
            (seen[5].1 - start) * dir > 0,
            "{method} from {start}: {:?}",
            &seen[..6]
        );
        // Beyond the home point in the direction of travel, by the stopping distance
        // (20 000 counts/s at 100 000 counts/s²: 2 000 counts) and a period or two.
        let past = (at - 1_000) * dir;
        assert!(
            (1_900..=2_100).contains(&past),
            "{method} from {start}: {past} past home"
        );
        // Attained while still moving, then at rest.
        assert!(seen.iter().any(|s| s.0 & HOMING_BITS == ATTAINED));
    }
}

#[test]
fn on_the_switch_and_the_index_pulse() {
    let hw = HomeHardware {
        switch: Some(3_000),
        index_pitch: 10_000,
        search_limit: 1_000_000,
        ..HomeHardware::default()
    };
    // Method 3: the switch is active above 3 000; from 25 000 the motor moves negative past
    // the edge, on at the index speed to the first pulse below it (0), which becomes the
    // offset. Method 5 mirrored: active below 3 000; from -25 000 positive, then on to the
    // first pulse above the edge (10 000).
    for (start, method, pulse, dir) in [(25_000, 3, 0, -1), (-25_000, 5, 10_000, 1)] {
        let mut m = ready(start, hw, method, 0);
        let seen = home(&mut m, RUN, 10_000);
        let (sw, at) = last(&seen);
        assert_eq!(
            sw & HOMING_BITS,
            ATTAINED | TARGET_REACHED,
            "method {method}"
        );
        // At the index speed (2 000 counts/s) the stop takes 20 counts and a period.
        let past = at * dir;
        assert!(
            (15..=30).contains(&past),
            "method {method}: {past} past the pulse at {pulse}"
        );
    }
}

#[test]
fn a_switch_that_is_never_found_is_a_homing_error() {
    let hw = HomeHardware {
        switch: None,
        index_pitch: 10_000,
        search_limit: 40_000,
        ..HomeHardware::default()
    };
    let mut m = ready(0, hw, 19, 0);
    let seen = home(&mut m, RUN, 10_000);
    let (sw, at) = last(&seen);
    assert_eq!(
        sw & HOMING_BITS,
        ERROR | TARGET_REACHED,
        "{:?}",
        last(&seen)
    );
    assert!(
        seen.iter().any(|s| s.0 & HOMING_BITS == ERROR),
        "error while stopping"
    );
    assert!((40_000..=43_000).contains(&at), "searched to {at}");
    // Position not re-referenced; homing again starts a new search (bit 4's next edge).
    home(&mut m, 0x0F, 2);
    let seen = home(&mut m, RUN, 3);
    assert_eq!(seen[1].0 & HOMING_BITS, 0, "in progress again");
}

#[test]
fn clearing_the_start_bit_interrupts_the_search() {
    let mut m = ready(5_000, HomeHardware::default(), 19, 0);
    home(&mut m, RUN, 50);
    let seen = home(&mut m, 0x0F, 2_000);
    let (sw, _) = last(&seen);
    assert_eq!(
        sw & HOMING_BITS,
        TARGET_REACHED,
        "interrupted, at rest: {sw:04X}"
    );
    assert!(seen.iter().all(|s| s.0 & ATTAINED == 0));
}

#[test]
fn bit_4_outside_operation_enabled_starts_nothing() {
    let mut m = ready(5_000, HomeHardware::default(), 35, 0);
    // Switched on (0x07): no homing.
    let seen = home(&mut m, 0x07 | START, 5);
    assert!(
        seen.iter().all(|s| s.0 & HOMING_BITS == 0 && s.1 == 5_000),
        "{seen:?}"
    );
}
