//! [`Check`]: the one place a rule's error is made, naming the key, the value as written,
//! its line:col and the allowed range with its unit; and the ranges every rate and position
//! of a machine file is held to.

use crate::error::ConfigError;
use crate::source::Source;

/// Smallest and largest value of any rate, limit or scale (velocity, acceleration, jerk,
/// feed, counts per unit): outside them the planner's arithmetic under- or overflows.
pub const MIN_POSITIVE: f64 = 1e-6;
pub const MAX_POSITIVE: f64 = 1e9;
/// Largest magnitude of a position (travel, pivot point): mm or degrees.
pub const MAX_POSITION: f64 = 1e6;
pub(crate) struct Check<'s, 'a> {
    pub(crate) src: &'s Source<'a>,
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
    pub(crate) fn finite(&self, path: &[&str], v: f64, unit: &str) -> Result<f64, ConfigError> {
        if v.abs() <= MAX_POSITION {
            Ok(v)
        } else {
            let rule = format!("must be in -{MAX_POSITION:e}..={MAX_POSITION:e} ({unit})");
            Err(self.invalid(path, Some(v.to_string()), rule))
        }
    }

    /// A point a program moves to (work offset, reference): within the NC coordinate domain.
    pub(crate) fn point(&self, path: &[&str], p: [f64; 3]) -> Result<[f64; 3], ConfigError> {
        const MAX: f64 = 1e5;
        if p.iter().all(|v| v.abs() <= MAX) {
            Ok(p)
        } else {
            let rule = format!("every coordinate must be in -{MAX:e}..={MAX:e} (mm)");
            Err(self.invalid(path, Some(format!("{p:?}")), rule))
        }
    }
}
