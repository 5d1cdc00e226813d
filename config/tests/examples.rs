//! The shipped machine files, defaults, reading from disk, and robustness on any input.

mod common;

use std::path::{Path, PathBuf};

use common::{parse, set, MINIMAL, PAPER, XYZAC};
use config::{AxisLimits, ConfigError, Interpolation, Kinematics, Machine, Method, RotaryName};

fn limits(min: f64, max: f64, velocity: f64, acceleration: f64, jerk: f64) -> AxisLimits {
    AxisLimits {
        min,
        max,
        velocity,
        acceleration,
        jerk,
    }
}

fn machines_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("machines")
}

#[test]
fn paper_machine_loads_with_expected_values() {
    let m = config::load(&machines_dir().join("paper-ac-table.toml")).unwrap();
    assert_eq!(m.name, "paper-ac-table");
    assert_eq!(m.period_s, 0.002);
    assert_eq!(m.kinematics, Kinematics::Paper);
    assert_eq!(m.axes.x, limits(-300.0, 300.0, 250.0, 2500.0, 50000.0));
    assert_eq!(m.axes.y, limits(-250.0, 250.0, 250.0, 2500.0, 50000.0));
    assert_eq!(m.axes.z, limits(-200.0, 200.0, 250.0, 2500.0, 50000.0));
    assert_eq!(m.axes.tilt_name, RotaryName::A);
    assert_eq!(m.axes.tilt, limits(-95.0, 95.0, 90.0, 900.0, 20000.0));
    assert_eq!(
        m.axes.c,
        limits(f64::NEG_INFINITY, f64::INFINITY, 180.0, 1800.0, 40000.0)
    );
    assert!(m.axes.c.is_unlimited() && !m.axes.tilt.is_unlimited());
    assert_eq!(
        m.interpolation,
        Interpolation {
            method: Method::Arclength,
            chord_tolerance_mm: 0.001,
            path_acceleration: 1000.0,
            path_jerk: 20000.0,
            max_feed_mm_min: 10000.0,
            rapid_feed_mm_min: 15000.0,
            compress: false,
            compression: config::Compress::DEFAULT,
        }
    );
    let names = m.axes.all().map(|(name, _)| name);
    assert_eq!(names, ["X", "Y", "Z", "A", "C"]);
}

/// The paper's example block (cutter points x -2..48, y 71..164, z 5..59 mm) fits the
/// paper machine's travels, since that machine has machine XYZ = workpiece XYZ.
#[test]
fn paper_example_fits_paper_machine() {
    let m = parse(PAPER).unwrap();
    let (lo, hi) = ([-2.0, 71.0, 5.0], [48.0, 164.0, 59.0]);
    for (i, axis) in [&m.axes.x, &m.axes.y, &m.axes.z].into_iter().enumerate() {
        assert!(axis.min < lo[i] && hi[i] < axis.max, "{i}: {axis:?}");
    }
}

#[test]
fn xyzac_trt_machine_loads_with_expected_values() {
    let m = config::load(&machines_dir().join("xyzac-trt-mill.toml")).unwrap();
    assert_eq!(m.name, "xyzac-trt-mill");
    assert_eq!(m.period_s, 0.001);
    assert_eq!(
        m.kinematics,
        Kinematics::XyzacTrt {
            a_axis_point: [0.0, 0.0, -50.0],
            c_axis_point: [0.0, 0.0, 0.0],
        }
    );
    assert_eq!(m.kinematics.kind(), "xyzac-trt");
    assert_eq!(m.axes.tilt_name, RotaryName::A);
    assert_eq!(m.axes.y, limits(-400.0, 400.0, 300.0, 3000.0, 60000.0));
    assert_eq!(m.axes.z, limits(-400.0, 400.0, 250.0, 2500.0, 50000.0));
    assert_eq!(m.axes.tilt, limits(-110.0, 110.0, 90.0, 900.0, 20000.0));
    assert_eq!(m.axes.c, limits(-3600.0, 3600.0, 180.0, 1800.0, 40000.0));
    assert_eq!(m.interpolation.method, Method::Arclength);
    assert_eq!(m.interpolation.chord_tolerance_mm, 0.002);
    assert_eq!(m.interpolation.max_feed_mm_min, 12000.0);
    // rapid_feed_mm_min is omitted in the file: it follows max_feed_mm_min.
    assert_eq!(m.interpolation.rapid_feed_mm_min, 12000.0);
}

