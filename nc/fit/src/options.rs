//! How to fit: the tolerances, what ends a run, the degree written.

use crate::Tolerance;

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
