//! The machine's life (`rt_loop::life`) against five simulated CiA-402 drives on a virtual
//! clock: an operator's whole session with the drives on throughout: enable, home three
//! axes by three methods (one failing), jog continuously until the client vanishes,
//! jog by a step, run a program with a pause, run another and stop it, an order in the
//! wrong mode, the e-stop, the reset, on again and off.
//!
//! Every target sent is checked by finite differences at the period: velocity and
//! acceleration within the axis limits in every mode but homing (the drive's own move,
//! then its position redefined), the jerk too while jogging; no target steps when one mode
//! hands over to the next. The loop's calls allocate nothing
//! (a counting global allocator armed around each [`Life::cycle`]).

mod common;

use drives::link::MemLink;
use drives::master::{DriveFault, HomeRequest, HomingError};
use drives::sim::{HomeHardware, Lockstep, SimNodeConfig};
use drives::wire::NodeId;
use heapless::spsc::{Consumer, Producer};
use nc_follow::jog::JogLimits;
use nc_follow::{Feeder, Follower, Queues};
use nc_geom::kinematics::MachineKinematics;
use nc_plan::stream::chunks;
use rt_loop::control::Command;
use rt_loop::life::{Happened, Life, Mode, Order, Queues as LifeQueues, Status};
use rt_loop::pipeline::StopReason;
use std::time::Duration;

#[global_allocator]
static ALLOC: test_support::CountingAlloc = test_support::CountingAlloc;

const PERIOD: f64 = 0.002;
/// Counts per mm (X Y Z) and per degree (A C): fine enough that the third difference of the
/// rounded targets is a small share of the jerk limit.
const CPU: [f64; 5] = [1e6, 1e6, 1e6, 1e4, 1e4];
/// The small mill's limits (nc_plan::fixtures::small_mill), per axis: velocity,
/// acceleration, jerk (mm or degrees, s).
const LIMITS: [(f64, f64, f64); 5] = [
    (250.0, 2500.0, 50000.0),
    (250.0, 2500.0, 50000.0),
    (250.0, 2500.0, 50000.0),
    (90.0, 900.0, 20000.0),
    (90.0, 900.0, 20000.0),
];
/// A continuous jog goes on this many periods after its last renewal (200 ms).
const DEADMAN: u32 = 100;

type Rx = Consumer<'static, Happened>;

struct Session {
    life: Life<'static, MemLink>,
    sim: Lockstep<MemLink>,
    orders: Producer<'static, Order>,
    happened: Rx,
    feeder: Feeder<'static>,
    source: std::vec::IntoIter<Box<nc_follow::Chunk>>,
    status: Status,
    t: u64,
    /// What each period sent, per axis (counts), and the mode it was sent in.
    sent: Vec<([i32; 5], Mode)>,
    log: Vec<Happened>,
}

impl Session {
    fn new() -> Session {
        let sims: Vec<SimNodeConfig> = (1..=5u8)
            .map(|n| SimNodeConfig {
                // Y starts 20 mm above its switch at 0, X and Z at 5 mm, A and C at 0.
                initial_position: match n {
                    2 => 20_000_000,
                    1 | 3 => 5_000_000,
                    _ => 0,
                },
                home: HomeHardware {
                    // Z has no switch: its search fails.
                    switch: (n != 3).then_some(0),
                    index_pitch: 1_000_000,
                    search_limit: 30_000_000,
                    ..HomeHardware::default()
                },
                ..SimNodeConfig::new(NodeId::new(n).unwrap())
            })
            .collect();
        let (link, drive_end) = MemLink::pair(1024);
        let (bus, sim) = common::lockstep_bus(link, drive_end, PERIOD, CPU, sims, common::LENIENT);
        let t = sim.now().as_nanos() as u64;
        let chunks: &'static mut Queues = Box::leak(Queues::new());
        let (feeder, inlet) = chunks.split(8);
        let (cfg, _) = nc_plan::fixtures::small_mill(PERIOD);
        let (start, _) = plan("G1 X0 Y0 Z0 A0 C0 F600\n");
        let follower = Follower::new(
            inlet,
            start,
            MachineKinematics::Paper,
            cfg.rotary,
            cfg.hold(),
        );
        let queues: &'static mut LifeQueues = Box::leak(Box::default());
        let ((orders, happened), rt) = queues.split();
        let life = Life::new(vec![bus], follower, rt, PERIOD, 1000, DEADMAN, true);
        Session {
            life,
            sim,
            orders,
            happened,
            feeder,
            source: Vec::new().into_iter(),
            status: Status::default(),
            t,
            sent: Vec::new(),
            log: Vec::new(),
        }
    }

