//! `[axes.*.home]`: how an axis finds its zero. The drive homes it (CiA-402 homing mode)
//! by the method named here, at speeds and an acceleration within the axis's limits, and
//! the home point becomes `position`; or the axis has an absolute encoder and needs none.

use crate::check::Check;
use crate::error::ConfigError;
use crate::raw::RawHome;
use machine::bus::{Drive, Home, HomeMethod};
use machine::AxisLimits;

/// The methods, as the file names them.
const METHODS: &str = "\"switch\", \"switch-index\", \"current\" or \"absolute\"";
/// Largest speed or acceleration a drive takes, counts/s (0x6099, 0x609A are 32-bit).
const MAX_COUNTS: f64 = 4_294_967_295.0;

pub(super) fn home(
    check: &Check<'_, '_>,
    key: &str,
    raw: &RawHome,
    limits: &AxisLimits,
    drive: &Drive,
) -> Result<Home, ConfigError> {
    let path = |field: &'static str| ["axes", key, "home", field];
    let direction = || -> Result<bool, ConfigError> {
        match raw.direction.as_deref() {
            Some("positive") => Ok(true),
            Some("negative") => Ok(false),
            Some(other) => Err(check.invalid(
                &path("direction"),
                Some(format!("{other:?}")),
                "must be \"positive\" or \"negative\": the side of its edge the home switch \
                 is active on"
                    .into(),
            )),
            None => Err(check.missing(
                &path("direction"),
                "missing: a switch method needs the side of its edge the home switch is \
                 active on (\"positive\" or \"negative\")"
                    .into(),
            )),
        }
    };
    let method = match raw.method.as_str() {
        "switch" => HomeMethod::Switch {
            positive: direction()?,
        },
        "switch-index" => HomeMethod::SwitchIndex {
            positive: direction()?,
        },
        "current" => HomeMethod::Current,
        "absolute" => HomeMethod::Absolute,
        other => {
            return Err(check.invalid(
                &path("method"),
                Some(format!("{other:?}")),
                format!("must be {METHODS}"),
            ))
        }
    };
    let position = raw.position.unwrap_or(0.0);
    let in_travel = limits.is_unlimited() || (limits.min..=limits.max).contains(&position);
    if !position.is_finite() || !in_travel || drive.counts(position).is_none() {
        return Err(check.invalid(
            &path("position"),
            Some(position.to_string()),
            format!(
                "must be within the axis's travel {}..{} (the home point's position)",
                limits.min, limits.max
            ),
        ));
    }
    // Speeds and the acceleration: within the axis's limits, in counts what a drive takes.
    let within = |field: &'static str, v: Option<f64>, default: f64, limit: f64, unit: &str| {
        let v = v.unwrap_or(default);
        let counts = v * drive.counts_per_unit;
        if v > 0.0 && v <= limit && (1.0..=MAX_COUNTS).contains(&counts) {
            Ok(v)
        } else {
            Err(check.invalid(
                &path(field),
                Some(v.to_string()),
                format!(
                    "must be more than 0 and at most the axis's {limit} {unit}, at least one \
                     count a second (at {} counts a unit)",
                    drive.counts_per_unit
                ),
            ))
        }
    };
    let unit = if drive.axis >= 3 { "deg" } else { "mm" };
    let search_velocity = within(
        "search_velocity",
        raw.search_velocity,
        limits.velocity / 10.0,
        limits.velocity,
        &format!("{unit}/s"),
    )?;
    let latch_velocity = within(
        "latch_velocity",
        raw.latch_velocity,
        search_velocity / 10.0,
        search_velocity,
        &format!("{unit}/s (the search velocity)"),
    )?;
    let acceleration = within(
        "acceleration",
        raw.acceleration,
        limits.acceleration / 2.0,
        limits.acceleration,
        &format!("{unit}/s^2"),
    )?;
    let sequence = match raw.sequence.unwrap_or(0) {
        s @ 0..=9 => s as u8,
        s => {
            return Err(check.invalid(
                &path("sequence"),
                Some(s.to_string()),
                "must be in 0..=9: axes home in rising order, equal ones together".into(),
            ))
        }
    };
    Ok(Home {
        method,
        position,
        search_velocity,
        latch_velocity,
        acceleration,
        sequence,
    })
}
