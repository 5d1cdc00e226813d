//! How to fit: the tolerances, what ends a run, the degree written.

use crate::Tolerance;
use nc_geom::program::{Merge, PathMode};

/// Length the orientation points stand off the cutter points (mm): `U V W` = `X Y Z` +
/// this times the tool vector, so the six decimals written give the axis to 1e-7 rad.
pub const TOOL_MM: f64 = 10.0;

/// How to fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    pub tol: Tolerance,
    /// A turn of the path between two moves above this (degrees) is a corner: runs end there.
    pub corner_deg: f64,
    /// Degree of the curves written (`G06.5 P`).
    pub degree: usize,
    /// Shortest run fitted, in moves.
    pub min_moves: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            tol: Tolerance {
                mm: 0.001,
                rad: 0.01f64.to_radians(),
            },
            corner_deg: 10.0,
            degree: 3,
            min_moves: 4,
        }
    }
}

/// The program's tolerances the compressor takes as they are (mm): the machine file's range
/// for `compress_tol_mm`. Below it the moves run as programmed (closer than the program
/// permits); above it the compressor fits within its top (closer too), and says so.
pub const PROGRAM_TOL_MM: core::ops::RangeInclusive<f64> = 1e-5..=1.0;

/// When the compressor is on, and how close: the machine's setting, and the program's
/// path-control words (`G61`, `G61.1`, `G64 P Q`: [`PathMode::merge`], LinuxCNC's rule for
/// its naive-CAM tolerance) where they are followed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Policy {
    /// The machine's fit (`[interpolation] compress_tol_mm` and the rest); a program's
    /// tolerance replaces its `tol.mm`.
    pub opts: Options,
    /// On where the program says nothing of its own (`G64` alone, or no path word): the
    /// machine file's `compress`, or `--compress`.
    pub on: bool,
    /// The program's path-control words decide (false: `--no-compress`, never on).
    pub follow_program: bool,
}

impl Policy {
    /// Never on, whatever the program says.
    pub fn off(opts: Options) -> Policy {
        Policy {
            opts,
            on: false,
            follow_program: false,
        }
    }

    /// On with `opts` where the program says nothing, its words followed.
    pub fn on(opts: Options) -> Policy {
        Policy {
            opts,
            on: true,
            follow_program: true,
        }
    }

    /// How to fit under `mode` (None: before any path word), or None: not at all.
    pub fn at(&self, mode: Option<PathMode>) -> Option<Options> {
        let machine = self.on.then_some(self.opts);
        if !self.follow_program {
            return machine;
        }
        match mode.map_or(Merge::Machine, PathMode::merge) {
            Merge::Off => None,
            Merge::Machine => machine,
            Merge::Within(mm) if mm < *PROGRAM_TOL_MM.start() => None,
            Merge::Within(mm) => {
                let mut o = self.opts;
                o.tol.mm = mm.min(*PROGRAM_TOL_MM.end());
                Some(o)
            }
        }
    }

    /// Whether any path-control mode could turn the compressor on.
    pub fn may_compress(&self) -> bool {
        self.on || self.follow_program
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_program_decides_where_it_is_followed() {
        let opts = Options::default();
        let q = |q: f64| {
            Some(PathMode::Blend {
                p_mm: None,
                q_mm: Some(q),
            })
        };
        let machine_off = Policy {
            on: false,
            ..Policy::on(opts)
        };
        assert_eq!(machine_off.at(None), None);
        assert_eq!(machine_off.at(Some(PathMode::default())), None);
        assert_eq!(machine_off.at(q(0.02)).map(|o| o.tol.mm), Some(0.02));
        assert_eq!(Policy::on(opts).at(None), Some(opts));
        assert_eq!(Policy::on(opts).at(Some(PathMode::Exact)), None);
        assert_eq!(Policy::on(opts).at(q(0.0)), None);
        // Closer than the program permits at both ends of the range.
        assert_eq!(Policy::on(opts).at(q(1e-6)), None);
        assert_eq!(Policy::on(opts).at(q(5.0)).map(|o| o.tol.mm), Some(1.0));
        // `--no-compress`: never, whatever the program permits.
        assert_eq!(Policy::off(opts).at(q(0.02)), None);
        assert!(!Policy::off(opts).may_compress());
        // The angle, corner and degree stay the machine's.
        let o = machine_off.at(q(0.3)).unwrap();
        assert_eq!(
            (o.tol.rad, o.corner_deg, o.degree),
            (opts.tol.rad, opts.corner_deg, opts.degree)
        );
    }
}
