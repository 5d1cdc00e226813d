//! `dnurbs serve`'s controller core on a virtual clock: the hub (requests as the control
//! socket passes them, validated against the machine's state) and the real-time thread's
//! life against the paper machine's five drives simulated in-process, a period at a time,
//! as fast as the machine computes. The machine file is the demo's, with a home table for
//! every axis (every method the simulated drives offer, one absolute) and fine counts.
//!
//! One operator's session: refusals while off, on, home, jog by a step, a continuous jog
//! whose client goes away, a jog beyond the travel, MDI (a move, a syntax error), load and
//! run a program with a pause, run it again and stop it, the e-stop and its reset, a drive
//! fault mid-move (the status names the node), reset, home again and run to the end. Every
//! target sent is checked by finite differences against the machine's limits.

mod common;

use config::bus::{Home, HomeMethod};
use dnurbs_tools::serve::hub::{Asker, Hub};
use dnurbs_tools::serve::machine::{lockstep_buses, Fixed};
use dnurbs_tools::serve::protocol::{Reply, Request};
use dnurbs_tools::simdrives::FaultArgs;
use drives::link::MemLink;
use drives::sim::Lockstep;
use rt_loop::life::{Life, Mode};
use std::time::Duration;

const RUN: Request = Request::Run {
    from_line: None,
    clearance: 10.0,
    confirm: false,
};

/// The node (Y) that faults, and the SYNC it faults at: after the session's first part.
const FAULT_NODE: u8 = 2;
const FAULT_AT: u64 = 40_000;

struct Rig {
    life: Life<'static, MemLink>,
    hub: Hub<'static>,
    sims: Vec<Lockstep<MemLink>>,
    drives: Vec<config::bus::Drive>,
    limits: [config::AxisLimits; 5],
    period: f64,
    t: u64,
    next_id: u64,
    /// Per period: each axis drive's target in axis units, and the life's mode.
    sent: Vec<([f64; 5], Mode)>,
    /// Per period: the interpolator's axes before they are rounded to counts, while a
    /// program runs (else the targets).
    path: Vec<([f64; 5], Mode)>,
}

fn machine() -> config::Machine {
    let mut m = dnurbs_tools::demo::demo_machine().unwrap();
    let methods = [
        (HomeMethod::Switch { positive: false }, -5.0, 0),
        (HomeMethod::SwitchIndex { positive: true }, 4.0, 0),
        (HomeMethod::Current, 2.5, 1),
        (HomeMethod::Absolute, 0.0, 0),
        (HomeMethod::Switch { positive: true }, 3.0, 2),
    ];
    let limits = [&m.axes.x, &m.axes.y, &m.axes.z, &m.axes.tilt, &m.axes.c].map(|l| l.clone());
    for d in m.drives.iter_mut() {
        let (method, position, sequence) = methods[d.axis];
        let l = &limits[d.axis];
        d.home = Some(Home {
            method,
            position,
            search_velocity: l.velocity / 10.0,
            latch_velocity: l.velocity / 100.0,
            acceleration: l.acceleration / 2.0,
            sequence,
        });
        // Fine counts: the finite differences see the setpoints, not the rounding.
        d.counts_per_unit = if d.axis < 3 { 1e6 } else { 1e5 };
    }
    m
}

impl Rig {
    fn new() -> Rig {
        let m = machine();
        let faults = FaultArgs {
            fault_at: vec![(FAULT_NODE, FAULT_AT)],
            ..FaultArgs::default()
        };
        let (buses, sims) = lockstep_buses(&m, &faults).unwrap();
        let drives = m.drives.clone();
        let shop = dnurbs_tools::shop::parse_setup(&m, &Default::default()).unwrap();
        let fixed: &'static mut Fixed = Box::leak(Fixed::new(m, shop));
        let limits = fixed.setup.limits.clone();
        let period = fixed.machine.period_s;
        let (life, hub) = fixed.split(buses);
        let t = sims[0].now().as_nanos() as u64;
        Rig {
            life,
            hub,
            sims,
            drives,
            limits,
            period,
            t,
            next_id: 0,
            sent: Vec::new(),
            path: Vec::new(),
        }
    }

