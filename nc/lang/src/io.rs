//! `M62`..`M68` (the machine's inputs and outputs) and the M-codes a machine defines
//! (`[mcodes]`), recorded as actions before the next move.
//!
//! - `M62 P<n>` / `M63 P<n>`: digital output `n` on / off as the next move starts;
//!   `M64` / `M65` the same at once (dnurbs records both before the next move: the path does
//!   not stop for either).
//! - `M66 P<n> | E<n> L<mode> Q<s>`: wait for digital input `n` (or analog `E<n>` with `L0`);
//!   `L0` reads at once, `L1`..`L4` wait for a rise, a fall, high, low, at most `Q` seconds.
//!   What it read (`#5399`) is refused: dnurbs plans ahead of the machine.
//! - `M67 E<n> Q<v>` / `M68 E<n> Q<v>`: analog output `n` set to `v`, synced / at once.
//!
//! An index beyond what the machine file's `[io]` gives is refused with its column, as is a
//! word another code of the line takes too (`G04 P1 M64 P2`).

use super::codes::{Code, IoCode};
use super::error::{ParseError, ParseErrorKind};
use super::line::Line;
use super::parser::Parser;
use crate::vocab::Motion;
use nc_geom::program::{ActionKind, Input, Orientation, SrcPos, UserAction, WaitMode};

/// Longest `M66` wait, s.
const MAX_WAIT_S: f64 = 3600.0;

impl IoCode {
    /// The letters this code reads.
    pub(crate) fn letters(self) -> &'static str {
        match self {
            IoCode::DigitalOn { .. } | IoCode::DigitalOff { .. } => "P",
            IoCode::Wait => "PELQ",
            IoCode::Analog { .. } => "EQ",
        }
    }
}