    fn order(&mut self, o: Order) {
        self.orders.enqueue(o).expect("room for the order");
    }

    /// One period: the loop (no heap event), then the drives and the planner.
    fn period(&mut self) {
        test_support::arm_this_thread();
        self.life.cycle(self.t);
        self.life.publish(&self.status);
        let events = test_support::disarm_this_thread();
        assert_eq!(
            events,
            0,
            "heap events in the loop, mode {:?}",
            self.life.mode()
        );
        let mut row = [0; 5];
        for (i, s) in self.life.buses()[0].master.status().iter().enumerate() {
            row[i] = s.target;
        }
        self.sent.push((row, self.life.mode()));
        self.t += (PERIOD * 1e9) as u64;
        self.sim.advance_to(Duration::from_nanos(self.t));
        self.feeder.feed(&mut self.source);
        while let Some(h) = self.happened.dequeue() {
            self.log.push(h);
        }
    }

    /// Periods until `done` says so of a report (at most `max`); the report.
    fn until(&mut self, max: usize, done: impl Fn(&Happened) -> bool) -> Happened {
        let from = self.log.len();
        for _ in 0..max {
            self.period();
            if let Some(h) = self.log[from..].iter().find(|h| done(h)) {
                return *h;
            }
        }
        panic!(
            "not within {max} periods; mode {:?}, reports {:?}",
            self.life.mode(),
            &self.log[from..]
        );
    }

    fn axes(&self) -> [f64; 5] {
        self.status.axes()
    }

    /// Plan `src` on the small mill and hand it to the loop; the planner pushes once the
    /// loop has taken it.
    fn program(&mut self, src: &str) {
        let (start, list) = plan(src);
        self.source = Vec::new().into_iter();
        self.order(Order::Program { start });
        self.until(2, |h| matches!(h, Happened::ProgramStarted));
        assert_eq!(
            self.feeder.reclaim(),
            0,
            "the last program's chunks came back"
        );
        self.feeder.next_program();
        self.source = list.into_iter();
    }
}

/// `src` planned on the small mill: its start and its chunks.
#[allow(clippy::vec_box)] // as the planner streams them
fn plan(src: &str) -> (nc_follow::Start, Vec<Box<nc_follow::Chunk>>) {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let program = nc_lang::parse(src).unwrap();
    let path = nc_geom::segment::build(&program, &kin, &bl).unwrap();
    let profile = nc_plan::plan::plan(&path, &kin, &cfg).unwrap();
    chunks(path, &profile, &cfg.hold(), 4)
}

fn limits(axis: usize) -> JogLimits {
    let (v, a, j) = LIMITS[axis];
    JogLimits {
        velocity: v,
        acceleration: a,
        jerk: j,
        min: -500.0,
        max: 500.0,
    }
}

/// Homing parameters in counts: searches at 20 mm/s, the latch at 2 mm/s, ramps at
/// 1000 mm/s^2, within the axis limits.
fn home(method: i8, offset_mm: f64) -> HomeRequest {
    HomeRequest {
        method,
        switch_speed: 20_000_000,
        index_speed: 2_000_000,
        acceleration: 1_000_000_000,
        offset: (offset_mm * 1e6) as i32,
        timeout_cycles: 20_000,
    }
}

