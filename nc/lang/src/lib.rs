//! The NC-program parser: source text -> [`Program`], or the first [`ParseError`].
//!
//! # The language
//!
//! RS274/NGC as LinuxCNC reads it (its interpreter `rs274` is the oracle of the
//! conformance suite), with the paper's `G06.5` double-NURBS block, Fanuc's `G06.2` NURBS
//! block and 5-axis `G00`/`G01`. Whatever is not listed here is an error, never silently
//! ignored.
//!
//! ```text
//! line      = [ "/" ] [ "N" digits ] ( o-line | { word | assignment } ) [ "\" newline line ]
//!           | "%"                      (first line: tape start; a later one ends the program)
//! word      = letter value ;           letters: A B C F G H I J K M N O P R S T U V W X Y Z
//! value     = number | "#" parameter | "[" expression "]" | function
//! parameter = value (1..5601) | "<" name ">"  ("_name": global, else local to its call)
//! assignment= "#" parameter "=" value
//! o-line    = "O" ( value | "<" name ">" ) keyword { "[" expression "]" }
//! comment   = "(" ... ")" on one line  |  ";" ... end of line
//! ```
//!
//! Spaces and tabs vanish anywhere outside comments (`G 0 X 1 . 5` is `G0X1.5`), letters
//! are case-insensitive. Numbers have no exponent. Expressions have every RS274/NGC operator
//! (`** * / MOD + - EQ NE GT GE LT LE AND OR XOR`) and function (`ABS ACOS ASIN ATAN[y]/[x]
//! COS EXISTS EXP FIX FUP LN ROUND SIN SQRT TAN`), angles in degrees. On a line, every value
//! reads the parameters as they were before the line; its assignments take effect after
//! (numbered, then named). O-words: `sub endsub call return if elseif else endif while
//! endwhile do repeat endrepeat break continue`. `(ABORT, text)` stops the program.
//!
//! Per line, after the interpreter:
//!
//! - `N` only as the first word; `G90` and `G21` (the defaults, the only modes supported) on
//!   any line; `M02` / `M30` end the program: the lines after it are not read (as LinuxCNC;
//!   without them the program ends at the end of the file or at its closing `%`). One code
//!   per modal group and one word per letter on a line. A line of only `N`, `F`, `G90`,
//!   `G21` or `G00`/`G01` sets modes and moves nothing.
//! - `F` sets the modal feed (mm/min, > 0). Every `G01` move (the start pose too) and every
//!   NURBS block needs one in effect; `G00` does not.
//! - `G00` / `G01` are modal: a line of coordinates alone continues the last of them. Missing
//!   `X Y Z` keep their values. Orientation is `I J K` (a tool vector, all three, normalised;
//!   so `K` on a `G01` line is the vector's third component, never a knot) or machine angles
//!   `A C` (`B C` on a B/C machine; a program uses A or B, not both). Missing orientation keeps
//!   the previous one, a missing angle the previous angle. A single angle after a programmed
//!   `I J K` is an error (the other angle cannot be inherited from a vector); before any
//!   orientation was programmed, the implicit vertical tool counts as `A0 C0`.
//! - **Start pose**: the first move must be a `G00`/`G01` that gives all of `X Y Z` (and an
//!   orientation, else the tool is vertical, `I0 J0 K1`). The interpolator starts there.
//! - `G06.5 P<degree>` (P required) and `G06.2 [P<rank>]` (Fanuc: rank = degree + 1, default
//!   4) open a NURBS block; that line carries the first control point and may carry `F`. Each
//!   control-point line has `X Y Z` (`G06.5`: also `U V W`, the orientation curve's control
//!   point; no modal values inside a block), its knot `K` and optionally the weight `R`
//!   (default 1). Then lines of `K` words only bring the last degree + 1 knots; the block ends
//!   when it has control points + degree + 1 knots. While knots are missing, a line counts as
//!   a control-point line if it has no G/M code and has a word only control points have (`K`,
//!   `R`, and for `G06.5` `U V W`); any other line cuts the block short (an error).
//! - A block's first control point must be the current position (within 1 um per axis). After
//!   the block the current position is its last control point and, for `G06.5`, the
//!   orientation is the vector from the last `X Y Z` to the last `U V W`. A NURBS mode is not
//!   modal: later coordinate lines continue the last `G00`/`G01`.
//!
//! The rules a NURBS block must satisfy (degree 1 to 5, at least degree + 1 and at most
//! [`MAX_CTRL`](nc_geom::program::MAX_CTRL) control points, finite, non-decreasing, clamped knots
//! with a non-empty range, positive weights, `U V W` at least 1 um from `X Y Z`) are each a
//! [`ParseErrorKind`] variant.
//!
//! Positions: a block's `pos` is its G word, or the first word of a modal-continuation line;
//! `ctrl_pos[i]` is the first word of control point `i` (the first of `X Y Z U V W R K` on its
//! line, so on the opening line it is not the G word). An error at the end of the file points
//! just past the last character.
//!
//! # Design
//!
//! The stages, each in its own file, each checking the rules it can see:
//!
//! - `text`: a physical line normalised (whitespace out, lower case, comments cut, every
//!   character keeping its column); `tape`: logical lines, kept while a loop or a call may
//!   go back to them.
//! - `syntax` (with `expr`): a line read into its words, assignments and O-word, values as
//!   expression trees, nothing evaluated.
//! - `interp` (with `evaluate`, `flow`, `subs`, `params`): parameters, the flow, the
//!   order of evaluation; hands each line's words, now numbers (`word`), on.
//! - `line`: one line of words -> its `N`, G and M codes decoded by modal group and the other
//!   words indexed by letter. Rules without state: unknown words, unsupported codes, repeats.
//! - `parser` (with `moves`, `nurbs`, `predefined`): the modal state machine. It resolves
//!   every modal value, so each [`Block`](nc_geom::program::Block) of the result is complete,
//!   and gives the interpreter the parameters that read its state (`#5420`, `#<_x>`, ...).
//!
//! Errors are reported at the first rule broken, at the offending token; parsing stops there
//! (an NC program is only run when it is entirely valid). The parser never panics: no indexing
//! that can fail, checked conversions, and every value is proved finite where it is computed. A
//! property test feeds it arbitrary text and mutations of the paper's example.

