//! [`Startup::parse`]: start-up modes read as a program's line and applied to a parser,
//! apart from the [`Startup`] type that the setup holds (so `modal` does not reach the parser).

use crate::error::ParseError;
use crate::interp::Interp;
use crate::modal::Setup;
use crate::parser::Parser;
use crate::source::StrLines;
use crate::startup::{Startup, StartupError, STARTUP_CODES};

impl Startup {
    /// Parses `text` (one line, as in a program, e.g. `G20 G17 G40 G49 G90 G94 G64 P0.001`)
    /// and applies it to a parser with `setup` (which must then define the work offset it
    /// selects).
    pub fn parse(text: &str, setup: &Setup) -> Result<Startup, StartupError> {
        if let Some(i) = text.find(['\n', '\r']) {
            return Err(StartupError {
                col: col_of(text, i),
                message: "start-up modes are one line".into(),
            });
        }
        let plain = Setup::default();
        let mut parser = Parser::new(&plain);
        let mut interp = Interp::new(StrLines::new(text), &plain);
        let mut words = Vec::new();
        let read = interp.next(&mut parser, &mut words).map_err(from_parse)?;
        if !read {
            words.clear();
        }
        let mut has_g64 = false;
        for w in &words {
            let allowed = match w.letter {
                'G' => is_startup_code(w.value),
                'P' | 'Q' => true,
                _ => false,
            };
            if !allowed {
                return Err(StartupError {
                    col: w.pos.col,
                    message: format!(
                        "{}{}: start-up modes hold only codes that set a mode ({STARTUP_CODES})",
                        w.letter, w.value
                    ),
                });
            }
            has_g64 |= w.letter == 'G' && w.value == 64.0;
        }
        if let Some(w) = words.iter().find(|w| matches!(w.letter, 'P' | 'Q')) {
            if !has_g64 {
                return Err(StartupError {
                    col: w.pos.col,
                    message: format!("{}{}: P and Q go only with G64", w.letter, w.value),
                });
            }
        }
        let startup = Startup {
            text: text.trim().to_owned(),
            words,
        };
        // Applied as a program's first line would be: a mode twice, an undefined work offset.
        let mut check = Parser::new(setup);
        check.line(&startup.words).map_err(from_parse)?;
        debug_assert!(check.blocks.is_empty());
        Ok(startup)
    }
}

fn is_startup_code(v: f64) -> bool {
    const CODES: [f64; 24] = [
        8.0, 17.0, 18.0, 19.0, 20.0, 21.0, 40.0, 49.0, 54.0, 55.0, 56.0, 57.0, 58.0, 59.0, 61.0,
        61.1, 64.0, 80.0, 90.0, 91.0, 90.1, 91.1, 93.0, 94.0,
    ];
    CODES.contains(&v) || v == 98.0 || v == 99.0
}

fn col_of(text: &str, byte: usize) -> u32 {
    u32::try_from(text[..byte].chars().count() + 1).unwrap_or(u32::MAX)
}

fn from_parse(e: ParseError) -> StartupError {
    StartupError {
        col: e.pos.col,
        message: e.kind.to_string(),
    }
}
