//! `nc_fit` on programs it did not write: the paper's 20 moves, a blade-like sweep, a
//! raster with corners, a post's program with lines that are not moves, and generated
//! curves. Every result is read back by the parser, built by the segment builder and
//! measured against the input by `fit::deviation` (dense sampling of the built paths), not
//! by the fit's own numbers.

use nalgebra::Vector3;
use nc_fit::deviation::{measure, Deviation};
use nc_fit::options::Options;
use nc_fit::runs::{fit_program, FitOutput};
use nc_fit::Tolerance;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::nurbs::DoubleNurbs;
use nc_geom::segment::build;
use nc_plan::fixtures::{blade, g01_program as g01, resample};
use proptest::prelude::*;
use std::fmt::Write;

const KIN: MachineKinematics = MachineKinematics::Paper;

/// Fit `src`, read the result back and measure it against the input.
fn fit_and_measure(src: &str, opts: &Options) -> (FitOutput, Deviation) {
    let (_, bl) = nc_plan::fixtures::small_mill(0.002);
    let input = nc_lang::parse(src).expect("input parses");
    let out = fit_program(src, &input, &KIN, opts);
    let fitted = nc_lang::parse(&out.text)
        .unwrap_or_else(|e| panic!("the result does not parse: {e}\n{}", out.text));
    let a = build(&input, &KIN, &bl).expect("input builds");
    let b = build(&fitted, &KIN, &bl)
        .unwrap_or_else(|e| panic!("the result does not build: {e}\n{}", out.text));
    let dev = measure(&a, &b, &KIN, 0.002, opts.tol.mm);
    // The streamed rewrite (`dnurbs fit`) writes the very same program, and its own check,
    // a piece at a time, finds it within what the whole paths' check finds plus the sampling.
    let mut streamed = Vec::new();
    let setup = nc_lang::Setup::default();
    let done = nc_fit::rewrite::rewrite(
        src.as_bytes(),
        &setup,
        &KIN,
        &bl,
        opts,
        0.002,
        &mut streamed,
    )
    .unwrap_or_else(|e| panic!("the streamed rewrite fails: {e}\n{src}"));
    assert_eq!(String::from_utf8(streamed).unwrap(), out.text);
    assert_eq!(done.summary, out.summary);
    assert!(
        (done.dev.point_mm - dev.point_mm).abs() < 1e-6,
        "{:?} {dev:?}",
        done.dev
    );
    assert!(
        (done.dev.point_deg - dev.point_deg).abs() < 1e-4,
        "{:?} {dev:?}",
        done.dev
    );
    assert_eq!(done.dev.points, dev.points);
    // Every block not fitted is there as it was: same kind, end, feed and rapid flag.
    let fitted_lines: Vec<(u32, u32)> = out
        .runs
        .iter()
        .filter(|r| r.found.fitted.is_some())
        .map(|r| r.lines)
        .collect();
    let in_run = |l: u32| fitted_lines.iter().any(|&(a, b)| (a..=b).contains(&l));
    let kept_in: Vec<String> = input
        .blocks
        .iter()
        .filter(|bl| !in_run(bl.pos().line))
        .map(describe)
        .collect();
    let kept_out: Vec<String> = fitted
        .blocks
        .iter()
        .filter(|bl| !matches!(bl, nc_geom::program::Block::Nurbs(n) if n.kind == nc_geom::program::NurbsKind::G065))
        .map(describe)
        .collect();
    assert_eq!(kept_in, kept_out, "{}", out.text);
    (out, dev)
}

fn describe(b: &nc_geom::program::Block) -> String {
    match b {
        nc_geom::program::Block::Linear(m) => {
            format!(
                "G01 rapid {} end {:?} feed {}",
                m.rapid, m.end, m.feed_mm_min
            )
        }
        nc_geom::program::Block::Nurbs(n) => {
            format!("{:?} {:?} feed {}", n.kind, n.ctrl, n.feed_mm_min)
        }
    }
}

