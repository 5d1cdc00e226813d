//! The words the language's stages and its error messages share: the motion word of a block
//! and the working plane of arcs.

use core::fmt;

/// Working plane of arcs (`G17` XY, `G18` ZX, `G19` YZ).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    Xy,
    Zx,
    Yz,
}

impl Plane {
    pub fn name(self) -> &'static str {
        match self {
            Plane::Xy => "G17 (XY)",
            Plane::Zx => "G18 (ZX)",
            Plane::Yz => "G19 (YZ)",
        }
    }

    /// The centre-offset words of the plane's two axes.
    pub fn offset_letters(self) -> &'static str {
        match self {
            Plane::Xy => "I J",
            Plane::Zx => "K I",
            Plane::Yz => "J K",
        }
    }

    /// The offset letters by axis index (X Y Z -> I J K).
    pub fn offset_letter(axis: usize) -> char {
        match axis {
            0 => 'I',
            1 => 'J',
            _ => 'K',
        }
    }

    /// Axis indices (first, second, normal) of the plane, right-handed: a counter-clockwise
    /// arc (`G03`) turns from the first axis toward the second, seen from +normal.
    pub fn axes(self) -> (usize, usize, usize) {
        match self {
            Plane::Xy => (0, 1, 2),
            Plane::Zx => (2, 0, 1),
            Plane::Yz => (1, 2, 0),
        }
    }
}

/// The motion word of a block, as named in messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    G00,
    G01,
    G02,
    G03,
    G062,
    G065,
    /// `G5`: a cubic spline in XY.
    G05,
    /// `G5.1`: a quadratic spline in XY.
    G051,
    /// `G5.2`: opens LinuxCNC's NURBS block (its lines are control points).
    G052,
    /// `G5.3`: closes it.
    G053,
    /// A canned cycle (expanded into straight moves).
    Cycle(Cycle),
}

/// The canned cycles dnurbs runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cycle {
    /// Drilling with chip breaking (pecks, a small retract between them).
    G73,
    /// Drilling.
    G81,
    /// Drilling with a dwell at the bottom.
    G82,
    /// Peck drilling (out to `R` between pecks).
    G83,
    /// Boring, feed out.
    G85,
    /// Boring, spindle stopped at the bottom, rapid out.
    G86,
    /// Boring, dwell at the bottom, feed out.
    G89,
}

impl Cycle {
    /// The cycle's G number.
    pub fn code(self) -> f64 {
        match self {
            Cycle::G73 => 73.0,
            Cycle::G81 => 81.0,
            Cycle::G82 => 82.0,
            Cycle::G83 => 83.0,
            Cycle::G85 => 85.0,
            Cycle::G86 => 86.0,
            Cycle::G89 => 89.0,
        }
    }

    /// It dwells at the bottom: `P` (seconds) is required when it starts.
    pub fn dwells(self) -> bool {
        matches!(self, Cycle::G82 | Cycle::G86 | Cycle::G89)
    }

    /// It pecks: `Q` (the peck, > 0) is required when it starts.
    pub fn pecks(self) -> bool {
        matches!(self, Cycle::G73 | Cycle::G83)
    }
}

impl fmt::Display for Cycle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "G{}", self.code())
    }
}

impl fmt::Display for Motion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Motion::G00 => "G00",
            Motion::G01 => "G01",
            Motion::G02 => "G02",
            Motion::G03 => "G03",
            Motion::G062 => "G06.2",
            Motion::G065 => "G06.5",
            Motion::G05 => "G05",
            Motion::G051 => "G05.1",
            Motion::G052 => "G05.2",
            Motion::G053 => "G05.3",
            Motion::Cycle(c) => return write!(f, "{c}"),
        })
    }
}
