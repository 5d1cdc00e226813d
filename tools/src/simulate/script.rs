//! `simulate --operator SCRIPT`: the operator's actions, one a line, in the order they are
//! taken:
//!
//! ```text
//! # comments and blank lines are skipped
//! at 2.31s pause          # at a time from the start of the program
//! after 1.5s resume       # that long after the action before it
//! at line 40 override 30  # once the tool machines that source line (override 0..=100 %)
//! at 3s stop
//! ```
//!
//! Each action waits for the one before it: the script is a sequence, as an operator's
//! hand is.

/// When an action is taken.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum When {
    /// At this time from the start, s.
    At(f64),
    /// This long after the action before it (from the start for the first), s.
    After(f64),
    /// Once the tool machines this source line (or a later one).
    Line(u32),
}

/// What the operator does.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Act {
    Pause,
    Resume,
    Stop,
    /// Feed override, percent.
    Override(u8),
}

/// One line of the script.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Action {
    pub when: When,
    pub act: Act,
    /// Its line in the script.
    pub line: usize,
}

/// Longest time a script may name, s (a day).
const MAX_S: f64 = 86_400.0;

/// The script's actions, or `line: what is wrong` for its first bad line.
pub fn parse(text: &str) -> Result<Vec<Action>, String> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let words: Vec<&str> = raw
            .split('#')
            .next()
            .unwrap_or("")
            .split_whitespace()
            .collect();
        if words.is_empty() {
            continue;
        }
        let bad = |what: &str| format!("line {line}: {what} (in {raw:?})");
        let seconds = |w: &str| -> Result<f64, String> {
            let v = w.strip_suffix('s').unwrap_or(w);
            match v.parse::<f64>() {
                Ok(t) if (0.0..=MAX_S).contains(&t) => Ok(t),
                _ => Err(bad(&format!("{w:?} is not a time 0..={MAX_S}s"))),
            }
        };
        let (when, rest) = match words[..] {
            ["at", "line", n, ref rest @ ..] => {
                let n = n
                    .parse::<u32>()
                    .ok()
                    .filter(|&n| n > 0)
                    .ok_or_else(|| bad(&format!("{n:?} is not a source line")))?;
                (When::Line(n), rest)
            }
            ["at", t, ref rest @ ..] => (When::At(seconds(t)?), rest),
            ["after", t, ref rest @ ..] => (When::After(seconds(t)?), rest),
            _ => {
                return Err(bad(
                    "an action starts with `at <time>s`, `after <time>s` or `at line <n>`",
                ))
            }
        };
        let act = match rest {
            ["pause"] => Act::Pause,
            ["resume"] => Act::Resume,
            ["stop"] => Act::Stop,
            ["override", p] => {
                let p = p.strip_suffix('%').unwrap_or(p);
                match p.parse::<u8>() {
                    Ok(p) if p <= 100 => Act::Override(p),
                    _ => return Err(bad(&format!("override {p:?} is not a percentage 0..=100"))),
                }
            }
            _ => {
                return Err(bad(
                    "the action is pause, resume, stop or override <percent>",
                ))
            }
        };
        out.push(Action { when, act, line });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_script_reads_as_its_documentation_says() {
        let s = "# a session\nat 2.31s pause\nafter 1.5s resume\n\nat line 40 override 30%\nat 3 stop # done\n";
        let a = parse(s).unwrap();
        assert_eq!(
            a.iter()
                .map(|a| (a.when, a.act, a.line))
                .collect::<Vec<_>>(),
            [
                (When::At(2.31), Act::Pause, 2),
                (When::After(1.5), Act::Resume, 3),
                (When::Line(40), Act::Override(30), 5),
                (When::At(3.0), Act::Stop, 6),
            ]
        );
        for (bad, says) in [
            ("at 2s jump\n", "line 1: the action is"),
            ("at -1s pause\n", "not a time"),
            ("at line 0 stop\n", "not a source line"),
            ("at 1s override 120\n", "0..=100"),
            ("pause\n", "starts with"),
        ] {
            let e = parse(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }
}