fn within(dev: &Deviation, tol: Tolerance) {
    assert!(dev.point_mm <= tol.mm + 5e-7, "{dev:?}");
    assert!(dev.point_deg <= tol.rad.to_degrees() * 1.001, "{dev:?}");
}

/// The paper's G06.5 block (its section 6.2), evaluated by the controller's own code.
fn paper_curve() -> DoubleNurbs {
    use nc_geom::fixtures::{PAPER_C, PAPER_DEGREE, PAPER_K, PAPER_T};
    DoubleNurbs::new(PAPER_DEGREE, &PAPER_C, &PAPER_T, &[1.0; 5], &PAPER_K).unwrap()
}

#[test]
fn the_papers_twenty_moves_become_one_block() {
    // Fig. 7: a CAM path of 20 moves, here at equal steps of length along the paper's block.
    let curve = paper_curve();
    let points = resample(
        |t| {
            let (c, d) = curve.cutter_and_tool(t.min(1.0), 0);
            (c.p, d.p)
        },
        1.0,
        20,
        0.0,
    );
    let src = g01(&points, 400.0);
    let opts = Options::default();
    let (out, dev) = fit_and_measure(&src, &opts);
    assert_eq!(out.summary.moves_in, 20, "{:?}", out.summary);
    assert_eq!(out.summary.moves_fitted, 20, "{:?}", out.summary);
    assert_eq!(out.summary.fitted_blocks, 1);
    assert_eq!(out.summary.blocks_out, 2, "{}", out.text);
    within(&dev, opts.tol);
    // It runs: the planner accepts it on the test machine.
    let (cfg, bl) = nc_plan::fixtures::small_mill(0.002);
    let prog = nc_lang::parse(&out.text).unwrap();
    let path = build(&prog, &KIN, &bl).unwrap();
    nc_plan::plan::plan(&path, &KIN, &cfg).expect("the fitted block plans");
}

#[test]
fn a_blade_sweep_of_3000_moves_shrinks_tenfold_within_the_tolerances() {
    let points = resample(blade, 8.0, 3000, 0.1);
    let src = g01(&points, 3000.0);
    let opts = Options::default();
    let (out, dev) = fit_and_measure(&src, &opts);
    let s = &out.summary;
    assert_eq!(s.moves_in, 3000);
    assert!(s.blocks_out * 10 <= s.blocks_in, "{s:?}");
    assert!(s.bytes_out * 10 <= s.bytes_in, "{s:?}");
    within(&dev, opts.tol);
    // Between the points the curve stays within a micrometre of the programmed chords too.
    assert!(dev.path_mm <= 2e-3, "{dev:?}");
}

/// Rows of `steps` moves of 0.1 mm along a gentle wave, joined by 1 mm step-over moves at
/// 90 degrees.
fn raster(rows: u32, steps: u32) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let mut points = Vec::new();
    let length = f64::from(steps) * 0.1;
    for r in 0..rows {
        let y = f64::from(r);
        for k in 0..=steps {
            let x = f64::from(k) * 0.1;
            let x = if r % 2 == 0 { x } else { length - x };
            let z = 0.5 * (x / 5.0).sin() + 0.1 * y;
            points.push((Vector3::new(x, y, z), Vector3::new(0.0, 0.0, 1.0)));
        }
    }
    points
}

