//! Stage 1 -> stage 2: checks every raw value and builds the [`Machine`].
//!
//! Each rule lives in exactly one place here, and its message states the allowed range with
//! the unit. The first violation is returned as [`ConfigError::Invalid`] with the key path,
//! the value as written and its line:col (looked up in [`Source`]).

use crate::error::ConfigError;
use crate::raw::{
    RawAxes, RawAxis, RawBus, RawFile, RawInterpolation, RawKinematics, RawMachine, RawRealtime,
};
use crate::source::Source;
use machine::bus::{self, Bus, Drive};
use machine::{
    Axes, AxisLimits, Compress, Interpolation, Kinematics, Machine, Method, Realtime, RotaryName,
};

/// Smallest and largest value of any rate, limit or scale (velocity, acceleration, jerk,
/// feed, counts per unit): outside them the planner's arithmetic under- or overflows.
pub const MIN_POSITIVE: f64 = 1e-6;
pub const MAX_POSITIVE: f64 = 1e9;
/// Largest magnitude of a position (travel, pivot point): mm or degrees.
pub const MAX_POSITION: f64 = 1e6;

/// Converts the raw file into a validated [`Machine`].
pub(crate) fn machine(raw: RawFile, src: &Source<'_>) -> Result<Machine, ConfigError> {
    let check = Check { src };
    let (name, period_s) = check.machine(&raw.machine)?;
    let kinematics = check.kinematics(&raw.kinematics)?;
    let axes = check.axes(&raw.axes, &kinematics)?;
    let interpolation = check.interpolation(&raw.interpolation.unwrap_or_default())?;
    let buses = check.buses(&raw.bus)?;
    let drives = check.drives(&raw.axes, &axes, &buses)?;
    let spindle = match &raw.spindle {
        Some(r) => Some(crate::spindle_coolant::spindle(&check, r, &buses, &drives)?),
        None => None,
    };
    let coolant = match &raw.coolant {
        Some(r) => Some(crate::spindle_coolant::coolant(
            &check,
            r,
            &buses,
            &drives,
            spindle.as_ref(),
        )?),
        None => None,
    };
    let nodes: Vec<bus::Nodes> = (0..buses.len())
        .map(|i| bus::Nodes {
            drives: (drives.iter().filter(|d| d.bus == i).count()
                + usize::from(spindle.as_ref().is_some_and(|s| s.bus == i)))
                as u32,
            io: u32::from(coolant.as_ref().is_some_and(|c| c.bus == i)),
        })
        .collect();
    let bus_overload = check.bus_load(&buses, &nodes, period_s);
    let realtime = check.realtime(&raw.realtime.unwrap_or_default(), period_s)?;
    let control_socket = match raw.control.and_then(|c| c.socket) {
        Some(s) if s.trim().is_empty() || s.contains('\0') => {
            return Err(check.invalid(
                &["control", "socket"],
                Some(format!("{s:?}")),
                "must be a path (e.g. \"/run/dnurbs/control.sock\")".into(),
            ))
        }
        other => other.map(std::path::PathBuf::from),
    };
    let offsets = raw.work_offsets.unwrap_or_default();
    let mut work_offsets = [None; 6];
    for ((slot, name), value) in work_offsets
        .iter_mut()
        .zip(["G54", "G55", "G56", "G57", "G58", "G59"])
        .zip([
            offsets.g54,
            offsets.g55,
            offsets.g56,
            offsets.g57,
            offsets.g58,
            offsets.g59,
        ])
    {
        if let Some(v) = value {
            *slot = Some(check.point(&["work_offsets", name], v)?);
        }
    }
    let reference = match raw.reference {
        Some(r) => Some(check.point(&["reference", "position"], r.position)?),
        None => None,
    };
    Ok(Machine {
        spindle,
        coolant,
        work_offsets,
        reference,
        name,
        period_s,
        kinematics,
        axes,
        interpolation,
        buses,
        drives,
        realtime,
        bus_overload,
        control_socket,
    })
}

pub(crate) struct Check<'s, 'a> {
    src: &'s Source<'a>,
}

impl Check<'_, '_> {
    /// An [`ConfigError::Invalid`] for `path`; `shown` is used if the value is not in the file
    /// as a single line (or not in the file at all).
    pub(crate) fn invalid(
        &self,
        path: &[&str],
        shown: Option<String>,
        rule: String,
    ) -> ConfigError {
        ConfigError::Invalid {
            at: self.src.locate(path),
            key: path.join("."),
            value: self.src.written(path).or(shown),
            rule,
        }
    }

