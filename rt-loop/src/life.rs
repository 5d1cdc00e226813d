//! The machine's life: what the real-time thread of `dnurbs serve` does every period, from
//! start-up to shutdown, with the drives staying on between programs.
//!
//! [`Life::cycle`] is called once a period. [`Order`]s come in through a preallocated SPSC
//! queue (from the controller's socket and planner threads), what happened goes out through
//! another ([`Happened`]), and [`Status`] is published in atomics. In between, the machine
//! is in one [`Mode`]:
//!
//! | mode | the drives | the targets |
//! |---|---|---|
//! | `off` | disabled | where the drives stand |
//! | `enabling` | brought to Operation enabled | where they stand |
//! | `holding` | enabled | the last ones, unchanged |
//! | `homing` | one axis homing (CiA-402 mode 6, the master's job) | its own position |
//! | `jog` | one axis jogging ([`nc_follow::jog::Jog`]) | the jog's, the others held |
//! | `program` | a program or an MDI line ([`Pipeline::from_here`]) | the interpolator's |
//! | `disabling` | the disable sequence | held |
//! | `fault` | quick-stopped and disabled by the master | held |
//!
//! Programs and MDI lines run on one pair of chunk queues for the machine's life: each
//! starts where the drives stand ([`Order::Program`]), with the interpolator handed the new
//! start ([`nc_follow::Follower::next_program`]); it ends with the drives holding where it
//! stopped (or, on a fault, quick-stopped). The rules an operator meets (no jog while a
//! program runs, homing first) are the controller's, before an order is sent; the checks
//! here are the last line: an order that does not fit the mode is refused with
//! [`Happened::Refused`] and changes nothing.
//!
//! Allocates nothing, locks nothing; every loop is bounded by the drives or a queue.

mod looping;
mod manual;

pub use looping::{life_loop, LoopCounts};

use crate::control::Command;
use crate::pipeline::{BusDrives, NotHere, Pipeline, PipelineError, StopReason};
use core::sync::atomic::{AtomicU64, AtomicU8, Ordering::Relaxed};
use drives::link::CanLink;
use drives::master::ResetRefused;
use drives::master::{BusCondition, DriveFault, HomeRefused, HomeRequest, HomingError};
use heapless::spsc::{Consumer, Producer, Queue};
use nc_follow::jog::{Jog, JogLimits, JogRefused};
use nc_follow::jog_line::{LineJog, LineRefused};
use nc_follow::{Follower, Start};

/// Slots of the order queue (it holds one fewer).
pub const ORDERS: usize = 16;
/// Slots of the queue of what happened (it holds one fewer).
pub const HAPPENINGS: usize = 64;

/// What the controller asks of the real-time thread.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Order {
    /// Enable the drives and hold where they stand.
    On,
    /// Disable the drives (at rest only).
    Off,
    /// Home the axis drive at `index` of bus `bus` (the master's node order) as `req` says;
    /// while others home, it homes with them (up to [`HOMING_AT_ONCE`]).
    Home {
        bus: usize,
        index: usize,
        req: HomeRequest,
    },
    /// Jog `axis` (0..5: X Y Z tilt C) continuously at `velocity` (signed, units/s); sent
    /// again, it renews the dead-man.
    Jog {
        axis: usize,
        limits: JogLimits,
        velocity: f64,
    },
    /// Jog `axis` from rest to `target` at up to `speed`.
    JogTo {
        axis: usize,
        limits: JogLimits,
        target: f64,
        speed: f64,
    },
    /// Jog X Y Z together along `dir` (machine X Y Z, any length), the rotary axes still:
    /// the workpiece's X, Y or Z, or the tool axis ([`nc_follow::jog_line`]).
    /// `distance`: incremental, that far at up to `speed`; none: continuous at `speed`
    /// (signed), renewed by the same order again.
    LineJog {
        dir: [f64; 3],
        limits: [JogLimits; 3],
        distance: Option<f64>,
        speed: f64,
    },
    /// Run the program (or MDI line) whose chunks the planner feeds from now on; it starts
    /// where the drives stand.
    Program { start: Start },
    /// Pause, resume, override or stop the program.
    Run(Command),
    /// Stop whatever moves: a jog stops jerk-limited, homing is interrupted, a program
    /// stops along its path.
    Stop,
    /// Acknowledge a fault (the CiA-402 fault-reset edge); the drives end disabled.
    Reset,
    /// Quick-stop and disable every drive.
    EStop,
}

