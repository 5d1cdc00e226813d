//! `[realtime]`, `[[bus]]` and the axes' drives: the hardware the machine runs on.

use crate::check::Check;
use crate::error::ConfigError;
use crate::raw::{RawAxes, RawAxis, RawBus, RawRealtime};
use machine::bus::{self, Bus, Drive};
use machine::{Axes, AxisLimits, Realtime, RotaryName};

impl Check<'_, '_> {
    pub(super) fn realtime(&self, r: &RawRealtime, period_s: f64) -> Result<Realtime, ConfigError> {
        let d = Realtime::default();
        let path = |field: &'static str| ["realtime", field];
        let int = |field, v: Option<i64>, default: i64, lo: i64, hi: i64, what: &str| {
            let x = v.unwrap_or(default);
            if (lo..=hi).contains(&x) {
                Ok(x)
            } else {
                let rule = format!("must be an integer in {lo}..={hi} ({what})");
                Err(self.invalid(&path(field), Some(x.to_string()), rule))
            }
        };
        let priority = int(
            "priority",
            r.priority,
            i64::from(d.priority),
            1,
            99,
            "SCHED_FIFO priority",
        )?;
        let cpu = match r.cpu {
            None => None,
            Some(c) => Some(int("cpu", Some(c), 0, 0, 4095, "CPU number")? as usize),
        };
        let idle_poll = r.idle_poll.unwrap_or(false);
        if idle_poll && cpu.is_none() {
            return Err(self.invalid(
                &path("idle_poll"),
                Some("true".into()),
                "needs `cpu`: the poller keeps the real-time thread's own CPU busy, so the \
                 thread must be pinned"
                    .into(),
            ));
        }
        // At most half the period: the rest is for the bus work and the other threads.
        let lead_us = r.lead_us.unwrap_or(d.lead_s * 1e6);
        let max_lead_us = (period_s * 1e6 / 2.0).min(10_000.0);
        if !(lead_us.is_finite() && (0.0..=max_lead_us).contains(&lead_us)) {
            return Err(self.invalid(
                &path("lead_us"),
                Some(lead_us.to_string()),
                format!("must be in 0..={max_lead_us} (µs, at most half the period)"),
            ));
        }
        let depth = int(
            "queue_depth",
            r.queue_depth,
            d.queue_depth as i64,
            2,
            Realtime::MAX_QUEUE_DEPTH as i64,
            "segments; the interpolator keeps one until it has the next",
        )?;
        let overruns = int(
            "max_consecutive_overruns",
            r.max_consecutive_overruns,
            d.max_consecutive_overruns as i64,
            1,
            100_000,
            "periods",
        )?;
        // Timeouts are given in ms; supervision shorter than two periods would fault on the
        // first late frame.
        let ms = |field, v: Option<f64>, default_s: f64, min_s: f64| {
            let x = v.unwrap_or(default_s * 1000.0);
            if x.is_finite() && x / 1000.0 >= min_s && x <= 600_000.0 {
                Ok(x / 1000.0)
            } else {
                let rule = format!("must be in {}..=600000 (ms)", min_s * 1000.0);
                Err(self.invalid(&path(field), Some(x.to_string()), rule))
            }
        };
        Ok(Realtime {
            priority: priority as i32,
            cpu,
            idle_poll,
            lead_s: lead_us * 1e-6,
            queue_depth: depth as usize,
            max_consecutive_overruns: overruns as u64,
            heartbeat_timeout_s: ms(
                "heartbeat_timeout_ms",
                r.heartbeat_timeout_ms,
                d.heartbeat_timeout_s,
                2.0 * period_s,
            )?,
            feedback_timeout_s: ms(
                "feedback_timeout_ms",
                r.feedback_timeout_ms,
                d.feedback_timeout_s.max(5.0 * period_s),
                2.0 * period_s,
            )?,
            boot_timeout_s: ms(
                "boot_timeout_ms",
                r.boot_timeout_ms,
                d.boot_timeout_s,
                0.001,
            )?,
            sdo_timeout_s: ms("sdo_timeout_ms", r.sdo_timeout_ms, d.sdo_timeout_s, 0.001)?,
        })
    }

