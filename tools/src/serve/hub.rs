//! The controller's hub: the one place where an operator's request meets the machine.
//!
//! [`Hub::request`] validates a request against the machine's state ([`Controller`]),
//! prepares what it needs (an MDI line or a program planned from where the machine
//! stands, a jog's limits, a homing sequence) and sends the real-time thread its
//! [`Order`]; [`Hub::poll`] takes what the thread reports ([`Happened`]), moves the
//! state on, feeds the running program's chunks, and answers the requests that waited for
//! the thread's word. Sans-I/O: the socket's threads and the tests call it alike, the tests
//! stepping the real-time side on a virtual clock.
//!
//! A request the thread may still refuse (on, reset, home, jog, a program) is answered
//! once it has answered; until then no other request of that kind is taken. A refusal
//! changes nothing.

use super::protocol::{Axis, Frame, Reply, Request};
use super::state::{Command, Controller, Event, State};
use super::work::{self, AxisDrive, Homing, Planned};
use crate::setup::MachineSetup;
use config::Machine;
use drives::master::{DriveFault, FaultCause};
use nc_follow::{Chunk, Feeder};
use nc_lang::mdi::Mdi;
use nc_lang::restart::Standing;
use rt_loop::control::Command as RunCommand;
use rt_loop::control::{Consumer, Producer};
use rt_loop::life::{Happened, Order, Status};
use serde::Serialize;

mod answer;
mod jog_line;
mod step;

/// Polls a request waits for the real-time thread's answer before it is refused (the
/// thread answers within a period or two; serve polls every millisecond at most).
pub const WAIT_POLLS: u64 = 10_000;

/// Who asked: the client's connection and the request's id.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Asker {
    pub client: u64,
    pub id: Option<u64>,
}

/// A request waiting for the real-time thread's word.
#[derive(Clone, Copy, Debug)]
enum Waiting {
    On(Controller),
    Off(Controller),
    Reset(Controller),
    /// The first drive of the homing started (or was refused).
    Home,
    Jog(Controller, JogKey),
    /// An MDI line or the program (the chunks wait in `next`).
    Program(Controller, Kind),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Mdi,
    Program,
}

/// The continuous jog under way: a renewal is the same request again.
#[derive(Clone, Copy, Debug, PartialEq)]
struct JogKey {
    frame: Frame,
    joint: usize,
    positive: bool,
    continuous: bool,
    client: u64,
}

/// A loaded program.
struct Loaded {
    name: String,
    text: String,
}

/// What `status` answers.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StatusBody {
    pub state: &'static str,
    /// The real-time thread's mode.
    pub mode: &'static str,
    pub homed: Vec<&'static str>,
    pub axis_names: Vec<&'static str>,
    /// The targets sent, mm and degrees, joint order.
    pub axes: Vec<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub loaded: Option<String>,
    /// The program's source line being machined (while one runs).
    pub line: u32,
    /// The feed override, % of the planned feed.
    pub override_pct: u8,
    /// Periods the real-time thread has run (one SYNC each).
    pub cycles: u64,
    /// The last fault, refusal of the thread or end of a program, with its reason.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// Reports of the real-time thread lost because their queue was full (0 unless the hub
    /// stalled for 63 reports).
    pub lost: u64,
}

