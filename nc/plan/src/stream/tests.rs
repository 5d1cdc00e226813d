//! Tests of the streaming follower against the offline interpolator, with holds, stops,
//! pauses and the spindle.

use super::*;
use crate::interp::tests::{machine, paper_program};
use crate::interp::{Interpolator, Method};
use crate::plan::plan;
use nc_follow::{Follower, Queues, StreamCounters};
use nc_geom::segment::build;
use nc_geom::setpoint::Setpoint;

fn planned(src: Option<&str>) -> (Path, FeedProfile, HoldConfig) {
    let (kin, cfg, bl) = machine();
    let program = match src {
        Some(s) => nc_lang::parse(s).unwrap(),
        None => paper_program(),
    };
    let path = build(&program, &kin, &bl).unwrap();
    let profile = plan(&path, &kin, &cfg).unwrap();
    (path, profile, cfg.hold())
}

const TWO: &str = include_str!("../../../../tests/data/two-blocks-g2.nc");
const G01: &str = include_str!("../../../../tests/data/g01-5axis.nc");

/// Run with the planner pushing one chunk every `every` periods (0: all at once) into a
/// queue `depth` deep.
fn stream(
    src: Option<&str>,
    depth: usize,
    every: u64,
    stop_at: Option<u64>,
) -> (Vec<Setpoint>, StreamCounters, Path) {
    let (path, profile, hold) = planned(src);
    let (kin, cfg, _) = machine();
    let keep = path.clone();
    // Cut for the default depth: with a shallower queue (or a planner that pushes one
    // chunk every `every` periods) the data can come too late, as a slow planner's does.
    let (start, all) = chunks(path, &profile, &hold, 64);
    let mut source = all.into_iter();
    let mut q = Queues::new();
    let (mut feeder, inlet) = q.split(depth);
    let mut f = Follower::new(inlet, start, kin, cfg.rotary, hold);
    let mut out = Vec::new();
    feeder.feed(&mut source.by_ref().take(1));
    for i in 0..400_000u64 {
        if every == 0 || i % every == 0 {
            let mut one = source
                .by_ref()
                .take(if every == 0 { usize::MAX } else { 1 });
            feeder.feed(&mut one);
        }
        if stop_at == Some(i) {
            f.request_stop();
        }
        let sp = f.step();
        out.push(sp);
        if sp.done || (stop_at.is_some() && f.is_stopped()) {
            break;
        }
    }
    feeder.feed(&mut std::iter::empty());
    (out, f.counters(), keep)
}

#[test]
fn with_all_data_at_hand_it_follows_the_plan_like_the_interpolator() {
    for src in [None, Some(TWO), Some(G01)] {
        let (path, profile, _) = planned(src);
        let (kin, cfg, _) = machine();
        let mut ip = Interpolator::new(
            &path,
            &profile,
            kin,
            cfg.rotary,
            Method::ArcLength,
            cfg.period,
            0.0,
        );
        let (sps, counters, _) = stream(src, 16, 0, None);
        let mut n = 0;
        for sp in &sps {
            let want = ip.step();
            assert!(
                (sp.p - want.p).norm() < 1e-9,
                "cycle {}: {} vs {}",
                sp.cycle,
                sp.p,
                want.p
            );
            for j in 0..5 {
                assert!((sp.joints[j] - want.joints[j]).abs() < 1e-9);
            }
            assert_eq!(sp.done, want.done, "cycle {}", sp.cycle);
            n += 1;
        }
        assert!(sps.last().unwrap().done && n > 100);
        assert_eq!(counters, StreamCounters::default());
    }
}

