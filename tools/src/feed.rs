//! The planner thread of `dnurbs run` and `dnurbs demo`: the program read, built, planned
//! and cut into chunks a line at a time ([`nc_plan::stream::Source`]), pushed into the queue as
//! the real-time thread frees room, so memory does not grow with the program and motion
//! starts once the first window is planned.
//!
//! **What is checked before motion.** A program of at most [`CHECK_WHOLE_BYTES`] is read
//! through the pre-pass ([`nc_plan::prepass`]: syntax, geometry, the travel at every programmed
//! point) from its first line to its last before anything moves, as `dnurbs check` does: an
//! error there is exit 2 with nothing touched. A longer one starts after its first window
//! (checked at the period like every window) while the pre-pass reads the rest beside the
//! planner. An error either of them meets ahead of the tool stops the tool along the path
//! (`Feeder::refuse`), disables the drives and ends the run with exit 2, the file, line and
//! reason in the report.

use crate::exit::InputError;
use crate::setup::MachineSetup;
use nc_fit::online::Compressing;
use nc_follow::{Chunk, Feeder, Start};
use nc_geom::kinematics::Joints;
use nc_geom::program::Action;
use nc_lang::{Entries, LineSource, ReadLines};
use nc_plan::stream::{ProgramSource, Source, StreamError};
use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, SyncSender};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// When the planner thread takes its next round (free what came back, push what fits).
pub enum Pace {
    /// Every millisecond, until the run is over (`finished`).
    Wall(Arc<AtomicBool>),
    /// When the simulated machine asks, once a period: a round per message on `go`,
    /// answered on `done`, until the machine hangs up. The planner and the loop then take
    /// turns as the loop and the drives do ([`crate::run::simulated`]).
    Lockstep {
        go: Receiver<()>,
        done: SyncSender<()>,
    },
}

impl Pace {
    /// Wait for the next round; `false` once the run is over.
    fn next_round(&mut self) -> bool {
        match self {
            Pace::Wall(finished) => !finished.load(Ordering::Acquire),
            Pace::Lockstep { go, .. } => go.recv().is_ok(),
        }
    }

    /// The round is done.
    fn round_done(&mut self) {
        match self {
            Pace::Wall(_) => std::thread::sleep(Duration::from_millis(1)),
            Pace::Lockstep { done, .. } => {
                let _ = done.send(());
            }
        }
    }
}

/// Programs up to this size are checked whole before anything moves (about 130 000 lines
/// of a CAM post, read in 0.1 to 0.2 s at the pre-pass's 0.6 to 1.25 M lines a second).
pub const CHECK_WHOLE_BYTES: u64 = 8 << 20;

/// Words without axes kept for the report; more are counted.
const MAX_WORDS: usize = 1000;

/// Where the program comes from.
#[derive(Clone, Debug)]
pub enum Input {
    /// Its text in memory (the demo's built-in program, the tests).
    Text(Arc<[u8]>),
    /// A file, read a line at a time.
    File(PathBuf),
}

/// What the planner thread hands the run before anything moves.
#[derive(Clone, Debug)]
pub struct Ready {
    pub start: Start,
    /// How long the first window took to plan, from the thread's start (the pre-pass, when
    /// the program is checked whole, included).
    pub first_window_s: f64,
    /// The program was checked whole before motion.
    pub checked_whole: bool,
}

/// What the planner thread learns as it reads, for the report.
#[derive(Debug, Default)]
pub struct Learned {
    /// The program's end joints, once the pre-pass has read it all.
    pub end_joints: OnceLock<Joints>,
    /// The program's lines, once the pre-pass has read it all.
    pub lines: OnceLock<u32>,
    /// Why the program was refused ahead of the tool (`file:line:col: reason`).
    pub refusal: Mutex<Option<(u32, String)>>,
    /// Words without axes (spindle, coolant, tools, stops, dwells) and how many more.
    pub words: Mutex<(Vec<String>, usize)>,
    /// The line of the last block the planner read (what an internal error names).
    pub planning_line: AtomicU32,
    /// What on-line compression has done so far, when it is on (all of it once the planner
    /// has read the program to its end).
    pub compressed: Mutex<Option<crate::simulate::Compression>>,
}

