//! Stage-2 errors: one test per validation rule. Each message must name the file, the
//! line:col of the value (or of its table when the key is absent), the key, the value as
//! written, and the allowed range with its unit.

mod common;

use common::{
    assert_at, assert_mentions, fail, parse, pos_of, remove, rename_table, set, MINIMAL, ORIGIN,
};
use config::ConfigError;

/// Sets `table.key = value` in the minimal file, expects an `Invalid` error for that key and
/// checks the whole message: `ORIGIN:line:col: table.key = value: rule`.
#[track_caller]
fn expect_invalid(table: &str, key: &str, value: &str, rule: &str) {
    let text = set(MINIMAL, table, key, value);
    let (err, shown) = fail(&text);
    assert!(matches!(err, ConfigError::Invalid { .. }), "{err:?}");
    let mut pos = pos_of(&text, &format!("{key} = {value}"));
    pos.column += key.len() + 3;
    let expected = format!(
        "{ORIGIN}:{}:{}: {table}.{key} = {value}: {rule}",
        pos.line, pos.column
    );
    assert_eq!(shown, expected);
}

#[test]
fn the_documented_example_message() {
    expect_invalid("axes.x", "velocity", "-3", "must be in 1e-6..=1e9 (mm/s)");
}

#[test]
fn machine_name_must_not_be_empty() {
    expect_invalid("machine", "name", "\"\"", "must be a non-empty string");
    expect_invalid("machine", "name", "\"  \"", "must be a non-empty string");
}

#[test]
fn period_must_be_in_range() {
    let rule = "must be finite and in 0.1..=100 (ms)";
    for bad in ["0.05", "0", "-2.0", "100.5", "nan", "inf"] {
        expect_invalid("machine", "period_ms", bad, rule);
    }
    for good in ["0.1", "100"] {
        common::parse(&set(MINIMAL, "machine", "period_ms", good)).unwrap();
    }
}

#[test]
fn unknown_kinematics_kind_lists_the_three_kinds() {
    expect_invalid(
        "kinematics",
        "kind",
        "\"xyzac\"",
        "must be one of \"paper\", \"xyzac-trt\", \"xyzbc-trt\", \"xyz\"",
    );
}

#[test]
fn trt_kinds_require_their_points() {
    let text = set(MINIMAL, "kinematics", "kind", "\"xyzac-trt\"");
    let text = set(&text, "kinematics", "c_axis_point", "[0, 0, 0]");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("kinematics.a_axis_point"));
    // An absent key points at its table.
    assert_at(&shown, pos_of(&text, "kinematics]"));
    assert_mentions(
        &shown,
        &["missing", "xyzac-trt", "A axis", "(mm, machine frame)"],
    );

    let text = set(MINIMAL, "kinematics", "kind", "\"xyzbc-trt\"");
    let text = set(&text, "kinematics", "b_axis_point", "[0, 0, 0]");
    let text = rename_table(&text, "axes.a", "axes.b");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("kinematics.c_axis_point"));
    assert_mentions(&shown, &["missing", "xyzbc-trt", "C (at B = 0) axis"]);
}

#[test]
fn kinematics_points_must_be_finite() {
    let text = set(MINIMAL, "kinematics", "kind", "\"xyzac-trt\"");
    let text = set(&text, "kinematics", "a_axis_point", "[0, 0, -50]");
    let text = set(&text, "kinematics", "c_axis_point", "[0, nan, 0]");
    let (err, shown) = fail(&text);
    assert!(matches!(err, ConfigError::Invalid { .. }), "{err:?}");
    assert_at(&shown, pos_of(&text, "[0, nan, 0]"));
    assert_mentions(
        &shown,
        &["kinematics.c_axis_point = [0, nan, 0]: must be [x, y, z] with coordinates in -1e6..=1e6 (mm"],
    );
}