#[test]
fn a_rehearsal_changes_nothing_and_lands_where_the_next_step_goes() {
    for src in [None, Some(TWO), Some(G01)] {
        let (plain, _, _) = stream(src, 16, 0, None);
        let (path, profile, hold) = planned(src);
        let (kin, cfg, _) = machine();
        let (start, all) = chunks(path, &profile, &hold, 16);
        let mut source = all.into_iter();
        let mut q = Queues::new();
        let (mut feeder, inlet) = q.split(16);
        let mut f = Follower::new(inlet, start, kin, cfg.rotary, hold);
        feeder.feed(&mut source.by_ref().take(1));
        // Summed over the run: how far the rehearsal, and the previous setpoint, are from
        // the step that follows.
        let (mut off, mut moved) = (0.0, 0.0);
        let mut prev = start.joints;
        for want in &plain {
            feeder.feed(&mut source.by_ref());
            let guess = f.rehearse();
            let sp = f.step();
            assert_eq!(sp, *want, "a rehearsal changed the setpoint");
            for j in 0..5 {
                off += (guess[j] - sp.joints[j]).abs();
                moved += (prev[j] - sp.joints[j]).abs();
            }
            prev = sp.joints;
        }
        feeder.feed(&mut std::iter::empty());
        assert!(off < 0.01 * moved, "rehearsed {off} away, moved {moved}");
    }
}

/// Path distance per period, and its first and second differences.
fn check_smooth(sps: &[Setpoint], hold: &HoldConfig, vmax: f64, acc: f64) {
    let ts = hold.period;
    let d: Vec<f64> = sps.windows(2).map(|w| (w[1].p - w[0].p).norm()).collect();
    for (i, x) in d.iter().enumerate() {
        assert!(
            *x <= vmax * ts * (1.0 + 1e-6) + 1e-12,
            "jump of {x} mm at {i}"
        );
    }
    for (i, w) in d.windows(2).enumerate() {
        // Chord lengths approximate arc lengths to well under 1e-6 mm here.
        let a = (w[1] - w[0]).abs() / (ts * ts);
        assert!(
            a <= acc + 1e-3 / (ts * ts) * 1e-3,
            "path acceleration {a} at {i}"
        );
    }
}

#[test]
fn an_underrunning_planner_makes_the_tool_hold_on_the_path_and_resume() {
    let (_, _, hold) = planned(Some(G01));
    let (_, cfg, _) = machine();
    // One chunk every 400 periods (0.8 s): slower than the program needs.
    let (sps, counters, path) = stream(Some(G01), 4, 400, None);
    assert!(counters.underruns >= 2, "{counters:?}");
    assert!(counters.hold_periods > 100, "{counters:?}");
    assert_eq!(counters.hard_stops, 0);
    assert_eq!(counters.leaked, 0);
    let last = sps.last().unwrap();
    assert!(last.done);
    let seg = path.segments.last().unwrap();
    assert!((last.p - seg.pose(seg.length).p).norm() < 1e-9);
    // At rest somewhere mid-program (a hold), not only at the ends.
    let stops = sps
        .windows(2)
        .skip(5)
        .filter(|w| (w[1].p - w[0].p).norm() < 1e-12 && !w[1].done)
        .count();
    assert!(stops > 100, "{stops} periods at rest");
    let vmax = path.segments.iter().map(|s| s.feed).fold(0.0, f64::max);
    check_smooth(&sps, &hold, vmax, 1.5 * cfg.path_acc + hold.acc);
}

#[test]
fn a_stop_request_decelerates_along_the_path_and_stays() {
    let (_, cfg, _) = machine();
    let (_, _, hold) = planned(None);
    let (sps, counters, path) = stream(None, 8, 0, Some(3000));
    let last = sps.last().unwrap();
    assert!(
        !last.done && sps.len() > 3000 && sps.len() < 3300,
        "{}",
        sps.len()
    );
    assert_eq!(counters.underruns, 0);
    // The stop point is on the curve.
    let (curve, _) = path.segments[0].nurbs().unwrap();
    let c = curve.cutter(last.u.unwrap(), 0);
    assert!((c.p - last.p).norm() < 1e-9);
    let v = 400.0 / 60.0;
    check_smooth(&sps, &hold, v, 1.5 * cfg.path_acc + hold.acc);
}

