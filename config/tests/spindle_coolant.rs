//! `[spindle]` and `[coolant]`: defaults, every rule with its position and the bus load they
//! add.

mod common;

use common::{assert_mentions, fail, MINIMAL, ORIGIN};

/// MINIMAL with five axis drives (nodes 1..=5) on bus "can0" at `period_ms`, plus `extra`.
fn machine(period_ms: &str, extra: &str) -> String {
    let mut text = MINIMAL.replace(
        "name = \"minimal\"",
        &format!("name = \"minimal\"\nperiod_ms = {period_ms}"),
    );
    text.push_str("\n[[bus]]\nname = \"can0\"\ninterface = \"vcan0\"\n");
    for (i, ax) in ["x", "y", "z", "a", "c"].iter().enumerate() {
        text.push_str(&format!(
            "\n[axes.{ax}.drive]\nbus = \"can0\"\nnode = {}\ncounts_per_unit = 1000.0\n",
            i + 1
        ));
    }
    text.push('\n');
    text.push_str(extra);
    text
}

const SPINDLE: &str =
    "[spindle]\nbus = \"can0\"\nnode = 6\nmax_rpm = 24000\nacceleration_rpm_s = 8000\n";
const COOLANT: &str = "[coolant]\nbus = \"can0\"\nnode = 7\nflood_output = 2\n";

#[test]
fn spindle_and_coolant_with_their_defaults() {
    let m = common::parse(&machine("4.0", &format!("{SPINDLE}{COOLANT}"))).unwrap();
    let s = m.spindle.as_ref().unwrap();
    assert_eq!(s.at, Some(config::BusNode { bus: 0, node: 6 }));
    assert_eq!((s.on_bus(0), s.on_bus(1), s.sign), (Some(6), None, 1));
    assert_eq!(s.quick_stop_rpm_s, 16000.0, "twice the acceleration");
    assert_eq!(s.at_speed_window_rpm, 240.0, "1 % of max_rpm");
    assert_eq!(s.at_speed_timeout_s, 5.0, "the full ramp + 2 s");
    assert_eq!((s.velocity(-12000.0), s.window_units()), (-12000, 240));
    let c = m.coolant.as_ref().unwrap();
    assert_eq!((c.mist_output, c.flood_output), (None, Some(2)));
    assert_eq!(c.outputs(true, true), 0b10, "no mist output: only flood");
    // 6 drives and a module at 4 ms: 55 + 6 * 230 + 2 * 65 = 1565 bits, 39.1 %.
    let n = m.bus_nodes(0);
    assert_eq!((n.drives, n.io), (6, 1));
    assert_eq!(config::bus::cycle_bits(n), 1565);
    assert_eq!(m.check_bus_load(), Ok(()));
}

#[test]
fn a_simulated_machine_has_them_without_a_bus() {
    let sim = |extra: &str| format!("{MINIMAL}\n{extra}");
    let spindle = "[spindle]\nmax_rpm = 24000\nacceleration_rpm_s = 8000\n";
    let coolant = "[coolant]\nmist_output = 1\nflood_output = 2\n";
    let m = common::parse(&sim(&format!("{spindle}{coolant}"))).unwrap();
    let (s, c) = (m.spindle.clone().unwrap(), m.coolant.clone().unwrap());
    assert_eq!((s.at, s.max_rpm, c.at), (None, 24000.0, None));
    assert_eq!(m.bus_nodes(0).drives, 0);
    // A bus or a node named on a machine without [[bus]] is refused by name.
    let (_, shown) = fail(&sim(SPINDLE));
    assert_mentions(&shown, &["spindle.bus", "no [[bus]]"]);
    let (_, shown) = fail(&sim("[coolant]\nnode = 7\nflood_output = 2\n"));
    assert_mentions(&shown, &["coolant.node", "omit node"]);
    // And a machine with a bus needs them on it.
    let (_, shown) = fail(&machine("4.0", spindle));
    assert_mentions(&shown, &["spindle.bus", "needs bus and node"]);
}

