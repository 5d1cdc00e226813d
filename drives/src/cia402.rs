//! The CiA-402 drive state machine ("power drive system" device control), pure: statusword
//! and goal in, controlword out, for the master ([`Sequencer`]); controlword in, statusword
//! out, for a simulated drive ([`DriveModel`]).
//!
//! # The graph (CiA-402-2, transition numbers as in the standard)
//!
//! ```text
//!  power on -0-> Not ready to switch on -1-> Switch on disabled <------------------+
//!                                             |  ^                                 |
//!                                  2 Shutdown |  | 7 Disable voltage/Quick stop    | 15 Fault reset
//!                                             v  |                                 |
//!                                       Ready to switch on <--+                  Fault
//!                                             |  ^            | 8 Shutdown         ^
//!                                 3 Switch on |  | 6 Shutdown |                    | 14 automatic
//!                                             v  |            |                    |
//!                                          Switched on        |         Fault reaction active
//!                                             |  ^            |                    ^
//!                          4 Enable operation |  | 5 Disable  |                    | 13 any state,
//!                                             v  | operation  |                    |    on a fault
//!                                       Operation enabled ----+
//!                                             |  ^
//!                                11 Quick stop|  | 16 Enable operation (quick-stop options 5-8)
//!                                             v  |
//!                                       Quick stop active --12 Disable voltage--> Switch on disabled
//! ```
//!
//! Also to Switch on disabled: 9 (Operation enabled, Disable voltage) and 10 (Switched on,
//! Disable voltage or Quick stop); Operation enabled -> Quick stop active is transition 11.
//! A drive whose quick-stop option code (0x605A) is 0..=4 takes transition 12 by itself once
//! stopped.
//!
//! Controlword commands (bit 7 fault reset, 3 enable operation, 2 quick stop (active low),
//! 1 enable voltage, 0 switch on): Shutdown 0x06, Switch on 0x07, Enable operation 0x0F,
//! Disable voltage 0x00, Quick stop 0x02, Disable operation 0x07, Fault reset: a rising edge
//! of bit 7 (0x80).
//!
//! # What the master sends
//!
//! [`next_controlword`] moves the drive one edge toward the [`Goal`] and holds it there. It
//! depends only on the observed state (and, for the fault-reset edge, on the last controlword),
//! so resending it while a drive is a cycle behind is harmless. Disabling steps down 5, 6, 7
//! rather than jumping with Disable voltage (9), which would switch off the power stage of a
//! moving axis and let it coast. Leaving Quick stop active goes through 12 (Disable voltage)
//! and back up, which works whatever the drive's quick-stop option code. In a persisting
//! fault the sequencer produces a reset edge every second call; how often to retry is the
//! caller's policy.
#![forbid(unsafe_code)]

/// A CiA-402 state, named as in the standard.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum State {
    NotReadyToSwitchOn,
    SwitchOnDisabled,
    ReadyToSwitchOn,
    SwitchedOn,
    OperationEnabled,
    QuickStopActive,
    FaultReactionActive,
    Fault,
}

impl State {
    /// (mask, value) of the statusword for each state (docs/canopen.md).
    const PATTERNS: [(u16, u16, State); 8] = [
        (0x4F, 0x00, State::NotReadyToSwitchOn),
        (0x4F, 0x40, State::SwitchOnDisabled),
        (0x6F, 0x21, State::ReadyToSwitchOn),
        (0x6F, 0x23, State::SwitchedOn),
        (0x6F, 0x27, State::OperationEnabled),
        (0x6F, 0x07, State::QuickStopActive),
        (0x4F, 0x0F, State::FaultReactionActive),
        (0x4F, 0x08, State::Fault),
    ];

    /// The state a statusword reports; `None` for a combination of bits 0-3, 5, 6 that the
    /// standard does not define.
    pub fn from_statusword(statusword: u16) -> Option<State> {
        Self::PATTERNS
            .iter()
            .find(|(mask, value, _)| statusword & mask == *value)
            .map(|&(_, _, state)| state)
    }

    /// The state's value bits of the statusword (bits 0-3, 5, 6).
    pub fn statusword_bits(self) -> u16 {
        Self::PATTERNS
            .iter()
            .find(|(_, _, state)| *state == self)
            .map_or(0, |&(_, value, _)| value)
    }
}

/// Statusword 0x6041 and its bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Statusword(pub u16);

impl Statusword {
    pub const VOLTAGE_ENABLED: u16 = 1 << 4;
    pub const WARNING: u16 = 1 << 7;
    pub const REMOTE: u16 = 1 << 9;
    pub const TARGET_REACHED: u16 = 1 << 10;
    /// In CSP: the drive follows the target position.
    pub const TARGET_FOLLOWED: u16 = 1 << 12;
    /// In CSP: following error.
    pub const FOLLOWING_ERROR: u16 = 1 << 13;