#[test]
fn points_not_taken_by_the_kind_are_errors() {
    let text = set(MINIMAL, "kinematics", "a_axis_point", "[0, 0, -50]");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("kinematics.a_axis_point"));
    assert_mentions(
        &shown,
        &["not a key of kind \"paper\", which takes no points"],
    );

    let text = set(MINIMAL, "kinematics", "kind", "\"xyzac-trt\"");
    let text = set(&text, "kinematics", "a_axis_point", "[0, 0, -50]");
    let text = set(&text, "kinematics", "c_axis_point", "[0, 0, 0]");
    let text = set(&text, "kinematics", "b_axis_point", "[0, 0, 0]");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("kinematics.b_axis_point"));
    assert_mentions(&shown, &["takes a_axis_point and c_axis_point"]);
}

#[test]
fn rates_must_be_finite_and_positive_with_units() {
    expect_invalid(
        "axes.y",
        "acceleration",
        "0",
        "must be in 1e-6..=1e9 (mm/s^2)",
    );
    expect_invalid("axes.z", "jerk", "inf", "must be in 1e-6..=1e9 (mm/s^3)");
    expect_invalid("axes.a", "velocity", "-90", "must be in 1e-6..=1e9 (deg/s)");
    expect_invalid(
        "axes.c",
        "acceleration",
        "nan",
        "must be in 1e-6..=1e9 (deg/s^2)",
    );
    expect_invalid("axes.c", "jerk", "-inf", "must be in 1e-6..=1e9 (deg/s^3)");
}

#[test]
fn travel_limits_must_be_finite() {
    expect_invalid("axes.x", "min", "-inf", "must be in -1e6..=1e6 (mm)");
    expect_invalid("axes.a", "max", "nan", "must be in -1e6..=1e6 (deg)");
}

#[test]
fn min_must_be_below_max() {
    expect_invalid(
        "axes.y",
        "max",
        "-100.0",
        "must be > axes.y.min = -100.0 (mm)",
    );
    expect_invalid("axes.a", "max", "-95", "must be > axes.a.min = -90.0 (deg)");
}

#[test]
fn linear_and_tilt_axes_need_both_limits() {
    let text = remove(MINIMAL, "axes.x", "min");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.x.min"));
    assert_at(&shown, pos_of(&text, "x]"));
    assert_mentions(
        &shown,
        &["missing", "needs min and max (mm)", "only C may omit both"],
    );

    let text = remove(&remove(MINIMAL, "axes.a", "min"), "axes.a", "max");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.a.min"));
    assert_mentions(&shown, &["needs min and max (deg)"]);
}

#[test]
fn c_axis_needs_both_limits_or_neither() {
    let text = set(MINIMAL, "axes.c", "min", "-720");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.c.max"));
    assert_at(&shown, pos_of(&text, "c]"));
    assert_mentions(
        &shown,
        &[
            "missing while axes.c.min is given",
            "(deg)",
            "omit both for unlimited rotation",
        ],
    );
}

#[test]
fn wrong_tilt_key_for_the_kind_names_the_expected_one() {
    let text = rename_table(MINIMAL, "axes.a", "axes.b");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.b"));
    assert_at(&shown, pos_of(&text, "b]"));
    assert_mentions(
        &shown,
        &["kind \"paper\" has no B axis", "configured as [axes.a]"],
    );

    let text = set(MINIMAL, "kinematics", "kind", "\"xyzbc-trt\"");
    let text = set(&text, "kinematics", "b_axis_point", "[0, 0, -50]");
    let text = set(&text, "kinematics", "c_axis_point", "[0, 0, 0]");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.a"));
    assert_mentions(
        &shown,
        &["kind \"xyzbc-trt\" has no A axis", "configured as [axes.b]"],
    );
}

#[test]
fn missing_tilt_table_names_the_expected_one() {
    let start = MINIMAL.find("[axes.a]").unwrap();
    let end = MINIMAL.find("[axes.c]").unwrap();
    let text = format!("{}{}", &MINIMAL[..start], &MINIMAL[end..]);
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.a"));
    assert_mentions(
        &shown,
        &[ORIGIN, "missing", "needs [axes.a]", "tilting A axis (deg"],
    );
}

