//! Validation of `[spindle]` and `[coolant]` into [`machine::Spindle`] and
//! [`machine::Coolant`]: each on a named `[[bus]]`, its node free on that bus.

use crate::check::{Check, MAX_POSITIVE};
use crate::error::ConfigError;
use crate::raw::{RawCoolant, RawSpindle};
use machine::bus::{Bus, Drive};
use machine::{BusNode, Coolant, Spindle};

/// Where `[section]` is: on its bus at a free node, or nowhere on a simulated machine (no
/// `[[bus]]`; then it must not name one).
pub(super) fn place(
    check: &Check<'_, '_>,
    section: &str,
    (bus, node): (Option<&str>, Option<i64>),
    buses: &[Bus],
    taken: &[(usize, u8)],
) -> Result<Option<BusNode>, ConfigError> {
    match (bus, node, buses.is_empty()) {
        (None, None, true) => Ok(None),
        (Some(name), Some(node), false) => {
            let bus = bus_index(check, section, name, buses)?;
            let node = node_free(check, section, node, bus, buses, taken)?;
            Ok(Some(BusNode { bus, node }))
        }
        (Some(name), _, true) => {
            let rule = "names no bus: this machine has no [[bus]] (it is simulated); omit bus \
                        and node, or add the [[bus]]"
                .to_owned();
            Err(check.invalid(&[section, "bus"], Some(format!("{name:?}")), rule))
        }
        (None, Some(node), true) => {
            let rule = "a simulated machine (no [[bus]]) has no nodes: omit node".to_owned();
            Err(check.invalid(&[section, "node"], Some(node.to_string()), rule))
        }
        (None, _, false) => Err(check.missing(
            &[section, "bus"],
            "missing: a machine with [[bus]] tables needs bus and node".into(),
        )),
        (Some(_), None, false) => Err(check.missing(
            &[section, "node"],
            "missing: the CANopen node id 1..=127 on its bus".into(),
        )),
    }
}

