//! `[axes.*.drive]`'s guard: what the drive is told to watch by itself (following error,
//! its time, the quick-stop and fault-reaction option codes), with its defaults.

use crate::check::Check;
use crate::error::ConfigError;
use crate::raw::RawDrive;
use machine::bus::Guard;
use machine::AxisLimits;

/// Largest following-error window the drive can be given, counts (2^32 - 1 switches it
/// off in CiA-402).
const MAX_WINDOW: f64 = 4_294_967_294.0;

pub(super) fn guard(
    check: &Check<'_, '_>,
    path: &dyn Fn(&'static str) -> [&str; 4],
    d: &RawDrive,
    limits: &AxisLimits,
    counts_per_unit: f64,
) -> Result<Guard, ConfigError> {
    let following_error = match d.following_error {
        None => limits.velocity * Guard::FOLLOWING_TIME_S,
        Some(e) => {
            let counts = e * counts_per_unit;
            if !(e > 0.0 && (1.0..=MAX_WINDOW).contains(&counts)) {
                let rule = format!(
                    "must be more than 0, at least one count and at most {MAX_WINDOW} counts \
                     (the following-error window 0x6065; at {counts_per_unit} counts a unit)"
                );
                return Err(check.invalid(&path("following_error"), Some(e.to_string()), rule));
            }
            e
        }
    };
    let timeout = match d.following_error_timeout_ms {
        None => Guard::TIMEOUT_MS,
        Some(t) => u16::try_from(t).map_err(|_| {
            let rule = "must be in 0..=65535 ms (0x6066)".to_owned();
            check.invalid(
                &path("following_error_timeout_ms"),
                Some(t.to_string()),
                rule,
            )
        })?,
    };
    let option = |key: &'static str, v: Option<i64>, default: i16| match v {
        None => Ok(default),
        Some(n @ 0..=8) => Ok(n as i16),
        Some(n) => Err(check.invalid(
            &path(key),
            Some(n.to_string()),
            "must be a CiA-402 option code 0..=8 (0 disables the drive, 1 slow-down ramp, \
             2 quick-stop ramp, ...)"
                .into(),
        )),
    };
    Ok(Guard {
        following_error: Some(following_error.min(MAX_WINDOW / counts_per_unit)),
        following_error_timeout_ms: timeout,
        quick_stop_option: option(
            "quick_stop_option",
            d.quick_stop_option,
            Guard::QUICK_STOP_OPTION,
        )?,
        fault_reaction_option: option(
            "fault_reaction_option",
            d.fault_reaction_option,
            Guard::FAULT_REACTION_OPTION,
        )?,
    })
}