/// The hub: the controller's state and its ends of the real-time thread's queues.
pub struct Hub<'q> {
    machine: &'q Machine,
    setup: &'q MachineSetup,
    ctl: Controller,
    orders: Producer<'q, Order>,
    happened: Consumer<'q, Happened>,
    feeder: Feeder<'q>,
    status: &'q Status,
    depth: usize,
    mdi: Mdi<'q>,
    shop: &'q nc_lang::Setup,
    loaded: Option<Loaded>,
    drives: [Vec<AxisDrive>; 5],
    homing: [Homing; 5],
    homed: [bool; 5],
    /// Homing groups still to home (joints), the first under way.
    sequence: Vec<Vec<usize>>,
    /// Drives of the group under way still homing.
    homing_left: usize,
    homing_failed: Option<String>,
    waiting: Option<(Asker, Waiting)>,
    /// Polls the request waiting has waited.
    waited: u64,
    answers: Vec<(Asker, Reply)>,
    /// The program or line planned, waiting for the thread to take it; then its chunks.
    next: Option<Planned>,
    source: std::vec::IntoIter<Box<Chunk>>,
    jog: Option<JogKey>,
    /// A stop was asked of the program or line under way: its end moves the state.
    stopping: bool,
    standing: Standing,
    message: Option<String>,
    override_pct: u8,
    /// The lines of the stops single block put before each block of the program under way
    /// (none: it was started with `run`).
    block_stops: Vec<u32>,
    /// The operator stop last let go (the thread still reports it for a period or two).
    released: Option<u32>,
}

