//! Runs of G01 moves in a program's text, and the program with each run fitted into one
//! G06.5 block ([`fit_program`]).
//!
//! A run is a sequence of `G01` moves on consecutive lines that hold nothing else (no
//! comment, no other word), all at one feed and tool length, in absolute millimetres with
//! a feed per minute (`G90 G21 G94`) or in inverse time (`G93`: the moves' speeds within
//! [`super::find::INVERSE_FEED_SPREAD`]; the block is written in `G94` at the run's length
//! over its time, and `G93` is restored on a line after it), each moving the cutter and
//! turning the tool by at most [`super::find::MAX_TURN_DEG`], with no corner sharper than
//! the corner angle between two moves. It starts where the move before it ends (that move must be a
//! `G00`/`G01`). Every other line is written as it was; so is a run the fit cannot bring
//! within the tolerances (it is counted).
//!
//! The modes after a block are those after its moves: a run begins where the modal motion
//! is already `G01`; a block fitted to moves given in machine angles is followed by a line
//! that gives both angles (after a `G06.5` block the tool axis is modal as a vector, and a
//! move that gives one angle, or a `G28` with the table tilted, would be refused): the
//! line after the run; or, where that line is a move of its own that leaves an angle
//! modal, that move with the angle written out ([`with_angles`]); or else a move of the
//! run kept as written. Work offsets are left out of the parse (the program's own numbers
//! are written back, and the offsets apply to them at run time as they did to the moves).

use super::find::{find_runs, moves_in, Found};
use super::Fitted;
use crate::options::{Options, TOOL_MM};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::{Block, Orientation, Program};
use nc_lang::MM_PER_INCH;
use std::fmt::Write;

/// One run, where it stands in the text, and what became of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// Source lines of its first and last move (1-based).
    pub lines: (u32, u32),
    pub found: Found,
}

/// What [`fit_program`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// Motion blocks (`G00`, `G01`, arcs, NURBS) in and out.
    pub blocks_in: usize,
    pub blocks_out: usize,
    /// `G01` moves in, and those now inside a G06.5 block.
    pub moves_in: usize,
    pub moves_fitted: usize,
    /// G06.5 blocks written.
    pub fitted_blocks: usize,
    /// Runs of at least `min_moves` the fit could not bring within tolerance (kept as G01).
    pub runs_kept: usize,
    pub bytes_in: usize,
    pub bytes_out: usize,
    /// The largest deviations the fit itself measured at the points (mm, degrees).
    pub fit_mm: f64,
    pub fit_deg: f64,
}

/// The fitted program.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOutput {
    pub text: String,
    pub runs: Vec<Run>,
    pub summary: Summary,
}

/// Modal state at the start of each line: whether a run may be written there (`G90`, `G21`
/// and `G94` or `G93` in effect), whether the modal motion is `G01` (a run that begins
/// where it is not, with a `G01` word of its own, would leave the motion mode changed once
/// that word is gone), whether feeds are inverse time, and the program's tilt letter.
fn modes(src: &str) -> Vec<(LineModes, Option<char>)> {
    let mut modes = Modes::default();
    src.split('\n')
        .map(|line| {
            let at = modes.line(line);
            (at, modes.tilt)
        })
        .collect()
}

/// The modes in effect at the start of a line.
#[derive(Clone, Copy, Debug)]
pub(super) struct LineModes {
    /// `G90`, `G21`, and `G94` or `G93`: a run may be written there.
    pub plain: bool,
    /// The modal motion is `G01`.
    pub g01: bool,
    /// The modal feed per minute, mm/min (see [`Modes`]).
    pub g94_feed: Option<f64>,
}

/// The modes [`modes`] follows, a line at a time.
#[derive(Clone, Copy, Debug)]
pub(super) struct Modes {
    abs: bool,
    mm: bool,
    /// The feed mode, in tenths: 940 (`G94`, per minute), 930 (`G93`, inverse time), 950.
    feed: u32,
    motion: u32,
    /// The letter of the program's first tilt word (`A` or `B`; the parser allows one).
    pub(super) tilt: Option<char>,
    /// The modal feed per minute (mm/min), the last `F` given under `G94`: under `G93` an
    /// `F` is its line's own and leaves it as it was.
    g94_feed: Option<f64>,
    /// Cutter radius compensation on (`G41`/`G42` until `G40`): its moves are left as they
    /// are (a G06.5 block is not compensated).
    comp: bool,
}

