//! The program's words that drive no axis (spindle, coolant, tools, stops, dwells), as the
//! lines `simulate` and `run` report. The machines dnurbs drives have no spindle or coolant
//! drive yet, so these are reported, never silently dropped.

use nc_fit::options::PROGRAM_TOL_MM;
use nc_geom::program::{
    Action, ActionKind, Coolant, Input, Merge, PathMode, Program, Spindle, UserAction, WaitMode,
};

/// What a path-control mode does to the path: dnurbs blends no corner; the on-line
/// compressor follows the naive-CAM tolerance ([`nc_fit::options::Policy`]).
fn path_mode(mode: PathMode) -> String {
    let (p_mm, q_mm) = match mode {
        PathMode::Exact => {
            return "G61/G61.1 exact path: the on-line compressor merges no move after it"
                .to_owned()
        }
        PathMode::Blend { p_mm, q_mm } => (p_mm, q_mm),
    };
    let word = |l: &str, v: Option<f64>| v.map(|v| format!(" {l}{v} mm")).unwrap_or_default();
    let code = format!("G64{}{}", word("P", p_mm), word("Q", q_mm));
    let blend = if p_mm.is_some() {
        "; corners are not blended, dnurbs follows them exactly"
    } else {
        ""
    };
    let (lo, hi) = (*PROGRAM_TOL_MM.start(), *PROGRAM_TOL_MM.end());
    let merge = match mode.merge() {
        Merge::Off => "the on-line compressor merges no move after it".to_owned(),
        Merge::Machine => {
            "the on-line compressor after it as the machine file or --compress sets it".to_owned()
        }
        Merge::Within(mm) if mm < lo => format!(
            "below the compressor's closest tolerance ({lo} mm): the moves after it run as programmed"
        ),
        Merge::Within(mm) if mm > hi => format!(
            "the on-line compressor merges runs of moves after it within {hi} mm, its largest tolerance (not with --no-compress)"
        ),
        Merge::Within(mm) => format!(
            "the on-line compressor merges runs of moves after it within {mm} mm (not with --no-compress)"
        ),
    };
    format!("{code}: {merge}{blend}")
}

/// One line per action: `line:col  word  what it does`.
pub fn describe(program: &Program) -> Vec<String> {
    program.actions.iter().map(describe_action).collect()
}

