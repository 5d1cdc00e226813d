//! The master's [`Sequencer`] driven against the drive-side [`DriveModel`], plus the
//! statusword and controlword tables.

use super::*;

const ALL_STATES: [State; 8] = [
    State::NotReadyToSwitchOn,
    State::SwitchOnDisabled,
    State::ReadyToSwitchOn,
    State::SwitchedOn,
    State::OperationEnabled,
    State::QuickStopActive,
    State::FaultReactionActive,
    State::Fault,
];

/// Runs sequencer and model in lock step until `goal` is reached; returns the controlwords
/// sent. Panics (test only) if the goal is not reached within 10 steps.
fn drive_to(model: &mut DriveModel, seq: &mut Sequencer, goal: Goal) -> Vec<u16> {
    let mut sent = Vec::new();
    for _ in 0..10 {
        let state = State::from_statusword(model.statusword()).expect("model statusword");
        if goal.reached(state) {
            return sent;
        }
        let cw = seq.step(state, goal);
        sent.push(cw.0);
        model.apply(cw.0);
    }
    panic!(
        "{goal:?} not reached from {:?}: sent {sent:02X?}",
        model.state()
    );
}

fn enabled() -> (DriveModel, Sequencer) {
    let mut model = DriveModel::new();
    let mut seq = Sequencer::new();
    model.tick();
    drive_to(&mut model, &mut seq, Goal::Enabled);
    (model, seq)
}

#[test]
fn statusword_patterns_of_the_docs() {
    let cases = [
        (0x0000, Some(State::NotReadyToSwitchOn)),
        (0x0250, Some(State::SwitchOnDisabled)),
        (0x0231, Some(State::ReadyToSwitchOn)),
        (0x0233, Some(State::SwitchedOn)),
        (0x1237, Some(State::OperationEnabled)),
        (0x0217, Some(State::QuickStopActive)),
        (0x021F, Some(State::FaultReactionActive)),
        (0x023F, Some(State::FaultReactionActive)), // bit 5 is outside the mask
        (0x0218, Some(State::Fault)),
        (0x0238, Some(State::Fault)),
        (0x0001, None),
        (0x0041, None),
        (0x0060, Some(State::SwitchOnDisabled)),
        (0x0027 | 0x40, None),
    ];
    for (sw, state) in cases {
        assert_eq!(State::from_statusword(sw), state, "0x{sw:04X}");
    }
    for state in ALL_STATES {
        assert_eq!(State::from_statusword(state.statusword_bits()), Some(state));
    }
}

#[test]
fn statusword_bits() {
    let sw = Statusword(0x3237 | 0x80);
    assert_eq!(sw.state(), Some(State::OperationEnabled));
    assert!(sw.target_followed() && sw.following_error() && sw.warning());
    assert!(sw.voltage_enabled() && sw.remote());
    let sw = Statusword(0x0040);
    assert!(!sw.target_followed() && !sw.following_error() && !sw.warning());
    assert!(!sw.voltage_enabled() && !sw.remote());
}

#[test]
fn next_controlword_table() {
    use Controlword as Cw;
    let last = Cw::ENABLE_OPERATION;
    let cases = [
        (
            State::NotReadyToSwitchOn,
            [last, Cw::DISABLE_VOLTAGE, Cw::QUICK_STOP],
        ),
        (
            State::SwitchOnDisabled,
            [Cw::SHUTDOWN, Cw::DISABLE_VOLTAGE, Cw::QUICK_STOP],
        ),
        (
            State::ReadyToSwitchOn,
            [Cw::SWITCH_ON, Cw::DISABLE_VOLTAGE, Cw::QUICK_STOP],
        ),
        (
            State::SwitchedOn,
            [Cw::ENABLE_OPERATION, Cw::SHUTDOWN, Cw::QUICK_STOP],
        ),
        (
            State::OperationEnabled,
            [Cw::ENABLE_OPERATION, Cw::DISABLE_OPERATION, Cw::QUICK_STOP],
        ),
        (
            State::QuickStopActive,
            [Cw::DISABLE_VOLTAGE, Cw::DISABLE_VOLTAGE, Cw::QUICK_STOP],
        ),
        (
            State::FaultReactionActive,
            [last, Cw::DISABLE_VOLTAGE, Cw::QUICK_STOP],
        ),
        (
            State::Fault,
            [Cw::FAULT_RESET, Cw::DISABLE_VOLTAGE, Cw::QUICK_STOP],
        ),
    ];
    for (state, expected) in cases {
        let got = [Goal::Enabled, Goal::Disabled, Goal::QuickStop]
            .map(|goal| next_controlword(state, goal, last));
        assert_eq!(got, expected, "{state:?}");
    }
}