impl Learned {
    fn refuse(&self, line: u32, why: String) {
        let mut r = self.refusal.lock().unwrap_or_else(|e| e.into_inner());
        r.get_or_insert((line, why));
    }

    /// The first refusal, if any.
    pub fn refusal(&self) -> Option<(u32, String)> {
        self.refusal
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// What on-line compression has done so far, when it is on.
    pub fn compressed(&self) -> Option<crate::simulate::Compression> {
        *self.compressed.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The words, with a last line for those not kept.
    pub fn words(&self) -> Vec<String> {
        let w = self.words.lock().unwrap_or_else(|e| e.into_inner());
        let mut out = w.0.clone();
        if w.1 > 0 {
            out.push(format!("... and {} more", w.1));
        }
        out
    }
}

/// A program's entries, its actions noted for the report on the way.
struct Noting<'l, E> {
    inner: E,
    learned: &'l Learned,
}

impl<E: ProgramSource> Iterator for Noting<'_, E> {
    type Item = <E as Iterator>::Item;

    fn next(&mut self) -> Option<Self::Item> {
        let e = self.inner.next();
        match &e {
            Some(Ok(nc_lang::Entry::Action(a))) => note(self.learned, a),
            Some(Ok(nc_lang::Entry::Block(_, b))) => {
                self.learned
                    .planning_line
                    .store(b.pos().line, Ordering::Relaxed);
            }
            _ => {}
        }
        e
    }
}

impl<E: ProgramSource> ProgramSource for Noting<'_, E> {
    fn tilt_word(&self) -> Option<(char, nc_geom::program::SrcPos)> {
        self.inner.tilt_word()
    }
}

fn note(learned: &Learned, a: &Action) {
    let mut w = learned.words.lock().unwrap_or_else(|e| e.into_inner());
    if w.0.len() < MAX_WORDS {
        w.0.push(crate::words::describe_action(a));
    } else {
        w.1 += 1;
    }
}

/// The run's planner side: what it plans for and where its chunks go.
#[derive(Clone)]
pub struct Job {
    pub input: Input,
    /// The program's name in messages (its path).
    pub name: String,
    pub setup: MachineSetup,
    pub shop: nc_lang::Setup,
    pub depth: usize,
    /// A control socket serves the run (an operator stop can be resumed).
    pub control: bool,
}

impl Job {
    fn unreadable(&self, error: std::io::Error) -> InputError {
        InputError::ReadProgram {
            file: self.name.clone(),
            error,
        }
    }

    fn stream_error(&self, e: StreamError) -> InputError {
        InputError::stream(&self.name, e)
    }

    fn size(&self) -> Result<u64, InputError> {
        match &self.input {
            Input::Text(t) => Ok(t.len() as u64),
            Input::File(p) => std::fs::metadata(p)
                .map(|m| m.len())
                .map_err(|e| self.unreadable(e)),
        }
    }

    /// A fresh reader over the program's lines.
    fn lines(&self) -> Result<Box<dyn LineSource + Send>, InputError> {
        Ok(match &self.input {
            Input::Text(t) => Box::new(ReadLines::new(std::io::Cursor::new(Arc::clone(t)))),
            Input::File(p) => {
                let f = std::fs::File::open(p).map_err(|e| self.unreadable(e))?;
                Box::new(ReadLines::new(std::io::BufReader::with_capacity(
                    1 << 16,
                    f,
                )))
            }
        })
    }

    /// The pre-pass over the whole program.
    fn prepass(
        &self,
        lines: Box<dyn LineSource + Send>,
    ) -> Result<nc_plan::prepass::Passed, InputError> {
        let s = &self.setup;
        nc_plan::prepass::check(lines, &self.shop, &s.kin, &s.build, &s.plan.travel)
            .map_err(|e| self.refused(e))
    }