#[test]
fn an_operator_pause_override_and_resume_stay_on_the_path_within_the_hold_limits() {
    let (_, cfg, _) = machine();
    let (path, profile, hold) = planned(None);
    let (kin, _, _) = machine();
    let keep = path.clone();
    let (start, all) = chunks(path, &profile, &hold, 16);
    let mut source = all.into_iter();
    let mut q = Queues::new();
    let (mut feeder, inlet) = q.split(16);
    let mut f = Follower::new(inlet, start, kin, cfg.rotary, hold);
    feeder.feed(&mut source);
    let mut sps = Vec::new();
    let mut paused_at_rest = 0;
    for i in 0..100_000u64 {
        match i {
            1000 => f.pause(),
            2500 => f.resume(),
            3000 => f.set_override(0.3),
            5000 => f.set_override(1.0),
            _ => {}
        }
        let sp = f.step();
        if (1500..2500).contains(&i) {
            assert_eq!(sp.feed, 0.0, "paused, still moving at {i}");
            paused_at_rest += 1;
        }
        if (4000..5000).contains(&i) {
            assert!(sp.feed <= 0.3 * 400.0 / 60.0 + 1e-9, "{} at {i}", sp.feed);
        }
        sps.push(sp);
        if sp.done {
            break;
        }
    }
    feeder.feed(&mut std::iter::empty());
    assert_eq!(paused_at_rest, 1000);
    assert!(
        sps.last().unwrap().done,
        "the program finished after the resume"
    );
    assert_eq!(f.counters().hard_stops, 0);
    // Every setpoint on the curve, the end reached.
    let (curve, _) = keep.segments[0].nurbs().unwrap();
    for sp in &sps[1..] {
        let c = curve.cutter(sp.u.unwrap(), 0);
        assert!((c.p - sp.p).norm() < 1e-9);
    }
    check_smooth(&sps, &hold, 400.0 / 60.0, 1.5 * cfg.path_acc + hold.acc);
}

/// A tool change and a spindle start before the same feed move: the path waits for the
/// operator with the spindle still stopped, then for the spindle at its speed, then
/// goes on; nothing moves while it waits.
#[test]
fn the_spindle_starts_only_after_the_tool_change_and_the_move_waits_for_its_speed() {
    let src = "G00 X0 Y0 Z50\nG01 X5 F600\nT2 M06\nS8000 M03 M08\nG01 X20 F600\nM05 M09\n";
    let (path, profile, hold) = planned(Some(src));
    let (kin, cfg, _) = machine();
    let (start, all) = chunks(path, &profile, &hold, 16);
    let mut source = all.into_iter();
    let mut q = Queues::new();
    let (mut feeder, inlet) = q.split(16);
    let mut f = Follower::new(inlet, start, kin, cfg.rotary, hold);
    f.wait_for_spindle(true);
    feeder.feed(&mut source);
    let (mut for_operator, mut for_spindle) = (0, 0);
    let mut last = f.step();
    for i in 0..20_000u64 {
        if f.awaiting().is_some() {
            for_operator += 1;
            assert_eq!(
                last.aux.spindle_rpm, 0.0,
                "the spindle started during the tool change"
            );
            if for_operator == 100 {
                f.resume();
            }
        }
        if let Some(line) = f.awaiting_spindle() {
            assert_eq!(line, 5);
            assert_eq!((last.aux.spindle_rpm, last.aux.flood), (8000.0, true));
            for_spindle += 1;
            // The drive reports the speed after 200 periods.
            f.spindle_at_speed((for_spindle >= 200).then_some(8000.0));
        }
        let waiting = |f: &Follower<'_>| f.awaiting().is_some() || f.awaiting_spindle().is_some();
        let before = waiting(&f);
        let sp = f.step();
        if before && waiting(&f) {
            assert_eq!(sp.p, last.p, "moved while waiting at {i}");
        }
        last = sp;
        if sp.done {
            break;
        }
    }
    feeder.feed(&mut std::iter::empty());
    assert!(last.done);
    assert_eq!((for_operator, for_spindle), (100, 200));
    assert_eq!(last.p.x, 20.0);
}