impl Default for Modes {
    fn default() -> Self {
        Modes {
            abs: true,
            mm: true,
            feed: 940,
            motion: 0,
            tilt: None,
            g94_feed: None,
            comp: false,
        }
    }
}

impl Modes {
    /// The modes at the start of `line`; then its G codes apply.
    pub(super) fn line(&mut self, line: &str) -> LineModes {
        let at_start = LineModes {
            plain: self.abs && self.mm && (self.feed == 940 || self.feed == 930) && !self.comp,
            g01: self.motion == 10,
            g94_feed: self.g94_feed,
        };
        let code = strip_comments(line);
        if self.tilt.is_none() {
            self.tilt = tilt_letter(&code);
        }
        for g in g_codes(&code) {
            match g {
                0 | 10 | 20 | 30 => self.motion = g,
                900 => self.abs = true,
                910 => self.abs = false,
                210 => self.mm = true,
                200 => self.mm = false,
                930 | 940 | 950 => self.feed = g,
                400 => self.comp = false,
                410 | 411 | 420 | 421 => self.comp = true,
                _ => {}
            }
        }
        // The line's G codes apply before its F, as the parser reads them.
        if self.feed == 940 {
            if let Some(f) = word_value(&code, 'F') {
                self.g94_feed = Some(if self.mm { f } else { f * MM_PER_INCH });
            }
        }
        at_start
    }
}

/// The G codes of a line (comments stripped), in tenths: `G91` is 910, `G06.5` 65.
fn g_codes(code: &str) -> impl Iterator<Item = u32> + '_ {
    code.char_indices()
        .filter(|(_, c)| c.eq_ignore_ascii_case(&'G'))
        .filter_map(|(i, _)| {
            let num: String = code[i + 1..]
                .trim_start()
                .chars()
                .take_while(|c| c.is_ascii_digit() || *c == '.')
                .collect();
            let x: f64 = num.parse().ok()?;
            let tenths = (x * 10.0).round();
            ((tenths - x * 10.0).abs() < 1e-6 && tenths < 10_000.0).then_some(tenths as u32)
        })
}

/// The value of the first `letter` word in `code`.
fn word_value(code: &str, letter: char) -> Option<f64> {
    let upper = code.to_ascii_uppercase();
    let at = upper.find(letter)?;
    let num: String = upper[at + 1..]
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || "+-.".contains(*c))
        .collect();
    num.parse().ok()
}

/// The letter of the first `A` or `B` word in `code`.
fn tilt_letter(code: &str) -> Option<char> {
    let mut chars = code.chars().peekable();
    while let Some(c) = chars.next() {
        let letter = c.to_ascii_uppercase();
        if letter == 'A' || letter == 'B' {
            while chars.peek() == Some(&' ') {
                chars.next();
            }
            if chars
                .peek()
                .is_some_and(|n| n.is_ascii_digit() || "+-.".contains(*n))
            {
                return Some(letter);
            }
        }
    }
    None
}

fn strip_comments(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut depth = 0;
    for ch in line.chars() {
        match ch {
            ';' if depth == 0 => break,
            '(' => depth += 1,
            ')' if depth > 0 => depth -= 1,
            _ if depth == 0 => out.push(ch),
            _ => {}
        }
    }
    out
}

/// A line that holds one linear move and nothing else: words N, G1/G01, X Y Z A B C I J K, F.
pub(super) fn pure_move_line(line: &str) -> bool {
    let mut chars = line.trim_end_matches('\r').chars().peekable();
    let mut words = 0;
    while let Some(ch) = chars.next() {
        if ch == ' ' || ch == '\t' {
            continue;
        }
        let letter = ch.to_ascii_uppercase();
        if !"NGXYZABCIJKF".contains(letter) {
            return false;
        }
        let mut num = String::new();
        while let Some(&c) = chars.peek() {
            if c.is_ascii_digit() || c == '.' || c == '-' || c == '+' || c == ' ' {
                if c != ' ' {
                    num.push(c);
                }
                chars.next();
                if c == ' ' && chars.peek().is_some_and(|c| c.is_ascii_alphabetic()) {
                    break;
                }
            } else {
                break;
            }
        }
        let Ok(x) = num.parse::<f64>() else {
            return false;
        };
        if letter == 'G' && x != 1.0 {
            return false;
        }
        words += 1;
    }
    words > 0
}

/// Whether `b` is a move whose tool axis the program gives by machine angles.
pub(super) fn in_angles(b: &Block) -> bool {
    matches!(b, Block::Linear(m) if matches!(m.orientation, Orientation::Angles { .. }))
}

