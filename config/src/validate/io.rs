//! Validation of `[io]`: how many inputs and outputs `M62`..`M68` may name, and on a
//! machine with a bus where the digital ones are on its I/O module ([`BusIo`]).

use super::spindle::place;
use crate::check::Check;
use crate::error::ConfigError;
use crate::raw::RawIo;
use machine::bus::{Bus, Drive};
use machine::io::MODULE_BITS;
use machine::{BusIo, Coolant, IoCounts, Spindle};

/// Most inputs or outputs of one kind on a simulated machine.
const MAX_IO: i64 = 64;

/// The counts, and on a machine with a bus the module the digital ones are on.
pub(crate) fn io(
    check: &Check<'_, '_>,
    raw: Option<RawIo>,
    buses: &[Bus],
    drives: &[Drive],
    spindle: Option<&Spindle>,
    coolant: Option<&Coolant>,
) -> Result<(IoCounts, Option<BusIo>), ConfigError> {
    let Some(raw) = raw else {
        return Ok((IoCounts::default(), None));
    };
    let count = |key: &str, v: Option<i64>| -> Result<u8, ConfigError> {
        match v {
            None => Ok(0),
            Some(n) if (0..=MAX_IO).contains(&n) => Ok(n as u8),
            Some(n) => Err(check.invalid(
                &["io", key],
                Some(n.to_string()),
                format!("must be in 0..={MAX_IO}"),
            )),
        }
    };
    let counts = IoCounts {
        digital_outputs: count("digital_outputs", raw.digital_outputs)?,
        digital_inputs: count("digital_inputs", raw.digital_inputs)?,
        analog_outputs: count("analog_outputs", raw.analog_outputs)?,
        analog_inputs: count("analog_inputs", raw.analog_inputs)?,
    };
    if buses.is_empty() {
        let given = [
            ("first_output", raw.first_output),
            ("first_input", raw.first_input),
            ("estop_input", raw.estop_input),
        ];
        if let Some((key, Some(v))) = given.into_iter().find(|(_, v)| v.is_some()) {
            let rule = "is for a machine with a bus (its I/O module's bits): a simulated \
                        machine's inputs and outputs are simulated"
                .to_owned();
            return Err(check.invalid(&["io", key], Some(v.to_string()), rule));
        }
        // `bus` and `node` on a simulated machine: `place` refuses them by name.
        place(check, "io", (raw.bus.as_deref(), raw.node), buses, &[])?;
        return Ok((counts, None));
    }
    for (key, n) in [
        ("analog_outputs", counts.analog_outputs),
        ("analog_inputs", counts.analog_inputs),
    ] {
        if n > 0 {
            let rule = "must be 0 on a machine with a bus: its I/O module (CiA-401, 0x6200 \
                        and 0x6000) gives dnurbs digital outputs and inputs only, so M67, \
                        M68 and M66 E are refused"
                .to_owned();
            return Err(check.invalid(&["io", key], Some(n.to_string()), rule));
        }
    }
    let at = module(check, &raw, buses, drives, spindle, coolant)?;
    let taken = |n: u8| -> Option<(&str, u8)> {
        let c = coolant?;
        [
            ("mist_output", c.mist_output),
            ("flood_output", c.flood_output),
        ]
        .into_iter()
        .find_map(|(key, o)| (o == Some(n)).then_some((key, n)))
    };
    let first_output = bits(check, "output", raw.first_output, counts.digital_outputs)?;
    if let Some((key, n)) = (0..counts.digital_outputs).find_map(|k| taken(first_output + k)) {
        let rule = format!(
            "with digital_outputs = {} takes module output {n}, which the coolant's {key} \
             switches: move the program's outputs past it",
            counts.digital_outputs
        );
        return Err(check.invalid(
            &["io", "first_output"],
            Some(first_output.to_string()),
            rule,
        ));
    }
    let first_input = bits(check, "input", raw.first_input, counts.digital_inputs)?;
    let estop_input = estop(check, raw.estop_input, first_input, counts.digital_inputs)?;
    let bus_io = BusIo {
        at,
        first_output,
        outputs: counts.digital_outputs,
        first_input,
        inputs: counts.digital_inputs,
        estop_input,
    };
    Ok((counts, Some(bus_io)))
}

/// The module: the coolant's when the machine has one (`bus` and `node` may then be
/// omitted), else the one `bus` and `node` name, on a node no drive takes.
fn module(
    check: &Check<'_, '_>,
    raw: &RawIo,
    buses: &[Bus],
    drives: &[Drive],
    spindle: Option<&Spindle>,
    coolant: Option<&Coolant>,
) -> Result<machine::BusNode, ConfigError> {
    if let Some(c) = coolant.and_then(|c| c.at) {
        let same = |name: &str| buses.get(c.bus).is_some_and(|b| b.name == name);
        return match (raw.bus.as_deref(), raw.node) {
            (None, None) => Ok(c),
            (Some(b), Some(n)) if same(b) && n == i64::from(c.node) => Ok(c),
            (_, node) => {
                let rule = format!(
                    "must be the coolant's I/O module (bus {:?}, node {}): a machine has one \
                     I/O module; omit bus and node",
                    buses.get(c.bus).map_or("", |b| b.name.as_str()),
                    c.node
                );
                Err(check.invalid(&["io", "node"], node.map(|n| n.to_string()), rule))
            }
        };
    }
    let mut taken: Vec<(usize, u8)> = drives.iter().map(|d| (d.bus, d.node)).collect();
    taken.extend(spindle.and_then(|s| s.at).map(|a| (a.bus, a.node)));
    let at = place(check, "io", (raw.bus.as_deref(), raw.node), buses, &taken)?;
    at.ok_or_else(|| check.missing(&["io", "bus"], "missing: the I/O module's bus".into()))
}

/// `first_output` or `first_input`: module bit 1..=8 of the program's first, all `count`
/// within the module's eight (default 1).
fn bits(
    check: &Check<'_, '_>,
    what: &str,
    first: Option<i64>,
    count: u8,
) -> Result<u8, ConfigError> {
    let key = format!("first_{what}");
    let first = first.unwrap_or(1);
    let last = first + i64::from(count) - 1;
    if !(1..=i64::from(MODULE_BITS)).contains(&first) || last > i64::from(MODULE_BITS) {
        let rule = format!(
            "must be a module {what} 1..=8 with the {count} digital_{what}s after it within \
             the module's {MODULE_BITS} (0x6{}00:01)",
            if what == "output" { "2" } else { "0" }
        );
        return Err(check.invalid(&["io", &key], Some(first.to_string()), rule));
    }
    Ok(first as u8)
}

/// `estop_input`: a module input 1..=8 that none of the program's `M66` inputs is.
fn estop(
    check: &Check<'_, '_>,
    input: Option<i64>,
    first_input: u8,
    inputs: u8,
) -> Result<Option<u8>, ConfigError> {
    let Some(n) = input else {
        return Ok(None);
    };
    let program = i64::from(first_input)..i64::from(first_input) + i64::from(inputs);
    let rule = if !(1..=i64::from(MODULE_BITS)).contains(&n) {
        format!("must be a module input 1..={MODULE_BITS} (0x6000:01): the one the normally closed e-stop chain is wired to")
    } else if program.contains(&n) {
        format!(
            "is one of the program's M66 inputs (module inputs {}..={}): the e-stop chain needs an input of its own",
            program.start,
            program.end - 1
        )
    } else {
        return Ok(Some(n as u8));
    };
    Err(check.invalid(&["io", "estop_input"], Some(n.to_string()), rule))
}