#[test]
fn a_raster_keeps_its_corners() {
    let rows = 6;
    let points = raster(rows, 300);
    let src = g01(&points, 3000.0);
    let opts = Options::default();
    let (out, dev) = fit_and_measure(&src, &opts);
    assert_eq!(
        out.summary.fitted_blocks, rows as usize,
        "{:?}",
        out.summary
    );
    within(&dev, opts.tol);
    // Each block starts and ends on a corner point exactly as programmed.
    let prog = nc_lang::parse(&out.text).unwrap();
    let corners: Vec<[f64; 3]> = prog
        .blocks
        .iter()
        .filter_map(|b| match b {
            nc_geom::program::Block::Nurbs(n) => Some([n.ctrl[0], n.ctrl[n.ctrl.len() - 1]]),
            _ => None,
        })
        .flatten()
        .collect();
    for c in corners {
        let hit = points.iter().any(|(p, _)| {
            (p - Vector3::from(c)).norm() < 1e-4 && (p.x.abs() < 1e-9 || (p.x - 30.0).abs() < 1e-9)
        });
        assert!(hit, "block end {c:?} is not a row end");
    }
}

#[test]
fn lines_that_are_not_plain_moves_pass_through_and_end_runs() {
    let wave = |k: usize| {
        let x = k as f64 * 0.1;
        format!("X{x:.4} Y{:.4} Z1", (x / 3.0).sin())
    };
    let mut src =
        String::from("%\nO1001 (post header)\nG90 G21 G94\nT1 M6\nS8000 M3\nG00 X0 Y0 Z1\n");
    for k in 1..=40 {
        let _ = writeln!(src, "G01 {} F2000", wave(k));
    }
    src.push_str("(a comment between two runs)\nM8\n");
    for k in 41..=80 {
        let _ = writeln!(src, "{}", wave(k));
    }
    src.push_str("G91\n");
    for _ in 81..=100 {
        src.push_str("X0.1 Y0.01\n");
    }
    src.push_str("G90 G93\n");
    for k in 101..=120 {
        let _ = writeln!(src, "{} F600", wave(k));
    }
    src.push_str("M5 M9\nM30\n%\n");
    let opts = Options::default();
    let (out, dev) = fit_and_measure(&src, &opts);
    within(&dev, opts.tol);
    // The two runs in G94, and the G93 section (written in G94 at its length over its
    // time, G93 restored after each block) in two: its moves all take 1/600 min, so their
    // speed follows their length, and a run ends where it changes by more than 1 %. Not
    // the G91 moves.
    assert_eq!(out.summary.fitted_blocks, 4, "{}", out.text);
    assert!(out.text.contains("G94 G06.5 P3"), "{}", out.text);
    assert!(
        out.text.contains("K1 K1 K1 K1\nF2000\nG93\nX"),
        "{}",
        out.text
    );
    // Every line that is not a fitted move is there, in order: the fitted ones are the
    // G01 lines of the first run and the bare wave lines (ending in Z1) of the others.
    let fitted = |l: &str| {
        l.starts_with("G01 X")
            || (l.starts_with('X') && (l.ends_with("Z1") || l.ends_with("Z1 F600")))
    };
    let kept: Vec<&str> = src.lines().filter(|l| !fitted(l)).collect();
    assert!(kept.len() > 30, "{kept:?}");
    let mut at = 0;
    for l in kept {
        let found = out.text[at..].find(l).unwrap_or_else(|| panic!("{l} lost"));
        at += found + l.len();
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    /// Generated curves (a random cubic net for the cutter, a random tilt and swing for the
    /// tool), sampled at jittered steps and rounded as a post would: wherever the fit writes
    /// a block, every programmed point and tool axis holds the tolerances.
    #[test]
    fn every_fitted_block_holds_the_tolerances(
        net in proptest::collection::vec((-40.0f64..40.0, -40.0f64..40.0, -20.0f64..20.0), 4..9),
        tilt in (0.0f64..40.0, -30.0f64..30.0, 0.5f64..3.0),
        n in 20usize..300,
        jitter in 0.0f64..0.5,
        tol_mm in 0.0005f64..0.01,
        tol_deg in 0.005f64..0.05,
    ) {
        let ctrl: Vec<[f64; 3]> = net.iter().map(|&(x, y, z)| [x, y, z]).collect();
        let m = ctrl.len();
        let mut knots = vec![0.0; 4];
        for j in 1..m - 3 {
            knots.push(j as f64 / (m - 3) as f64);
        }
        knots.extend([1.0; 4]);
        let curve = DoubleNurbs::new(3, &ctrl, &[], &vec![1.0; m], &knots).unwrap();
        let axis = |t: f64| {
            let lean = (tilt.0 + tilt.1 * (tilt.2 * t).sin()).to_radians();
            let sw = tilt.2 * t;
            Vector3::new(lean.sin() * sw.cos(), lean.sin() * sw.sin(), lean.cos())
        };
        let mut points = resample(|t| (curve.cutter(t.min(1.0), 0).p, axis(t)), 1.0, n, 0.0);
        // Jitter the spacing: move each interior point along the curve by up to `jitter` of
        // a step (keeps the order).
        for k in 1..points.len() - 1 {
            let f = jitter * (((k * 7919) % 13) as f64 / 13.0 - 0.5);
            let (a, b) = (points[k].0, points[k + 1].0);
            points[k].0 = a + (b - a) * f.max(0.0);
        }
        let src = g01(&points, 2000.0);
        let opts = Options {
            tol: Tolerance { mm: tol_mm, rad: tol_deg.to_radians() },
            ..Options::default()
        };
        let (_, dev) = fit_and_measure(&src, &opts);
        prop_assert!(dev.point_mm <= tol_mm + 5e-7, "{dev:?}\n{src}");
        prop_assert!(dev.point_deg <= tol_deg * 1.001, "{dev:?}\n{src}");
    }
}

/// On-line compression (`nc_fit::compress`) of a parsed program: every programmed point
/// within the tolerances of the compressed path, every program word before the same point
/// as before, and the compressed program planned faster.
#[test]
fn compressing_a_program_keeps_its_points_and_its_words() {
    let points = resample(blade, 8.0, 1200, 0.1);
    let mut src = g01(&points, 3000.0);
    // A coolant word in the middle splits the run; the program ends with a rapid.
    let mid = src.lines().position(|l| l.starts_with("N6000 ")).unwrap();
    let mut lines: Vec<&str> = src.lines().collect();
    lines.insert(mid, "M8");
    lines.insert(lines.len() - 2, "G00 Z150");
    src = lines.join("\n") + "\n";
    let (cfg, bl) = nc_plan::fixtures::small_mill(0.002);
    let program = nc_lang::parse(&src).unwrap();
    let opts = Options::default();
    let policy = nc_fit::options::Policy::on(opts);
    let (small, c) = nc_fit::compress::compress(&program, &KIN, &policy);
    let c = c.expect("compression is on");
    assert_eq!(c.fitted_blocks, 2, "{c:?}");
    assert_eq!(c.moves_fitted, 1200, "{c:?}");
    assert_eq!(small.blocks.len(), 4, "{c:?}");
    let (a, b) = (
        build(&program, &KIN, &bl).unwrap(),
        build(&small, &KIN, &bl).unwrap(),
    );
    within(&measure(&a, &b, &KIN, 0.002, opts.tol.mm), opts.tol);
    // Each word stands before a block that starts where it started before.
    let start_of =
        |p: &nc_geom::program::Program, k: usize| match k.checked_sub(1).map(|j| &p.blocks[j]) {
            Some(nc_geom::program::Block::Linear(m)) => m.end,
            Some(nc_geom::program::Block::Nurbs(n)) => n.ctrl[n.ctrl.len() - 1],
            None => [f64::NAN; 3],
        };
    assert_eq!(program.actions.len(), small.actions.len());
    for (x, y) in program.actions.iter().zip(&small.actions) {
        assert_eq!(x.kind, y.kind);
        let (p, q) = (
            start_of(&program, x.before_block),
            start_of(&small, y.before_block),
        );
        assert!(
            (Vector3::from(p) - Vector3::from(q)).norm() < 1e-12,
            "{x:?} {y:?}"
        );
    }
    let t_in = nc_plan::plan::plan(&a, &KIN, &cfg).unwrap().duration;
    let t_out = nc_plan::plan::plan(&b, &KIN, &cfg).unwrap().duration;
    assert!(t_out < t_in, "{t_out} s compressed, {t_in} s as G01");
}

/// A compressed raster slows into each row end and leaves it without creeping: the speed
/// ten periods' travel (at the corner's speed) before and after a corner is above the
/// corner's. Before, the planner's station at the end of a NURBS segment lay a rounding
/// error short of the segment's end (`h n` for the length), so the check's cap at the corner
/// also fell on the station before it: the path crept at the corner's speed over a whole
/// station, one period's travel at the feed (about 20 ms a row end of the 3-axis raster).
#[test]
fn a_compressed_row_end_is_passed_without_creeping() {
    // 1 ms and a chord tolerance of 2 um, as on the xyzac-trt-mill: the corner's speed is
    // then set by the axes' acceleration (a velocity jump of a Ts), not by its chord.
    let period = 0.001;
    let (mut cfg, bl) = nc_plan::fixtures::small_mill(period);
    cfg.chord_tol = 0.002;
    // Rows of several lengths: whether `h n` misses the length depends on it.
    for steps in [150, 223, 300, 417, 600] {
        let src = g01(&raster(4, steps), 3000.0);
        let program = nc_lang::parse(&src).unwrap();
        let policy = nc_fit::options::Policy::on(Options::default());
        let (small, c) = nc_fit::compress::compress(&program, &KIN, &policy);
        let c = c.expect("compression is on");
        assert_eq!(c.fitted_blocks, 4, "{c:?}");
        let path = build(&small, &KIN, &bl).unwrap();
        let profile = nc_plan::plan::plan(&path, &KIN, &cfg).unwrap();
        // The time at which the path passes position s (s grows with t).
        let time_at = |s: f64| {
            let (mut lo, mut hi) = (0.0, profile.duration);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if profile.motion_at(mid).s < s {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            hi
        };
        let point = |s: f64| {
            let k = profile
                .seg_start
                .partition_point(|&b| b <= s)
                .saturating_sub(1);
            let k = k.min(path.segments.len() - 1);
            let seg = &path.segments[k];
            seg.pose((s - profile.seg_start[k]).clamp(0.0, seg.length))
                .p
        };
        let mut corners = 0;
        for k in 1..path.segments.len() {
            let s = profile.seg_start[k];
            let (a, b, c) = (point(s - 0.01), point(s), point(s + 0.01));
            if (b - a).angle(&(c - b)) < 45f64.to_radians() {
                continue;
            }
            corners += 1;
            let vc = profile.motion_at(time_at(s)).v;
            let d = 10.0 * vc * period;
            for side in [s - d, s + d] {
                let v = profile.motion_at(time_at(side)).v;
                assert!(
                    v > 1.05 * vc,
                    "rows of {steps} moves: corner at s = {s:.4} passed at {vc:.3} mm/s, \
                     {v:.3} mm/s at s = {side:.4}"
                );
            }
        }
        assert_eq!(corners, 6, "three row ends, two corners each");
    }
}

/// The check measures a path against itself as zero, whatever its moves' lengths: a long
/// rapid approach, turns of the rotary axes alone, short moves and a long straight one, so
/// the input's straight moves, measured as whole chords, are followed however far the
/// output's samples run along one.
#[test]
fn a_path_measured_against_itself_is_not_off() {
    let mut src = String::from("G90 G21 G94\nG00 X250 Y0 Z50\nG01 A10 F1000\nG01 C30\n");
    for k in 1..=200 {
        let t = f64::from(k) * 0.01;
        let _ = writeln!(
            src,
            "G01 X{:.4} Y{:.4} Z{:.4} F2000",
            250.0 - 20.0 * t,
            5.0 * t.sin(),
            50.0 - t
        );
    }
    src.push_str("G01 X0 Y-40 Z10\nG01 A0 C0\nG01 X0.1 Y-40.05\n");
    let (_, bl) = nc_plan::fixtures::small_mill(0.002);
    let path = build(&nc_lang::parse(&src).unwrap(), &KIN, &bl).unwrap();
    let dev = measure(&path, &path, &KIN, 0.002, 0.001);
    assert!(dev.point_mm < 1e-9 && dev.path_mm < 1e-9, "{dev:?}");
    assert!(dev.point_deg < 1e-6, "{dev:?}");
    assert_eq!(dev.points, 206);
}

/// A curve whose span is far longer than the straight line between its ends is measured
/// along its length: a G06.5 block whose weights run from 0.005 to 768 (found by the fuzz
/// target `nc_compressed`, the block before a run of moves it fitted) loops between its
/// knots, and the check looked for a span's end within twice the straight distance to it
/// and found it 5.7 mm off the block itself, so `dnurbs fit` refused to write a program
/// whose every point it had kept.
#[test]
fn a_looping_nurbs_span_measured_against_itself_is_not_off() {
    let src = "G90 G21\nG01 X-0.2827 Y-15.433 Z-4.3496 F1000\n\
        G06.5 P2 F12104.3456 X-0.2827 Y-15.433 Z-4.3496 U-0.28268 V-15.43317 W-1.32146 R1 K0\n\
        X-4.919203 Y-19.078374 Z-13.635058 U-4.834112 V-19.865217 W-10.712172 R3.750246 K0\n\
        X-2.590794 Y-19.078374 Z-13.823828 U-1.899286 V-18.831795 W-10.886032 R0.022319 K0\n\
        X-2.590794 Y-20.844983 Z-8.597086 U-3.205734 V-21.451591 W-5.694759 R768.25415 K0.455003\n\
        X4.823020 Y-11.247886 Z-14.374911 U6.474493 V-11.220475 W-11.836898 R0.004603 K0.916189\n\
        K1 K1 K1\n";
    let (_, bl) = nc_plan::fixtures::small_mill(0.002);
    let path = build(&nc_lang::parse(src).unwrap(), &KIN, &bl).unwrap();
    let dev = measure(&path, &path, &KIN, 0.002, 0.001);
    assert!(dev.point_mm < 1e-6 && dev.path_mm < 1e-6, "{dev:?}");
}

/// A program that goes back over its own path (a reversal, as `compressed_posts.rs`
/// generates them: 3 um forward, back, on) with the tool tilted on the way back, against
/// an output that passes its first point 0.5 um off and the rest exactly: each point is
/// taken where the output first passes within the tolerance after the point before, so
/// 0.5 um and no angle. Taken at the nearest visit instead, the first point went to the
/// return's exact visit and its tilted tool (1.15 deg); taken from a few samples behind,
/// the return's point went to the first visit and its vertical tool (both found by
/// `compressed_posts.rs`).
#[test]
fn a_reversal_is_measured_in_the_order_of_its_points() {
    let (_, bl) = nc_plan::fixtures::small_mill(0.002);
    let prog = |first_y: f64| {
        format!(
            "G01 X0 Y0 Z0 F600\nX1 Y{first_y} I0 J0 K1\nX1.003 Y0\n\
             X1 Y0 I0 J0.02 K1\nX1.2 Y0\n"
        )
    };
    let path = |src: &str| build(&nc_lang::parse(src).unwrap(), &KIN, &bl).unwrap();
    let (input, output) = (path(&prog(0.0)), path(&prog(0.0005)));
    let dev = measure(&input, &output, &KIN, 0.002, 0.001);
    assert!(
        dev.point_mm > 0.0004 && dev.point_mm < 0.0005 + 1e-9,
        "{dev:?}"
    );
    assert!(dev.point_deg < 1e-6, "{dev:?}");
    assert_eq!(dev.points, 5);
}