    pub(crate) fn missing(&self, path: &[&str], rule: String) -> ConfigError {
        ConfigError::Invalid {
            at: self.src.locate(path),
            key: path.join("."),
            value: None,
            rule,
        }
    }

    /// `v` in `MIN_POSITIVE..=MAX_POSITIVE`: a rate, a limit or a scale.
    pub(crate) fn positive(&self, path: &[&str], v: f64, unit: &str) -> Result<f64, ConfigError> {
        if (MIN_POSITIVE..=MAX_POSITIVE).contains(&v) {
            Ok(v)
        } else {
            let rule = format!("must be in {MIN_POSITIVE:e}..={MAX_POSITIVE:e} ({unit})");
            Err(self.invalid(path, Some(v.to_string()), rule))
        }
    }

    /// `|v| <= MAX_POSITION`: a position (travel, pivot point).
    fn finite(&self, path: &[&str], v: f64, unit: &str) -> Result<f64, ConfigError> {
        if v.abs() <= MAX_POSITION {
            Ok(v)
        } else {
            let rule = format!("must be in -{MAX_POSITION:e}..={MAX_POSITION:e} ({unit})");
            Err(self.invalid(path, Some(v.to_string()), rule))
        }
    }

    /// A point a program moves to (work offset, reference): within the NC coordinate domain.
    fn point(&self, path: &[&str], p: [f64; 3]) -> Result<[f64; 3], ConfigError> {
        const MAX: f64 = 1e5;
        if p.iter().all(|v| v.abs() <= MAX) {
            Ok(p)
        } else {
            let rule = format!("every coordinate must be in -{MAX:e}..={MAX:e} (mm)");
            Err(self.invalid(path, Some(format!("{p:?}")), rule))
        }
    }

    fn machine(&self, m: &RawMachine) -> Result<(String, f64), ConfigError> {
        if m.name.trim().is_empty() {
            let rule = "must be a non-empty string".to_owned();
            return Err(self.invalid(&["machine", "name"], Some(format!("{:?}", m.name)), rule));
        }
        let ms = m.period_ms.unwrap_or(Machine::DEFAULT_PERIOD_MS);
        let (lo, hi) = (Machine::MIN_PERIOD_MS, Machine::MAX_PERIOD_MS);
        if !(ms.is_finite() && (lo..=hi).contains(&ms)) {
            let rule = format!("must be finite and in {lo}..={hi} (ms)");
            return Err(self.invalid(&["machine", "period_ms"], Some(ms.to_string()), rule));
        }
        Ok((m.name.clone(), ms / 1000.0))
    }

    fn kinematics(&self, k: &RawKinematics) -> Result<Kinematics, ConfigError> {
        let Some(kind) = Kind::parse(&k.kind) else {
            let [paper, ac, bc] = Kinematics::KINDS;
            let rule = format!("must be one of \"{paper}\", \"{ac}\", \"{bc}\"");
            let shown = Some(format!("{:?}", k.kind));
            return Err(self.invalid(&["kinematics", "kind"], shown, rule));
        };
        let given = [
            ("a_axis_point", k.a_axis_point),
            ("b_axis_point", k.b_axis_point),
            ("c_axis_point", k.c_axis_point),
        ];
        for (key, value) in given {
            if value.is_some() && !kind.points().contains(&key) {
                let takes = match kind.points() {
                    [] => "no points".to_owned(),
                    keys => keys.join(" and "),
                };
                let rule = format!("not a key of kind \"{}\", which takes {takes}", k.kind);
                return Err(self.invalid(&["kinematics", key], value.map(fmt_point), rule));
            }
        }
        let point = |key: &str, value: Option<[f64; 3]>, axis: &str| {
            let path = ["kinematics", key];
            match value {
                None => Err(self.missing(
                    &path,
                    format!(
                        "missing: kind \"{}\" needs [x, y, z] of a point on the {axis} axis \
                         (mm, machine frame)",
                        k.kind
                    ),
                )),
                Some(p) if p.iter().all(|c| c.abs() <= MAX_POSITION) => Ok(p),
                Some(p) => Err(self.invalid(
                    &path,
                    Some(fmt_point(p)),
                    format!("must be [x, y, z] with coordinates in -{MAX_POSITION:e}..={MAX_POSITION:e} (mm, machine frame)"),
                )),
            }
        };
        Ok(match kind {
            Kind::Paper => Kinematics::Paper,
            Kind::XyzacTrt => Kinematics::XyzacTrt {
                a_axis_point: point("a_axis_point", k.a_axis_point, "A")?,
                c_axis_point: point("c_axis_point", k.c_axis_point, "C (at A = 0)")?,
            },
            Kind::XyzbcTrt => Kinematics::XyzbcTrt {
                b_axis_point: point("b_axis_point", k.b_axis_point, "B")?,
                c_axis_point: point("c_axis_point", k.c_axis_point, "C (at B = 0)")?,
            },
        })
    }