impl Order {
    pub fn name(&self) -> &'static str {
        match self {
            Order::On => "on",
            Order::Off => "off",
            Order::Home { .. } => "home",
            Order::Jog { .. } => "jog",
            Order::JogTo { .. } => "jog to",
            Order::LineJog { .. } => "jog along a line",
            Order::Program { .. } => "program",
            Order::Run(Command::Pause) => "pause",
            Order::Run(Command::Resume) => "resume",
            Order::Run(Command::Override(_)) => "override",
            Order::Run(Command::Stop) | Order::Stop => "stop",
            Order::Reset => "reset",
            Order::EStop => "estop",
        }
    }
}

/// What the real-time thread reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Happened {
    /// Every drive is Operation enabled (`on`).
    Enabled,
    /// The drives did not enable within the timeout: disabled again.
    EnableTimeout,
    /// Every drive has left Operation enabled (`off`, or after a reset).
    Disabled,
    Homed {
        bus: usize,
        index: usize,
        counts: i32,
    },
    HomingFailed {
        bus: usize,
        index: usize,
        error: HomingError,
    },
    /// Homing started for the drive at `index` of bus `bus`.
    HomingStarted {
        bus: usize,
        index: usize,
    },
    HomeRefused(HomeRefused),
    /// A jog started (or a continuous one was renewed).
    JogStarted,
    JogRefused(JogRefused),
    LineJogRefused(LineRefused),
    /// A jog came to rest; `limited`: short of the travel.
    JogDone {
        limited: bool,
    },
    /// The program started.
    ProgramStarted,
    /// The program did not start (a drive is not at its start).
    ProgramRefused(PipelineError),
    /// The program is over: at its end (`reason` none) or stopped; `line` where it stopped.
    ProgramEnded {
        reason: Option<StopReason>,
        line: u32,
    },
    /// A drive, the bus, the e-stop chain or the operator's e-stop: every drive
    /// quick-stopped, then disabled.
    Fault(DriveFault),
    /// A condition of the bus (a warning, or what stopped a jog).
    Bus(BusCondition),
    /// The fault is acknowledged; the drives end disabled.
    ResetDone(DriveFault),
    ResetRefused(ResetRefused),
    /// The order does not fit the mode.
    Refused {
        order: &'static str,
        mode: Mode,
    },
}

/// Where the machine is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Off,
    Enabling,
    Holding,
    Homing,
    Jog,
    Program,
    Disabling,
    Fault,
}

impl Mode {
    pub const ALL: [Mode; 8] = [
        Mode::Off,
        Mode::Enabling,
        Mode::Holding,
        Mode::Homing,
        Mode::Jog,
        Mode::Program,
        Mode::Disabling,
        Mode::Fault,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Mode::Off => "off",
            Mode::Enabling => "enabling",
            Mode::Holding => "holding",
            Mode::Homing => "homing",
            Mode::Jog => "jog",
            Mode::Program => "program",
            Mode::Disabling => "disabling",
            Mode::Fault => "fault",
        }
    }

    fn index(self) -> u8 {
        Mode::ALL.iter().position(|&m| m == self).unwrap_or(0) as u8
    }
}

/// What [`Life::publish`] writes every period, for the status on any thread.
#[derive(Debug, Default)]
pub struct Status {
    mode: AtomicU8,
    /// Periods the life has run ([`Life::cycle`] calls); each sends one SYNC a bus.
    cycles: AtomicU64,
    /// Reports lost because their queue was full ([`Life::lost`]).
    lost: AtomicU64,
    /// The targets sent, per axis (mm, degrees), as f64 bits.
    axes: [AtomicU64; 5],
    /// The program's progress while one runs.
    pub run: crate::control::Progress,
}