    /// One period: the loop, the drives, the hub.
    fn step(&mut self) -> Vec<(Asker, Reply)> {
        self.life.cycle(self.t);
        self.life.publish(self.hub.published());
        let mut row = [0.0; 5];
        for (d, s) in self.drives.iter().zip(self.life.buses()[0].master.status()) {
            row[d.axis] = d.position(s.target);
        }
        // A fault's quick stop is the drives' own ramp (0x6085), whatever the targets.
        let faulted = self.life.buses()[0].master.fault().is_some();
        let mode = if faulted {
            Mode::Fault
        } else {
            self.life.mode()
        };
        self.sent.push((row, mode));
        let exact = if mode == Mode::Program {
            self.hub.published().run.snapshot().axes
        } else {
            row
        };
        self.path.push((exact, mode));
        self.t += (self.period * 1e9).round() as u64;
        for s in self.sims.iter_mut() {
            s.advance_to(Duration::from_nanos(self.t));
        }
        self.hub.poll()
    }

    /// Ask as client 1 and wait for the answer (at most 1000 periods).
    fn ask(&mut self, request: Request) -> Reply {
        self.ask_as(1, request)
    }

    fn ask_as(&mut self, client: u64, request: Request) -> Reply {
        self.next_id += 1;
        let who = Asker {
            client,
            id: Some(self.next_id),
        };
        if let Some(r) = self.hub.request(who, request.clone()) {
            return r;
        }
        for _ in 0..1000 {
            if let Some((_, r)) = self.step().into_iter().find(|(a, _)| *a == who) {
                return r;
            }
        }
        panic!("{request:?}: no answer in 1000 periods");
    }

    fn ok(&mut self, request: Request) -> &'static str {
        let r = self.ask(request.clone());
        assert!(r.ok, "{request:?}: {:?}", r.error);
        r.state.unwrap()
    }

    fn refused(&mut self, request: Request, says: &str) {
        let before = self.hub.state();
        let r = self.ask(request.clone());
        assert!(!r.ok, "{request:?} taken in state {}", before.name());
        let e = r.error.unwrap();
        assert!(e.contains(says), "{request:?}: {e}");
        assert_eq!(
            self.hub.state(),
            before,
            "{request:?} refused but the state moved"
        );
    }

    /// Periods until the state is `name` (at most `max`).
    fn until(&mut self, name: &str, max: usize) {
        for k in 0..max {
            if self.hub.state().name() == name {
                return;
            }
            if std::env::var_os("SERVE_DEBUG").is_some() && k % 2000 == 0 {
                eprintln!("{k}: {:?}", self.hub.status());
            }
            self.step();
        }
        panic!(
            "not {name} within {max} periods: {} ({:?})",
            self.hub.state().name(),
            self.hub.status().message
        );
    }

    fn axes(&self) -> Vec<f64> {
        self.hub.status().axes
    }

    fn sync(&self) -> u64 {
        self.sims[0].bus().records().last().map_or(0, |r| r.sync)
    }
}