/// `M64` then two `M66` before one move, on inputs wired back from the outputs (one period
/// late, as a valve's switch): the path waits at rest with the output already on until its
/// input is high, then for a rise that never comes until the 0.5 s timeout, then goes on,
/// and `M65` switches the output off from the move after it.
#[test]
fn the_path_waits_for_its_inputs_with_the_outputs_on_and_goes_on_at_a_timeout() {
    let src = "G00 X0 Y0 Z50\nG01 X5 F600\nM64 P2\nM66 P2 L3 Q5\nM66 P1 L1 Q0.5\n\
               G01 X20 F600\nM65 P2\nG01 X25\nM2";
    let mut setup = nc_lang::Setup::default();
    setup.io.digital_outputs = 4;
    setup.io.digital_inputs = 4;
    let (kin, cfg, bl) = machine();
    let program = nc_lang::parse_with(src, &setup).unwrap();
    let path = build(&program, &kin, &bl).unwrap();
    let profile = plan(&path, &kin, &cfg).unwrap();
    let hold = cfg.hold();
    let (start, all) = chunks(path, &profile, &hold, 16);
    let mut q = Queues::new();
    let (mut feeder, inlet) = q.split(16);
    let mut f = Follower::new(inlet, start, kin, cfg.rotary, hold);
    feeder.feed(&mut all.into_iter());
    let mut last = f.step();
    let mut waited = [0u64; 2];
    for i in 0..20_000u64 {
        // The inputs as the module reports them: the outputs of the last period.
        f.inputs(Some(last.aux.outputs));
        let before = f.awaiting_input();
        let sp = f.step();
        if let Some(line) = before.filter(|_| f.awaiting_input().is_some()) {
            assert_eq!(sp.p, last.p, "moved while waiting at {i}");
            assert_eq!(sp.aux.outputs, 1 << 2, "the M64 before the wait is on");
            waited[usize::from(line == 5)] += 1;
        }
        if sp.p.x > 20.0 + 1e-9 {
            assert_eq!(sp.aux.outputs, 0, "M65 is in effect after X20");
        }
        last = sp;
        if sp.done {
            break;
        }
    }
    feeder.feed(&mut std::iter::empty());
    assert!(last.done);
    assert_eq!(last.p.x, 25.0);
    // P2 is high one period after the output went on; the rise on P1 never comes.
    assert!(waited[0] <= 1, "{waited:?}");
    let timeout_periods = (0.5 / hold.period).round() as u64;
    assert!(
        waited[1].abs_diff(timeout_periods) <= 1,
        "{waited:?} against {timeout_periods}"
    );
    assert_eq!(f.input_timeouts(), (1, Some(5)));
}

/// Without an I/O module (a simulated machine) an `M66` passes at once.
#[test]
fn without_inputs_an_input_wait_passes_at_once() {
    let src = "G00 X0 Y0 Z50\nG01 X5 F600\nM66 P0 L3 Q5\nG01 X20\nM2";
    let mut setup = nc_lang::Setup::default();
    setup.io.digital_inputs = 1;
    let (kin, cfg, bl) = machine();
    let program = nc_lang::parse_with(src, &setup).unwrap();
    let path = build(&program, &kin, &bl).unwrap();
    assert!(path.segments.iter().any(|s| s.inputs[0].is_some()));
    let profile = plan(&path, &kin, &cfg).unwrap();
    let hold = cfg.hold();
    let (start, all) = chunks(path, &profile, &hold, 16);
    let mut q = Queues::new();
    let (mut feeder, inlet) = q.split(16);
    let mut f = Follower::new(inlet, start, kin, cfg.rotary, hold);
    feeder.feed(&mut all.into_iter());
    let mut done = false;
    for _ in 0..20_000u64 {
        f.inputs(None);
        let sp = f.step();
        assert_eq!(f.awaiting_input(), None);
        if sp.done {
            done = true;
            break;
        }
    }
    feeder.feed(&mut std::iter::empty());
    assert!(done);
    assert_eq!(f.input_timeouts(), (0, None));
}