impl Status {
    pub fn mode(&self) -> Mode {
        Mode::ALL[usize::from(self.mode.load(Relaxed)).min(Mode::ALL.len() - 1)]
    }

    pub fn cycles(&self) -> u64 {
        self.cycles.load(Relaxed)
    }

    pub fn lost(&self) -> u64 {
        self.lost.load(Relaxed)
    }

    pub fn axes(&self) -> [f64; 5] {
        core::array::from_fn(|j| f64::from_bits(self.axes[j].load(Relaxed)))
    }
}

/// The queues between the controller and the real-time thread, allocated once.
pub struct Queues {
    orders: Queue<Order, ORDERS>,
    happenings: Queue<Happened, HAPPENINGS>,
}

impl Default for Queues {
    fn default() -> Self {
        Queues {
            orders: Queue::new(),
            happenings: Queue::new(),
        }
    }
}

impl Queues {
    /// The controller's ends (orders in, happenings out) and the real-time thread's.
    #[allow(clippy::type_complexity)]
    pub fn split(
        &mut self,
    ) -> (
        (Producer<'_, Order>, Consumer<'_, Happened>),
        (Consumer<'_, Order>, Producer<'_, Happened>),
    ) {
        let (op, oc) = self.orders.split();
        let (hp, hc) = self.happenings.split();
        ((op, hc), (oc, hp))
    }
}

/// What the mode keeps from period to period. (A jog's plan is inline: boxing it would
/// allocate in the real-time thread.)
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
enum Doing {
    Off,
    Enabling {
        cycles: u64,
    },
    Holding,
    /// The axes homing together, bus and index ([`HOMING_AT_ONCE`] at most).
    Homing {
        jobs: [(u8, u8); HOMING_AT_ONCE],
        n: usize,
    },
    Jog {
        axis: usize,
        jog: Jog,
    },
    LineJog {
        jog: LineJog,
    },
    Program,
    Disabling {
        cycles: u64,
    },
    Fault,
}

/// Most axes homing at once (a homing sequence's group).
pub const HOMING_AT_ONCE: usize = 8;

/// The buses and the interpolator: free between programs, inside the pipeline during one.
/// (Moved, never boxed: boxing would allocate in the real-time thread.)
#[allow(clippy::large_enum_variant)]
enum Parts<'q, L: CanLink> {
    Free {
        buses: Vec<BusDrives<L>>,
        follower: Follower<'q>,
    },
    Running(Pipeline<'q, L>),
    /// Only while one is moved into the other.
    Moving,
}

/// The real-time thread's state for the machine's life.
pub struct Life<'q, L: CanLink> {
    parts: Parts<'q, L>,
    doing: Doing,
    orders: Consumer<'q, Order>,
    out: Producer<'q, Happened>,
    /// Reports the queue had no room for.
    lost: u64,
    cycles: u64,
    period: f64,
    enable_timeout_cycles: u64,
    /// Periods a continuous jog goes on after its last renewal.
    deadman_periods: u32,
    c_continuous: bool,
}

impl<'q, L: CanLink> Life<'q, L> {
    /// Off, the drives disabled. `follower`: the interpolator on the life's chunk queues;
    /// `deadman_periods`: a continuous jog's dead-man.
    pub fn new(
        buses: Vec<BusDrives<L>>,
        follower: Follower<'q>,
        (orders, out): (Consumer<'q, Order>, Producer<'q, Happened>),
        period: f64,
        enable_timeout_cycles: u64,
        deadman_periods: u32,
        c_continuous: bool,
    ) -> Self {
        Life {
            parts: Parts::Free { buses, follower },
            doing: Doing::Off,
            orders,
            out,
            lost: 0,
            cycles: 0,
            period,
            enable_timeout_cycles,
            deadman_periods,
            c_continuous,
        }
    }