impl<'q> Hub<'q> {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        machine: &'q Machine,
        setup: &'q MachineSetup,
        shop: &'q nc_lang::Setup,
        (orders, happened): (Producer<'q, Order>, Consumer<'q, Happened>),
        feeder: Feeder<'q>,
        status: &'q Status,
    ) -> Self {
        let drives = work::axis_drives(machine);
        let limits = setup.limits.clone();
        let homing: [Homing; 5] =
            core::array::from_fn(|j| work::homing(machine, &drives[j], &limits[j]));
        let homed = core::array::from_fn(|j| homing[j] == Homing::Absolute);
        let all_absolute = homed.iter().all(|&h| h);
        Hub {
            machine,
            setup,
            ctl: Controller::new(all_absolute),
            orders,
            happened,
            feeder,
            status,
            depth: machine.realtime.queue_depth,
            mdi: Mdi::new(shop),
            shop,
            loaded: None,
            drives,
            homing,
            homed,
            sequence: Vec::new(),
            homing_left: 0,
            homing_failed: None,
            waiting: None,
            waited: 0,
            answers: Vec::new(),
            next: None,
            source: Vec::new().into_iter(),
            jog: None,
            stopping: false,
            standing: Standing {
                joints: [0.0; 5],
                tool_length: 0.0,
            },
            message: None,
            override_pct: 100,
            block_stops: Vec::new(),
            released: None,
        }
    }

    pub fn state(&self) -> State {
        self.ctl.state()
    }

    /// What the real-time thread publishes (its [`rt_loop::life::Life::publish`]).
    pub fn published(&self) -> &'q Status {
        self.status
    }

    /// Take `request`: its answer now, or `None` if it waits for the real-time thread
    /// ([`Hub::poll`] gives it then).
    pub fn request(&mut self, who: Asker, request: Request) -> Option<Reply> {
        if request == Request::Status {
            let body = serde_json::to_value(self.status()).unwrap_or_default();
            return Some(Reply::ok(who.id, self.ctl.state().name()).with_status(body));
        }
        match self.take(who, request) {
            Ok(Some(state)) => Some(Reply::ok(who.id, state.name())),
            Ok(None) => None,
            Err(e) => Some(Reply::refused(who.id, e)),
        }
    }

    /// The status now.
    pub fn status(&self) -> StatusBody {
        let axes = self.status.axes();
        let names = self.setup.axis_names;
        let run = self.status.run.snapshot();
        let running = matches!(
            self.ctl.state(),
            State::Running | State::Paused | State::Stepping | State::Mdi
        );
        StatusBody {
            state: self.ctl.state().name(),
            mode: self.status.mode().name(),
            homed: (0..5)
                .filter(|&j| self.homed[j] && !self.drives[j].is_empty())
                .map(|j| names[j])
                .collect(),
            axis_names: names.to_vec(),
            axes: axes.to_vec(),
            loaded: self.loaded.as_ref().map(|l| l.name.clone()),
            line: if running { run.line } else { 0 },
            override_pct: self.override_pct,
            cycles: self.status.cycles(),
            message: self.message.clone(),
            lost: self.status.lost(),
        }
    }

    /// A client went away: a continuous jog it held stops at once.
    pub fn gone(&mut self, client: u64) {
        if self.jog.is_some_and(|k| k.client == client && k.continuous) {
            self.send(Order::Stop);
        }
    }

    /// Take what the real-time thread reported, feed the program, and the answers that
    /// are ready.
    pub fn poll(&mut self) -> Vec<(Asker, Reply)> {
        for _ in 0..rt_loop::life::HAPPENINGS {
            let Some(h) = self.happened.dequeue() else {
                break;
            };
            self.happened(h);
        }
        self.feeder.feed(&mut self.source);
        self.watch_stops();
        self.give_up_waiting();
        std::mem::take(&mut self.answers)
    }

    /// A request the real-time thread has not answered in [`WAIT_POLLS`] polls is refused;
    /// whatever it may still start is stopped (a program gets no chunks).
    fn give_up_waiting(&mut self) {
        let Some((who, waiting)) = self.waiting else {
            self.waited = 0;
            return;
        };
        self.waited += 1;
        if self.waited <= WAIT_POLLS {
            return;
        }
        self.waiting = None;
        self.waited = 0;
        self.next = None;
        self.send(Order::Stop);
        if matches!(waiting, Waiting::On(_)) {
            // Should it enable the drives after all, they are disabled again.
            self.send(Order::Off);
        }
        let why = "the real-time thread did not answer in time (is it running?): stopped; \
                   check the status";
        self.message = Some(why.into());
        self.answers.push((who, Reply::refused(who.id, why)));
    }

    fn send(&mut self, o: Order) {
        if self.orders.enqueue(o).is_err() {
            // The thread takes 16 a period: a full queue means it is not running.
            self.message = Some(format!(
                "the real-time thread is not taking orders: {} dropped",
                o.name()
            ));
        }
    }

    /// The request's work: `Ok(Some)` done (the state now), `Ok(None)` waiting.
    fn take(&mut self, who: Asker, request: Request) -> Result<Option<State>, String> {
        if self.waiting.is_some() && !matches!(request, Request::Estop) {
            return Err(format!(
                "{}: busy with the last request (the real-time thread has not answered yet): \
                 send it again",
                request_name(&request)
            ));
        }
        let mut next = self.ctl;
        match request {
            Request::Status => Ok(Some(self.ctl.state())),
            Request::Estop => {
                self.ctl
                    .command(Command::EStop)
                    .map_err(|e| e.to_string())?;
                self.send(Order::EStop);
                self.after_stop_of_motion();
                Ok(Some(self.ctl.state()))
            }
            Request::On => self.wait_for(who, &mut next, Command::On, Order::On, Waiting::On),
            Request::Off => self.wait_for(who, &mut next, Command::Off, Order::Off, Waiting::Off),
            Request::Reset => {
                self.wait_for(who, &mut next, Command::Reset, Order::Reset, Waiting::Reset)
            }
            Request::Home(axis) => self.home(who, axis),
            Request::Jog {
                axis,
                positive,
                step,
                speed,
                frame: Frame::Machine,
            } => self.jog(who, axis, positive, step, speed),
            Request::Jog {
                axis,
                positive,
                step,
                speed,
                frame,
            } => self.line_jog(who, axis, frame, positive, step, speed),
            Request::Mdi(line) => self.mdi(who, &line),
            Request::Load(file) => self.load(&file),
            Request::Run {
                from_line,
                clearance,
                confirm,
            } => match from_line {
                None => self.run(who, false),
                Some(n) => self.restart(who, n, clearance, confirm),
            },
            Request::Step => self.step(who),
            Request::Pause => {
                self.ctl
                    .command(Command::Pause)
                    .map_err(|e| e.to_string())?;
                self.send(Order::Run(RunCommand::Pause));
                Ok(Some(self.ctl.state()))
            }
            Request::Resume => {
                self.ctl
                    .command(Command::Resume)
                    .map_err(|e| e.to_string())?;
                // An operator stop (M00, M01, a block's end in single block) is let go.
                self.released = self.status.run.snapshot().awaiting;
                self.send(Order::Run(RunCommand::Resume));
                Ok(Some(self.ctl.state()))
            }
            Request::Override(p) => {
                self.ctl
                    .command(Command::Override)
                    .map_err(|e| e.to_string())?;
                self.override_pct = p;
                self.send(Order::Run(RunCommand::Override(p)));
                Ok(Some(self.ctl.state()))
            }
            Request::Stop => {
                // Checked, not taken: the state moves when the motion has come to rest.
                next.command(Command::Stop).map_err(|e| e.to_string())?;
                self.stopping = true;
                self.send(Order::Stop);
                Ok(Some(self.ctl.state()))
            }
        }
    }

    /// Check `c`, send `o` and wait for the thread's word before the state moves.
    fn wait_for(
        &mut self,
        who: Asker,
        next: &mut Controller,
        c: Command,
        o: Order,
        waiting: fn(Controller) -> Waiting,
    ) -> Result<Option<State>, String> {
        next.command(c).map_err(|e| e.to_string())?;
        self.send(o);
        self.waiting = Some((who, waiting(*next)));
        Ok(None)
    }

    /// Motion stopped by a fault or the e-stop: nothing is fed or jogged any more, the
    /// axes without an absolute encoder must be homed again.
    fn after_stop_of_motion(&mut self) {
        self.source = Vec::new().into_iter();
        self.next = None;
        self.jog = None;
        self.stopping = false;
        self.sequence.clear();
        self.homing_left = 0;
        for j in 0..5 {
            self.homed[j] = self.homing[j] == Homing::Absolute;
        }
    }

    /// Where the machine stands now, for the next MDI line or program.
    fn stand_here(&mut self, tool_length: Option<f64>) {
        let axes = self.status.axes();
        let joints = core::array::from_fn(|j| {
            if j >= 3 {
                axes[j].to_radians()
            } else {
                axes[j]
            }
        });
        self.standing = Standing {
            joints,
            tool_length: tool_length.unwrap_or(self.standing.tool_length),
        };
        self.mdi.standing(&self.standing, &self.setup.kin);
    }

    /// Joint index of `axis` on this machine, or why not.
    fn joint(&self, axis: Axis) -> Result<usize, String> {
        let names = self.setup.axis_names;
        let letter = match axis {
            Axis::X => "X",
            Axis::Y => "Y",
            Axis::Z => "Z",
            Axis::A => "A",
            Axis::B => "B",
            Axis::C => "C",
        };
        let j = names
            .iter()
            .position(|n| *n == letter)
            .filter(|&j| !self.drives[j].is_empty())
            .ok_or_else(|| {
                let have: Vec<&str> = (0..5)
                    .filter(|&j| !self.drives[j].is_empty())
                    .map(|j| names[j])
                    .collect();
                format!(
                    "axis {letter}: this machine has no such axis (its axes: {})",
                    have.join(" ")
                )
            })?;
        Ok(j)
    }

    /// The machine's name, for messages.
    pub fn machine_name(&self) -> &str {
        &self.machine.name
    }
}

fn request_name(r: &Request) -> &'static str {
    match r {
        Request::Status => "status",
        Request::On => "on",
        Request::Off => "off",
        Request::Home(_) => "home",
        Request::Jog { .. } => "jog",
        Request::Mdi(_) => "mdi",
        Request::Load(_) => "load",
        Request::Run { .. } => "run",
        Request::Pause => "pause",
        Request::Resume => "resume",
        Request::Step => "step",
        Request::Stop => "stop",
        Request::Override(_) => "override",
        Request::Reset => "reset",
        Request::Estop => "estop",
    }
}

/// A fault's event for the state: the e-stop chain or the operator's e-stop, or a fault.
fn fault_event(f: &DriveFault) -> Event {
    match f.cause {
        FaultCause::EStop(_) => Event::EStopInput,
        _ => Event::Fault,
    }
}
