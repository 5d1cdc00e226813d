//! Every command in every state: taken where the table of the module says, refused
//! elsewhere with its reason and the controller unchanged.

use super::*;

/// A controller in `state`, reached by commands and events as an operator would.
fn reach(state: State) -> Controller {
    let mut c = Controller::new(false);
    let cmd = |c: &mut Controller, k| {
        c.command(k)
            .unwrap_or_else(|e| panic!("reaching {state:?}: {e}"));
    };
    let idle = |c: &mut Controller| {
        cmd(c, Command::On);
        cmd(c, Command::Home);
        c.event(Event::Homed { all: true });
    };
    match state {
        State::Off => {}
        State::On => cmd(&mut c, Command::On),
        State::Homing => {
            cmd(&mut c, Command::On);
            cmd(&mut c, Command::Home);
        }
        State::Idle => idle(&mut c),
        State::Jog => {
            cmd(&mut c, Command::On);
            cmd(&mut c, Command::Jog);
        }
        State::Mdi => {
            idle(&mut c);
            cmd(&mut c, Command::Mdi);
        }
        State::Running | State::Paused | State::Stepping => {
            idle(&mut c);
            cmd(&mut c, Command::Load);
            cmd(
                &mut c,
                if state == State::Stepping {
                    Command::Step
                } else {
                    Command::Run
                },
            );
            if state == State::Paused {
                cmd(&mut c, Command::Pause);
            }
        }
        State::EStop => cmd(&mut c, Command::EStop),
        State::Fault => {
            cmd(&mut c, Command::On);
            c.event(Event::Fault);
        }
    }
    assert_eq!(c.state(), state);
    c
}

const STATES: [State; 11] = [
    State::EStop,
    State::Off,
    State::On,
    State::Homing,
    State::Idle,
    State::Jog,
    State::Mdi,
    State::Running,
    State::Paused,
    State::Stepping,
    State::Fault,
];

/// Where each command is taken (the module's table).
fn takes(c: Command, s: State) -> bool {
    use State as S;
    match c {
        Command::EStop => true,
        Command::Reset => matches!(s, S::EStop | S::Fault),
        Command::On => s == S::Off,
        Command::Off => matches!(s, S::On | S::Idle | S::Paused),
        Command::Home | Command::Jog => matches!(s, S::On | S::Idle),
        Command::Mdi => s == S::Idle,
        Command::Load => matches!(s, S::Off | S::On | S::Idle),
        // In the states reached here, Idle has no program loaded.
        Command::Run => false,
        Command::Step => s == S::Paused,
        Command::Pause => matches!(s, S::Running | S::Stepping | S::Mdi),
        Command::Resume => s == S::Paused,
        Command::Stop => matches!(
            s,
            S::Homing | S::Jog | S::Mdi | S::Running | S::Paused | S::Stepping
        ),
        Command::Override => s.enabled(),
    }
}

#[test]
fn every_command_in_every_state() {
    for s in STATES {
        for c in Command::ALL {
            let before = reach(s);
            let mut after = before;
            match after.command(c) {
                Ok(_) => assert!(takes(c, s), "{} taken in {}", c.name(), s.name()),
                Err(e) => {
                    assert!(!takes(c, s), "{} refused in {}: {e}", c.name(), s.name());
                    assert_eq!(after, before, "a refusal changes nothing");
                    assert!(
                        e.to_string().starts_with(&format!(
                            "{} refused in state {}: ",
                            c.name(),
                            s.name()
                        )),
                        "{e}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_program_runs_only_homed_and_loaded() {
    let mut c = reach(State::On);
    let e = c.command(Command::Run).unwrap_err();
    assert_eq!(e.reason, "not every axis is homed: home first");
    let mut c = reach(State::Idle);
    assert_eq!(
        c.command(Command::Run).unwrap_err().reason,
        "no program is loaded: load one first"
    );
    c.command(Command::Load).unwrap();
    assert_eq!(c.command(Command::Run), Ok(State::Running));
    assert_eq!(c.event(Event::ProgramEnd), State::Idle);
    // Every axis absolute: no homing needed.
    let mut c = Controller::new(true);
    c.command(Command::On).unwrap();
    c.command(Command::Load).unwrap();
    assert_eq!(c.command(Command::Run), Ok(State::Running));
}

#[test]
fn stepping_runs_a_block_then_pauses() {
    let mut c = reach(State::Stepping);
    assert_eq!(c.event(Event::AtRest), State::Paused);
    assert_eq!(c.command(Command::Step), Ok(State::Stepping));
    assert_eq!(c.event(Event::AtRest), State::Paused);
    assert_eq!(c.command(Command::Resume), Ok(State::Running), "runs on");
    c.command(Command::Pause).unwrap();
    assert_eq!(c.command(Command::Stop), Ok(State::Idle));
    c.command(Command::Run).unwrap();
    c.command(Command::Pause).unwrap();
    assert_eq!(
        c.command(Command::Resume),
        Ok(State::Running),
        "no longer stepping"
    );
}

#[test]
fn a_fault_or_an_e_stop_needs_a_reset_and_homing_again() {
    for e in [Event::Fault, Event::EStopInput] {
        let mut c = reach(State::Running);
        let to = c.event(e);
        assert!(matches!(to, State::Fault | State::EStop));
        assert!(!c.homed());
        assert_eq!(c.command(Command::Reset), Ok(State::Off));
        assert_eq!(c.command(Command::On), Ok(State::On), "homing again");
    }
    let mut c = Controller::new(true);
    c.command(Command::On).unwrap();
    c.event(Event::Fault);
    c.command(Command::Reset).unwrap();
    assert_eq!(
        c.command(Command::On),
        Ok(State::Idle),
        "absolute encoders keep theirs"
    );
}

#[test]
fn homing_that_fails_or_leaves_axes_unhomed_stays_on() {
    let mut c = reach(State::Homing);
    assert_eq!(c.event(Event::HomingFailed), State::On);
    c.command(Command::Home).unwrap();
    assert_eq!(c.event(Event::Homed { all: false }), State::On);
    c.command(Command::Home).unwrap();
    assert_eq!(c.event(Event::Homed { all: true }), State::Idle);
    // A jog ends where it began: homed or not.
    c.command(Command::Jog).unwrap();
    assert_eq!(c.event(Event::AtRest), State::Idle);
}