#[test]
fn the_spindle_and_the_module_count_in_the_bus_load() {
    // Five drives alone fit 2 ms (60.25 %); with the spindle and the module 78.25 %.
    let alone = common::parse(&machine("2.0", "")).unwrap();
    assert_eq!(alone.check_bus_load(), Ok(()));
    let m = common::parse(&machine("2.0", &format!("{SPINDLE}{COOLANT}"))).unwrap();
    let shown = m.check_bus_load().unwrap_err();
    assert_mentions(
        shown,
        &[
            ORIGIN,
            "bus.0.max_load",
            "6 drives and 1 I/O module",
            "1565 bits",
            "78.2 %",
        ],
    );
}

#[test]
fn every_rule_names_the_key_and_the_value() {
    let cases: [(&str, &[&str]); 9] = [
        (
            "[spindle]\nbus = \"can0\"\nnode = 3\nmax_rpm = 24000\nacceleration_rpm_s = 8000\n",
            &[
                "spindle.node = 3",
                "unique on bus \"can0\"",
                "1, 2, 3, 4, 5",
            ],
        ),
        (
            "[spindle]\nbus = \"can9\"\nnode = 6\nmax_rpm = 24000\nacceleration_rpm_s = 8000\n",
            &["spindle.bus = \"can9\"", "one of \"can0\""],
        ),
        (
            "[spindle]\nbus = \"can0\"\nnode = 6\nmax_rpm = 0\nacceleration_rpm_s = 8000\n",
            &["spindle.max_rpm = 0", "(rpm)"],
        ),
        (
            "[spindle]\nbus = \"can0\"\nnode = 6\nmax_rpm = 24000\nacceleration_rpm_s = 8000\n\
             units_per_rpm = 100000\n",
            &["spindle.max_rpm = 24000", "32-bit target velocity 0x60FF"],
        ),
        (
            "[spindle]\nbus = \"can0\"\nnode = 6\nmax_rpm = 24000\nacceleration_rpm_s = 8000\n\
             at_speed_window_rpm = 30000\n",
            &["spindle.at_speed_window_rpm = 30000", "at most max_rpm"],
        ),
        (
            "[spindle]\nbus = \"can0\"\nnode = 6\nmax_rpm = 24000\nacceleration_rpm_s = 8000\n\
             sign = 2\n",
            &["spindle.sign = 2", "must be 1 or -1"],
        ),
        (
            "[coolant]\nbus = \"can0\"\nnode = 5\nflood_output = 2\n",
            &["coolant.node = 5", "unique on bus"],
        ),
        (
            "[coolant]\nbus = \"can0\"\nnode = 7\nmist_output = 9\n",
            &["coolant.mist_output = 9", "output 1..=8"],
        ),
        (
            "[coolant]\nbus = \"can0\"\nnode = 7\nmist_output = 2\nflood_output = 2\n",
            &["coolant.flood_output = 2", "must differ from mist_output"],
        ),
    ];
    for (extra, parts) in cases {
        let (_, shown) = fail(&machine("4.0", extra));
        let mut all = vec![ORIGIN];
        all.extend_from_slice(parts);
        assert_mentions(&shown, &all);
    }
    // The coolant may not take the spindle's node either, nor have no output at all.
    let (_, shown) = fail(&machine(
        "4.0",
        &format!("{SPINDLE}[coolant]\nbus = \"can0\"\nnode = 6\nmist_output = 1\n"),
    ));
    assert_mentions(&shown, &["coolant.node = 6", "and the spindle", "6"]);
    let (_, shown) = fail(&machine("4.0", "[coolant]\nbus = \"can0\"\nnode = 7\n"));
    assert_mentions(
        &shown,
        &["coolant", "needs mist_output (M07) or flood_output (M08)"],
    );
}