#[test]
fn an_operators_session_with_the_drives_on_throughout() {
    let mut s = Session::new();
    for _ in 0..5 {
        s.period();
    }
    assert_eq!(s.life.mode(), Mode::Off);

    // Refused while off: nothing moves.
    s.order(Order::Jog {
        axis: 0,
        limits: limits(0),
        velocity: 10.0,
    });
    let h = s.until(2, |h| matches!(h, Happened::Refused { .. }));
    assert_eq!(
        h,
        Happened::Refused {
            order: "jog",
            mode: Mode::Off
        }
    );

    s.order(Order::On);
    s.until(500, |h| *h == Happened::Enabled);
    assert_eq!(s.life.mode(), Mode::Holding);

    // Homing: X on its position (35) and Y on its switch (19) together, then Z, whose
    // switch is never found.
    s.order(Order::Home {
        bus: 0,
        index: 0,
        req: home(35, 0.0),
    });
    s.order(Order::Home {
        bus: 0,
        index: 1,
        req: home(19, 1.0),
    });
    let from = s.log.len();
    s.until(20_000, |h| matches!(h, Happened::Homed { index: 1, .. }));
    let homed: Vec<Happened> = s.log[from..]
        .iter()
        .filter(|h| matches!(h, Happened::Homed { .. } | Happened::HomingStarted { .. }))
        .copied()
        .collect();
    assert_eq!(homed.len(), 4, "{homed:?}");
    assert!(homed.contains(&Happened::Homed {
        bus: 0,
        index: 0,
        counts: 0
    }));
    let Some(&Happened::Homed { counts, .. }) = homed.last() else {
        panic!("{homed:?}")
    };
    // Past the home point (1 mm) by the stop from 20 mm/s at 1000 mm/s^2 (0.2 mm).
    assert!((0.75e6..=0.85e6).contains(&f64::from(counts)), "{counts}");
    assert_eq!(s.life.mode(), Mode::Holding);
    s.order(Order::Home {
        bus: 0,
        index: 2,
        req: home(19, 0.0),
    });
    let h = s.until(20_000, |h| matches!(h, Happened::HomingFailed { .. }));
    assert!(
        matches!(
            h,
            Happened::HomingFailed {
                index: 2,
                error: HomingError::Drive(_),
                ..
            }
        ),
        "{h:?}"
    );
    assert_eq!(s.life.mode(), Mode::Holding);

    // The operator stops a homing under way (Z searching again): not homed, the drive back
    // in cyclic synchronous position where it stands, and it holds there.
    s.order(Order::Home {
        bus: 0,
        index: 2,
        req: home(19, 0.0),
    });
    for _ in 0..200 {
        s.period();
    }
    assert_eq!(s.life.mode(), Mode::Homing);
    s.order(Order::Stop);
    let h = s.until(500, |h| matches!(h, Happened::HomingFailed { .. }));
    assert!(
        matches!(
            h,
            Happened::HomingFailed {
                index: 2,
                error: HomingError::Stopped,
                ..
            }
        ),
        "{h:?}"
    );
    assert_eq!(s.life.mode(), Mode::Holding);
    for _ in 0..20 {
        s.period();
    }
    let actual = |s: &Session| s.life.buses()[0].master.status()[2].actual;
    let z = actual(&s);
    for _ in 0..100 {
        s.period();
    }
    assert_eq!(actual(&s), z, "the drive holds where the stop left it");

    // Continuous jog of X at 50 mm/s, renewed every 20 periods for 300, then the client
    // vanishes: the jog stops within the dead-man and the stop from 50 mm/s.
    s.order(Order::Jog {
        axis: 0,
        limits: limits(0),
        velocity: 50.0,
    });
    for k in 0..300 {
        if k % 20 == 19 {
            s.order(Order::Jog {
                axis: 0,
                limits: limits(0),
                velocity: 50.0,
            });
        }
        s.period();
    }
    assert_eq!(s.life.mode(), Mode::Jog);
    // The last renewal came before the last period (k = 299).
    let last_renewal = s.sent.len() - 1;
    s.until(1000, |h| matches!(h, Happened::JogDone { .. }));
    let rest = s.sent.len();
    let stop_periods = (50.0 / 2500.0 + 2500.0 / 50000.0) / PERIOD;
    assert!(
        ((rest - last_renewal) as f64) <= f64::from(DEADMAN) + stop_periods + 2.0,
        "at rest {} periods after the last renewal",
        rest - last_renewal
    );
    // Another axis's jog while X jogs is refused (checked below, mid-jog).
    let x0 = s.axes()[0];

    // Incremental: X +10 mm, ending there exactly.
    s.order(Order::JogTo {
        axis: 0,
        limits: limits(0),
        target: x0 + 10.0,
        speed: 100.0,
    });
    s.period();
    s.order(Order::Jog {
        axis: 1,
        limits: limits(1),
        velocity: 5.0,
    });
    let h = s.until(2, |h| matches!(h, Happened::Refused { .. }));
    assert_eq!(
        h,
        Happened::Refused {
            order: "jog",
            mode: Mode::Jog
        }
    );
    s.until(2000, |h| matches!(h, Happened::JogDone { .. }));
    assert!((s.axes()[0] - (x0 + 10.0)).abs() < 1e-6, "{:?}", s.axes());

    // Along a line of X Y Z (the workpiece's diagonal, say): 5 mm, both axes their share.
    let before = s.axes();
    s.order(Order::LineJog {
        dir: [1.0, 1.0, 0.0],
        limits: [limits(0), limits(1), limits(2)],
        distance: Some(5.0),
        speed: 40.0,
    });
    s.until(2000, |h| matches!(h, Happened::JogDone { .. }));
    let after = s.axes();
    let share = 5.0 / 2f64.sqrt();
    assert!((after[0] - before[0] - share).abs() < 1e-6, "{after:?}");
    assert!((after[1] - before[1] - share).abs() < 1e-6, "{after:?}");
    assert_eq!(after[2], before[2]);

    // A program from where the machine stands, paused and resumed.
    let a = s.axes();
    let src = format!(
        "G90 G1 X{x:.6} Y{y:.6} Z{z:.6} A0 C0 F1200\nX{x2:.6}\nY{y2:.6} Z{z2:.6}\nX{x:.6}\n",
        x = a[0],
        y = a[1],
        z = a[2],
        x2 = a[0] + 30.0,
        y2 = a[1] + 10.0,
        z2 = a[2] - 2.0
    );
    s.program(&src);
    assert_eq!(s.life.mode(), Mode::Program);
    for _ in 0..200 {
        s.period();
    }
    s.order(Order::Run(Command::Pause));
    for _ in 0..300 {
        s.period();
    }
    let held = s.axes();
    for _ in 0..50 {
        s.period();
    }
    assert_eq!(s.axes(), held, "paused: the path stands");
    // Homing or jogging is refused while a program runs.
    s.order(Order::JogTo {
        axis: 0,
        limits: limits(0),
        target: 0.0,
        speed: 10.0,
    });
    s.order(Order::Run(Command::Resume));
    let h = s.until(20_000, |h| matches!(h, Happened::ProgramEnded { .. }));
    assert_eq!(
        h,
        Happened::ProgramEnded {
            reason: None,
            line: 0
        }
        .with_line(h)
    );
    assert!(s.log.contains(&Happened::Refused {
        order: "jog to",
        mode: Mode::Program
    }));
    assert_eq!(s.life.mode(), Mode::Holding);
    let end = s.axes();
    assert!((end[0] - a[0]).abs() < 1e-6 && (end[1] - (a[1] + 10.0)).abs() < 1e-6);

    // Another, stopped by the operator: it ends where the path came to rest, drives on.
    let src = format!(
        "G90 G1 X{x:.6} Y{y:.6} Z{z:.6} A0 C0 F3000\nX{x2:.6}\n",
        x = end[0],
        y = end[1],
        z = end[2],
        x2 = end[0] + 100.0
    );
    s.program(&src);
    for _ in 0..400 {
        s.period();
    }
    s.order(Order::Stop);
    let h = s.until(5000, |h| matches!(h, Happened::ProgramEnded { .. }));
    assert!(
        matches!(
            h,
            Happened::ProgramEnded {
                reason: Some(StopReason::Operator),
                ..
            }
        ),
        "{h:?}"
    );
    assert_eq!(s.life.mode(), Mode::Holding);
    let stopped = s.axes();
    assert!(stopped[0] > end[0] + 1.0 && stopped[0] < end[0] + 100.0);

    // A program that does not start where the machine stands is refused, nothing moves.
    let (start, _) = plan("G1 X0 Y0 Z0 A0 C0 F600\nX1\n");
    s.order(Order::Program { start });
    let h = s.until(2, |h| matches!(h, Happened::ProgramRefused(_)));
    assert!(h_names_axis(&h, "X"), "{h:?}");
    assert_eq!(s.life.mode(), Mode::Holding);

    // The operator's e-stop: quick stop, disabled; orders refused until the reset.
    s.order(Order::EStop);
    let h = s.until(10, |h| matches!(h, Happened::Fault(_)));
    assert!(
        matches!(
            h,
            Happened::Fault(DriveFault {
                node: DriveFault::OPERATOR,
                ..
            })
        ),
        "{h:?}"
    );
    s.order(Order::On);
    s.until(2, |h| matches!(h, Happened::Refused { .. }));
    for _ in 0..500 {
        s.period();
    }
    s.order(Order::Reset);
    s.until(2, |h| matches!(h, Happened::ResetDone(_)));
    assert_eq!(s.life.mode(), Mode::Off);
    for _ in 0..300 {
        s.period();
    }
    s.order(Order::On);
    s.until(500, |h| *h == Happened::Enabled);
    s.order(Order::Off);
    s.until(500, |h| *h == Happened::Disabled);
    assert_eq!(s.life.mode(), Mode::Off);
    assert_eq!(s.life.lost(), 0);

    check_targets(&s.sent);
}