fn with_interpolation(key: &str, value: &str) -> String {
    format!("{MINIMAL}\n[interpolation]\n{key} = {value}\n")
}

#[test]
fn unknown_method_lists_the_methods() {
    let text = with_interpolation("method", "\"taylor3\"");
    let (_, shown) = fail(&text);
    assert_at(&shown, pos_of(&text, "\"taylor3\""));
    assert_mentions(
        &shown,
        &["interpolation.method = \"taylor3\": must be one of \"arclength\", \"taylor1\", \"taylor2\""],
    );
    for name in ["arclength", "taylor1", "taylor2"] {
        let m = common::parse(&with_interpolation("method", &format!("\"{name}\""))).unwrap();
        assert_eq!(m.interpolation.method.to_string(), name);
    }
}

#[test]
fn chord_tolerance_must_be_in_range() {
    for bad in ["0", "-0.001", "1.5", "nan"] {
        let text = with_interpolation("chord_tolerance_mm", bad);
        let (_, shown) = fail(&text);
        let mut pos = pos_of(&text, &format!("= {bad}\n"));
        pos.column += 2;
        assert_at(&shown, pos);
        assert_mentions(
            &shown,
            &[&format!(
                "interpolation.chord_tolerance_mm = {bad}: must be finite and in (0, 1] (mm)"
            )],
        );
    }
    let m = common::parse(&with_interpolation("chord_tolerance_mm", "1")).unwrap();
    assert_eq!(m.interpolation.chord_tolerance_mm, 1.0);
}

#[test]
fn path_limits_and_feeds_must_be_positive() {
    for (key, unit) in [
        ("path_acceleration", "mm/s^2"),
        ("path_jerk", "mm/s^3"),
        ("max_feed_mm_min", "mm/min"),
        ("rapid_feed_mm_min", "mm/min"),
    ] {
        let text = with_interpolation(key, "-1");
        let (err, shown) = fail(&text);
        assert_eq!(err.key(), Some(format!("interpolation.{key}").as_str()));
        assert_mentions(
            &shown,
            &[&format!("{key} = -1: must be in 1e-6..=1e9 ({unit})")],
        );
    }
}

/// The minimal file with one bus and a drive on every axis (nodes 1..=5).
fn with_drives(period_ms: &str, bitrate: &str) -> String {
    let mut text = MINIMAL.replace(
        "name = \"minimal\"",
        &format!("name = \"minimal\"\nperiod_ms = {period_ms}"),
    );
    text.push_str(&format!(
        "\n[[bus]]\nname = \"can0\"\ninterface = \"vcan0\"\nbitrate = {bitrate}\n"
    ));
    for (i, ax) in ["x", "y", "z", "a", "c"].iter().enumerate() {
        text.push_str(&format!(
            "\n[axes.{ax}.drive]\nbus = \"can0\"\nnode = {}\ncounts_per_unit = 1000.0\n",
            i + 1
        ));
    }
    text
}

#[test]
fn drives_load_and_convert_counts() {
    let m = common::parse(&with_drives("2.0", "1000000")).unwrap();
    assert_eq!(m.buses.len(), 1);
    assert_eq!(m.buses[0].interface, "vcan0");
    assert_eq!(m.drives.len(), 5);
    assert_eq!(
        m.drives.iter().map(|d| d.node).collect::<Vec<_>>(),
        [1, 2, 3, 4, 5]
    );
    assert_eq!(m.drives[3].axis, 3);
    assert_eq!(m.drives[0].counts(1.5), Some(1500));
    // The example machine carries drives too, within its bus load.
    let p = common::parse(common::PAPER).unwrap();
    assert_eq!(p.drives.len(), 5);
    assert!(
        config::bus::load(config::bus::drives(5), p.buses[0].bitrate, p.period_s)
            <= p.buses[0].max_load
    );
}