/// Whether a line gives both machine angles (its tilt and its `C`). After a `G06.5` block
/// the tool axis is modal as a vector, and a move that gives one angle alone, or a `G28`
/// with the table tilted, is refused; so a block fitted to moves given in angles must be
/// followed by a line that gives both (the line after the run, a move after it written
/// with both, or the run's next move, kept as written).
pub(super) fn sets_angles(line: &str) -> bool {
    let code = strip_comments(line).to_ascii_uppercase();
    code.contains('C') && (code.contains('A') || code.contains('B'))
}

/// A block fitted to moves in angles may end before block `next` without a line that
/// gives both angles after it when `next` is a move in angles on a `plain` line of its
/// own (a pure move in plain modes): kept, it is written with both ([`with_angles`]).
pub(super) fn restorable(next: Option<&Block>, plain: bool) -> bool {
    plain && next.is_some_and(in_angles)
}

/// `line` (a plain move, without its ending) with the angle words it leaves modal written
/// out, from the values its block resolved: after a `G06.5` block the tool axis is modal
/// as a vector, so a move there must give both angles. `tilt`: the program's tilt letter.
pub(super) fn with_angles(line: &str, block: &Block, tilt: char) -> String {
    let Block::Linear(m) = block else {
        return line.to_owned();
    };
    let Orientation::Angles { r1_deg, r2_deg } = m.orientation else {
        return line.to_owned();
    };
    let code = strip_comments(line).to_ascii_uppercase();
    let (body, cr) = match line.strip_suffix('\r') {
        Some(body) => (body, "\r"),
        None => (line, ""),
    };
    let mut out = body.trim_end().to_owned();
    if tilt_letter(&code).is_none() {
        let _ = write!(out, " {tilt}{r1_deg}");
    }
    if !code.contains('C') {
        let _ = write!(out, " C{r2_deg}");
    }
    out.push_str(cr);
    out
}

/// The tilt letter to write: the program's, else the machine's.
pub(super) fn tilt_of(program: Option<char>, kin: &MachineKinematics) -> char {
    program.unwrap_or(match kin.tilt_kind() {
        nc_geom::kinematics::Tilt::A => 'A',
        nc_geom::kinematics::Tilt::B => 'B',
    })
}

/// Fit every run of `program` (parsed from `src` without work offsets).
pub fn fit_program(
    src: &str,
    program: &Program,
    kin: &MachineKinematics,
    opts: &Options,
) -> FitOutput {
    let lines: Vec<&str> = src.split('\n').collect();
    let modes = modes(src);
    let line_of = |b: usize| program.blocks[b].pos().line as usize;
    // The text's side of a run: a line of its own, in plain modes.
    let plain_line = |b: usize| {
        let l = line_of(b);
        l >= 1
            && lines.get(l - 1).is_some_and(|t| pure_move_line(t))
            && modes.get(l - 1).is_some_and(|m| m.0.plain)
    };
    let found = find_runs(
        program,
        kin,
        opts,
        |b| {
            let g01 = plain_line(b) && modes.get(line_of(b) - 1).is_some_and(|m| m.0.g01);
            g01.then_some(opts.tol)
        },
        |k| plain_line(k) && line_of(k) == line_of(k - 1) + 1,
        // The line after block k (the next move of the run, or the line after it).
        |k, _| {
            !in_angles(&program.blocks[k])
                || lines.get(line_of(k)).is_some_and(|t| sets_angles(t))
                || (k + 1 < program.blocks.len()
                    && line_of(k + 1) == line_of(k) + 1
                    && restorable(program.blocks.get(k + 1), plain_line(k + 1)))
        },
    );
    let mut summary = Summary {
        blocks_in: program.blocks.len(),
        moves_in: moves_in(program),
        bytes_in: src.len(),
        ..Summary::default()
    };
    let runs: Vec<Run> = found
        .into_iter()
        .map(|f| Run {
            lines: (line_of(f.blocks.0) as u32, line_of(f.blocks.1) as u32),
            found: f,
        })
        .collect();
    let mut text = String::with_capacity(src.len() / 2);
    let mut next = 0;
    // The line after a block fitted to moves in angles, when it is a move that leaves an
    // angle modal: its index and the line as written then.
    let mut restore: Option<(usize, String)> = None;
    let line_at = |i: usize, restore: &Option<(usize, String)>| match restore {
        Some((r, written)) if *r == i => written.clone(),
        _ => lines[i].to_owned(),
    };
    for run in &runs {
        let Some(f) = &run.found.fitted else {
            summary.runs_kept += 1;
            continue;
        };
        let (l0, l1) = (run.lines.0 as usize, run.lines.1 as usize);
        for i in next..l0 - 1 {
            text.push_str(&line_at(i, &restore));
            text.push('\n');
        }
        let n_word = n_word(lines[l0 - 1]);
        // The block's lines end as its first move's line did.
        let eol = if lines[l0 - 1].ends_with('\r') {
            "\r\n"
        } else {
            "\n"
        };
        let g94_feed = modes.get(l0 - 1).and_then(|m| m.0.g94_feed);
        write_block(&mut text, f, &run.found, n_word.as_deref(), eol, g94_feed);
        next = l1;
        let k = run.found.blocks.1;
        restore = (in_angles(&program.blocks[k])
            && !lines.get(l1).is_some_and(|t| sets_angles(t))
            && k + 1 < program.blocks.len()
            && line_of(k + 1) == l1 + 1
            && restorable(program.blocks.get(k + 1), plain_line(k + 1)))
        .then(|| {
            let tilt = tilt_of(modes.get(l1).and_then(|m| m.1), kin);
            (l1, with_angles(lines[l1], &program.blocks[k + 1], tilt))
        });
        summary.fitted_blocks += 1;
        summary.moves_fitted += l1 + 1 - l0;
        summary.fit_mm = summary.fit_mm.max(f.dev_mm);
        summary.fit_deg = summary.fit_deg.max(f.dev_rad.to_degrees());
    }
    let from = next.min(lines.len());
    for i in from..lines.len() {
        text.push_str(&line_at(i, &restore));
        if i + 1 < lines.len() {
            text.push('\n');
        }
    }
    summary.bytes_out = text.len();
    summary.blocks_out = summary.blocks_in - summary.moves_fitted + summary.fitted_blocks;
    FitOutput {
        text,
        runs,
        summary,
    }
}

