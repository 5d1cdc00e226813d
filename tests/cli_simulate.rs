//! `dnurbs simulate` end to end: the real binary on the programs in tests/data, its trace
//! checked against independent evaluations (Cox-de Boor, closed-form kinematics).

mod common;
use common::*;

#[test]
fn paper_example_lies_on_both_curves_with_paper_kinematics() {
    let (s, rows) = simulate("paper-example.nc", "paper-ac-table.toml", &[]);
    assert_eq!(s["method"], "arclength");
    assert!(f(&s, "feed_fluctuation_max") < 1e-4, "{s}");
    assert!(f(&s, "feed_fluctuation_periods") > 1000.0);
    assert!(f(&s, "end_position_error_mm") < 1e-9);
    assert!(f(&s, "tool_axis_deviation_max_deg") < 0.01, "{s}");
    assert_within_limits(&s);
    assert_eq!(rows[0].cycle, 0);
    assert_eq!(rows[0].t, 0.0);
    assert_eq!(f(&s, "cycles") as usize, rows.len());
    let mut on_curve = 0;
    for r in &rows {
        // Paper kinematics: machine XYZ = workpiece XYZ; T = (-sinA sinC, sinA cosC, cosA).
        for a in 0..3 {
            assert!((r.axes[a] - r.p[a]).abs() < 1e-12);
        }
        let (a, c) = (r.axes[3].to_radians(), r.axes[4].to_radians());
        let t = [-a.sin() * c.sin(), a.sin() * c.cos(), a.cos()];
        assert!(
            dist(t, r.tool) < 1e-9,
            "row {}: A/C give {t:?}, tool {:?}",
            r.cycle,
            r.tool
        );
        assert!(r.feed <= 400.0 + 1e-9, "row {} feed {}", r.cycle, r.feed);
        if let Some(u) = r.u {
            let c = nurbs_point(3, &PAPER_C, &[1.0; 5], &PAPER_K, u);
            let ct = nurbs_point(3, &PAPER_T, &[1.0; 5], &PAPER_K, u);
            assert!(dist(c, r.p) < 1e-9, "row {}: {c:?} vs {:?}", r.cycle, r.p);
            let axis = unit([ct[0] - c[0], ct[1] - c[1], ct[2] - c[2]]);
            assert!(dist(axis, r.tool) < 1e-9);
            on_curve += 1;
        }
    }
    assert!(
        on_curve + 2 >= rows.len(),
        "{on_curve} of {} rows on the curve",
        rows.len()
    );
    let last = rows.last().unwrap();
    assert!(dist(last.p, PAPER_C[4]) < 1e-9);
    assert_eq!(last.feed, 0.0);
    // C stays continuous: no step bigger than the C axis can make in one period.
    for w in rows.windows(2) {
        assert!((w[1].axes[4] - w[0].axes[4]).abs() < 180.0 * 0.002 + 1e-9);
    }
}

#[test]
fn methods_rank_taylor1_taylor2_arclength() {
    let mut fl = vec![];
    for m in ["taylor1", "taylor2", "arclength"] {
        let (s, rows) = simulate("paper-example.nc", "paper-ac-table.toml", &["--method", m]);
        assert_eq!(s["method"], m);
        let last = rows.last().unwrap();
        assert!(dist(last.p, PAPER_C[4]) < 1e-9, "{m} ends at {:?}", last.p);
        fl.push(f(&s, "feed_fluctuation_max"));
    }
    assert!(
        fl[0] > fl[1] && fl[1] > fl[2],
        "taylor1 {} taylor2 {} arclength {}",
        fl[0],
        fl[1],
        fl[2]
    );
}