/// Each drive's own guard: by default a following error of the distance its axis covers
/// at its velocity limit in 20 ms, 10 ms, the quick-stop ramp on a quick stop and on a
/// fault; each key checked with its range.
#[test]
fn a_drive_guards_its_following_error_and_stop_reactions() {
    let m = common::parse(&with_drives("2.0", "1000000")).unwrap();
    let x = &m.drives[0];
    let want = m.axes.x.velocity * 0.02;
    assert_eq!(x.guard.following_error, Some(want));
    assert_eq!(
        (
            x.guard.following_error_timeout_ms,
            x.guard.quick_stop_option,
            x.guard.fault_reaction_option
        ),
        (10, 2, 2)
    );
    let text = set(
        &with_drives("2.0", "1000000"),
        "axes.x.drive",
        "following_error",
        "0.5",
    );
    let text = set(&text, "axes.x.drive", "following_error_timeout_ms", "25");
    let text = set(&text, "axes.x.drive", "quick_stop_option", "6");
    let m = common::parse(&text).unwrap();
    let g = m.drives[0].guard;
    assert_eq!(
        (
            g.following_error,
            g.following_error_timeout_ms,
            g.quick_stop_option
        ),
        (Some(0.5), 25, 6)
    );
    for (key, value, rule) in [
        ("following_error", "0", "at least one count"),
        ("following_error", "0.0001", "at least one count"),
        ("following_error_timeout_ms", "70000", "0..=65535 ms"),
        ("quick_stop_option", "9", "CiA-402 option code 0..=8"),
        ("fault_reaction_option", "-1", "CiA-402 option code 0..=8"),
    ] {
        let (_, shown) = fail(&set(
            &with_drives("2.0", "1000000"),
            "axes.x.drive",
            key,
            value,
        ));
        assert_mentions(&shown, &[&format!("axes.x.drive.{key} = {value}"), rule]);
    }
}

#[test]
fn bus_load_over_the_maximum_says_by_how_much() {
    // 5 drives at 1 ms on 1 Mbit/s: 1205 bits = 120.5 % against the default 70 %. The file
    // is valid (simulate uses no bus); where the bus is used, the check refuses it.
    let m = common::parse(&with_drives("1.0", "1000000")).unwrap();
    let shown = m.check_bus_load().unwrap_err();
    assert_mentions(
        shown,
        &[
            ORIGIN,
            "bus.0.max_load",
            "1205 bits",
            "120.5 %",
            "70.0 %",
            "by 50.5 points",
        ],
    );
    let ok = common::parse(&with_drives("2.0", "1000000")).unwrap();
    assert_eq!(ok.check_bus_load(), Ok(()));
}

#[test]
fn drive_rules() {
    let base = with_drives("2.0", "1000000");
    let cases = [
        (
            base.replacen("node = 2", "node = 1", 1),
            "axes.y.drive.node",
            "unique",
        ),
        (
            base.replacen("node = 3", "node = 128", 1),
            "axes.z.drive.node",
            "1..=127",
        ),
        (
            base.replacen("bus = \"can0\"\nnode = 1", "bus = \"can9\"\nnode = 1", 1),
            "axes.x.drive.bus",
            "\"can0\"",
        ),
        (
            base.replacen("counts_per_unit = 1000.0", "counts_per_unit = -5.0", 1),
            "axes.x.drive.counts_per_unit",
            "1e-6..=1e9",
        ),
        (
            base.replacen("counts_per_unit = 1000.0", "counts_per_unit = 1e8", 1),
            "axes.x.drive.counts_per_unit",
            "32-bit",
        ),
        (
            base.replacen("node = 1\n", "node = 1\nsign = 2\n", 1),
            "axes.x.drive.sign",
            "1 or -1",
        ),
        (
            base.replace("bitrate = 1000000", "bitrate = 5000000"),
            "bus.0.bitrate",
            "10000..=1000000",
        ),
        (
            base.replace(
                "interface = \"vcan0\"",
                "interface = \"a-name-much-too-long\"",
            ),
            "bus.0.interface",
            "15 bytes",
        ),
        (
            base.replacen(
                "\n[axes.c.drive]\nbus = \"can0\"\nnode = 5\ncounts_per_unit = 1000.0\n",
                "",
                1,
            ),
            "axes.c",
            "drive on every axis",
        ),
    ];
    for (text, key, words) in cases {
        let (_, shown) = fail(&text);
        assert_mentions(&shown, &[ORIGIN, key, words]);
    }
}