/// The line's `N` word, if it starts with one.
pub(super) fn n_word(line: &str) -> Option<String> {
    let t = line.trim_start();
    let rest = t.strip_prefix(['N', 'n'])?;
    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
    (!digits.is_empty()).then(|| format!("N{digits}"))
}

/// A number with up to six decimals, no trailing zeros.
fn num(x: f64) -> String {
    let s = format!("{x:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_owned()
    } else {
        s.to_owned()
    }
}

/// Run `found`'s block, fitted as `f`. A run programmed in inverse time (`G93`) is written
/// at its length over its time in `G94`; after it, the feed per minute in effect before
/// it (`g94_feed`, which its `F` replaced) and then `G93` are restored, each on a line.
pub(super) fn write_block(
    out: &mut String,
    f: &Fitted,
    found: &Found,
    n: Option<&str>,
    eol: &str,
    g94_feed: Option<f64>,
) {
    let (p, feed) = (f.degree, found.feed_mm_min);
    let inverse = found.inverse_minutes.is_some();
    for (i, (c, t)) in f.ctrl.iter().zip(&f.tool).enumerate() {
        if i == 0 {
            if let Some(n) = n {
                let _ = write!(out, "{n} ");
            }
            if inverse {
                out.push_str("G94 ");
            }
            let _ = write!(out, "G06.5 P{p} ");
        }
        let _ = write!(
            out,
            "X{} Y{} Z{} U{} V{} W{} K{}",
            num(c[0]),
            num(c[1]),
            num(c[2]),
            num(c[0] + TOOL_MM * t[0]),
            num(c[1] + TOOL_MM * t[1]),
            num(c[2] + TOOL_MM * t[2]),
            knot(f.knots[i])
        );
        if i == 0 {
            let _ = write!(out, " F{}", num(feed));
        }
        out.push_str(eol);
    }
    let tail: Vec<String> = f.knots[f.ctrl.len()..].iter().map(|&k| knot(k)).collect();
    let _ = write!(out, "K{}{eol}", tail.join(" K"));
    if inverse {
        if let Some(feed) = g94_feed {
            let _ = write!(out, "F{feed}{eol}");
        }
        let _ = write!(out, "G93{eol}");
    }
}

/// Knots with twelve significant decimals: the fit's parameters, not lengths.
fn knot(k: f64) -> String {
    let s = format!("{k:.12}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_owned()
}
