//! The requests that prepare work (home, jog, MDI, load, run) and what the hub does with
//! each report of the real-time thread.

use super::{fault_event, Asker, Hub, JogKey, Kind, Loaded, Waiting};
use crate::serve::protocol::{Axis, Reply};
use crate::serve::state::{Command, Event, State};
use crate::serve::work::{self, Homing, Planned, MAX_PROGRAM_BYTES};
use nc_lang::{Entry, StrLines};
use rt_loop::life::{Happened, Order};

/// A continuous jog without a speed goes at this share of the axis's velocity limit.
pub const JOG_DEFAULT_SHARE: f64 = 0.1;

impl Hub<'_> {
    /// Home `axis`, or every axis in the machine file's sequence.
    pub(super) fn home(&mut self, who: Asker, axis: Option<Axis>) -> Result<Option<State>, String> {
        let mut next = self.ctl;
        next.command(Command::Home).map_err(|e| e.to_string())?;
        let joints: Vec<usize> = match axis {
            Some(a) => vec![self.joint(a)?],
            None => (0..5).filter(|&j| !self.drives[j].is_empty()).collect(),
        };
        // Groups in rising sequence; an axis homed where it stands, or absolute, at once.
        let mut groups: Vec<(u8, Vec<usize>)> = Vec::new();
        for &j in &joints {
            match &self.homing[j] {
                Homing::Absolute => {}
                Homing::Here => self.homed[j] = true,
                Homing::Drive { sequence, .. } => {
                    match groups.iter_mut().find(|(s, _)| s == sequence) {
                        Some((_, g)) => g.push(j),
                        None => groups.push((*sequence, vec![j])),
                    }
                }
            }
        }
        groups.sort_by_key(|(s, _)| *s);
        self.sequence = groups.into_iter().map(|(_, g)| g).collect();
        self.homing_failed = None;
        self.ctl = next;
        if self.sequence.is_empty() {
            let all = self.all_homed();
            self.ctl.event(Event::Homed { all });
            return Ok(Some(self.ctl.state()));
        }
        self.start_group();
        self.waiting = Some((who, Waiting::Home));
        Ok(None)
    }

    fn all_homed(&self) -> bool {
        (0..5).all(|j| self.homed[j] || self.drives[j].is_empty())
    }

    /// Send the homing of the first group's drives.
    fn start_group(&mut self) {
        let Some(group) = self.sequence.first().cloned() else {
            return;
        };
        self.homing_left = 0;
        for j in group {
            if let Homing::Drive { requests, .. } = self.homing[j].clone() {
                for (bus, index, req) in requests {
                    self.send(Order::Home { bus, index, req });
                    self.homing_left += 1;
                }
            }
        }
    }

    /// A drive's homing ended (`failed`: why not homed).
    fn homing_ended(&mut self, bus: usize, index: usize, failed: Option<String>) {
        let joint = (0..5).find(|&j| {
            self.drives[j]
                .iter()
                .any(|d| d.bus == bus && d.index == index)
        });
        if let Some(why) = failed {
            let name = joint.map_or("?", |j| self.setup.axis_names[j]);
            self.homing_failed
                .get_or_insert(format!("homing {name} failed: {why}"));
        }
        self.homing_left = self.homing_left.saturating_sub(1);
        if self.homing_left > 0 {
            return;
        }
        // The group is over: its axes homed unless one of theirs failed.
        let group = if self.sequence.is_empty() {
            Vec::new()
        } else {
            self.sequence.remove(0)
        };
        if self.homing_failed.is_none() {
            for j in group {
                self.homed[j] = true;
            }
        }
        if let Some(why) = self.homing_failed.clone() {
            self.sequence.clear();
            self.message = Some(why);
            self.ctl.event(Event::HomingFailed);
        } else if self.sequence.is_empty() {
            self.stopping = false;
            let all = self.all_homed();
            self.ctl.event(Event::Homed { all });
        } else {
            self.start_group();
        }
    }

    pub(super) fn jog(
        &mut self,
        who: Asker,
        axis: Axis,
        positive: bool,
        step: Option<f64>,
        speed: Option<f64>,
    ) -> Result<Option<State>, String> {
        let joint = self.joint(axis)?;
        let key = JogKey {
            frame: crate::serve::protocol::Frame::Machine,
            joint,
            positive,
            continuous: step.is_none(),
            client: who.client,
        };
        let limits = &self.setup.limits[joint];
        let d = &self.drives[joint][0].drive;
        let lim = work::jog_limits(limits, d, self.homed[joint]);
        let speed = speed.unwrap_or(limits.velocity * JOG_DEFAULT_SHARE);
        let sign = if positive { 1.0 } else { -1.0 };
        // The same continuous jog again: the operator still holds the key.
        if self.ctl.state() == State::Jog
            && self.jog.is_some_and(|k| {
                k.continuous && key.continuous && k.joint == joint && k.frame == key.frame
            })
        {
            self.send(Order::Jog {
                axis: joint,
                limits: lim,
                velocity: sign * speed,
            });
            self.jog = Some(key);
            return Ok(Some(State::Jog));
        }
        let mut next = self.ctl;
        next.command(Command::Jog).map_err(|e| e.to_string())?;
        let order = match step {
            None => Order::Jog {
                axis: joint,
                limits: lim,
                velocity: sign * speed,
            },
            Some(d) => {
                let from = self.status.axes()[joint];
                Order::JogTo {
                    axis: joint,
                    limits: lim,
                    target: from + sign * d,
                    speed,
                }
            }
        };
        self.send(order);
        self.waiting = Some((who, Waiting::Jog(next, key)));
        Ok(None)
    }

    pub(super) fn mdi(&mut self, who: Asker, line: &str) -> Result<Option<State>, String> {
        let mut next = self.ctl;
        next.command(Command::Mdi).map_err(|e| e.to_string())?;
        self.stand_here(None);
        let out = self
            .mdi
            .line(line)
            .map_err(|e| format!("mdi `{line}`: {e}"))?;
        let program =
            nc_lang::mdi::program(&out, self.mdi.tilt_word(), &self.standing, &self.setup.kin);
        match work::plan(&program, self.setup, self.depth) {
            Ok(p) if !p.moves => {
                // Modes, offsets, a tool: taken, nothing moves.
                self.standing.tool_length = p.tool_length;
                Ok(Some(self.ctl.state()))
            }
            Ok(p) => {
                self.hand_over(who, next, Kind::Mdi, p);
                Ok(None)
            }
            Err(e) => {
                self.mdi.take_back();
                Err(format!("mdi `{line}`: {e}"))
            }
        }
    }

    pub(super) fn load(&mut self, file: &str) -> Result<Option<State>, String> {
        let mut next = self.ctl;
        next.command(Command::Load).map_err(|e| e.to_string())?;
        let size = std::fs::metadata(file)
            .map_err(|e| format!("load {file}: {e}"))?
            .len();
        if size > MAX_PROGRAM_BYTES {
            return Err(format!(
                "load {file}: {size} bytes: dnurbs serve plans a program whole before it \
                 moves, up to {MAX_PROGRAM_BYTES} bytes (dnurbs run streams larger ones)"
            ));
        }
        let text = std::fs::read_to_string(file).map_err(|e| format!("load {file}: {e}"))?;
        // Read through once, as `run` will read it (from where the machine stands, its
        // first move from there): a program that does not read is not loaded.
        self.stand_here(None);
        let mut check = nc_lang::mdi::Mdi::new(self.shop);
        check.standing(&self.standing, &self.setup.kin);
        for e in check.into_program(StrLines::new(&text)) {
            e.map_err(|e| format!("load {file}:{e}"))?;
        }
        self.loaded = Some(Loaded {
            name: file.to_owned(),
            text,
        });
        self.ctl = next;
        Ok(Some(self.ctl.state()))
    }

    /// Run the loaded program (`single_block`: with a stop before each block, as `step`
    /// starts it).
    pub(super) fn run(&mut self, who: Asker, single_block: bool) -> Result<Option<State>, String> {
        let mut next = self.ctl;
        let c = if single_block {
            Command::Step
        } else {
            Command::Run
        };
        next.command(c).map_err(|e| e.to_string())?;
        self.stand_here(None);
        let Some(loaded) = self.loaded.as_ref() else {
            return Err("run: no program is loaded".into());
        };
        let name = loaded.name.clone();
        // The program starts in the state the MDI lines left, from where the machine
        // stands; the session after it starts afresh.
        let session = std::mem::replace(&mut self.mdi, nc_lang::mdi::Mdi::new(self.shop));
        let mut entries = session.into_program(StrLines::new(&loaded.text));
        let mut all: Vec<Entry> = Vec::new();
        for e in entries.by_ref() {
            all.push(e.map_err(|e| format!("run {name}:{e}"))?);
        }
        let mut program = work::from_here(&all, entries.tilt_word(), &self.standing, self.setup);
        self.block_stops = if single_block {
            work::stop_before_each_block(&mut program)
        } else {
            Vec::new()
        };
        let planned =
            work::plan(&program, self.setup, self.depth).map_err(|e| format!("run {name}: {e}"))?;
        self.hand_over(who, next, Kind::Program, planned);
        Ok(None)
    }

    /// Run the loaded program from `line`: the lines before it read without moving, what
    /// they left on restored, and the approach from where the machine stands (back along
    /// the tool axis by `clearance`, over, down onto the restart pose). Unless `confirm`,
    /// the answer says what the approach would be and nothing moves.
    pub(super) fn restart(
        &mut self,
        who: Asker,
        line: u32,
        clearance: f64,
        confirm: bool,
    ) -> Result<Option<State>, String> {
        let mut next = self.ctl;
        next.command(Command::Run).map_err(|e| e.to_string())?;
        self.stand_here(None);
        let Some(loaded) = self.loaded.as_ref() else {
            return Err("run: no program is loaded".into());
        };
        let name = loaded.name.clone();
        let program = nc_lang::parse_with(&loaded.text, self.shop).map_err(|e| {
            let first = e.first().map_or(String::new(), |p| p.to_string());
            format!("run {name}:{first}")
        })?;
        let r = nc_lang::restart::from_line(
            &program,
            line,
            &self.setup.kin,
            &self.setup.build,
            &self.standing,
            clearance,
        )
        .map_err(|e| format!("run {name} from line {line}: {e}"))?;
        let [up, over, down] = r
            .approach
            .map(|p| format!("X{:.3} Y{:.3} Z{:.3}", p[0], p[1], p[2]));
        let restored = r.modal.aux;
        if !confirm {
            return Err(format!(
                "run {name} from line {line} (restarts at line {}): the approach: back \
                 along the tool axis to {up}, over to {over}, down to {down}; spindle {} \
                 rpm, coolant {}; nothing moved: confirm it (ctl run --from-line {line} \
                 --confirm)",
                r.line,
                restored.spindle_rpm,
                if restored.mist || restored.flood {
                    "on"
                } else {
                    "off"
                },
            ));
        }
        let planned = work::plan(&r.program, self.setup, self.depth)
            .map_err(|e| format!("run {name} from line {line}: {e}"))?;
        self.block_stops = Vec::new();
        self.message = Some(format!(
            "restarted {name} at line {}: approach over {over}, down to {down}",
            r.line
        ));
        self.hand_over(who, next, Kind::Program, planned);
        Ok(None)
    }

    /// Send the planned work to the thread; its chunks follow once it has taken it.
    fn hand_over(
        &mut self,
        who: Asker,
        next: crate::serve::state::Controller,
        kind: Kind,
        p: Planned,
    ) {
        self.send(Order::Program { start: p.start });
        self.next = Some(p);
        self.waiting = Some((who, Waiting::Program(next, kind)));
    }

    /// Answer the request waiting, if `f` says this report answers it: `Ok` takes the
    /// state the request was checked for, `Err` refuses it and changes nothing.
    fn answer(&mut self, f: impl FnOnce(Waiting) -> Option<Result<(), String>>) {
        let Some((who, w)) = self.waiting else {
            return;
        };
        let Some(r) = f(w) else {
            return;
        };
        self.waiting = None;
        let reply = match r {
            Ok(()) => {
                match w {
                    Waiting::On(n) | Waiting::Off(n) | Waiting::Reset(n) => self.ctl = n,
                    Waiting::Program(n, _) => self.ctl = n,
                    Waiting::Jog(n, key) => {
                        self.ctl = n;
                        self.jog = Some(key);
                    }
                    Waiting::Home => {}
                }
                Reply::ok(who.id, self.ctl.state().name())
            }
            Err(e) => Reply::refused(who.id, e),
        };
        self.answers.push((who, reply));
    }

    /// What the hub does with one report.
    pub(super) fn happened(&mut self, h: Happened) {
        match h {
            Happened::Enabled => self.answer(|w| matches!(w, Waiting::On(_)).then_some(Ok(()))),
            Happened::EnableTimeout => self.answer(|w| {
                matches!(w, Waiting::On(_)).then(|| {
                    Err(
                        "on: the drives did not reach Operation enabled in time: disabled \
                         again"
                            .into(),
                    )
                })
            }),
            Happened::Disabled => self.answer(|w| matches!(w, Waiting::Off(_)).then_some(Ok(()))),
            Happened::ResetDone(f) => {
                self.message = Some(format!("reset: {f}"));
                self.answer(|w| matches!(w, Waiting::Reset(_)).then_some(Ok(())))
            }
            Happened::ResetRefused(e) => self.answer(|w| {
                matches!(w, Waiting::Reset(_)).then(|| Err(format!("reset refused: {e}")))
            }),
            Happened::HomingStarted { .. } => {
                self.answer(|w| matches!(w, Waiting::Home).then_some(Ok(())))
            }
            Happened::HomeRefused(e) => {
                self.answer(|w| {
                    matches!(w, Waiting::Home).then(|| Err(format!("home refused: {e}")))
                });
                self.homing_ended(usize::MAX, usize::MAX, Some(e.to_string()));
            }
            Happened::Homed { bus, index, .. } => self.homing_ended(bus, index, None),
            Happened::HomingFailed { bus, index, error } => {
                self.homing_ended(bus, index, Some(error.to_string()))
            }
            Happened::JogStarted => {
                self.answer(|w| matches!(w, Waiting::Jog(..)).then_some(Ok(())))
            }
            Happened::JogRefused(e) => self.answer(|w| {
                matches!(w, Waiting::Jog(..)).then(|| Err(format!("jog refused: {e}")))
            }),
            Happened::LineJogRefused(e) => self.answer(|w| {
                matches!(w, Waiting::Jog(..)).then(|| Err(format!("jog refused: {e}")))
            }),
            Happened::JogDone { limited } => {
                if limited {
                    self.message = Some("jog stopped short of the travel".into());
                }
                self.jog = None;
                self.stopping = false;
                self.ctl.event(Event::AtRest);
                self.stand_here(None);
            }
            Happened::ProgramStarted => {
                if let Some(p) = self.next.take() {
                    // The last program's chunks are back (the thread handed them over).
                    self.feeder.reclaim();
                    self.feeder.next_program();
                    self.standing.tool_length = p.tool_length;
                    self.source = p.chunks.into_iter();
                    // The override the operator set holds for every program and line.
                    if self.override_pct != 100 {
                        let o = rt_loop::control::Command::Override(self.override_pct);
                        self.send(Order::Run(o));
                    }
                }
                self.answer(|w| matches!(w, Waiting::Program(..)).then_some(Ok(())))
            }
            Happened::ProgramRefused(e) => {
                self.next = None;
                let e = match e {
                    rt_loop::pipeline::PipelineError::NotAtStart {
                        axis,
                        actual,
                        start,
                    } => format!(
                        "axis {axis} is at {actual:.4} but the move was planned from \
                         {start:.4}: the machine moved since; send it again"
                    ),
                    other => other.to_string(),
                };
                let mdi = matches!(self.waiting, Some((_, Waiting::Program(_, Kind::Mdi))));
                if mdi {
                    self.mdi.take_back();
                }
                self.answer(|w| match w {
                    Waiting::Program(_, Kind::Mdi) => Some(Err(format!("mdi refused: {e}"))),
                    Waiting::Program(..) => Some(Err(format!("run refused: {e}"))),
                    _ => None,
                });
            }
            Happened::ProgramEnded { reason, line } => {
                self.source = Vec::new().into_iter();
                self.message = reason.map(|r| format!("stopped at line {line}: {r}"));
                if reason.is_some_and(|r| {
                    r.node().is_some() || matches!(r, rt_loop::pipeline::StopReason::Fault(_))
                }) {
                    return; // the fault that follows moves the state
                }
                if self.stopping {
                    self.stopping = false;
                    let _ = self.ctl.command(Command::Stop);
                } else {
                    let s = self.ctl.state();
                    self.ctl.event(if s == State::Mdi {
                        Event::AtRest
                    } else {
                        Event::ProgramEnd
                    });
                }
                self.stand_here(None);
            }
            Happened::Fault(f) => {
                self.message = Some(format!("fault: {f}; reset, then home again"));
                self.ctl.event(fault_event(&f));
                self.after_stop_of_motion();
                self.answer(|_| Some(Err(format!("fault: {f}"))));
            }
            Happened::Bus(c) => self.message = Some(format!("CAN bus: {c}")),
            Happened::Refused { order, mode } => {
                let why = format!(
                    "{order} refused by the real-time thread in mode {}",
                    mode.name()
                );
                self.message = Some(why.clone());
                self.answer(|_| Some(Err(why)));
            }
        }
    }
}