    pub(super) fn buses(&self, raw: &[RawBus]) -> Result<Vec<Bus>, ConfigError> {
        // Two tables on one interface would pass the load check separately while their
        // frames share one wire.
        for (i, b) in raw.iter().enumerate() {
            if let Some(first) = raw[..i].iter().position(|o| o.interface == b.interface) {
                let idx = i.to_string();
                let rule = format!(
                    "must differ from every other [[bus]] interface: bus {first} ({:?}) is already on it; put all drives of one wire in one [[bus]]",
                    raw[first].name
                );
                return Err(self.invalid(
                    &["bus", idx.as_str(), "interface"],
                    Some(format!("{:?}", b.interface)),
                    rule,
                ));
            }
        }
        let mut out: Vec<Bus> = Vec::with_capacity(raw.len());
        for (i, b) in raw.iter().enumerate() {
            let idx = i.to_string();
            let path = |field: &'static str| ["bus", idx.as_str(), field];
            if b.name.trim().is_empty() || out.iter().any(|o| o.name == b.name) {
                let rule = "must be a non-empty name, unique among the [[bus]] tables".to_owned();
                return Err(self.invalid(&path("name"), Some(format!("{:?}", b.name)), rule));
            }
            if b.interface.is_empty() || b.interface.len() > 15 || b.interface.contains(['/', ' '])
            {
                let rule =
                    "must be a network interface name of 1 to 15 bytes (e.g. \"can0\")".to_owned();
                return Err(self.invalid(
                    &path("interface"),
                    Some(format!("{:?}", b.interface)),
                    rule,
                ));
            }
            let bitrate = b.bitrate.unwrap_or(i64::from(bus::DEFAULT_BITRATE));
            if !(10_000..=1_000_000).contains(&bitrate) {
                let rule = "must be in 10000..=1000000 (bit/s)".to_owned();
                return Err(self.invalid(&path("bitrate"), Some(bitrate.to_string()), rule));
            }
            let max_load = b.max_load.unwrap_or(bus::DEFAULT_MAX_LOAD);
            if !(max_load.is_finite() && max_load > 0.0 && max_load <= 1.0) {
                let rule = "must be in (0, 1] (fraction of the bitrate)".to_owned();
                return Err(self.invalid(&path("max_load"), Some(max_load.to_string()), rule));
            }
            out.push(Bus {
                name: b.name.clone(),
                interface: b.interface.clone(),
                bitrate: bitrate as u32,
                max_load,
            });
        }
        Ok(out)
    }