    /// The pre-pass's refusal as an input error naming the file.
    fn refused(&self, e: nc_plan::prepass::Refused) -> InputError {
        match e {
            nc_plan::prepass::Refused::Parse(errors) => InputError::Parse {
                file: self.name.clone(),
                errors,
            },
            other => InputError::Checked {
                file: self.name.clone(),
                error: other,
            },
        }
    }

    /// A program that stops for the operator needs someone to resume it.
    fn operator_reachable(&self, stop: Option<nc_geom::program::SrcPos>) -> Result<(), InputError> {
        match stop {
            Some(pos) if !self.control => Err(InputError::Usage(format!(
                "{}:{pos}: the program stops here for the operator (M00, M01 or M06) and \
                 only the control socket can resume it: run with --control SOCKET (or the \
                 machine file's [control] socket) and resume with `dnurbs ctl SOCKET resume`",
                self.name
            ))),
            _ => Ok(()),
        }
    }
}

/// The planner thread's body: check, plan the first window, say `ready`, then plan and push
/// chunks into `feeder`, a round at the `pace` asked, until the run is over.
pub fn plan_and_feed(
    job: &Job,
    mut feeder: Feeder,
    mut pace: Pace,
    ready: std::sync::mpsc::SyncSender<Result<Ready, InputError>>,
    learned: &Arc<Learned>,
) {
    // A panic here must not leave the tool holding for data that never comes: the run is
    // refused at the line being planned, and stops along the path. (Before the first
    // window the dropped sender ends the run: "the planner thread ended without a result".)
    let body =
        std::panic::AssertUnwindSafe(|| feed_program(job, &mut feeder, &mut pace, ready, learned));
    if let Err(panic) = std::panic::catch_unwind(body) {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let line = learned.planning_line.load(Ordering::Relaxed);
        learned.refuse(
            line,
            format!("{}:{line}: internal error in the planner: {what}", job.name),
        );
        feeder.refuse(line);
        while pace.next_round() {
            feeder.feed(&mut std::iter::empty());
            pace.round_done();
        }
    }
    // Free what the interpolator handed back.
    feeder.feed(&mut std::iter::empty());
}

fn feed_program(
    job: &Job,
    feeder: &mut Feeder,
    pace: &mut Pace,
    ready: std::sync::mpsc::SyncSender<Result<Ready, InputError>>,
    learned: &Arc<Learned>,
) {
    let t0 = Instant::now();
    // A pipe or FIFO can be read once: read it whole, then as a program in memory.
    let piped;
    let job = match &job.input {
        Input::File(p) if !std::fs::metadata(p).is_ok_and(|m| m.is_file()) => {
            match std::fs::read(p) {
                Ok(bytes) => {
                    piped = Job {
                        input: Input::Text(bytes.into()),
                        ..job.clone()
                    };
                    &piped
                }
                Err(e) => {
                    let _ = ready.send(Err(job.unreadable(e)));
                    return;
                }
            }
        }
        _ => job,
    };
    let source = match prepare(job, learned) {
        Ok(s) => s,
        Err(e) => {
            let _ = ready.send(Err(e));
            return;
        }
    };
    let m = job.setup.machine();
    let run = Feed {
        job,
        learned,
        t0,
        checked: source.checked,
    };
    // Runs of moves are compressed (when that is on) as the lines are read; what reaches
    // the builder is noted (its line is what an internal error names).
    let entries = Compressing::new(
        Entries::new(source.lines, &job.shop),
        &job.setup.kin,
        job.setup.compress,
    );
    let entries = Noting {
        inner: entries,
        learned,
    };
    run.go(Source::new(entries, m, job.depth), feeder, pace, ready);
}

/// The program's lines, ready to stream, and whether it was checked whole.
struct Prepared {
    lines: Box<dyn LineSource + Send>,
    checked: bool,
}