/// The Taylor methods drift from the plan, which is checked on the arclength setpoints only:
/// where their own setpoints break a limit, the summary lists each axis and quantity over
/// its limit with the worst fraction, its time, block and line, and the trace agrees (every
/// fraction recomputed from it by finite differences at the period). Arc length on the same
/// program lists nothing.
#[test]
fn a_taylor_excess_is_listed_where_it_happens() {
    let m = config::load(&machine("xyzac-trt-mill.toml")).unwrap();
    let (out, s, rows) = common::simulate_output(
        "classics/dual-spline.nc",
        "xyzac-trt-mill.toml",
        &["--method", "taylor1"],
    );
    // Never a success (issue 56): exit 2, and stderr says why and what run sends.
    assert_eq!(out.status.code(), Some(2), "{s}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("the taylor1 setpoints exceed an axis limit") && err.contains("arclength"),
        "{err}"
    );
    let listed = s["limits_exceeded"].as_array().expect("limits_exceeded");
    assert!(
        !listed.is_empty(),
        "taylor1 on dual-spline is over a limit: {s}"
    );
    let ts = f(&s, "period_s");
    // (fraction, row) of the largest velocity and acceleration of each axis.
    let mut worst = [[(0.0f64, 0usize); 2]; 5];
    for k in 1..rows.len() {
        for (j, (_, l)) in m.axes.all().iter().enumerate() {
            let q = |i: usize| rows[i].axes[j];
            let v = (q(k) - q(k - 1)).abs() / ts / l.velocity;
            let a = (k >= 2).then(|| (q(k) - 2.0 * q(k - 1) + q(k - 2)).abs() / (ts * ts));
            for (n, x) in [(0, Some(v)), (1, a.map(|a| a / l.acceleration))] {
                if let Some(x) = x.filter(|&x| x > worst[j][n].0) {
                    worst[j][n] = (x, k);
                }
            }
        }
    }
    let mut expected = vec![];
    for (n, quantity) in ["velocity", "acceleration"].iter().enumerate() {
        for (j, (name, _)) in m.axes.all().iter().enumerate() {
            let (frac, k) = worst[j][n];
            if frac > 1.0 + 1e-6 {
                expected.push((
                    name.to_string(),
                    quantity.to_string(),
                    frac,
                    rows[k].t,
                    rows[k].block,
                ));
            }
        }
    }
    assert_eq!(
        listed.len(),
        expected.len(),
        "{listed:?} against the trace's {expected:?}"
    );
    let text = std::fs::read_to_string(data("classics/dual-spline.nc")).unwrap();
    for (e, (axis, quantity, frac, t, block)) in listed.iter().zip(&expected) {
        assert_eq!(e["axis"], axis.as_str(), "{e}");
        assert_eq!(e["quantity"], quantity.as_str(), "{e}");
        assert!(
            (f(e, "fraction") / frac - 1.0).abs() < 1e-6,
            "{e}: the trace gives {frac}"
        );
        assert_eq!(f(e, "t_s"), *t, "{e}");
        assert_eq!(f(e, "block") as u32, *block, "{e}");
        let key = format!("axis_{quantity}_fraction");
        assert_eq!(f(&s[key.as_str()], axis), f(e, "fraction"), "{e}");
        // The line named is the block's first: a motion line of the program.
        let line = text.lines().nth(f(e, "line") as usize - 1).unwrap_or("");
        assert!(line.contains("G06.5"), "{e}: line {line:?}");
    }
    let (s, _) = simulate(
        "classics/dual-spline.nc",
        "xyzac-trt-mill.toml",
        &["--method", "arclength"],
    );
    assert_within_limits(&s);
    let out = dnurbs(&[
        "simulate",
        data("classics/dual-spline.nc").to_str().unwrap(),
        "--machine",
        machine("xyzac-trt-mill.toml").to_str().unwrap(),
        "--method",
        "taylor1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("limits             EXCEEDED by these taylor1 setpoints: ")
            && text.contains("which run sends"),
        "{text}"
    );
    // `compare` puts the same in its last column, and `within` for arc length.
    let out = dnurbs(&[
        "compare",
        data("classics/dual-spline.nc").to_str().unwrap(),
        "--machine",
        machine("xyzac-trt-mill.toml").to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let table = String::from_utf8_lossy(&out.stdout);
    let cell = |method: &str| {
        let row = table
            .lines()
            .find(|l| l.starts_with(&format!("| dual-spline.nc | {method} |")))
            .unwrap_or_else(|| panic!("no {method} row: {table}"));
        row.trim_end_matches(" |")
            .rsplit(" | ")
            .next()
            .unwrap()
            .to_string()
    };
    let brief: Vec<String> = listed
        .iter()
        .map(|e| {
            let q = &e["quantity"].as_str().unwrap()[..3];
            format!(
                "{} {q} {:.1}% at {:.3} s",
                e["axis"].as_str().unwrap(),
                f(e, "fraction") * 100.0,
                f(e, "t_s")
            )
        })
        .collect();
    assert_eq!(cell("taylor1"), brief.join(", "), "{table}");
    assert_eq!(cell("arclength"), "within", "{table}");
}

#[test]
fn tight_curvature_is_slowed_by_centripetal_and_c_axis_limits() {
    let (s, rows) = simulate("tight-curvature.nc", "paper-ac-table.toml", &[]);
    assert!(f(&s, "feed_fluctuation_max") < 1e-4, "{s}");
    assert_within_limits(&s);
    // The C axis is the binding limit on the circle: it runs close to its velocity limit.
    let c = s["axis_velocity_fraction"]["C"].as_f64().unwrap();
    assert!(c > 0.8, "C velocity fraction {c}");
    let on_circle: Vec<&Row> = rows.iter().filter(|r| r.block == 3).collect();
    assert!(on_circle.iter().all(|r| r.feed < 3000.0));
    // The circle (radius 4 about X10 Y10) is followed exactly: the 1e-9 mm the radius may
    // differ by comes from the program's 8-digit weight 0.70710678 for cos(45 deg).
    for r in &on_circle {
        let rad = ((r.p[0] - 10.0).powi(2) + (r.p[1] - 10.0).powi(2)).sqrt();
        assert!((rad - 4.0).abs() < 1e-8 && r.p[2].abs() < 1e-12, "{r:?}");
    }
    let last = rows.last().unwrap();
    assert!(dist(last.p, [10.0, 6.0, 5.0]) < 1e-9);
}

#[test]
fn a_g2_joint_is_passed_at_speed() {
    let (s, rows) = simulate("two-blocks-g2.nc", "paper-ac-table.toml", &[]);
    assert_within_limits(&s);
    let first_of_2 = rows
        .iter()
        .position(|r| r.block == 3)
        .expect("second block reached");
    let at_joint = rows[first_of_2].feed;
    assert!(
        at_joint > 0.9 * 2000.0,
        "feed at the joint {at_joint} mm/min"
    );
    let last = rows.last().unwrap();
    assert!(dist(last.p, [60.0, -10.0, 0.0]) < 1e-9 && last.feed == 0.0);
}

#[test]
fn rtcp_machine_axes_carry_the_cutter_point() {
    let (s, rows) = simulate(
        "paper-example.nc",
        "xyzac-trt-mill.toml",
        &["--method", "arclength"],
    );
    assert_within_limits(&s);
    assert!(f(&s, "feed_fluctuation_max") < 1e-4);
    // Forward kinematics written out independently: undo the A tilt about the pivot
    // (0, 0, -50), then the C turn about the Z axis through the origin.
    for r in &rows {
        let (a, c) = (r.axes[3].to_radians(), r.axes[4].to_radians());
        let m = [r.axes[0], r.axes[1], r.axes[2] + 50.0];
        let (y, z) = (
            m[1] * a.cos() + m[2] * a.sin(),
            -m[1] * a.sin() + m[2] * a.cos(),
        );
        let q = [m[0], y, z - 50.0];
        let p = [
            q[0] * c.cos() - q[1] * c.sin(),
            q[0] * c.sin() + q[1] * c.cos(),
            q[2],
        ];
        assert!(dist(p, r.p) < 1e-9, "row {}: {p:?} vs {:?}", r.cycle, r.p);
    }
}

#[test]
fn text_summary_and_help() {
    let prog = data("paper-example.nc");
    let mach = machine("paper-ac-table.toml");
    let out = dnurbs(&[
        "simulate",
        prog.to_str().unwrap(),
        "--machine",
        mach.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for word in [
        "feed fluctuation",
        "chord error",
        "axis velocity",
        "machining time",
    ] {
        assert!(text.contains(word), "{word} missing from\n{text}");
    }
    let help = dnurbs(&["simulate", "--help"]);
    let help = String::from_utf8(help.stdout).unwrap();
    assert!(help.contains("--trace") && help.contains("--method") && help.contains("taylor2"));
}

#[test]
fn c_turns_at_rest_where_the_tool_leaves_the_vertical_in_a_new_direction() {
    let (s, rows) = simulate("vertical-turns.nc", "paper-ac-table.toml", &[]);
    assert_within_limits(&s);
    // Somewhere the cutter stands still at X40 Y0 while C turns by 90 degrees.
    let turning: Vec<&Row> = rows
        .iter()
        .filter(|r| dist(r.p, [40.0, 0.0, 10.0]) < 1e-12)
        .collect();
    let c_span = turning
        .iter()
        .map(|r| r.axes[4])
        .fold(f64::NEG_INFINITY, f64::max)
        - turning
            .iter()
            .map(|r| r.axes[4])
            .fold(f64::INFINITY, f64::min);
    // The turn starts and ends at rest between two periods, so the sampled span falls short
    // of 90 degrees by what C moves in the slowest period (microdegrees).
    assert!(
        (c_span - 90.0).abs() < 1e-3,
        "C turned {c_span} deg at the vertical"
    );
    let last = rows.last().unwrap();
    assert!(dist(last.p, [40.0, 20.0, 10.0]) < 1e-9);
}

/// On a machine with a `[spindle]`, the summary gives the feed moves that wait for the
/// spindle's speed and the time its ramps take there (not in the machining time): here
/// 0 -> 12 000 rpm and 12 000 -> 6 000 rpm at the posts machine's 8 000 rpm/s, 1.5 s +
/// 0.75 s. A machine without one says nothing about it.
#[test]
fn simulate_reports_the_spindle_waits_beside_the_machining_time() {
    let prog = temp("spindle-waits.nc");
    std::fs::write(
        &prog,
        "G90 G21\nG00 X0 Y0 Z5\nS12000 M03\nG01 X10 F600\nS6000\nG01 X20\nM05\nG00 Z50\nM30\n",
    )
    .unwrap();
    let posts = root().join("tests/data/posts/machine.toml");
    let args = |m: &std::path::Path, json: bool| {
        let mut a = vec![
            "simulate".to_owned(),
            prog.to_str().unwrap().to_owned(),
            "--machine".to_owned(),
            m.to_str().unwrap().to_owned(),
        ];
        if json {
            a.push("--json".to_owned());
        }
        a
    };
    let run = |a: Vec<String>| {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let out = dnurbs(&a);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).to_string()
    };
    let text = run(args(&posts, false));
    assert!(
        text.contains("spindle waits      2 feed moves wait for the spindle's speed: about 2.250 s of ramps, not in the machining time"),
        "{text}"
    );
    let json: serde_json::Value = serde_json::from_str(&run(args(&posts, true))).unwrap();
    assert_eq!(json["spindle_waits"]["count"], 2, "{json}");
    assert!(
        (f(&json["spindle_waits"], "ramp_s") - 2.25).abs() < 1e-12,
        "{json}"
    );
    let paper = machine("paper-ac-table.toml");
    let text = run(args(&paper, false));
    assert!(!text.contains("spindle waits"), "{text}");
    let json: serde_json::Value = serde_json::from_str(&run(args(&paper, true))).unwrap();
    assert!(json.get("spindle_waits").is_none(), "{json}");
}

/// A wiggle of `n` G01 moves of 0.05 mm at F3000 with coolant words, as a post writes it.
fn long_program(n: usize, break_at: Option<usize>) -> String {
    let mut s = String::from("%\nG90 G21 G94\nM08\n");
    for k in 0..=n {
        let d = k as f64 * 0.05;
        let x = -200.0 + d % 400.0;
        let y = 2.0 * (d / 400.0).floor() + 0.5 * (x / 2.0).sin();
        let x = if Some(k) == break_at { 400.0 } else { x };
        let g = if k < 2 { "G01 " } else { "" };
        let f = if k == 0 { " F3000" } else { "" };
        s += &format!(
            "N{} {g}X{x:.4} Y{y:.4} Z0.0000 I0.0 J0.0 K1.0{f}\n",
            10 * (k + 1)
        );
    }
    s + "M09\nM30\n%\n"
}

/// A program longer than `simulate` parses whole (8 MiB, where every syntax error is listed)
/// is read, built, planned and interpolated a line at a time, holding a window of it: the
/// summary is the one the whole path gives (the library's `simulate::run` and `summarize`,
/// which keep everything), every word listed; an error deep in it is refused at its line.
#[test]
fn a_long_program_is_simulated_as_it_is_read_with_the_whole_paths_summary() {
    let n = 180_000;
    let text = long_program(n, None);
    assert!(text.len() as u64 > dnurbs_tools::feed::CHECK_WHOLE_BYTES);
    let file = temp("long.nc");
    std::fs::write(&file, &text).unwrap();
    let mach = machine("paper-ac-table.toml");
    let args = [
        "simulate",
        file.to_str().unwrap(),
        "--machine",
        mach.to_str().unwrap(),
        "--json",
    ];
    let out = dnurbs(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON summary");

    let m = dnurbs_tools::load_machine(&mach).unwrap();
    let shop = dnurbs_tools::shop::ShopArgs::default().load().unwrap();
    let prog =
        nc_lang::parse_with(&text, &dnurbs_tools::shop::parse_setup(&m, &shop).unwrap()).unwrap();
    let setup = dnurbs_tools::setup::MachineSetup::new(&m);
    let whole = dnurbs_tools::simulate::run(&prog, &setup, setup.method).unwrap();
    let mut want = dnurbs_tools::simulate::summarize(&whole, &setup, prog.blocks.len());
    want.program_words = dnurbs_tools::words::describe(&prog);
    // Through the same text and parser (serde_json's float parser may be 1 ulp off).
    let want: serde_json::Value =
        serde_json::from_str(&serde_json::to_string_pretty(&want).unwrap()).unwrap();
    assert_eq!(got, want);
    assert_eq!(got["blocks"], n + 1);
    assert_eq!(
        got["program_words"].as_array().map(Vec::len),
        Some(2),
        "{got}"
    );

    // X400 at move 170 000, past the 290 mm travel: refused at its line, and the trace of
    // what came before it is not left as if it were the program's.
    std::fs::write(&file, long_program(n, Some(170_000))).unwrap();
    let trace = temp("refused-trace.csv");
    let mut with_trace = args.to_vec();
    with_trace.extend(["--trace", trace.to_str().unwrap()]);
    let out = dnurbs(&with_trace);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("{}:170004:", file.display())),
        "{err}"
    );
    assert!(!trace.exists(), "a refused program's trace is removed");
    let _ = std::fs::remove_file(&file);
}

/// A machine file whose jerk is set huge (as one means "none", LinuxCNC having none): every
/// axis's jerk is planned at 0.098 of its acceleration a period, `simulate` says so on
/// stderr, and a raster of short moves plans within every limit. With the ramps planned to
/// 90 % of the acceleration, the check's reserve for a jerk of 1e9 (half the acceleration)
/// refused it on its first ramp.
#[test]
fn a_jerk_set_huge_is_planned_at_a_tenth_of_the_acceleration_a_period_and_said() {
    let text = common::machine_text("xyzac-trt-mill.toml");
    let huge: String = text
        .lines()
        .map(|l| match l.split_once('=') {
            Some((k, _)) if matches!(k.trim(), "jerk" | "path_jerk") => {
                format!("{k}= 1.0e9")
            }
            _ => l.to_owned(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert_eq!(huge.matches("= 1.0e9").count(), 6, "{huge}");
    let mill = temp("huge-jerk.toml");
    std::fs::write(&mill, huge).unwrap();
    let mut program = String::from("%\nG90 G21 G94\nG01 X0 Y0 Z0 F3000\n");
    for row in 0..4 {
        for k in 0..=100 {
            let x = f64::from(if row % 2 == 0 { k } else { 100 - k }) * 0.1;
            let z = 0.5 * (x / 1.5).sin();
            program += &format!("X{x:.4} Y{row}.0 Z{z:.4}\n");
        }
    }
    program += "M30\n%\n";
    let nc = temp("huge-jerk.nc");
    std::fs::write(&nc, program).unwrap();
    let out = dnurbs(&[
        "simulate",
        nc.to_str().unwrap(),
        "--machine",
        mill.to_str().unwrap(),
        "--method",
        "arclength",
        "--json",
    ]);
    let _ = (std::fs::remove_file(&mill), std::fs::remove_file(&nc));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "planned at a jerk of 0.098 of the axis's acceleration a period (1 ms), less the \
             15 % every plan keeps for a hold"
        ) && stderr.contains("X 1.0000e9 -> 2.4990e5 mm/s^3")
            && stderr.contains("C 1.0000e9 -> 1.4994e5 deg/s^3"),
        "{stderr}"
    );
    let s: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_within_limits(&s);
}

#[test]
fn a_program_as_linuxcnc_users_write_it_runs_on_every_shipped_machine() {
    // Its first move gives only Z (the homed machine starts at its reference), G55 and
    // G43 H1 come from the machine file's offsets and tool table, mm from its start-up modes.
    let nc = temp("shop.nc");
    let program = "G0 Z5\nT1 M6\nG43 H1 G55\nG0 X10 Y10\nG1 Z-1 F300\nG1 X20\nG0 Z5\nM30\n";
    std::fs::write(&nc, program).unwrap();
    for name in [
        "paper-ac-table.toml",
        "xyz-mill.toml",
        "xyzac-trt-mill.toml",
        "xyzbc-trt-mill.toml",
    ] {
        let mill = config::load(&machine(name)).unwrap();
        let trace = temp("shop.csv");
        let out = dnurbs(&[
            "simulate",
            nc.to_str().unwrap(),
            "--machine",
            machine(name).to_str().unwrap(),
            "--trace",
            trace.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let rows = read_trace(&trace);
        let _ = std::fs::remove_file(&trace);
        let (first, last) = (&rows[0], &rows[rows.len() - 1]);
        assert_eq!(
            first.p,
            mill.reference.unwrap(),
            "{name}: starts at the reference"
        );
        let end = [20.0, 10.0, 5.0];
        assert!(
            last.p.iter().zip(end).all(|(a, b)| (a - b).abs() < 1e-9),
            "{name}: ends at {:?}",
            last.p
        );
        // The tool's length (80 mm, T1 of the machine's table) is between tip and spindle.
        assert!(
            (last.axes[2] - 85.0).abs() < 1e-6,
            "{name}: Z {}",
            last.axes[2]
        );
    }
    // A program without G20/G21 on a machine whose start-up modes say inch: in inches.
    std::fs::write(&nc, "G0 Z1\nG1 X2 Y1 F10\nM30\n").unwrap();
    let inch = temp("inch.toml");
    let text = common::machine_text("xyzac-trt-mill.toml").replace("G17 G21", "G17 G20");
    std::fs::write(&inch, text).unwrap();
    let trace = temp("inch.csv");
    let out = dnurbs(&[
        "simulate",
        nc.to_str().unwrap(),
        "--machine",
        inch.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = read_trace(&trace);
    let last = &rows[rows.len() - 1].p;
    let _ = [&nc, &inch, &trace].map(std::fs::remove_file);
    let end = [50.8, 25.4, 25.4];
    assert!(
        last.iter().zip(end).all(|(a, b)| (a - b).abs() < 1e-9),
        "{last:?}"
    );
}