impl Parser<'_> {
    /// The line's `M62`..`M68`, if any.
    pub(super) fn io(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let Some((Code::Io(code), pos)) = line.code_of_group(16) else {
            return Ok(());
        };
        let value = code.value();
        shared(line, code)?;
        let io = self.setup.io;
        let index = |letter: char, count: u8, what: &'static str| -> Result<u8, ParseError> {
            let w = line.get(letter).ok_or(
                ParseErrorKind::IoWordMissing {
                    code: value,
                    letter,
                }
                .at(pos),
            )?;
            match super::word::as_uint(w.value) {
                Some(n) if n < u32::from(count) => Ok(n as u8),
                _ => Err(ParseErrorKind::NoSuchIo {
                    code: value,
                    letter,
                    value: w.value,
                    count,
                    what,
                }
                .at(w.pos)),
            }
        };
        let kind = match code {
            IoCode::DigitalOn { synced } | IoCode::DigitalOff { synced } => {
                let index = index('P', io.digital_outputs, "digital_outputs")?;
                let on = matches!(code, IoCode::DigitalOn { .. });
                ActionKind::DigitalOutput { index, on, synced }
            }
            IoCode::Analog { synced } => {
                let index = index('E', io.analog_outputs, "analog_outputs")?;
                let q = line.get('Q').ok_or(
                    ParseErrorKind::IoWordMissing {
                        code: value,
                        letter: 'Q',
                    }
                    .at(pos),
                )?;
                ActionKind::AnalogOutput {
                    index,
                    value: q.value,
                    synced,
                }
            }
            IoCode::Wait => {
                let mode = match line.get('L').map(|w| (w, super::word::as_uint(w.value))) {
                    None | Some((_, Some(0))) => WaitMode::Immediate,
                    Some((_, Some(1))) => WaitMode::Rise,
                    Some((_, Some(2))) => WaitMode::Fall,
                    Some((_, Some(3))) => WaitMode::High,
                    Some((_, Some(4))) => WaitMode::Low,
                    Some((w, _)) => {
                        return Err(ParseErrorKind::BadWaitMode { value: w.value }.at(w.pos))
                    }
                };
                let input = match (line.get('P'), line.get('E')) {
                    (Some(_), Some(e)) => {
                        let kind = ParseErrorKind::WordShared {
                            letter: 'E',
                            first_letter: 'M',
                            first: 66.0,
                            second_letter: 'M',
                            second: 66.0,
                        };
                        return Err(kind.at(e.pos));
                    }
                    (_, Some(_)) => Input::Analog(index('E', io.analog_inputs, "analog_inputs")?),
                    _ => Input::Digital(index('P', io.digital_inputs, "digital_inputs")?),
                };
                if let (Input::Analog(_), false) = (input, mode == WaitMode::Immediate) {
                    let l = line.value('L').unwrap_or(0.0) as u8; // 1..=4 here
                    return Err(ParseErrorKind::AnalogWait { mode: l }.at(pos));
                }
                let timeout_s = match line.get('Q') {
                    Some(q) if (0.0..=MAX_WAIT_S).contains(&q.value) => q.value,
                    Some(q) => {
                        return Err(ParseErrorKind::BadWaitTimeout { value: q.value }.at(q.pos))
                    }
                    None => 0.0,
                };
                if timeout_s == 0.0 && mode != WaitMode::Immediate {
                    let l = line.value('L').unwrap_or(0.0) as u8; // 1..=4 here
                    return Err(ParseErrorKind::ZeroWaitTimeout { mode: l }.at(pos));
                }
                ActionKind::WaitInput {
                    input,
                    mode,
                    timeout_s,
                }
            }
        };
        self.act(pos, kind);
        Ok(())
    }

    /// The line's machine-defined M-code, if any.
    pub(super) fn user_m(&mut self, line: &Line<'_>) -> Result<(), ParseError> {
        let Some((Code::User(code), pos)) = line.code_of_group(17) else {
            return Ok(());
        };
        let Some(&action) = self.setup.user_mcodes.get(&code) else {
            return Ok(()); // classified only when the machine defines it
        };
        match action {
            UserAction::TcpOn => {
                self.modal.tcp_off = None;
                self.modal.tcp_on = true;
            }
            UserAction::TcpOff => {
                self.modal.tcp_off = Some(code);
                self.modal.tcp_on = false;
            }
            UserAction::Ignore | UserAction::Stop => {}
            UserAction::Output { .. } | UserAction::Wait { .. } => {}
        }
        self.act(pos, ActionKind::UserM { code, action });
        // An output or a wait is then the action its M62/M63/M66 would be.
        match action {
            UserAction::Output { index, on } => {
                self.user_io(code, pos, index, self.setup.io.digital_outputs)?;
                self.act(
                    pos,
                    ActionKind::DigitalOutput {
                        index,
                        on,
                        synced: true,
                    },
                );
            }
            UserAction::Wait {
                input,
                mode,
                timeout_s,
            } => {
                self.user_io(code, pos, input, self.setup.io.digital_inputs)?;
                let input = Input::Digital(input);
                self.act(
                    pos,
                    ActionKind::WaitInput {
                        input,
                        mode,
                        timeout_s,
                    },
                );
            }
            _ => {}
        }
        if action == UserAction::Stop && self.wait.operator.is_none() {
            self.wait.operator = Some(pos);
        }
        Ok(())
    }

    /// A machine-defined M-code's output or input `n` is one of the machine's `count` (the
    /// machine file checks it; a setup built otherwise is checked here).
    fn user_io(&self, code: u32, pos: SrcPos, n: u8, count: u8) -> Result<(), ParseError> {
        if n < count {
            return Ok(());
        }
        let kind = ParseErrorKind::NoSuchIo {
            code: f64::from(code),
            letter: 'P',
            value: f64::from(n),
            count,
            what: "digital_outputs or digital_inputs",
        };
        Err(kind.at(pos))
    }

    /// After a move with tool-centre-point control off: the rotary axes must be at 0.
    pub(super) fn check_tcp_off(&self, pos: SrcPos) -> Result<(), ParseError> {
        let Some(code) = self.modal.tcp_off else {
            return Ok(());
        };
        let (r1, r2) = match self.orientation {
            Orientation::Angles { r1_deg, r2_deg } => (r1_deg, r2_deg),
            Orientation::Vector([x, y, _]) if x == 0.0 && y == 0.0 => (0.0, 0.0),
            Orientation::Vector(_) => (f64::NAN, f64::NAN),
        };
        if r1 == 0.0 && r2 == 0.0 {
            return Ok(());
        }
        Err(ParseErrorKind::TcpOffTurned { code, r1, r2 }.at(pos))
    }
}

/// A letter of `code` another code of the line takes too.
fn shared(line: &Line<'_>, code: IoCode) -> Result<(), ParseError> {
    let mut others: Vec<(char, f64, &str)> = Vec::new();
    if let Some((Code::Dwell, _)) = line.code_of_group(1) {
        others.push(('G', 4.0, "P"));
    }
    if let Some((Code::Blend(true), _)) = line.code_of_group(10) {
        others.push(('G', 64.0, "PQ"));
    }
    match line.motion {
        Some((Motion::Cycle(c), _)) => others.push(('G', c.code(), "PQL")),
        Some((m @ (Motion::G02 | Motion::G03), _)) => {
            others.push(('G', if m == Motion::G02 { 2.0 } else { 3.0 }, "P"));
        }
        Some((Motion::G062, _)) => others.push(('G', 6.2, "P")),
        _ => {}
    }
    for letter in code.letters().chars() {
        let Some(w) = line.get(letter) else { continue };
        if let Some(&(first_letter, first, _)) = others.iter().find(|o| o.2.contains(letter)) {
            let kind = ParseErrorKind::WordShared {
                letter,
                first_letter,
                first,
                second_letter: 'M',
                second: code.value(),
            };
            return Err(kind.at(w.pos));
        }
    }
    Ok(())
}
