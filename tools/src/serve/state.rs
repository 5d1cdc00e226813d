//! The long-lived controller's machine states and the rules between them. Pure: [`Controller::command`] takes an operator's command and either moves to a new
//! state or refuses it with the reason and leaves everything as it was;
//! [`Controller::event`] takes what the machine reports (homing done, motion done, a fault,
//! the e-stop input).
//!
//! The states, as an operator meets them:
//!
//! | state | the drives | what may be asked |
//! |---|---|---|
//! | `estop` | quick-stopped, disabled | `reset` |
//! | `off` | disabled | `on`, `load` |
//! | `on` | enabled, holding, not every axis homed | `home`, `jog`, `load`, `off` |
//! | `homing` | homing | `stop` |
//! | `idle` | enabled, holding, homed | `home`, `jog`, `mdi`, `load`, `run`, `step`, `off` |
//! | `jog` | one axis jogging | `stop` (or the jog ends) |
//! | `mdi` | running an MDI line | `pause`, `stop` |
//! | `running` | running the program | `pause`, `stop`, `override` |
//! | `paused` | held along the path | `resume`, `step`, `stop`, `off` |
//! | `stepping` | running one block, then paused | `pause`, `stop` |
//! | `fault` | quick-stopped, disabled | `reset` |
//!
//! `estop` is taken in every state, `override` in every enabled one. A program runs only
//! once every axis is homed (or has an absolute encoder), as in LinuxCNC; so does MDI.

use serde::Serialize;

/// Where the machine is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum State {
    EStop,
    Off,
    On,
    Homing,
    Idle,
    Jog,
    Mdi,
    Running,
    Paused,
    Stepping,
    Fault,
}

impl State {
    pub fn name(self) -> &'static str {
        match self {
            State::EStop => "estop",
            State::Off => "off",
            State::On => "on",
            State::Homing => "homing",
            State::Idle => "idle",
            State::Jog => "jog",
            State::Mdi => "mdi",
            State::Running => "running",
            State::Paused => "paused",
            State::Stepping => "stepping",
            State::Fault => "fault",
        }
    }

    /// The drives are enabled.
    pub fn enabled(self) -> bool {
        !matches!(self, State::EStop | State::Off | State::Fault)
    }

    /// Something moves (or may, with a program held).
    fn moving(self) -> bool {
        matches!(
            self,
            State::Homing | State::Jog | State::Mdi | State::Running | State::Stepping
        )
    }
}

/// An operator's command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    On,
    Off,
    Home,
    Jog,
    Mdi,
    Load,
    Run,
    Pause,
    Resume,
    Step,
    Stop,
    Override,
    Reset,
    EStop,
}

impl Command {
    pub fn name(self) -> &'static str {
        match self {
            Command::On => "on",
            Command::Off => "off",
            Command::Home => "home",
            Command::Jog => "jog",
            Command::Mdi => "mdi",
            Command::Load => "load",
            Command::Run => "run",
            Command::Pause => "pause",
            Command::Resume => "resume",
            Command::Step => "step",
            Command::Stop => "stop",
            Command::Override => "override",
            Command::Reset => "reset",
            Command::EStop => "estop",
        }
    }

    pub const ALL: [Command; 14] = [
        Command::On,
        Command::Off,
        Command::Home,
        Command::Jog,
        Command::Mdi,
        Command::Load,
        Command::Run,
        Command::Pause,
        Command::Resume,
        Command::Step,
        Command::Stop,
        Command::Override,
        Command::Reset,
        Command::EStop,
    ];
}

/// What the machine reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// Homing ended; `all`: every axis is now homed (or absolute).
    Homed { all: bool },
    /// Homing failed (the drive's error, a timeout): the axes not homed stay so.
    HomingFailed,
    /// A jog, an MDI line, a stop or a step's block came to rest.
    AtRest,
    /// The program ran to its end.
    ProgramEnd,
    /// A drive or the bus faulted (the master quick-stopped every drive).
    Fault,
    /// The e-stop input opened.
    EStopInput,
}

/// A command the controller does not take in its state, and why.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{command} refused in state {state}: {reason}")]
pub struct Refused {
    pub command: &'static str,
    pub state: &'static str,
    pub reason: &'static str,
}

/// The controller's state and what it remembers across states.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Controller {
    state: State,
    /// Every axis has an absolute encoder: homed from the start and after a reset.
    all_absolute: bool,
    /// Every axis homed or absolute.
    homed: bool,
    /// A program is loaded.
    loaded: bool,
    /// The program runs a block at a time.
    stepping: bool,
}