/// The node on `bus` is not used by an axis (or, for the coolant, by the spindle).
fn node_free(
    check: &Check<'_, '_>,
    section: &str,
    node: i64,
    bus: usize,
    buses: &[Bus],
    taken: &[(usize, u8)],
) -> Result<u8, ConfigError> {
    if !(1..=127).contains(&node) || taken.contains(&(bus, node as u8)) {
        let rule = format!(
            "must be a CANopen node id in 1..=127, unique on bus {:?} (the axes' drives{} use {})",
            buses[bus].name,
            if section == "coolant" {
                " and the spindle"
            } else {
                ""
            },
            taken
                .iter()
                .filter(|t| t.0 == bus)
                .map(|t| t.1.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
        return Err(check.invalid(&[section, "node"], Some(node.to_string()), rule));
    }
    Ok(node as u8)
}

fn bus_index(
    check: &Check<'_, '_>,
    section: &str,
    name: &str,
    buses: &[Bus],
) -> Result<usize, ConfigError> {
    buses.iter().position(|b| b.name == name).ok_or_else(|| {
        let names: Vec<String> = buses.iter().map(|b| format!("{:?}", b.name)).collect();
        let rule = if names.is_empty() {
            "names no bus: add a [[bus]] table with this name".to_owned()
        } else {
            format!("must name a [[bus]]: one of {}", names.join(", "))
        };
        check.invalid(&[section, "bus"], Some(format!("{name:?}")), rule)
    })
}

pub(crate) fn spindle(
    check: &Check<'_, '_>,
    raw: &RawSpindle,
    buses: &[Bus],
    drives: &[Drive],
) -> Result<Spindle, ConfigError> {
    let taken: Vec<(usize, u8)> = drives.iter().map(|d| (d.bus, d.node)).collect();
    let at = place(
        check,
        "spindle",
        (raw.bus.as_deref(), raw.node),
        buses,
        &taken,
    )?;
    let max_rpm = check.positive(&["spindle", "max_rpm"], raw.max_rpm, "rpm")?;
    let acceleration_rpm_s = check.positive(
        &["spindle", "acceleration_rpm_s"],
        raw.acceleration_rpm_s,
        "rpm/s",
    )?;
    let quick_stop_rpm_s = match raw.quick_stop_rpm_s {
        Some(v) => check.positive(&["spindle", "quick_stop_rpm_s"], v, "rpm/s")?,
        None => (2.0 * acceleration_rpm_s).min(MAX_POSITIVE),
    };
    let units_per_rpm = match raw.units_per_rpm {
        Some(v) => check.positive(&["spindle", "units_per_rpm"], v, "drive units per rpm")?,
        None => 1.0,
    };
    let sign = raw.sign.unwrap_or(1);
    if sign != 1 && sign != -1 {
        let rule = "must be 1 or -1".to_owned();
        return Err(check.invalid(&["spindle", "sign"], Some(sign.to_string()), rule));
    }
    // The drive's objects: 0x60FF/0x606C i32, 0x6083..0x6085 u32, 0x606D u16.
    let fits = |v: f64, max: f64| v * units_per_rpm <= max;
    if !fits(max_rpm, f64::from(i32::MAX)) {
        let rule = format!(
            "times units_per_rpm = {units_per_rpm} must fit the drive's 32-bit target \
             velocity 0x60FF"
        );
        return Err(check.invalid(&["spindle", "max_rpm"], Some(max_rpm.to_string()), rule));
    }
    for (key, v) in [
        ("acceleration_rpm_s", acceleration_rpm_s),
        ("quick_stop_rpm_s", quick_stop_rpm_s),
    ] {
        if !fits(v, f64::from(u32::MAX)) {
            let rule = "times units_per_rpm must fit the drive's 32-bit ramp (0x6083..0x6085)";
            return Err(check.invalid(&["spindle", key], Some(v.to_string()), rule.into()));
        }
    }
    let at_speed_window_rpm = match raw.at_speed_window_rpm {
        Some(v) => check.positive(&["spindle", "at_speed_window_rpm"], v, "rpm")?,
        None => (max_rpm * 0.01).max(1.0),
    };
    if !fits(at_speed_window_rpm, f64::from(u16::MAX)) || at_speed_window_rpm > max_rpm {
        let rule = format!(
            "must be at most max_rpm ({max_rpm}) and, times units_per_rpm, fit the drive's \
             16-bit velocity window 0x606D"
        );
        return Err(check.invalid(
            &["spindle", "at_speed_window_rpm"],
            Some(at_speed_window_rpm.to_string()),
            rule,
        ));
    }
    let at_speed_timeout_s = match raw.at_speed_timeout_s {
        Some(v) if (0.01..=600.0).contains(&v) => v,
        Some(v) => {
            let rule = "must be in 0.01..=600 (s)".to_owned();
            return Err(check.invalid(
                &["spindle", "at_speed_timeout_s"],
                Some(v.to_string()),
                rule,
            ));
        }
        None => (max_rpm / acceleration_rpm_s + 2.0).min(600.0),
    };
    Ok(Spindle {
        at,
        max_rpm,
        acceleration_rpm_s,
        quick_stop_rpm_s,
        units_per_rpm,
        sign: sign as i8,
        at_speed_window_rpm,
        at_speed_timeout_s,
    })
}

pub(crate) fn coolant(
    check: &Check<'_, '_>,
    raw: &RawCoolant,
    buses: &[Bus],
    drives: &[Drive],
    spindle: Option<&Spindle>,
) -> Result<Coolant, ConfigError> {
    let mut taken: Vec<(usize, u8)> = drives.iter().map(|d| (d.bus, d.node)).collect();
    taken.extend(spindle.and_then(|s| s.at).map(|a| (a.bus, a.node)));
    let at = place(
        check,
        "coolant",
        (raw.bus.as_deref(), raw.node),
        buses,
        &taken,
    )?;
    let output = |key: &str, v: Option<i64>| -> Result<Option<u8>, ConfigError> {
        match v {
            None => Ok(None),
            Some(n @ 1..=8) => Ok(Some(n as u8)),
            Some(n) => Err(check.invalid(
                &["coolant", key],
                Some(n.to_string()),
                "must be a digital output 1..=8 of the module (0x6200:01)".into(),
            )),
        }
    };
    let mist_output = output("mist_output", raw.mist_output)?;
    let flood_output = output("flood_output", raw.flood_output)?;
    match (mist_output, flood_output) {
        (None, None) => Err(check.missing(
            &["coolant"],
            "needs mist_output (M07) or flood_output (M08), or both".into(),
        )),
        (Some(a), Some(b)) if a == b => Err(check.invalid(
            &["coolant", "flood_output"],
            Some(b.to_string()),
            "must differ from mist_output".into(),
        )),
        _ => Ok(Coolant {
            at,
            mist_output,
            flood_output,
        }),
    }
}
