//! `[axes.*.home]`: how an axis is homed. The methods with their CiA-402 numbers (the
//! drive's sign applied), the defaults within the axis's limits, and each key refused with
//! its value, its rule and its place.

mod common;

use common::*;
use config::bus::HomeMethod;

/// The minimal machine with drives, and `[axes.x.home]` with `keys`.
fn with_home(keys: &str) -> String {
    let mut text = MINIMAL.to_owned();
    text.push_str("\n[[bus]]\nname = \"can0\"\ninterface = \"vcan0\"\n");
    for (i, ax) in ["x", "y", "z", "a", "c"].iter().enumerate() {
        text.push_str(&format!(
            "\n[axes.{ax}.drive]\nbus = \"can0\"\nnode = {}\ncounts_per_unit = 1000.0\n",
            i + 1
        ));
    }
    text.push_str(&format!("\n[axes.x.home]\n{keys}\n"));
    text
}

#[test]
fn each_method_and_its_defaults() {
    let m = parse(&with_home(
        "method = \"switch\"\ndirection = \"negative\"\nposition = -99.5",
    ))
    .unwrap();
    let x = &m.drives[0];
    let h = x.home.expect("homed");
    assert_eq!(h.method, HomeMethod::Switch { positive: false });
    assert_eq!(x.homing_method(h.method), Some(21));
    assert_eq!(h.position, -99.5);
    // A tenth of the velocity limit (100 mm/s), a tenth of that, half the acceleration.
    assert_eq!(
        (
            h.search_velocity,
            h.latch_velocity,
            h.acceleration,
            h.sequence
        ),
        (10.0, 1.0, 500.0, 0)
    );
    assert_eq!(m.drives[1].home, None, "no [axes.y.home]");
    let m = parse(&with_home(
        "method = \"switch-index\"\ndirection = \"positive\"\nsearch_velocity = 50\n\
         latch_velocity = 5\nacceleration = 800\nsequence = 2",
    ))
    .unwrap();
    let h = m.drives[0].home.unwrap();
    assert_eq!(m.drives[0].homing_method(h.method), Some(3));
    assert_eq!(
        (
            h.search_velocity,
            h.latch_velocity,
            h.acceleration,
            h.sequence
        ),
        (50.0, 5.0, 800.0, 2)
    );
    for (method, want) in [
        ("current", HomeMethod::Current),
        ("absolute", HomeMethod::Absolute),
    ] {
        let m = parse(&with_home(&format!("method = \"{method}\""))).unwrap();
        assert_eq!(m.drives[0].home.unwrap().method, want);
    }
}

#[test]
fn every_key_is_checked_with_its_rule_and_place() {
    let base = "method = \"switch\"\ndirection = \"negative\"";
    for (key, value, rule) in [
        (
            "method",
            "\"limit\"",
            "\"switch\", \"switch-index\", \"current\" or \"absolute\"",
        ),
        ("direction", "\"up\"", "\"positive\" or \"negative\""),
        ("position", "150.0", "within the axis's travel -100..100"),
        ("search_velocity", "0", "at most the axis's 100 mm/s"),
        ("search_velocity", "101", "at most the axis's 100 mm/s"),
        ("latch_velocity", "20", "the search velocity"),
        ("acceleration", "2000", "at most the axis's 1000 mm/s^2"),
        ("sequence", "10", "0..=9"),
    ] {
        let text = set(&with_home(base), "axes.x.home", key, value);
        let (_, shown) = fail(&text);
        assert_mentions(&shown, &[&format!("axes.x.home.{key} = {value}"), rule]);
        // At the value.
        let mut at = pos_of(&text, &format!("{key} = {value}"));
        at.column += key.len() + 3;
        assert_at(&shown, at);
    }
    // A switch without its side.
    let (_, shown) = fail(&with_home("method = \"switch\""));
    assert_mentions(&shown, &["axes.x.home.direction", "missing"]);
    // An unknown key.
    let (_, shown) = fail(&with_home("method = \"current\"\nspeed = 3"));
    assert_mentions(&shown, &["speed"]);
}

#[test]
fn homing_needs_the_drive_that_homes() {
    let text = format!("{MINIMAL}\n[axes.x.home]\nmethod = \"current\"\n");
    let (_, shown) = fail(&text);
    assert_mentions(&shown, &["axes.x.drive", "the drive homes the axis"]);
}