mod arc;
mod arc_move;
pub(crate) mod codes;
mod comp;
mod comp_corner;
mod comp_parse;
mod context;
mod coord_offset;
mod cycles;
mod error;
mod evaluate;
mod expr;
mod feed;
mod flow;
mod g10;
mod g52;
mod interp;
mod interp_error;
mod io;
mod length;
mod line;
mod machine_move;
pub mod mdi;
mod modal;
mod moves;
mod name;
mod nurbs;
mod nurbs_open;
mod open_g52;
mod params;
mod parser;
mod path;
mod polar;
mod predefined;
pub mod restart;
mod rotation;
mod rules;
mod saved;
mod source;
mod splines;
mod startup;
mod startup_parse;
mod stream;
mod subs;
mod syntax;
mod tape;
#[cfg(test)]
mod tests;
mod text;
mod vocab;
mod word;
pub use word::continues;

pub use arc::{arc, ArcNet, ArcTol, Centre};
pub use error::{Context, ParseError, ParseErrorKind};
pub use interp_error::InterpError;
pub use modal::{Io, Setup, MAX_ERRORS, MM_PER_INCH};
pub use name::Name;
pub use rules::{
    ARC_RADIUS_REL_TOL, ARC_RADIUS_TOL_IN, ARC_RADIUS_TOL_MM, ARC_REACH_TOL_IN, ARC_REACH_TOL_MM,
    G_LIST, HELIX_TOL_MM, MAX_CALL_DEPTH, MAX_DWELL_S, MAX_LOOP_LINES, MAX_PARAMETER,
    MIN_ARC_RADIUS_MM, MIN_FEED_MM_MIN, MIN_TOOL_OFFSET_MM, MIN_VECTOR_LENGTH, MIN_WEIGHT, M_LIST,
    START_TOLERANCE_MM,
};
pub use source::{LineSource, ReadLines, StrLines, MAX_LINE_BYTES};
pub use startup::{Startup, StartupError, STARTUP_CODES};
pub use stream::{Entries, Entry};
pub use vocab::{Cycle, Motion, Plane};
pub use word::word_limit;

use nc_geom::program::Program;

/// Every error of a program, in source order: at most [`MAX_ERRORS`], and `more` when the
/// parse stopped there.
#[derive(Clone, Debug, PartialEq)]
pub struct ParseErrors {
    pub errors: Vec<ParseError>,
    pub more: bool,
}

impl ParseErrors {
    /// The first error (there is always one).
    pub fn first(&self) -> Option<&ParseError> {
        self.errors.first()
    }
}

/// Parses a whole NC program with no shop setup (no work offsets, reference position or
/// tools); the first error only.
///
/// ```
/// let program = nc_lang::parse("G00 X0 Y0 Z10\nG01 Z0 F500\nM30\n").unwrap();
/// assert_eq!(program.blocks.len(), 2);
/// ```
pub fn parse(src: &str) -> Result<Program, ParseError> {
    parse_with(src, &Setup::default()).map_err(|e| {
        e.errors.first().copied().unwrap_or(ParseError {
            pos: nc_geom::program::SrcPos::default(),
            kind: ParseErrorKind::MisplacedTapeMark,
        })
    })
}

/// Parses a whole NC program against the shop's [`Setup`], reporting every error (up to
/// [`MAX_ERRORS`]). After an error the line is skipped (a NURBS block with it), so later
/// errors may follow from the first one.
pub fn parse_with(src: &str, setup: &Setup) -> Result<Program, ParseErrors> {
    parse_lines(StrLines::new(src), setup)
}

/// [`parse_with`] from any source of lines ([`ReadLines`] reads a file as it goes).
pub fn parse_lines<S: LineSource>(lines: S, setup: &Setup) -> Result<Program, ParseErrors> {
    let mut entries = Entries::new(lines, setup);
    let mut program = Program::default();
    let mut errors = Vec::new();
    while let Some(entry) = entries.next() {
        match entry {
            Ok(Entry::Block(_, block)) => program.blocks.push(block),
            Ok(Entry::Action(action)) => program.actions.push(action),
            Err(e) => {
                errors.push(e);
                if errors.len() >= MAX_ERRORS {
                    let more = !entries.is_finished();
                    return Err(ParseErrors { errors, more });
                }
            }
        }
    }
    if !errors.is_empty() {
        return Err(ParseErrors {
            errors,
            more: false,
        });
    }
    program.end = entries.end();
    program.tilt_word = entries.tilt_word();
    program.rerun = entries.rerun().to_vec();
    Ok(program)
}
