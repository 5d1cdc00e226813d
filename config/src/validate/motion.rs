//! `[machine]`, `[kinematics]`, `[axes.*]` and `[interpolation]`: the machine's motion.

use crate::check::{Check, MAX_POSITION};
use crate::error::ConfigError;
use crate::raw::{RawAxes, RawAxis, RawInterpolation, RawKinematics, RawMachine};
use machine::{Axes, AxisLimits, Compress, Interpolation, Kinematics, Machine, Method, RotaryName};

impl Check<'_, '_> {
    pub(super) fn machine(&self, m: &RawMachine) -> Result<(String, f64), ConfigError> {
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

    pub(super) fn kinematics(&self, k: &RawKinematics) -> Result<Kinematics, ConfigError> {
        let Some(kind) = Kind::parse(&k.kind) else {
            let [paper, ac, bc, xyz] = Kinematics::KINDS;
            let rule = format!("must be one of \"{paper}\", \"{ac}\", \"{bc}\", \"{xyz}\"");
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
            Kind::Xyz => Kinematics::Xyz,
        })
    }

    pub(super) fn axes(&self, a: &RawAxes, kin: &Kinematics) -> Result<Axes, ConfigError> {
        if !kin.has_rotary_axes() {
            let given = [
                ("a", a.a.is_some()),
                ("b", a.b.is_some()),
                ("c", a.c.is_some()),
            ];
            if let Some((key, _)) = given.into_iter().find(|(_, g)| *g) {
                let rule = format!(
                    "kinematics kind \"{}\" is a 3-axis mill without rotary axes: remove \
                     [axes.{key}]",
                    kin.kind()
                );
                return Err(self.missing(&["axes", key], rule));
            }
            return Ok(Axes {
                x: self.axis("x", &a.x, LINEAR, false)?,
                y: self.axis("y", &a.y, LINEAR, false)?,
                z: self.axis("z", &a.z, LINEAR, false)?,
                tilt_name: kin.tilt_name(),
                tilt: Axes::locked(),
                c: Axes::locked(),
            });
        }
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
            c: match &a.c {
                Some(c) => self.axis("c", c, ROTARY, true)?,
                None => {
                    let rule = format!(
                        "missing: kinematics kind \"{kind}\" needs [axes.c] for its rotary \
                         table (deg, deg/s, deg/s^2, deg/s^3; no min/max: continuous)"
                    );
                    return Err(self.missing(&["axes", "c"], rule));
                }
            },
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

    pub(super) fn interpolation(&self, i: &RawInterpolation) -> Result<Interpolation, ConfigError> {
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

/// `[kinematics] kind`, before its points are checked.
#[derive(Clone, Copy)]
enum Kind {
    Paper,
    XyzacTrt,
    XyzbcTrt,
    Xyz,
}

impl Kind {
    fn parse(name: &str) -> Option<Kind> {
        let [paper, ac, bc, xyz] = Kinematics::KINDS;
        match name {
            n if n == paper => Some(Kind::Paper),
            n if n == ac => Some(Kind::XyzacTrt),
            n if n == bc => Some(Kind::XyzbcTrt),
            n if n == xyz => Some(Kind::Xyz),
            _ => None,
        }
    }

    /// The point keys this kind requires (and the only ones it accepts).
    fn points(self) -> &'static [&'static str] {
        match self {
            Kind::Paper | Kind::Xyz => &[],
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