/// The pre-pass (whole, or started beside the planner) and the source of entries.
fn prepare(job: &Job, learned: &Arc<Learned>) -> Result<Prepared, InputError> {
    let size = job.size()?;
    let checked = size <= CHECK_WHOLE_BYTES;
    if checked {
        let passed = job.prepass(job.lines()?)?;
        job.operator_reachable(passed.operator_stop)?;
        let _ = learned.end_joints.set(passed.end_joints);
        let _ = learned.lines.set(passed.lines);
    } else {
        // Beside the planner, with a reader of its own; what it refuses stops the run.
        let lines = job.lines()?;
        let j = job.clone();
        let learned = Arc::clone(learned);
        std::thread::Builder::new()
            .name("dnurbs-prepass".into())
            .spawn(move || {
                let s = &j.setup;
                match nc_plan::prepass::check(lines, &j.shop, &s.kin, &s.build, &s.plan.travel) {
                    Ok(p) => match j.operator_reachable(p.operator_stop) {
                        Ok(()) => {
                            let _ = learned.end_joints.set(p.end_joints);
                            let _ = learned.lines.set(p.lines);
                        }
                        Err(e) => {
                            learned.refuse(p.operator_stop.map_or(1, |pos| pos.line), e.to_string())
                        }
                    },
                    Err(r) => learned.refuse(r.pos().line, j.refused(r).to_string()),
                }
            })
            .map_err(|e| job.unreadable(e))?;
    }
    Ok(Prepared {
        lines: job.lines()?,
        checked,
    })
}

/// The streaming stage, once the entries are ready.
struct Feed<'j> {
    job: &'j Job,
    learned: &'j Arc<Learned>,
    t0: Instant,
    checked: bool,
}

impl Feed<'_> {
    fn go<E: ProgramSource>(
        self,
        mut source: Source<'_, Noting<'_, Compressing<'_, E>>>,
        feeder: &mut Feeder,
        pace: &mut Pace,
        ready: std::sync::mpsc::SyncSender<Result<Ready, InputError>>,
    ) {
        if let Some(&n) = self.learned.lines.get() {
            source.set_lines(n);
        }
        // The first window: motion waits for it.
        let mut held: VecDeque<Box<Chunk>> = VecDeque::new();
        match source.next_chunk() {
            Ok(c) => held.extend(c),
            Err(e) => {
                let _ = ready.send(Err(self.job.stream_error(e)));
                return;
            }
        }
        let Some(start) = source.start() else {
            let _ = ready.send(Err(InputError::Usage(format!(
                "{}: the program has no start pose",
                self.job.name
            ))));
            return;
        };
        // The pre-pass beside the planner may have refused the program already: then
        // nothing moves.
        if let Some((_, why)) = self.learned.refusal() {
            let _ = ready.send(Err(InputError::Usage(why)));
            return;
        }
        let r = Ready {
            start,
            first_window_s: self.t0.elapsed().as_secs_f64(),
            checked_whole: self.checked,
        };
        if ready.send(Ok(r)).is_err() {
            return;
        }
        let mut stopped = false;
        while pace.next_round() {
            if !stopped {
                if let Some((line, _)) = self.learned.refusal() {
                    feeder.refuse(line);
                    stopped = true;
                }
            }
            if let Some(j) = source.end_joints() {
                let _ = self.learned.end_joints.set(j);
            }
            if let Some(&n) = self.learned.lines.get() {
                source.set_lines(n);
            }
            let mut failed = None;
            if stopped {
                feeder.feed(&mut std::iter::empty());
            } else {
                let mut chunks = std::iter::from_fn(|| {
                    if let Some(c) = held.pop_front() {
                        return Some(c);
                    }
                    match source.next_chunk() {
                        Ok(c) => c,
                        Err(e) => {
                            failed = Some(e);
                            None
                        }
                    }
                });
                feeder.feed(&mut chunks);
            }
            if let Some(e) = failed {
                let line = e.pos().line;
                self.learned
                    .refuse(line, self.job.stream_error(e).to_string());
                feeder.refuse(line);
                stopped = true;
            }
            // After the feed: the last chunk is not pushed before the program has ended.
            if let Some(c) = source.entries().inner.compressed() {
                *self
                    .learned
                    .compressed
                    .lock()
                    .unwrap_or_else(|e| e.into_inner()) = Some(c.into());
            }
            pace.round_done();
        }
    }
}