    fn axes(&self, a: &RawAxes, kin: &Kinematics) -> Result<Axes, ConfigError> {
        let tilt_name = kin.tilt_name();
        let (tilt, other, other_name) = match tilt_name {
            RotaryName::A => (&a.a, &a.b, RotaryName::B),
            RotaryName::B => (&a.b, &a.a, RotaryName::A),
        };
        let kind = kin.kind();
        let (want, other_key) = (tilt_name.key(), other_name.key());
        if other.is_some() {
            let rule = format!(
                "kinematics kind \"{kind}\" has no {other_name} axis: its tilting axis is \
                 {tilt_name}, configured as [axes.{want}]"
            );
            return Err(self.missing(&["axes", other_key], rule));
        }
        let Some(tilt) = tilt else {
            let rule = format!(
                "missing: kinematics kind \"{kind}\" needs [axes.{want}] for its tilting \
                 {tilt_name} axis (deg, deg/s, deg/s^2, deg/s^3)"
            );
            return Err(self.missing(&["axes", want], rule));
        };
        Ok(Axes {
            x: self.axis("x", &a.x, LINEAR, false)?,
            y: self.axis("y", &a.y, LINEAR, false)?,
            z: self.axis("z", &a.z, LINEAR, false)?,
            tilt_name,
            tilt: self.axis(want, tilt, ROTARY, false)?,
            c: self.axis("c", &a.c, ROTARY, true)?,
        })
    }

    fn axis(
        &self,
        key: &str,
        a: &RawAxis,
        units: Units,
        may_be_unlimited: bool,
    ) -> Result<AxisLimits, ConfigError> {
        let path = |field: &'static str| ["axes", key, field];
        let (min, max) = match (a.min, a.max) {
            (None, None) if may_be_unlimited => (f64::NEG_INFINITY, f64::INFINITY),
            (Some(min), Some(max)) => {
                let min = self.finite(&path("min"), min, units.pos)?;
                let max = self.finite(&path("max"), max, units.pos)?;
                if min >= max {
                    let min_shown = self.src.written(&path("min")).unwrap_or(min.to_string());
                    let rule = format!("must be > axes.{key}.min = {min_shown} ({})", units.pos);
                    return Err(self.invalid(&path("max"), Some(max.to_string()), rule));
                }
                (min, max)
            }
            (min, _) => {
                let (absent, present) = if min.is_none() {
                    ("min", "max")
                } else {
                    ("max", "min")
                };
                let rule = if may_be_unlimited {
                    format!(
                        "missing while axes.{key}.{present} is given: give both min and max \
                         ({}), or omit both for unlimited rotation",
                        units.pos
                    )
                } else {
                    format!(
                        "missing: axes.{key} needs min and max ({}); only C may omit both",
                        units.pos
                    )
                };
                return Err(self.missing(&path(absent), rule));
            }
        };
        Ok(AxisLimits {
            min,
            max,
            velocity: self.positive(&path("velocity"), a.velocity, units.vel)?,
            acceleration: self.positive(&path("acceleration"), a.acceleration, units.acc)?,
            jerk: self.positive(&path("jerk"), a.jerk, units.jerk)?,
        })
    }

    fn interpolation(&self, i: &RawInterpolation) -> Result<Interpolation, ConfigError> {
        let d = Interpolation::default();
        let path = |field: &'static str| ["interpolation", field];
        let method = match &i.method {
            None => d.method,
            Some(name) => name.parse::<Method>().map_err(|_| {
                let names: Vec<String> = Method::ALL.iter().map(|m| format!("\"{m}\"")).collect();
                let rule = format!("must be one of {}", names.join(", "));
                self.invalid(&path("method"), Some(format!("{name:?}")), rule)
            })?,
        };
        let chord = i.chord_tolerance_mm.unwrap_or(d.chord_tolerance_mm);
        let hi = Interpolation::MAX_CHORD_TOLERANCE_MM;
        if !(chord.is_finite() && chord > 0.0 && chord <= hi) {
            let rule = format!("must be finite and in (0, {hi}] (mm)");
            return Err(self.invalid(&path("chord_tolerance_mm"), Some(chord.to_string()), rule));
        }
        let opt = |field, v: Option<f64>, default, unit| {
            self.positive(&path(field), v.unwrap_or(default), unit)
        };
        let max_feed = opt(
            "max_feed_mm_min",
            i.max_feed_mm_min,
            d.max_feed_mm_min,
            "mm/min",
        )?;
        Ok(Interpolation {
            method,
            chord_tolerance_mm: chord,
            path_acceleration: opt(
                "path_acceleration",
                i.path_acceleration,
                d.path_acceleration,
                "mm/s^2",
            )?,
            path_jerk: opt("path_jerk", i.path_jerk, d.path_jerk, "mm/s^3")?,
            max_feed_mm_min: max_feed,
            rapid_feed_mm_min: opt("rapid_feed_mm_min", i.rapid_feed_mm_min, max_feed, "mm/min")?,
            compress: i.compress.unwrap_or(false),
            compression: self.compression(i)?,
        })
    }