/// Every point of the paper's example, tilted by A in -75..=75 deg about the A axis 50 mm
/// below the table and turned by C, stays inside the X/Y/Z travels of the trt mill.
#[test]
fn paper_example_tilted_fits_xyzac_trt_machine() {
    let m = parse(XYZAC).unwrap();
    let Kinematics::XyzacTrt { a_axis_point, .. } = m.kinematics else {
        panic!("not xyzac-trt");
    };
    let pivot_z = a_axis_point[2];
    let corners = [-2.0f64, 48.0].into_iter().flat_map(|x| {
        [71.0f64, 164.0]
            .into_iter()
            .flat_map(move |y| [5.0f64, 59.0].map(|z| [x, y, z]))
    });
    for p in corners {
        for a_deg in (-75..=75).step_by(5) {
            for c_deg in (0..360).step_by(15) {
                let (sc, cc) = f64::from(c_deg).to_radians().sin_cos();
                let (x, y) = (cc * p[0] - sc * p[1], sc * p[0] + cc * p[1]);
                let (sa, ca) = f64::from(a_deg).to_radians().sin_cos();
                let (yz, zz) = (
                    ca * y - sa * (p[2] - pivot_z),
                    sa * y + ca * (p[2] - pivot_z),
                );
                let q = [x, yz, zz + pivot_z];
                for (v, axis) in q.iter().zip([&m.axes.x, &m.axes.y, &m.axes.z]) {
                    assert!(
                        axis.min <= *v && *v <= axis.max,
                        "{p:?} A={a_deg} C={c_deg}"
                    );
                }
            }
        }
    }
}

#[test]
fn every_shipped_machine_is_ready_for_real_programs() {
    // A homed position, G54..G59, a tool table and start-up modes: a program that leaves an
    // axis out of its first move, selects G55 or calls G43 H1 runs as it does on LinuxCNC.
    let mut names: Vec<String> = std::fs::read_dir(machines_dir())
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "paper-ac-table.toml",
            "xyz-mill.toml",
            "xyzac-trt-mill.toml",
            "xyzbc-trt-mill.toml"
        ]
    );
    for name in names {
        let m = config::load(&machines_dir().join(&name)).unwrap_or_else(|e| panic!("{e}"));
        let reference = m
            .reference
            .unwrap_or_else(|| panic!("{name}: no reference"));
        let inside = |v: f64, l: &AxisLimits| l.min <= v && v <= l.max;
        assert!(
            inside(reference[0], &m.axes.x)
                && inside(reference[1], &m.axes.y)
                && inside(reference[2], &m.axes.z),
            "{name}: the reference is outside the travel"
        );
        assert!(
            m.work_offsets.iter().all(Option::is_some),
            "{name}: G54..G59"
        );
        assert!(m.program.startup.contains("G21"), "{name}: start-up units");
        assert!(m.program.tools.len() >= 20, "{name}: tool table");
        assert!(m.program.tools.values().all(|t| t.diameter_mm.is_some()));
        // A spindle and coolant, simulated: the paper's machine is on a bus whose load at
        // 2 ms leaves no room for a spindle drive and an I/O module (78 % of 70 %).
        if name != "paper-ac-table.toml" {
            assert!(
                m.spindle.is_some() && m.coolant.is_some(),
                "{name}: spindle, coolant"
            );
        }
    }
}

#[test]
fn defaults_apply_when_keys_are_omitted() {
    let m: Machine = parse(MINIMAL).unwrap();
    assert_eq!(m.period_s, Machine::DEFAULT_PERIOD_MS / 1000.0);
    assert_eq!(m.period_s, 0.002);
    assert_eq!(m.interpolation, Interpolation::default());
    assert_eq!(m.interpolation.method, Method::Arclength);
    assert_eq!(m.interpolation.chord_tolerance_mm, 0.001);
    assert_eq!(m.interpolation.path_acceleration, 1000.0);
    assert_eq!(m.interpolation.path_jerk, 20000.0);
    assert_eq!(m.interpolation.max_feed_mm_min, 10000.0);
    assert_eq!(m.interpolation.rapid_feed_mm_min, 10000.0);
}

#[test]
fn rapid_feed_defaults_to_max_feed_in_a_partial_section() {
    let text = format!("{MINIMAL}\n[interpolation]\nmax_feed_mm_min = 6000\n");
    let m = parse(&text).unwrap();
    assert_eq!(m.interpolation.max_feed_mm_min, 6000.0);
    assert_eq!(m.interpolation.rapid_feed_mm_min, 6000.0);
    assert_eq!(m.interpolation.path_jerk, 20000.0);
}