#[test]
fn two_buses_split_the_load() {
    // Five drives at 1 ms overload one 1 Mbit/s bus (120.5 %). Split 3 + 2 over two buses
    // they fit under a max_load of 80 %: 55 + 6 * 115 = 745 bits (74.5 %) and
    // 55 + 4 * 115 = 515 bits (51.5 %).
    let mut text = with_drives("1.0", "1000000");
    text.push_str("\n[[bus]]\nname = \"can1\"\ninterface = \"can1\"\nmax_load = 0.8\n");
    let text = text
        .replacen("bus = \"can0\"\nnode = 4", "bus = \"can1\"\nnode = 4", 1)
        .replacen("bus = \"can0\"\nnode = 5", "bus = \"can1\"\nnode = 5", 1)
        .replace("bitrate = 1000000\n", "bitrate = 1000000\nmax_load = 0.8\n");
    let m = common::parse(&text).unwrap();
    assert_eq!(m.check_bus_load(), Ok(()));
    assert_eq!(m.buses.len(), 2);
    let on = |b: usize| m.drives.iter().filter(|d| d.bus == b).count() as u32;
    assert_eq!((on(0), on(1)), (3, 2));
    assert_eq!(config::bus::cycle_bits(config::bus::drives(3)), 745);
    assert!(
        (config::bus::load(config::bus::drives(3), 1_000_000, m.period_s) - 0.745).abs() < 1e-12
    );
    assert!(
        (config::bus::load(config::bus::drives(2), 1_000_000, m.period_s) - 0.515).abs() < 1e-12
    );
}

#[test]
fn realtime_settings_have_ranges_and_defaults() {
    let with = |key: &str, value: &str| {
        let text = format!("{MINIMAL}\n[realtime]\n{key} = {value}\n");
        let (err, shown) = fail(&text);
        assert!(matches!(err, ConfigError::Invalid { .. }), "{err:?}");
        let pos = pos_of(&text, &format!("{key} = {value}"));
        assert!(
            shown.starts_with(&format!(
                "{ORIGIN}:{}:{}: realtime.{key} = {value}: ",
                pos.line,
                pos.column + key.len() + 3
            )),
            "{shown}"
        );
        shown
    };
    assert!(with("priority", "0").ends_with("must be an integer in 1..=99 (SCHED_FIFO priority)"));
    assert!(with("priority", "100").contains("1..=99"));
    assert!(with("queue_depth", "0").contains("2..=1024 (segments"));
    // One segment alive would deadlock a hold: the interpolator waits at its end for the
    // next, which the planner cannot push until that one is handed back.
    assert!(with("queue_depth", "1").contains("2..=1024 (segments; the interpolator keeps one"));
    let two = parse(&format!("{MINIMAL}\n[realtime]\nqueue_depth = 2\n")).unwrap();
    assert_eq!(two.realtime.queue_depth, 2);
    assert!(with("queue_depth", "5000").contains("2..=1024"));
    assert!(with("cpu", "-1").contains("CPU number"));
    // Supervision shorter than two periods (2 ms here) would fault on the first late frame.
    assert!(with("heartbeat_timeout_ms", "3").contains("must be in 4..=600000 (ms)"));
    assert!(with("feedback_timeout_ms", "nan").contains("(ms)"));
    // The lead is at most half the period (2 ms here), never negative.
    assert!(with("lead_us", "1001").ends_with("must be in 0..=1000 (µs, at most half the period)"));
    assert!(with("lead_us", "-1").contains("0..=1000"));
    let text = format!("{MINIMAL}\n[realtime]\nlead_us = 60\n");
    let m = config::from_str(&text, std::path::Path::new(ORIGIN)).unwrap();
    assert!((m.realtime.lead_s - 60e-6).abs() < 1e-15);
    let m = config::from_str(MINIMAL, std::path::Path::new(ORIGIN)).unwrap();
    assert_eq!(m.realtime, config::Realtime::default());
    let text = format!("{MINIMAL}\n[realtime]\npriority = 42\ncpu = 1\nqueue_depth = 8\n");
    let m = config::from_str(&text, std::path::Path::new(ORIGIN)).unwrap();
    assert_eq!(
        (m.realtime.priority, m.realtime.cpu, m.realtime.queue_depth),
        (42, Some(1), 8)
    );
    assert!(!m.realtime.idle_poll);
    // Polling is for the real-time thread's own CPU: without one it is refused, not ignored.
    assert!(with("idle_poll", "true").contains("needs `cpu`"));
    let text = format!("{MINIMAL}\n[realtime]\ncpu = 1\nidle_poll = true\n");
    let m = config::from_str(&text, std::path::Path::new(ORIGIN)).unwrap();
    assert_eq!((m.realtime.cpu, m.realtime.idle_poll), (Some(1), true));
    let unknown = format!("{MINIMAL}\n[realtime]\nprio = 42\n");
    assert!(fail(&unknown).1.contains("prio"));
}