#[test]
fn enables_from_power_on_in_three_steps() {
    let mut model = DriveModel::new();
    let mut seq = Sequencer::new();
    assert_eq!(model.state(), State::NotReadyToSwitchOn);
    // The drive is still in self-test: the sequencer waits.
    assert_eq!(
        seq.step(State::NotReadyToSwitchOn, Goal::Enabled),
        Controlword::DISABLE_VOLTAGE
    );
    assert_eq!(model.tick(), 0x0240);
    let sent = drive_to(&mut model, &mut seq, Goal::Enabled);
    assert_eq!(sent, [0x06, 0x07, 0x0F]);
    assert_eq!(model.statusword(), 0x1237);
    // Holding: the sequencer keeps sending Enable operation.
    assert_eq!(
        seq.step(State::OperationEnabled, Goal::Enabled),
        Controlword::ENABLE_OPERATION
    );
    assert_eq!(model.apply(0x0F), 0x1237);
}

#[test]
fn fault_reset_and_re_enable() {
    let (mut model, mut seq) = enabled();
    model.inject_fault();
    assert_eq!(model.statusword(), 0x020F);
    // Fault reaction active: the sequencer waits and the drive ignores it.
    let cw = seq.step(model.state(), Goal::Enabled);
    assert_eq!(cw, Controlword::ENABLE_OPERATION);
    assert_eq!(model.apply(cw.0), 0x020F);
    assert_eq!(model.tick(), 0x0208);
    let sent = drive_to(&mut model, &mut seq, Goal::Enabled);
    assert_eq!(sent, [0x80, 0x06, 0x07, 0x0F]);
}

#[test]
fn fault_reset_needs_a_rising_edge() {
    let mut seq = Sequencer::new();
    // A fault that persists: the sequencer alternates 0x80 and 0x00.
    let sent: Vec<u16> = (0..4)
        .map(|_| seq.step(State::Fault, Goal::Enabled).0)
        .collect();
    assert_eq!(sent, [0x80, 0x00, 0x80, 0x00]);

    let mut model = DriveModel::new();
    model.tick();
    // Bit 7 already high when the fault appears: no edge, no reset.
    model.apply(0x80);
    model.inject_fault();
    model.tick();
    model.apply(0x80);
    assert_eq!(model.state(), State::Fault);
    let mut seq = Sequencer::new();
    let mut last = seq.step(State::Fault, Goal::Enabled);
    model.apply(last.0);
    assert_eq!(
        model.state(),
        State::Fault,
        "0x80 after 0x80 is not an edge"
    );
    last = seq.step(State::Fault, Goal::Enabled);
    assert_eq!(last, Controlword::DISABLE_VOLTAGE);
    model.apply(last.0);
    let sent = drive_to(&mut model, &mut seq, Goal::Enabled);
    assert_eq!(sent, [0x80, 0x06, 0x07, 0x0F]);
}

#[test]
fn quick_stop_and_back() {
    let (mut model, mut seq) = enabled();
    assert_eq!(drive_to(&mut model, &mut seq, Goal::QuickStop), [0x02]);
    assert_eq!(model.statusword(), 0x0217);
    // Holding the quick stop.
    assert_eq!(
        seq.step(model.state(), Goal::QuickStop),
        Controlword::QUICK_STOP
    );
    assert_eq!(model.apply(0x02), 0x0217);
    let sent = drive_to(&mut model, &mut seq, Goal::Enabled);
    assert_eq!(sent, [0x00, 0x06, 0x07, 0x0F]);
}