    pub fn state(self) -> Option<State> {
        State::from_statusword(self.0)
    }

    /// Bit 4: high voltage is applied to the drive.
    pub const fn voltage_enabled(self) -> bool {
        self.0 & Self::VOLTAGE_ENABLED != 0
    }

    /// Bit 7.
    pub const fn warning(self) -> bool {
        self.0 & Self::WARNING != 0
    }

    /// Bit 9: the drive accepts commands over the bus.
    pub const fn remote(self) -> bool {
        self.0 & Self::REMOTE != 0
    }

    /// Bit 10: target reached; in profile velocity mode, the velocity has been within the
    /// velocity window 0x606D of the target for the window time 0x606E.
    pub const fn target_reached(self) -> bool {
        self.0 & Self::TARGET_REACHED != 0
    }

    /// Bit 12 in cyclic synchronous position mode: the drive follows the target.
    pub const fn target_followed(self) -> bool {
        self.0 & Self::TARGET_FOLLOWED != 0
    }

    /// Bit 13 in cyclic synchronous position mode: following error.
    pub const fn following_error(self) -> bool {
        self.0 & Self::FOLLOWING_ERROR != 0
    }
}

/// Controlword 0x6040 and the device-control commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Controlword(pub u16);

impl Controlword {
    pub const SHUTDOWN: Self = Self(0x06);
    pub const SWITCH_ON: Self = Self(0x07);
    pub const ENABLE_OPERATION: Self = Self(0x0F);
    pub const DISABLE_VOLTAGE: Self = Self(0x00);
    pub const QUICK_STOP: Self = Self(0x02);
    pub const DISABLE_OPERATION: Self = Self(0x07);
    /// Effective on its rising edge: the previous controlword must have bit 7 clear.
    pub const FAULT_RESET: Self = Self(0x80);

    const FAULT_RESET_BIT: u16 = 0x80;
}

/// Where the master wants the drive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Goal {
    /// Operation enabled: the drive follows the target.
    Enabled,
    /// Switch on disabled, reached through Disable operation and Shutdown.
    Disabled,
    /// Quick stop active (or Switch on disabled, where a drive ends a quick stop).
    QuickStop,
}

impl Goal {
    /// `true` once `state` is where this goal holds the drive.
    pub fn reached(self, state: State) -> bool {
        match self {
            Goal::Enabled => state == State::OperationEnabled,
            Goal::Disabled => state == State::SwitchOnDisabled,
            Goal::QuickStop => matches!(state, State::QuickStopActive | State::SwitchOnDisabled),
        }
    }
}

/// The controlword that moves a drive in `state` one transition toward `goal`; `last` is the
/// previous controlword sent, needed for the fault-reset edge and to wait in the automatic
/// states.
pub fn next_controlword(state: State, goal: Goal, last: Controlword) -> Controlword {
    use State as S;
    match (goal, state) {
        (Goal::Enabled, S::NotReadyToSwitchOn | S::FaultReactionActive) => last, // automatic
        (Goal::Enabled, S::SwitchOnDisabled) => Controlword::SHUTDOWN,           // 2
        (Goal::Enabled, S::ReadyToSwitchOn) => Controlword::SWITCH_ON,           // 3
        (Goal::Enabled, S::SwitchedOn | S::OperationEnabled) => Controlword::ENABLE_OPERATION, // 4
        (Goal::Enabled, S::QuickStopActive) => Controlword::DISABLE_VOLTAGE,     // 12
        (Goal::Enabled, S::Fault) if last.0 & Controlword::FAULT_RESET_BIT != 0 => {
            Controlword::DISABLE_VOLTAGE // bit 7 low, so that the next call makes an edge
        }
        (Goal::Enabled, S::Fault) => Controlword::FAULT_RESET, // 15
        (Goal::Disabled, S::OperationEnabled) => Controlword::DISABLE_OPERATION, // 5
        (Goal::Disabled, S::SwitchedOn) => Controlword::SHUTDOWN, // 6
        (Goal::Disabled, _) => Controlword::DISABLE_VOLTAGE,   // 7, 12; holds everywhere else
        (Goal::QuickStop, _) => Controlword::QUICK_STOP,       // 11, 7, 10; no-op elsewhere
    }
}

/// [`next_controlword`] with the last controlword kept for the caller.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sequencer {
    last: Controlword,
}

impl Sequencer {
    /// Starts as if Disable voltage had been sent.
    pub const fn new() -> Self {
        Self {
            last: Controlword::DISABLE_VOLTAGE,
        }
    }

    /// The controlword to send this cycle.
    pub fn step(&mut self, state: State, goal: Goal) -> Controlword {
        self.last = next_controlword(state, goal, self.last);
        self.last
    }

    pub const fn last(&self) -> Controlword {
        self.last
    }
}

impl Default for Sequencer {
    fn default() -> Self {
        Self::new()
    }
}