#[test]
fn values_outside_the_documented_domain_are_refused() {
    // Measured: velocity 1e-300 and a pivot at 1e308 ran simulate for minutes and gigabytes.
    expect_invalid(
        "axes.x",
        "velocity",
        "1e-300",
        "must be in 1e-6..=1e9 (mm/s)",
    );
    expect_invalid(
        "axes.y",
        "acceleration",
        "1e300",
        "must be in 1e-6..=1e9 (mm/s^2)",
    );
    expect_invalid("axes.x", "max", "1e308", "must be in -1e6..=1e6 (mm)");
    let text = set(MINIMAL, "kinematics", "kind", "\"xyzac-trt\"");
    let text = set(&text, "kinematics", "a_axis_point", "[0, 0, 1e308]");
    let text = set(&text, "kinematics", "c_axis_point", "[0, 0, 0]");
    let (_, shown) = fail(&text);
    assert_mentions(
        &shown,
        &["kinematics.a_axis_point", "-1e6..=1e6 (mm, machine frame)"],
    );
}

#[test]
fn two_buses_on_one_interface_are_refused() {
    // Measured: 74.5 % + 51.5 % of one wire passed the load check bus by bus.
    let mut text = with_drives("2.0", "1000000");
    text.push_str("\n[[bus]]\nname = \"other\"\ninterface = \"vcan0\"\n");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("bus.1.interface"), "{shown}");
    assert_mentions(&shown, &["\"vcan0\"", "bus 0 (\"can0\") is already on it"]);
}

#[test]
fn compression_tolerances_must_be_in_range() {
    for (key, bad, rule) in [
        ("compress_tol_mm", "0", "0.00001..=1"),
        ("compress_tol_mm", "2", "0.00001..=1"),
        ("compress_tol_deg", "nan", "0.0001..=5"),
        ("compress_corner_deg", "-1", "0..=180"),
    ] {
        let text = with_interpolation(key, bad);
        let (_, shown) = fail(&text);
        assert_mentions(&shown, &[&format!("interpolation.{key} = {bad}")]);
        assert_mentions(&shown, &[rule]);
    }
    let m = common::parse(&with_interpolation("compress", "true")).unwrap();
    assert!(m.interpolation.compress);
    assert_eq!(m.interpolation.compression, config::Compress::DEFAULT);
    let m = common::parse(&with_interpolation("compress_tol_mm", "0.005")).unwrap();
    assert!(!m.interpolation.compress);
    assert_eq!(m.interpolation.compression.tol_mm, 0.005);
}