    pub(super) fn drives(
        &self,
        raw: &RawAxes,
        axes: &Axes,
        buses: &[Bus],
    ) -> Result<Vec<Drive>, ConfigError> {
        let tilt_key = axes.tilt_name.key();
        let tilt = match axes.tilt_name {
            RotaryName::A => raw.a.as_ref(),
            RotaryName::B => raw.b.as_ref(),
        };
        let keyed: [(&str, Option<&RawAxis>, &AxisLimits); 5] = [
            ("x", Some(&raw.x), &axes.x),
            ("y", Some(&raw.y), &axes.y),
            ("z", Some(&raw.z), &axes.z),
            (tilt_key, tilt, &axes.tilt),
            ("c", raw.c.as_ref(), &axes.c),
        ];
        let mut out: Vec<Drive> = Vec::new();
        for (axis, (key, raw_axis, limits)) in keyed.iter().enumerate() {
            let path = |field: &'static str| ["axes", key, "drive", field];
            let Some(d) = raw_axis.and_then(|a| a.drive.as_ref()) else {
                if raw_axis.is_some_and(|a| a.home.is_some()) {
                    let rule = "needs [axes.{axis}.drive]: the drive homes the axis"
                        .replace("{axis}", key);
                    return Err(self.missing(&["axes", key, "drive"], rule));
                }
                if !buses.is_empty() {
                    let rule =
                        "missing: a machine with [[bus]] tables needs a drive on every axis \
                                (bus, node, counts_per_unit)"
                            .to_owned();
                    return Err(self.missing(&["axes", key], rule));
                }
                continue;
            };
            let Some(bus) = buses.iter().position(|b| b.name == d.bus) else {
                let names: Vec<String> = buses.iter().map(|b| format!("{:?}", b.name)).collect();
                let rule = if names.is_empty() {
                    "names no bus: add a [[bus]] table with this name".to_owned()
                } else {
                    format!("must name a [[bus]]: one of {}", names.join(", "))
                };
                return Err(self.invalid(&path("bus"), Some(format!("{:?}", d.bus)), rule));
            };
            if !(1..=127).contains(&d.node)
                || out
                    .iter()
                    .any(|o| o.bus == bus && i64::from(o.node) == d.node)
            {
                let rule = format!(
                    "must be a CANopen node id in 1..=127, unique on bus {:?}",
                    d.bus
                );
                return Err(self.invalid(&path("node"), Some(d.node.to_string()), rule));
            }
            let unit = if axis >= 3 { "counts/deg" } else { "counts/mm" };
            let counts_per_unit =
                self.positive(&path("counts_per_unit"), d.counts_per_unit, unit)?;
            let sign = d.sign.unwrap_or(1);
            if sign != 1 && sign != -1 {
                let rule = "must be 1 or -1".to_owned();
                return Err(self.invalid(&path("sign"), Some(sign.to_string()), rule));
            }
            let offset = d.offset.unwrap_or(0);
            let Ok(offset) = i32::try_from(offset) else {
                let rule = "must fit a 32-bit signed count".to_owned();
                return Err(self.invalid(&path("offset"), Some(offset.to_string()), rule));
            };
            let drive = Drive {
                axis,
                bus,
                node: d.node as u8,
                counts_per_unit,
                sign: sign as i8,
                offset,
                guard: super::guard::guard(self, &path, d, limits, counts_per_unit)?,
                home: None,
            };
            if !limits.is_unlimited()
                && (drive.counts(limits.min).is_none() || drive.counts(limits.max).is_none())
            {
                let rule = format!(
                    "at this scale the travel {}..{} does not fit the drive's 32-bit position \
                     (counts from {:.0} to {:.0}, limit +-2147483647)",
                    limits.min,
                    limits.max,
                    limits.min * counts_per_unit * f64::from(drive.sign) + f64::from(offset),
                    limits.max * counts_per_unit * f64::from(drive.sign) + f64::from(offset),
                );
                return Err(self.invalid(
                    &path("counts_per_unit"),
                    Some(counts_per_unit.to_string()),
                    rule,
                ));
            }
            let mut drive = drive;
            if let Some(h) = raw_axis.and_then(|a| a.home.as_ref()) {
                drive.home = Some(super::home::home(self, key, h, limits, &drive)?);
            }
            out.push(drive);
        }
        Ok(out)
    }

    /// The first bus over its `max_load` at this period, as a positioned message. Not an
    /// error of the file: `dnurbs run` and `demo` refuse it, `simulate` (no bus) warns.
    pub(super) fn bus_load(
        &self,
        buses: &[Bus],
        nodes: &[bus::Nodes],
        period_s: f64,
    ) -> Option<String> {
        for (i, (b, &n)) in buses.iter().zip(nodes).enumerate() {
            let load = bus::load(n, b.bitrate, period_s);
            if load > b.max_load {
                let idx = i.to_string();
                let io = if n.io > 0 {
                    format!(" and {} I/O module", n.io)
                } else {
                    String::new()
                };
                let rule = format!(
                    "bus {:?} would carry {} drives{io}: {} bits per {} ms cycle = {:.1} % of {} bit/s, \
                     over max_load {:.1} % by {:.1} points: lengthen the period, raise the bitrate \
                     or move axes to another bus",
                    b.name,
                    n.drives,
                    bus::cycle_bits(n),
                    period_s * 1e3,
                    load * 100.0,
                    b.bitrate,
                    b.max_load * 100.0,
                    (load - b.max_load) * 100.0,
                );
                let e = self.invalid(
                    &["bus", idx.as_str(), "max_load"],
                    Some(b.max_load.to_string()),
                    rule,
                );
                return Some(e.to_string());
            }
        }
        None
    }
}