/// One action's line: `line:col  word  what it does`.
pub fn describe_action(a: &Action) -> String {
    {
        {
            let what = match a.kind {
                ActionKind::Spindle { dir, rpm } => match dir {
                    Spindle::Cw => format!("M03 spindle clockwise at S{rpm}"),
                    Spindle::Ccw => format!("M04 spindle counter-clockwise at S{rpm}"),
                    Spindle::Off => "M05 spindle stop".to_owned(),
                },
                ActionKind::Speed { rpm } => format!("S{rpm} spindle speed"),
                ActionKind::Coolant(c) => match c {
                    Coolant::Mist => "M07 mist coolant on".to_owned(),
                    Coolant::Flood => "M08 flood coolant on".to_owned(),
                    Coolant::Off => "M09 coolant off".to_owned(),
                },
                ActionKind::SelectTool { tool } => format!("T{tool} tool selected"),
                ActionKind::ChangeTool { tool } => {
                    let t = tool.map_or("no tool selected".to_owned(), |t| format!("T{t}"));
                    if a.before_block == 0 {
                        format!(
                            "M06 tool change ({t}) before the first move: loaded at cycle start"
                        )
                    } else {
                        format!("M06 tool change ({t}): the path stops for the operator")
                    }
                }
                ActionKind::Dwell { seconds } => format!("G04 dwell {seconds} s"),
                ActionKind::Stop => "M00 program stop: the path stops for the operator".to_owned(),
                ActionKind::OptionalStop { taken: true } => {
                    "M01 optional stop (on): the path stops for the operator".to_owned()
                }
                ActionKind::OptionalStop { taken: false } => {
                    "M01 optional stop (off: passed)".to_owned()
                }
                ActionKind::DigitalOutput { index, on, synced } => {
                    let code = match (on, synced) {
                        (true, true) => "M62",
                        (false, true) => "M63",
                        (true, false) => "M64",
                        (false, false) => "M65",
                    };
                    let state = if on { "on" } else { "off" };
                    let when = if synced {
                        "as the next move starts"
                    } else {
                        "at once"
                    };
                    format!("{code} P{index} digital output {index} {state} {when} (the machine file's [io]: a bit of its I/O module on a bus, else simulated)")
                }
                ActionKind::AnalogOutput {
                    index,
                    value,
                    synced,
                } => {
                    let code = if synced { "M67" } else { "M68" };
                    format!("{code} E{index} Q{value} analog output {index} set (simulated: the machine file's [io])")
                }
                ActionKind::WaitInput {
                    input,
                    mode,
                    timeout_s,
                } => {
                    let which = match input {
                        Input::Digital(n) => format!("P{n} digital input {n}"),
                        Input::Analog(n) => format!("E{n} analog input {n}"),
                    };
                    let how = match mode {
                        WaitMode::Immediate => "read at once",
                        WaitMode::Rise => "wait for a rise",
                        WaitMode::Fall => "wait for a fall",
                        WaitMode::High => "wait until high",
                        WaitMode::Low => "wait until low",
                    };
                    let wait = if mode == WaitMode::Immediate {
                        "(what it reads is refused: dnurbs plans ahead)"
                    } else {
                        "(the path waits at rest: on a bus the I/O module's input answers, on a simulated machine at once; at the timeout the path goes on)"
                    };
                    format!("M66 {which}: {how}, at most {timeout_s} s {wait}")
                }
                ActionKind::FeedClamped {
                    programmed_mm_min,
                    used_mm_min,
                } => format!(
                    "F{programmed_mm_min} mm/min is above the machine's max_feed_mm_min: feed moves run at {used_mm_min} mm/min"
                ),
                ActionKind::PathMode(mode) => path_mode(mode),
                ActionKind::UserM { code, action } => match action {
                    UserAction::Ignore => {
                        format!("M{code} ignored, as the machine file's [mcodes] says")
                    }
                    UserAction::TcpOn => format!(
                        "M{code} tool-centre-point control on (the machine file's [mcodes]; dnurbs places the tool tip on its trunnion machines anyway)"
                    ),
                    UserAction::TcpOff => format!(
                        "M{code} tool-centre-point control off (the machine file's [mcodes]): moves keep the rotary axes at 0 from here"
                    ),
                    UserAction::Stop => format!(
                        "M{code} program stop (the machine file's [mcodes]): the path stops for the operator"
                    ),
                    UserAction::Output { index, on } => format!(
                        "M{code} digital output {index} {} (the machine file's [mcodes]: as M6{} P{index})",
                        if on { "on" } else { "off" },
                        if on { 2 } else { 3 }
                    ),
                    UserAction::Wait { input, mode, timeout_s } => format!(
                        "M{code} waits for digital input {input} (the machine file's [mcodes]: as M66 P{input} L{} Q{timeout_s})",
                        match mode {
                            WaitMode::Rise => 1,
                            WaitMode::Fall => 2,
                            WaitMode::High => 3,
                            _ => 4,
                        }
                    ),
                },
            };
            format!("{}  {what}", a.pos)
        }
    }
}

/// The report's section: a heading and the lines, or nothing.
pub fn text(words: &[String]) -> String {
    if words.is_empty() {
        return String::new();
    }
    let mut s = format!(
        "program words without axes: {} (spindle and coolant words drive the machine's [spindle] \
         and [coolant] where it has them, and are only reported where it has not)\n",
        words.len()
    );
    for w in words {
        s.push_str("  ");
        s.push_str(w);
        s.push('\n');
    }
    s
}

/// A program's entries, each action's line ([`describe_action`]) added to `words` on the
/// way: the words of a program that is read as it is planned.
pub struct Noted<'w, E> {
    inner: E,
    words: &'w mut Vec<String>,
}

impl<'w, E> Noted<'w, E> {
    pub fn new(inner: E, words: &'w mut Vec<String>) -> Self {
        Noted { inner, words }
    }
}

impl<E: nc_plan::stream::ProgramSource> Iterator for Noted<'_, E> {
    type Item = <E as Iterator>::Item;

    fn next(&mut self) -> Option<Self::Item> {
        let e = self.inner.next();
        if let Some(Ok(nc_lang::Entry::Action(a))) = &e {
            self.words.push(describe_action(a));
        }
        e
    }
}

impl<E: nc_plan::stream::ProgramSource> nc_plan::stream::ProgramSource for Noted<'_, E> {
    fn tilt_word(&self) -> Option<(char, nc_geom::program::SrcPos)> {
        self.inner.tilt_word()
    }
}