    /// The compressor's tolerances (checked whether or not `compress` is on).
    fn compression(&self, i: &RawInterpolation) -> Result<Compress, ConfigError> {
        let d = Compress::DEFAULT;
        let range = |field: &'static str, v: Option<f64>, default: f64, (lo, hi): (f64, f64)| {
            let x = v.unwrap_or(default);
            if x.is_finite() && (lo..=hi).contains(&x) {
                Ok(x)
            } else {
                Err(self.invalid(
                    &["interpolation", field],
                    Some(x.to_string()),
                    format!("must be finite and in {lo}..={hi}"),
                ))
            }
        };
        Ok(Compress {
            tol_mm: range(
                "compress_tol_mm",
                i.compress_tol_mm,
                d.tol_mm,
                Compress::TOL_MM,
            )?,
            tol_deg: range(
                "compress_tol_deg",
                i.compress_tol_deg,
                d.tol_deg,
                Compress::TOL_DEG,
            )?,
            corner_deg: range(
                "compress_corner_deg",
                i.compress_corner_deg,
                d.corner_deg,
                Compress::CORNER_DEG,
            )?,
        })
    }
}

impl Check<'_, '_> {
    fn realtime(&self, r: &RawRealtime, period_s: f64) -> Result<Realtime, ConfigError> {
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

    fn buses(&self, raw: &[RawBus]) -> Result<Vec<Bus>, ConfigError> {
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

    fn drives(&self, raw: &RawAxes, axes: &Axes, buses: &[Bus]) -> Result<Vec<Drive>, ConfigError> {
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
            ("c", Some(&raw.c), &axes.c),
        ];
        let mut out: Vec<Drive> = Vec::new();
        for (axis, (key, raw_axis, limits)) in keyed.iter().enumerate() {
            let path = |field: &'static str| ["axes", key, "drive", field];
            let Some(d) = raw_axis.and_then(|a| a.drive.as_ref()) else {
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
            out.push(drive);
        }
        Ok(out)
    }

    /// The first bus over its `max_load` at this period, as a positioned message. Not an
    /// error of the file: `dnurbs run` and `demo` refuse it, `simulate` (no bus) warns.
    fn bus_load(&self, buses: &[Bus], nodes: &[bus::Nodes], period_s: f64) -> Option<String> {
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

/// `[kinematics] kind`, before its points are checked.
#[derive(Clone, Copy)]
enum Kind {
    Paper,
    XyzacTrt,
    XyzbcTrt,
}

impl Kind {
    fn parse(name: &str) -> Option<Kind> {
        let [paper, ac, bc] = Kinematics::KINDS;
        match name {
            n if n == paper => Some(Kind::Paper),
            n if n == ac => Some(Kind::XyzacTrt),
            n if n == bc => Some(Kind::XyzbcTrt),
            _ => None,
        }
    }

    /// The point keys this kind requires (and the only ones it accepts).
    fn points(self) -> &'static [&'static str] {
        match self {
            Kind::Paper => &[],
            Kind::XyzacTrt => &["a_axis_point", "c_axis_point"],
            Kind::XyzbcTrt => &["b_axis_point", "c_axis_point"],
        }
    }
}

/// Units of one axis kind, for messages.
#[derive(Clone, Copy)]
struct Units {
    pos: &'static str,
    vel: &'static str,
    acc: &'static str,
    jerk: &'static str,
}

const LINEAR: Units = Units {
    pos: "mm",
    vel: "mm/s",
    acc: "mm/s^2",
    jerk: "mm/s^3",
};

const ROTARY: Units = Units {
    pos: "deg",
    vel: "deg/s",
    acc: "deg/s^2",
    jerk: "deg/s^3",
};

fn fmt_point(p: [f64; 3]) -> String {
    format!("[{}, {}, {}]", p[0], p[1], p[2])
}