fn jog(axis: &str, positive: bool, step: Option<f64>, speed: Option<f64>) -> Request {
    let line = format!(
        r#"{{"v":1,"cmd":"jog","axis":"{axis}","dir":"{}"{}{}}}"#,
        if positive { "+" } else { "-" },
        step.map_or(String::new(), |s| format!(r#","step":{s}"#)),
        speed.map_or(String::new(), |s| format!(r#","speed":{s}"#)),
    );
    dnurbs_tools::serve::protocol::Request::parse(&line)
        .unwrap()
        .request
}

#[test]
fn an_operators_session_on_the_controller_core() {
    let mut rig = Rig::new();
    for _ in 0..10 {
        rig.step();
    }
    assert_eq!(rig.hub.state().name(), "off");
    rig.refused(jog("X", true, Some(1.0), None), "turn it on first");
    rig.refused(RUN, "turn it on first");
    rig.refused(Request::Reset, "nothing to reset");

    assert_eq!(rig.ok(Request::On), "on");
    rig.refused(Request::Mdi("G0 X0".into()), "not every axis is homed");
    rig.refused(jog("B", true, Some(1.0), None), "no such axis");

    // Every axis in the file's sequence: X (switch) and Y (switch and index) together,
    // then Z (here), then C (switch); A is absolute.
    assert_eq!(rig.ok(Request::Home(None)), "homing");
    rig.until("idle", 200_000);
    assert_eq!(rig.hub.status().homed, ["X", "Y", "Z", "A", "C"]);
    let a = rig.axes();
    for (j, home) in [(0, -5.0), (1, 4.0), (2, 2.5), (4, 3.0)] {
        let l = &rig.limits[j];
        // Past the home point by the stop from the search (or latch) velocity.
        let v = l.velocity / 10.0;
        let slack = v * v / l.acceleration + 2.0 * v * rig.period + 1e-3;
        assert!(
            (a[j] - home).abs() <= slack,
            "axis {j} at {}, home {home}",
            a[j]
        );
    }

    // Jog X by 10 mm, ending there exactly.
    let x0 = a[0];
    assert_eq!(rig.ok(jog("X", true, Some(10.0), Some(50.0))), "jog");
    rig.refused(Request::Mdi("G0 X0".into()), "only at rest");
    rig.until("idle", 5000);
    assert!(
        (rig.axes()[0] - (x0 + 10.0)).abs() < 1e-6,
        "{:?}",
        rig.axes()
    );
    rig.refused(jog("X", true, Some(1000.0), None), "outside the travel");

    // Along the workpiece's X with A at 20 degrees (C where it homed): the tip 10 mm along
    // the workpiece's X; then 2 mm back along the tool axis, X Y Z together. The rotary
    // axes stand still.
    assert_eq!(rig.ok(jog("A", true, Some(20.0), Some(30.0))), "jog");
    rig.until("idle", 5000);
    let tip = |a: &[f64]| {
        use nc_geom::kinematics::Kinematics;
        let m = nc_geom::kinematics::MachineKinematics::Paper;
        let p = m.unplace(
            &nalgebra::Vector3::new(a[0], a[1], a[2]),
            a[3].to_radians(),
            a[4].to_radians(),
        );
        (p, m.tool_axis(a[3].to_radians(), a[4].to_radians()))
    };
    let a0 = rig.axes();
    let work = |axis: &str, positive: bool, step: f64, frame: &str| {
        let line = format!(
            r#"{{"v":1,"cmd":"jog","axis":"{axis}","dir":"{}","step":{step},"frame":"{frame}"}}"#,
            if positive { "+" } else { "-" }
        );
        Request::parse(&line).unwrap().request
    };
    assert_eq!(rig.ok(work("X", true, 10.0, "work")), "jog");
    rig.until("idle", 5000);
    let a1 = rig.axes();
    let ((p0, _), (p1, t1)) = (tip(&a0), tip(&a1));
    assert!(((p1 - p0) - nalgebra::Vector3::new(10.0, 0.0, 0.0)).norm() < 1e-6);
    assert_eq!((a1[3], a1[4]), (a0[3], a0[4]));
    assert_eq!(rig.ok(work("Z", false, 2.0, "tool")), "jog");
    rig.until("idle", 5000);
    let (p2, _) = tip(&rig.axes());
    assert!(((p2 - p1) + 2.0 * t1).norm() < 1e-6, "{:?}", p2 - p1);
    let bad = r#"{"v":1,"cmd":"jog","axis":"A","dir":"+","frame":"work"}"#;
    let e = Request::parse(bad).unwrap_err().to_string();
    assert!(e.contains("work jogs X, Y or Z"), "{e}");
    assert_eq!(rig.ok(jog("A", false, Some(20.0), Some(30.0))), "jog");
    rig.until("idle", 5000);

    // Continuous, renewed by client 7, which then goes away: stopped at once.
    assert_eq!(
        rig.ask_as(7, jog("Y", false, None, Some(20.0))).state,
        Some("jog")
    );
    for k in 0..100 {
        if k % 25 == 0 {
            assert!(rig.ask_as(7, jog("Y", false, None, Some(20.0))).ok);
        }
        rig.step();
    }
    let gone = rig.sent.len();
    rig.hub.gone(7);
    rig.until("idle", 500);
    // The stop from 20 mm/s: well under the dead-man's 200 ms.
    assert!(
        rig.sent.len() - gone < 50,
        "{} periods",
        rig.sent.len() - gone
    );
    // Not renewed: the dead-man stops it 200 ms after the jog began.
    assert!(rig.ask_as(8, jog("Y", true, None, Some(20.0))).ok);
    let began = rig.sent.len();
    rig.until("idle", 500);
    let took = (rig.sent.len() - began) as f64 * rig.period;
    assert!((0.2..0.3).contains(&took), "dead-man stop after {took} s");

    // MDI: a rapid; a syntax error changes nothing.
    assert_eq!(rig.ok(Request::Mdi("G0 X0 Y0".into())), "mdi");
    rig.until("idle", 5000);
    let a = rig.axes();
    assert!(a[0].abs() < 1e-6 && a[1].abs() < 1e-6, "{a:?}");
    rig.refused(Request::Mdi("G0 X".into()), "mdi `G0 X`");
    rig.refused(Request::Mdi("G0 X900".into()), "mdi `G0 X900`");
    assert_eq!(rig.ok(Request::Mdi("G91".into())), "idle");
    assert_eq!(rig.ok(Request::Mdi("G0 Z1".into())), "mdi");
    rig.until("idle", 5000);
    assert!((rig.axes()[2] - (a[2] + 1.0)).abs() < 1e-6);
    assert_eq!(rig.ok(Request::Mdi("G90".into())), "idle");

    // Load and run, with a pause.
    let program = common::root()
        .join("tests/data/two-blocks-g2.nc")
        .display()
        .to_string();
    rig.refused(Request::Load("/no/such/file.nc".into()), "/no/such/file.nc");
    assert_eq!(rig.ok(Request::Load(program.clone())), "idle");
    assert_eq!(rig.ok(RUN), "running");
    let whole_from = rig.sent.len();
    for _ in 0..300 {
        rig.step();
    }
    assert!(rig.hub.status().line > 0);
    assert_eq!(rig.ok(Request::Pause), "paused");
    rig.refused(jog("X", true, Some(1.0), None), "only at rest");
    for _ in 0..500 {
        rig.step();
    }
    let held = rig.axes();
    rig.step();
    assert_eq!(rig.axes(), held, "paused: standing");
    // Slow (20 %): the run is also the reference path of the restart below, its
    // setpoints dense enough that chords between them stand for the curve.
    assert_eq!(rig.ok(Request::Override(20)), "paused");
    assert_eq!(rig.ok(Request::Resume), "running");
    rig.until("idle", 50_000);
    let whole = rig.path[whole_from..].to_vec();
    let end = rig.axes();
    assert!(
        (end[0] - 60.0).abs() < 1e-6 && (end[1] + 10.0).abs() < 1e-6,
        "{end:?}"
    );

    // Restart from line 14, the second NURBS block, from elsewhere: the approach is said
    // first and nothing moves; confirmed, the tool comes down onto the block's start and
    // follows the program's path from there.
    assert_eq!(rig.ok(Request::Mdi("G0 X-10 Y-10 Z5".into())), "mdi");
    rig.until("idle", 5000);
    let restart = |confirm| Request::Run {
        from_line: Some(14),
        clearance: 10.0,
        confirm,
    };
    rig.refused(restart(false), "the approach: back along the tool axis");
    assert_eq!(rig.ok(restart(true)), "running");
    let from = rig.sent.len();
    rig.until("idle", 50_000);
    on_the_path(&rig.path[from..], &whole);
    let end = rig.axes();
    assert!((end[0] - 60.0).abs() < 1e-6 && (end[1] + 10.0).abs() < 1e-6);

    // Single block: started with step, each block ends at rest and waits; step runs the
    // next, resume runs on.
    assert_eq!(rig.ok(Request::Mdi("G0 X-10 Y-10 Z5".into())), "mdi");
    rig.until("idle", 5000);
    assert_eq!(rig.ok(Request::Step), "stepping");
    rig.until("paused", 20_000);
    let a = rig.axes();
    assert!(
        a[0].abs() < 1e-6 && a[1].abs() < 1e-6 && a[2].abs() < 1e-6,
        "{a:?}"
    );
    let m = rig.hub.status().message.unwrap();
    assert!(m.contains("line 9"), "{m}");
    assert_eq!(rig.ok(Request::Step), "stepping");
    rig.until("paused", 20_000);
    let a = rig.axes();
    assert!((a[0] - 30.0).abs() < 1e-6 && a[1].abs() < 1e-6, "{a:?}");
    assert_eq!(rig.ok(Request::Resume), "running");
    rig.until("idle", 20_000);
    let a = rig.axes();
    assert!(
        (a[0] - 60.0).abs() < 1e-6 && (a[1] + 10.0).abs() < 1e-6,
        "{a:?}"
    );
    // A program started with run is planned without block stops: no step from its middle.
    assert_eq!(rig.ok(Request::Mdi("G0 X0 Y0".into())), "mdi");
    rig.until("idle", 5000);
    assert_eq!(rig.ok(RUN), "running");
    for _ in 0..200 {
        rig.step();
    }
    assert_eq!(rig.ok(Request::Pause), "paused");
    rig.refused(Request::Step, "started with run");
    assert_eq!(rig.ok(Request::Resume), "running");
    rig.until("idle", 20_000);

    // Again, stopped along the path.
    assert_eq!(rig.ok(Request::Override(100)), "idle");
    assert_eq!(rig.ok(RUN), "running");
    for _ in 0..600 {
        rig.step();
    }
    assert_eq!(rig.ok(Request::Stop), "running");
    rig.until("idle", 5000);
    assert!(rig
        .hub
        .status()
        .message
        .unwrap()
        .contains("stopped by the operator"));

    // The e-stop: every drive quick-stopped and disabled; homing is lost.
    assert_eq!(rig.ok(Request::Estop), "estop");
    rig.refused(Request::On, "reset first");
    for _ in 0..300 {
        rig.step();
    }
    assert_eq!(rig.ok(Request::Reset), "off");
    assert_eq!(rig.ok(Request::On), "on");
    assert_eq!(rig.hub.status().homed, ["A"]);
    assert_eq!(rig.ok(Request::Home(None)), "homing");
    rig.until("idle", 200_000);

    // A drive fault mid-move: a long move started just before node 2 faults.
    assert!(
        rig.sync() < FAULT_AT - 600,
        "the session got to SYNC {}",
        rig.sync()
    );
    while rig.sync() < FAULT_AT - 500 {
        rig.step();
    }
    assert_eq!(rig.ok(Request::Mdi("G1 X200 F3000".into())), "mdi");
    rig.until("fault", 2000);
    let message = rig.hub.status().message.unwrap();
    assert!(message.contains("node 2"), "{message}");
    rig.refused(Request::On, "reset first");
    for _ in 0..500 {
        rig.step();
    }
    assert_eq!(rig.ok(Request::Reset), "off");
    assert_eq!(rig.ok(Request::On), "on");
    assert_eq!(rig.ok(Request::Home(None)), "homing");
    rig.until("idle", 200_000);
    assert_eq!(rig.ok(Request::Mdi("G0 X0 Y0".into())), "mdi");
    rig.until("idle", 5000);
    assert_eq!(rig.ok(RUN), "running");
    rig.until("idle", 50_000);
    let end = rig.axes();
    assert!(
        (end[0] - 60.0).abs() < 1e-6 && (end[1] + 10.0).abs() < 1e-6,
        "{end:?}"
    );
    assert_eq!(rig.ok(Request::Off), "off");
    assert_eq!(rig.hub.status().lost, 0);

    check_targets(&rig.sent, &rig.limits, rig.period);
}

/// From where the restart's approach comes down onto the path (the first setpoint within
/// 1 um of it), the tool tip of every setpoint of the restarted run (in the workpiece
/// frame; the interpolator's, before the rounding to counts) is within 1 um of the whole
/// run's (its tips joined by straight lines: at 2 ms and these
/// feeds a chord of the curves deviates from them by far less).
fn on_the_path(restarted: &[([f64; 5], Mode)], whole: &[([f64; 5], Mode)]) {
    // The tool tip in the workpiece frame (the paper machine, no tool length).
    let tip = |j: &[f64; 5]| -> [f64; 5] {
        use nc_geom::kinematics::Kinematics;
        let m = nc_geom::kinematics::MachineKinematics::Paper;
        let p = m.unplace(
            &nalgebra::Vector3::new(j[0], j[1], j[2]),
            j[3].to_radians(),
            j[4].to_radians(),
        );
        [p.x, p.y, p.z, 0.0, 0.0]
    };
    let whole: Vec<([f64; 5], Mode)> = whole.iter().map(|(j, m)| (tip(j), *m)).collect();
    let restarted: Vec<([f64; 5], Mode)> = restarted.iter().map(|(j, m)| (tip(j), *m)).collect();
    // The reference is the whole run's tips joined by chords: each chord is off the
    // curve by at most its sagitta, L^2 k / 8 (k from the circle through its neighbours),
    // which the distance may take on top of the 1 um.
    let pts: Vec<[f64; 3]> = whole.iter().map(|(p, _)| [p[0], p[1], p[2]]).collect();
    let sub = |a: &[f64; 3], b: &[f64; 3]| [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let curvature = |i: usize| -> f64 {
        if i == 0 || i + 1 >= pts.len() {
            return 0.0;
        }
        let (a, b, c) = (&pts[i - 1], &pts[i], &pts[i + 1]);
        let (u, v) = (sub(a, b), sub(a, c));
        let cross = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let d = norm(sub(a, b)) * norm(sub(b, c)) * norm(sub(a, c));
        if d > 0.0 {
            2.0 * norm(cross) / d
        } else {
            0.0
        }
    };
    let sagitta: Vec<f64> = (0..pts.len().saturating_sub(1))
        .map(|i| {
            let l = norm(sub(&pts[i], &pts[i + 1]));
            l * l * curvature(i).max(curvature(i + 1)) / 8.0
        })
        .collect();
    // Distance from `p` to the reference less the chord's sagitta, and the distance alone.
    let dist2 = |p: &[f64; 5]| -> (f64, f64) {
        let mut best = (f64::INFINITY, f64::INFINITY);
        for (w, sag) in pts.windows(2).zip(&sagitta) {
            let (a, b) = (&w[0], &w[1]);
            let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
            let l2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
            let t = if l2 > 0.0 {
                ((ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2]) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let e = [ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]];
            let d = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
            if (d - sag).max(0.0) < best.0 || ((d - sag).max(0.0) == best.0 && d < best.1) {
                best = ((d - sag).max(0.0), d);
            }
        }
        best
    };
    let dist = |p: &[f64; 5]| dist2(p).0;
    let first = restarted
        .iter()
        .position(|(p, _)| dist(p) < 1e-6)
        .expect("the approach comes down onto the path");
    let (mut worst, mut raw) = (0.0f64, 0.0f64);
    for (k, (p, _)) in restarted.iter().enumerate().skip(first) {
        let (d, plain) = dist2(p);
        worst = worst.max(d);
        raw = raw.max(plain);
        assert!(
            d < 1e-6,
            "period {k} after the restart: {d} mm off the path at {p:?}"
        );
    }
    assert!(
        restarted.len() - first > 500,
        "{} periods on the path",
        restarted.len() - first
    );
    eprintln!(
        "restart: {} periods on the path after the approach, at most {raw:.2e} mm from the \
         reference chords ({worst:.2e} beyond their sagitta)",
        restarted.len() - first
    );
}

/// Velocity and acceleration of every axis within its limits at every period outside
/// homing (the drive's own move, then its position redefined) and the quick stops of the
/// e-stop and the fault (the drive's own ramp); the jerk too while jogging.
fn check_targets(sent: &[([f64; 5], Mode)], limits: &[config::AxisLimits; 5], period: f64) {
    let mut worst = [[0.0f64; 3]; 5];
    for j in 0..5 {
        let l = &limits[j];
        for k in 3..sent.len() {
            let modes = || (k - 3..=k).map(|i| sent[i].1);
            if modes().any(|m| matches!(m, Mode::Homing | Mode::Fault | Mode::Off)) {
                continue;
            }
            let q = |i: usize| sent[i].0[j];
            let v = (q(k) - q(k - 1)) / period;
            let a = (q(k) - 2.0 * q(k - 1) + q(k - 2)) / period.powi(2);
            let jerk = (q(k) - 3.0 * q(k - 1) + 3.0 * q(k - 2) - q(k - 3)) / period.powi(3);
            let count = if j < 3 { 1e-6 } else { 1e-5 };
            assert!(
                v.abs() <= l.velocity + count / period,
                "axis {j} period {k} ({:?}): velocity {v}",
                sent[k].1
            );
            assert!(
                a.abs() <= l.acceleration + 2.0 * count / period.powi(2),
                "axis {j} period {k} ({:?}): acceleration {a}",
                sent[k].1
            );
            let jogging = modes().all(|m| m == Mode::Jog);
            if jogging {
                assert!(
                    jerk.abs() <= l.jerk + 4.0 * count / period.powi(3),
                    "axis {j} period {k}: jerk {jerk}"
                );
                worst[j][2] = worst[j][2].max(jerk.abs() / l.jerk);
            }
            worst[j][0] = worst[j][0].max(v.abs() / l.velocity);
            worst[j][1] = worst[j][1].max(a.abs() / l.acceleration);
        }
    }
    eprintln!(
        "{} periods; largest share of the limits (v, a, jog jerk) per axis: {worst:.3?}",
        sent.len()
    );
}

/// A request the real-time thread never answers (its loop not running) is refused after
/// `WAIT_POLLS` polls, the state unchanged; what it may still do once it runs is undone.
#[test]
fn a_request_the_real_time_thread_never_answers_is_refused() {
    let mut rig = Rig::new();
    let who = Asker {
        client: 1,
        id: Some(1),
    };
    assert_eq!(rig.hub.request(who, Request::On), None);
    let mut answer = None;
    for _ in 0..=dnurbs_tools::serve::hub::WAIT_POLLS {
        if let Some((_, r)) = rig.hub.poll().into_iter().next() {
            answer = Some(r);
            break;
        }
    }
    let r = answer.expect("an answer");
    assert!(!r.ok && r.error.unwrap().contains("did not answer in time"));
    assert_eq!(rig.hub.state().name(), "off");
    // The loop runs again: the late `on` is followed by the `off` sent with the refusal.
    for _ in 0..1000 {
        rig.step();
    }
    assert_eq!(rig.life.mode(), Mode::Off);
    assert_eq!(rig.hub.state().name(), "off");
}