    pub fn mode(&self) -> Mode {
        match self.doing {
            Doing::Off => Mode::Off,
            Doing::Enabling { .. } => Mode::Enabling,
            Doing::Holding => Mode::Holding,
            Doing::Homing { .. } => Mode::Homing,
            Doing::Jog { .. } | Doing::LineJog { .. } => Mode::Jog,
            Doing::Program => Mode::Program,
            Doing::Disabling { .. } => Mode::Disabling,
            Doing::Fault => Mode::Fault,
        }
    }

    /// Reports lost because the controller did not take them in time.
    pub fn lost(&self) -> u64 {
        self.lost
    }

    /// The buses, whichever part holds them.
    pub fn buses(&self) -> &[BusDrives<L>] {
        match &self.parts {
            Parts::Free { buses, .. } => buses,
            Parts::Running(p) => &p.buses,
            Parts::Moving => &[],
        }
    }

    fn buses_mut(&mut self) -> &mut [BusDrives<L>] {
        match &mut self.parts {
            Parts::Free { buses, .. } => buses,
            Parts::Running(p) => &mut p.buses,
            Parts::Moving => &mut [],
        }
    }

    fn report(&mut self, h: Happened) {
        if self.out.enqueue(h).is_err() {
            self.lost += 1;
        }
    }

    /// Publish the mode, the axes and a program's progress.
    ///
    /// Real-time thread.
    pub fn publish(&self, status: &Status) {
        status.mode.store(self.mode().index(), Relaxed);
        status.cycles.store(self.cycles, Relaxed);
        status.lost.store(self.lost, Relaxed);
        let mut axes = [0.0; 5];
        for b in self.buses() {
            for (d, t) in b.drives.iter().zip(&b.targets) {
                if let Some(a) = axes.get_mut(d.axis) {
                    *a = d.position(*t);
                }
            }
        }
        for (s, a) in status.axes.iter().zip(axes) {
            s.store(a.to_bits(), Relaxed);
        }
        if let Parts::Running(p) = &self.parts {
            p.publish(&status.run);
        }
    }

    /// One period at monotonic time `now_ns`.
    ///
    /// Real-time thread.
    pub fn cycle(&mut self, now_ns: u64) {
        self.cycles = self.cycles.wrapping_add(1);
        for _ in 0..ORDERS {
            let Some(o) = self.orders.dequeue() else {
                break;
            };
            self.order(o);
        }
        if let Parts::Running(p) = &mut self.parts {
            p.cycle(now_ns, false);
            if p.stage() == crate::pipeline::Stage::Finished {
                self.program_over();
            }
            return;
        }
        self.manual_cycle(now_ns as f64 * 1e-9);
    }