#[test]
fn disable_steps_down_without_coasting() {
    let (mut model, mut seq) = enabled();
    let sent = drive_to(&mut model, &mut seq, Goal::Disabled);
    assert_eq!(sent, [0x07, 0x06, 0x00]);
    assert_eq!(model.statusword(), 0x0240);
}

#[test]
fn quick_stop_when_not_enabled_disables() {
    let mut model = DriveModel::new();
    model.tick();
    model.apply(0x06);
    model.apply(0x07);
    assert_eq!(model.state(), State::SwitchedOn);
    let mut seq = Sequencer::new();
    assert_eq!(drive_to(&mut model, &mut seq, Goal::QuickStop), [0x02]);
    assert_eq!(model.state(), State::SwitchOnDisabled);
}

#[test]
fn drive_model_transitions() {
    // (from, controlword, to), one row per numbered transition plus some non-transitions.
    use State as S;
    let cases = [
        (S::SwitchOnDisabled, 0x06, S::ReadyToSwitchOn),  // 2
        (S::ReadyToSwitchOn, 0x07, S::SwitchedOn),        // 3
        (S::ReadyToSwitchOn, 0x0F, S::OperationEnabled),  // 3 + 4
        (S::SwitchedOn, 0x0F, S::OperationEnabled),       // 4
        (S::OperationEnabled, 0x07, S::SwitchedOn),       // 5
        (S::SwitchedOn, 0x06, S::ReadyToSwitchOn),        // 6
        (S::ReadyToSwitchOn, 0x00, S::SwitchOnDisabled),  // 7
        (S::ReadyToSwitchOn, 0x02, S::SwitchOnDisabled),  // 7
        (S::OperationEnabled, 0x06, S::ReadyToSwitchOn),  // 8
        (S::OperationEnabled, 0x00, S::SwitchOnDisabled), // 9
        (S::SwitchedOn, 0x02, S::SwitchOnDisabled),       // 10
        (S::OperationEnabled, 0x02, S::QuickStopActive),  // 11
        (S::QuickStopActive, 0x00, S::SwitchOnDisabled),  // 12
        (S::QuickStopActive, 0x0F, S::OperationEnabled),  // 16
        (S::SwitchOnDisabled, 0x07, S::SwitchOnDisabled),
        (S::SwitchOnDisabled, 0x0F, S::SwitchOnDisabled),
        (S::QuickStopActive, 0x06, S::QuickStopActive),
        (S::OperationEnabled, 0x8F, S::OperationEnabled), // fault reset outside Fault
        (S::OperationEnabled, 0x010F, S::OperationEnabled), // halt bit: not modelled
    ];
    for (from, cw, to) in cases {
        let mut model = reach(from);
        model.apply(cw);
        assert_eq!(model.state(), to, "{from:?} + 0x{cw:02X}");
    }
    let mut model = reach(S::OperationEnabled);
    model.inject_fault();
    model.apply(0x80);
    assert_eq!(
        model.state(),
        S::FaultReactionActive,
        "no reset during the reaction"
    );
    model.inject_fault();
    assert_eq!(model.tick(), 0x0208);
    model.inject_fault();
    assert_eq!(model.state(), S::Fault);
}

/// A model in `state`, reached through the model's own transitions.
fn reach(state: State) -> DriveModel {
    let mut model = DriveModel::new();
    model.tick();
    let path: &[u16] = match state {
        State::SwitchOnDisabled => &[],
        State::ReadyToSwitchOn => &[0x06],
        State::SwitchedOn => &[0x06, 0x07],
        State::OperationEnabled => &[0x06, 0x07, 0x0F],
        State::QuickStopActive => &[0x06, 0x07, 0x0F, 0x02],
        other => panic!("reach({other:?}) is not needed"),
    };
    for &cw in path {
        model.apply(cw);
    }
    assert_eq!(model.state(), state);
    model
}