/// A drive's side of the state machine, for the simulated drive: applies controlwords per
/// the graph above and reports the statusword, in cyclic synchronous position mode.
///
/// It starts in Not ready to switch on; [`tick`](Self::tick) performs the automatic
/// transitions (1 and 14). It behaves as quick-stop option codes 5..=8 (stays in Quick stop
/// active, accepts transition 16); "Switch on + Enable operation" (0x0F) in Ready to switch
/// on takes 3 and 4 at once, as the standard allows. The statusword has bit 9 (remote)
/// always, bit 4 (voltage enabled) in Switched on, Operation enabled and Quick stop active,
/// and bit 12 (target followed) in Operation enabled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DriveModel {
    state: State,
    last_controlword: u16,
}

/// A device-control command, decoded from a controlword by the drive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Command {
    DisableVoltage,
    QuickStop,
    Shutdown,
    SwitchOn, // also Disable operation
    EnableOperation,
    FaultReset,
    Held,
}

impl Command {
    /// CiA-402 table "command coding": bits 7, 3, 2, 1, 0.
    fn decode(controlword: u16, previous: u16) -> Self {
        let bit = |n: u16| controlword & (1 << n) != 0;
        if bit(7) {
            return if previous & Controlword::FAULT_RESET_BIT == 0 {
                Command::FaultReset
            } else {
                Command::Held // bit 7 held high: no command
            };
        }
        match (bit(3), bit(2), bit(1), bit(0)) {
            (_, _, false, _) => Command::DisableVoltage,
            (_, false, true, _) => Command::QuickStop,
            (_, true, true, false) => Command::Shutdown,
            (false, true, true, true) => Command::SwitchOn,
            (true, true, true, true) => Command::EnableOperation,
        }
    }
}

impl DriveModel {
    pub const fn new() -> Self {
        Self {
            state: State::NotReadyToSwitchOn,
            last_controlword: 0,
        }
    }

    pub const fn state(&self) -> State {
        self.state
    }

    /// Applies a received controlword and returns the resulting statusword.
    pub fn apply(&mut self, controlword: u16) -> u16 {
        use Command as C;
        use State as S;
        let command = Command::decode(controlword, self.last_controlword);
        self.last_controlword = controlword;
        self.state = match (self.state, command) {
            (S::SwitchOnDisabled, C::Shutdown) => S::ReadyToSwitchOn, // 2
            (S::ReadyToSwitchOn, C::SwitchOn) => S::SwitchedOn,       // 3
            (S::ReadyToSwitchOn, C::EnableOperation) => S::OperationEnabled, // 3 + 4
            (S::SwitchedOn, C::EnableOperation) => S::OperationEnabled, // 4
            (S::OperationEnabled, C::SwitchOn) => S::SwitchedOn,      // 5
            (S::SwitchedOn, C::Shutdown) => S::ReadyToSwitchOn,       // 6
            (S::ReadyToSwitchOn, C::DisableVoltage | C::QuickStop) => S::SwitchOnDisabled, // 7
            (S::OperationEnabled, C::Shutdown) => S::ReadyToSwitchOn, // 8
            (S::OperationEnabled, C::DisableVoltage) => S::SwitchOnDisabled, // 9
            (S::SwitchedOn, C::DisableVoltage | C::QuickStop) => S::SwitchOnDisabled, // 10
            (S::OperationEnabled, C::QuickStop) => S::QuickStopActive, // 11
            (S::QuickStopActive, C::DisableVoltage) => S::SwitchOnDisabled, // 12
            (S::Fault, C::FaultReset) => S::SwitchOnDisabled,         // 15
            (S::QuickStopActive, C::EnableOperation) => S::OperationEnabled, // 16
            (state, _) => state,
        };
        self.statusword()
    }

    /// Automatic transitions: 1 (self-test done) and 14 (fault reaction done).
    pub fn tick(&mut self) -> u16 {
        self.state = match self.state {
            State::NotReadyToSwitchOn => State::SwitchOnDisabled,
            State::FaultReactionActive => State::Fault,
            state => state,
        };
        self.statusword()
    }

    /// A fault occurs (transition 13); the next [`tick`](Self::tick) enters Fault.
    pub fn inject_fault(&mut self) {
        if !matches!(self.state, State::FaultReactionActive | State::Fault) {
            self.state = State::FaultReactionActive;
        }
    }

    pub fn statusword(&self) -> u16 {
        let voltage = matches!(
            self.state,
            State::SwitchedOn | State::OperationEnabled | State::QuickStopActive
        );
        let following = self.state == State::OperationEnabled;
        self.state.statusword_bits()
            | Statusword::REMOTE
            | if voltage {
                Statusword::VOLTAGE_ENABLED
            } else {
                0
            }
            | if following {
                Statusword::TARGET_FOLLOWED
            } else {
                0
            }
    }
}

impl Default for DriveModel {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests;