impl Controller {
    /// After start-up: off, nothing homed unless every axis is `absolute`, nothing loaded.
    pub fn new(all_absolute: bool) -> Self {
        Controller {
            state: State::Off,
            all_absolute,
            homed: all_absolute,
            loaded: false,
            stepping: false,
        }
    }

    pub fn state(&self) -> State {
        self.state
    }

    pub fn homed(&self) -> bool {
        self.homed
    }

    pub fn loaded(&self) -> bool {
        self.loaded
    }

    /// Take `c`, or refuse it and change nothing.
    pub fn command(&mut self, c: Command) -> Result<State, Refused> {
        use State as S;
        let s = self.state;
        let refuse = |reason| Refused {
            command: c.name(),
            state: s.name(),
            reason,
        };
        let idle = |homed: bool| if homed { S::Idle } else { S::On };
        let next = match (c, s) {
            (Command::EStop, _) => {
                // The quick stop may lose the axes' positions: home again.
                self.homed = self.all_absolute;
                self.stepping = false;
                S::EStop
            }
            (Command::Reset, S::EStop | S::Fault) => S::Off,
            (Command::Reset, _) => return Err(refuse("nothing to reset")),
            (_, S::EStop) => return Err(refuse("the e-stop is on: reset first")),
            (_, S::Fault) => return Err(refuse("a fault stopped the machine: reset first")),
            (Command::On, S::Off) => idle(self.homed),
            (Command::On, _) => return Err(refuse("the machine is already on")),
            (Command::Load, _) if s.moving() || s == S::Paused => {
                return Err(refuse("a program or a move is under way: stop first"))
            }
            (Command::Load, _) => {
                self.loaded = true;
                s
            }
            (_, S::Off) => return Err(refuse("the machine is off: turn it on first")),
            (Command::Off, S::On | S::Idle | S::Paused) => S::Off,
            (Command::Off, _) => return Err(refuse("the machine is moving: stop first")),
            (Command::Override, _) => s,
            (Command::Home | Command::Jog, S::On | S::Idle) => {
                if c == Command::Home {
                    S::Homing
                } else {
                    S::Jog
                }
            }
            (Command::Home | Command::Jog, _) => {
                return Err(refuse("only at rest, outside a program: stop first"))
            }
            (Command::Mdi | Command::Run | Command::Step, S::On) => {
                return Err(refuse("not every axis is homed: home first"))
            }
            (Command::Mdi, S::Idle) => S::Mdi,
            (Command::Run | Command::Step, S::Idle) if !self.loaded => {
                return Err(refuse("no program is loaded: load one first"))
            }
            (Command::Run, S::Idle) => {
                self.stepping = false;
                S::Running
            }
            (Command::Step, S::Idle | S::Paused) => {
                self.stepping = true;
                S::Stepping
            }
            (Command::Mdi | Command::Run | Command::Step, _) => {
                return Err(refuse("only at rest, outside a program"))
            }
            (Command::Pause, S::Running | S::Stepping | S::Mdi) => S::Paused,
            (Command::Pause, _) => return Err(refuse("nothing runs")),
            (Command::Resume, S::Paused) => {
                // Runs on (as LinuxCNC's resume after a step); `step` is the next block.
                self.stepping = false;
                S::Running
            }
            (Command::Resume, _) => return Err(refuse("nothing is paused")),
            (Command::Stop, S::Homing | S::Jog | S::Mdi | S::Running | S::Paused | S::Stepping) => {
                // Brought to rest along the path (or the jog's stop); homing is interrupted.
                self.stepping = false;
                idle(self.homed)
            }
            (Command::Stop, _) => return Err(refuse("nothing moves")),
        };
        self.state = next;
        Ok(next)
    }

    /// What the machine reported.
    pub fn event(&mut self, e: Event) -> State {
        use State as S;
        let s = self.state;
        self.state = match (e, s) {
            (Event::EStopInput, _) => S::EStop,
            (Event::Fault, _) if s.enabled() => S::Fault,
            (Event::Homed { all }, S::Homing) => {
                self.homed = all;
                if all {
                    S::Idle
                } else {
                    S::On
                }
            }
            (Event::HomingFailed, S::Homing) => S::On,
            (Event::AtRest, S::Jog | S::Mdi) => {
                if self.homed {
                    S::Idle
                } else {
                    S::On
                }
            }
            (Event::AtRest, S::Stepping) => S::Paused,
            (Event::ProgramEnd, S::Running | S::Stepping) => {
                self.stepping = false;
                S::Idle
            }
            _ => s,
        };
        // A fault or an e-stop may have lost the axes' positions: home again (an
        // absolute encoder keeps its position).
        if matches!(self.state, S::EStop | S::Fault) && s != self.state {
            self.homed = self.all_absolute;
        }
        self.state
    }
}

#[cfg(test)]
mod tests;