    /// Take an order, or refuse it.
    fn order(&mut self, o: Order) {
        let refused = Happened::Refused {
            order: o.name(),
            mode: self.mode(),
        };
        match (o, self.doing) {
            (Order::EStop, _) => {
                for b in self.buses_mut() {
                    b.master.estop();
                }
            }
            (Order::Reset, Doing::Fault) => self.reset(),
            (Order::On, Doing::Off) => self.doing = Doing::Enabling { cycles: 0 },
            (Order::Off, Doing::Holding | Doing::Enabling { .. }) => {
                self.doing = Doing::Disabling { cycles: 0 }
            }
            (Order::Home { bus, index, req }, Doing::Holding | Doing::Homing { .. }) => {
                self.home(bus, index, req)
            }
            (
                Order::Jog {
                    axis,
                    limits,
                    velocity,
                },
                Doing::Holding,
            ) => self.jog(axis, limits, |j| j.velocity(velocity)),
            (Order::Jog { axis, velocity, .. }, Doing::Jog { axis: a, mut jog }) if a == axis => {
                // The same jog again: the key is still held (a new speed takes effect).
                match jog.velocity(velocity) {
                    Ok(()) => {
                        self.doing = Doing::Jog { axis, jog };
                        self.report(Happened::JogStarted);
                    }
                    Err(e) => self.report(Happened::JogRefused(e)),
                }
            }
            (
                Order::JogTo {
                    axis,
                    limits,
                    target,
                    speed,
                },
                Doing::Holding,
            ) => self.jog(axis, limits, |j| j.to(target, speed)),
            (
                Order::LineJog {
                    dir,
                    limits,
                    distance,
                    speed,
                },
                Doing::Holding,
            ) => self.line_jog(dir, &limits, distance, speed),
            (
                Order::LineJog {
                    distance: None,
                    speed,
                    dir,
                    ..
                },
                Doing::LineJog { mut jog },
            ) if same_direction(jog.direction(), dir) => match jog.velocity(speed) {
                Ok(()) => {
                    self.doing = Doing::LineJog { jog };
                    self.report(Happened::JogStarted);
                }
                Err(e) => self.report(Happened::LineJogRefused(e)),
            },
            (Order::Program { start }, Doing::Holding) => self.program(start),
            (Order::Run(c), Doing::Program) => {
                if let Parts::Running(p) = &mut self.parts {
                    p.command(c);
                }
            }
            (Order::Run(Command::Override(_)), _) => {}
            (Order::Stop, Doing::Program) => {
                if let Parts::Running(p) = &mut self.parts {
                    p.command(Command::Stop);
                }
            }
            (Order::Stop, Doing::Jog { axis, mut jog }) => {
                jog.stop();
                self.doing = Doing::Jog { axis, jog };
            }
            (Order::Stop, Doing::LineJog { mut jog }) => {
                jog.stop();
                self.doing = Doing::LineJog { jog };
            }
            (Order::Stop, Doing::Homing { jobs, n }) => {
                for &(bus, index) in jobs.iter().take(n) {
                    self.stop_homing(usize::from(bus), usize::from(index));
                }
            }
            _ => self.report(refused),
        }
    }

    /// Start a program from where the drives stand.
    fn program(&mut self, start: Start) {
        let (buses, follower) = match core::mem::replace(&mut self.parts, Parts::Moving) {
            Parts::Free { buses, follower } => (buses, follower),
            // Cannot be (a program starts only from holding): put it back as it was.
            other => {
                self.parts = other;
                return;
            }
        };
        let follower = follower.next_program(start);
        match Pipeline::from_here(
            follower,
            buses,
            start.joints,
            self.period,
            self.c_continuous,
            self.enable_timeout_cycles,
        ) {
            Ok(p) => {
                self.parts = Parts::Running(p);
                self.doing = Doing::Program;
                self.report(Happened::ProgramStarted);
            }
            Err(NotHere {
                error,
                follower,
                buses,
            }) => {
                self.parts = Parts::Free { buses, follower };
                self.report(Happened::ProgramRefused(error));
            }
        }
    }

    /// The pipeline finished: the parts come back, the drives hold where the path ended
    /// (or, after a fault, the master has quick-stopped them).
    fn program_over(&mut self) {
        let p = match core::mem::replace(&mut self.parts, Parts::Moving) {
            Parts::Running(p) => p,
            other => {
                self.parts = other;
                return;
            }
        };
        let reason = p.reason();
        let line = p.stop_line().unwrap_or(0);
        let (follower, buses) = p.into_parts();
        let faulted = buses.iter().find_map(|b| b.master.fault().copied());
        let enabled = buses.iter().all(|b| {
            b.master.status().iter().all(|s| {
                s.kind == drives::master::NodeKind::Io
                    || s.state == Some(drives::cia402::State::OperationEnabled)
            })
        });
        self.parts = Parts::Free { buses, follower };
        self.report(Happened::ProgramEnded { reason, line });
        self.doing = match faulted {
            Some(f) => {
                self.report(Happened::Fault(f));
                Doing::Fault
            }
            None if enabled => Doing::Holding,
            None => Doing::Off,
        };
    }
}

/// `a` and `b` (any lengths) point the same way (a renewal of the same line jog).
fn same_direction(a: [f64; 3], b: [f64; 3]) -> bool {
    let n = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    n > 0.0 && (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / n > 1.0 - 1e-12
}