fn h_names_axis(h: &Happened, axis: &str) -> bool {
    match h {
        Happened::ProgramRefused(e) => e.to_string().contains(&format!("axis {axis} ")),
        _ => false,
    }
}

trait WithLine {
    fn with_line(self, other: Happened) -> Happened;
}

impl WithLine for Happened {
    /// `self` with the line `other` reports (the line is not what is checked).
    fn with_line(self, other: Happened) -> Happened {
        match (self, other) {
            (Happened::ProgramEnded { reason, .. }, Happened::ProgramEnded { line, .. }) => {
                Happened::ProgramEnded { reason, line }
            }
            (me, _) => me,
        }
    }
}

/// Velocity and acceleration of every axis within its limits in every period but while
/// homing (the drive moves by itself at its homing request's speeds and ramps, and then
/// its position is redefined), and the jerk while jogging.
fn check_targets(sent: &[([i32; 5], Mode)]) {
    assert!(sent.len() > 5000, "{} periods", sent.len());
    let mut worst = [[0.0f64; 3]; 5];
    for j in 0..5 {
        let unit = 1.0 / CPU[j];
        let q: Vec<f64> = sent.iter().map(|(t, _)| f64::from(t[j]) * unit).collect();
        let (vmax, amax, jmax) = LIMITS[j];
        for k in 3..q.len() {
            // Homing moves the drive by itself and then redefines its position (the home
            // offset): what it reports then is no motion of ours.
            if (k - 3..=k).any(|i| sent[i].1 == Mode::Homing) {
                continue;
            }
            let v = (q[k] - q[k - 1]) / PERIOD;
            let a = (q[k] - 2.0 * q[k - 1] + q[k - 2]) / PERIOD.powi(2);
            let jerk = (q[k] - 3.0 * q[k - 1] + 3.0 * q[k - 2] - q[k - 3]) / PERIOD.powi(3);
            let slack = |n: f64, p: i32| n * unit / PERIOD.powi(p);
            assert!(
                v.abs() <= vmax + slack(1.0, 1),
                "axis {j} period {k} ({:?}): velocity {v}",
                sent[k].1
            );
            assert!(
                a.abs() <= amax + slack(2.0, 2),
                "axis {j} period {k} ({:?}): acceleration {a}",
                sent[k].1
            );
            let jogging = (k - 3..=k).all(|i| sent[i].1 == Mode::Jog);
            if jogging {
                assert!(
                    jerk.abs() <= jmax + slack(4.0, 3),
                    "axis {j} period {k}: jerk {jerk}"
                );
            }
            worst[j][0] = worst[j][0].max(v.abs() / vmax);
            worst[j][1] = worst[j][1].max(a.abs() / amax);
            if jogging {
                worst[j][2] = worst[j][2].max(jerk.abs() / jmax);
            }
        }
    }
    eprintln!("largest share of the limits (v, a, jog jerk) per axis: {worst:.3?}");
}
