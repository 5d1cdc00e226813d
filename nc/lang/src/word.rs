//! [`Word`]: a letter and its value, as the interpreter hands them to the modal state
//! machine once every expression on the line is evaluated, and the range each letter's
//! value may have ([`word_limit`]).

use nc_geom::program::SrcPos;

/// One word: an (upper-cased) letter and its evaluated value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Word {
    pub letter: char,
    pub value: f64,
    /// The value as a `u32` when it is a whole number within 0.0001 (LinuxCNC's rule for
    /// integer words: tool, `H`, `L`, `P` of a dwell's code, `N`).
    pub uint: Option<u32>,
    pub pos: SrcPos,
}

/// `v` as a `u32` when it is a whole number within 0.0001 that fits.
pub(crate) fn as_uint(v: f64) -> Option<u32> {
    let r = v.round();
    ((v - r).abs() <= crate::rules::WHOLE_TOLERANCE && (0.0..=f64::from(u32::MAX)).contains(&r))
        .then_some(r as u32)
}

/// Largest magnitude a word's number may have. Coordinates up to 100 m and angles up to
/// 10^6 degrees cover every machine; beyond them the arithmetic of the planner loses the
/// micrometre (and far beyond, overflows), so such a number is refused where it is written.
/// A feed up to 10^9 is taken and run at the machine's highest feed (said where it is
/// written, as LinuxCNC clamps it to the machine's speed).
/// The other words have checks of their own: I J K are normalised as a direction (or are
/// knots, checked by the curve), N is a `u32`, G M P are codes.
pub const fn word_limit(letter: char) -> f64 {
    match letter {
        'X' | 'Y' | 'Z' | 'U' | 'V' | 'W' => 1e5,
        'A' | 'B' | 'C' | 'R' => 1e6,
        'F' => 1e9,
        _ => f64::MAX,
    }
}

/// Whether a physical line goes on with the next one (it ends with a `\` outside any
/// comment).
pub fn continues(text: &str) -> bool {
    text.contains('\\') && crate::text::normalise(1, text).is_ok_and(|n| n.continued.is_some())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_values_within_the_tolerance_are_integers() {
        assert_eq!(as_uint(3.0), Some(3));
        assert_eq!(as_uint(2.99995), Some(3));
        assert_eq!(as_uint(3.0002), None);
        assert_eq!(as_uint(-1.0), None);
        assert_eq!(as_uint(5e9), None);
        assert!(continues("X1 \\"));
        assert!(!continues("X1 (\\)"));
    }
}