#[test]
fn integers_are_accepted_for_numbers() {
    let text = set(MINIMAL, "machine", "period_ms", "1");
    let text = set(&text, "axes.x", "velocity", "120");
    let m = parse(&text).unwrap();
    assert_eq!(m.period_s, 0.001);
    assert_eq!(m.axes.x.velocity, 120.0);
}

#[test]
fn xyzbc_trt_uses_the_b_table() {
    let text = set(MINIMAL, "kinematics", "kind", "\"xyzbc-trt\"");
    let text = set(&text, "kinematics", "b_axis_point", "[0, -10.5, -80]");
    let text = set(&text, "kinematics", "c_axis_point", "[0, 0, 0]");
    let text = common::rename_table(&text, "axes.a", "axes.b");
    let m = parse(&text).unwrap();
    assert_eq!(
        m.kinematics,
        Kinematics::XyzbcTrt {
            b_axis_point: [0.0, -10.5, -80.0],
            c_axis_point: [0.0; 3],
        }
    );
    assert_eq!(m.axes.tilt_name, RotaryName::B);
    assert_eq!(m.axes.tilt.min, -90.0);
    assert_eq!(m.axes.all()[3].0, "B");
}

#[test]
fn xyz_is_a_three_axis_mill_whose_rotary_axes_are_locked() {
    let three = MINIMAL
        .split("[axes.a]")
        .next()
        .expect("the linear axes")
        .replace("kind = \"paper\"", "kind = \"xyz\"");
    let m = parse(&three).unwrap();
    assert_eq!(m.kinematics, Kinematics::Xyz);
    assert!(!m.kinematics.has_rotary_axes());
    for l in [&m.axes.tilt, &m.axes.c] {
        assert_eq!((l.min, l.max), (0.0, 0.0));
    }
    // A rotary table on it is refused by name.
    let with_c = format!("{three}\n[axes.c]\nvelocity = 1.0\nacceleration = 1.0\njerk = 1.0\n");
    let (_, shown) = common::fail(&with_c);
    common::assert_mentions(&shown, &["axes.c", "3-axis mill without rotary axes"]);
    // So is a bus: dnurbs's bus machines have five axes.
    let with_bus =
        format!("{three}\n[[bus]]\nname = \"can0\"\ninterface = \"can0\"\nbitrate = 1000000\n");
    let (_, shown) = common::fail(&with_bus);
    common::assert_mentions(&shown, &["kinematics.kind", "simulation only"]);
    // And the other kinds still need their C table.
    let (_, shown) = common::fail(&MINIMAL.replace(
        "[axes.c]\nvelocity = 180.0\nacceleration = 1800.0\njerk = 18000.0\n",
        "",
    ));
    common::assert_mentions(&shown, &["axes.c", "missing"]);
}

#[test]
fn limited_c_table_keeps_its_limits() {
    let text = set(MINIMAL, "axes.c", "min", "-720");
    let text = set(&text, "axes.c", "max", "720");
    let m = parse(&text).unwrap();
    assert_eq!((m.axes.c.min, m.axes.c.max), (-720.0, 720.0));
    assert!(!m.axes.c.is_unlimited());
}

#[test]
fn missing_file_is_a_read_error_naming_the_path() {
    let path = machines_dir().join("no-such-machine.toml");
    let err = config::load(&path).unwrap_err();
    assert!(matches!(err, ConfigError::Read { .. }), "{err:?}");
    common::assert_mentions(&err.to_string(), &["no-such-machine.toml", "cannot read"]);
    assert!(std::error::Error::source(&err).is_some());
}

/// No input may panic: every prefix of both example files, and each file with every line
/// dropped in turn, either loads or returns an error that names the file.
#[test]
fn no_panic_on_truncated_or_mangled_input() {
    for text in [PAPER, XYZAC, MINIMAL] {
        for end in (0..=text.len()).filter(|&i| text.is_char_boundary(i)) {
            check_no_panic(&text[..end]);
        }
        let lines: Vec<&str> = text.lines().collect();
        for skip in 0..lines.len() {
            let mut mangled: Vec<&str> = lines.clone();
            mangled.remove(skip);
            check_no_panic(&mangled.join("\n"));
        }
    }
    for odd in [
        "\u{feff}",
        "\0",
        "[[",
        "é = 1",
        "a.b.c.d = 1",
        "machine = 3",
        "x = 1e999",
    ] {
        check_no_panic(odd);
    }
}

fn check_no_panic(text: &str) {
    if let Err(e) = parse(text) {
        assert!(e.to_string().starts_with(common::ORIGIN), "{e}");
    }
}
