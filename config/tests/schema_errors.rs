//! Stage-1 errors: TOML syntax, unknown keys, missing keys and wrong value types.
//! Each must name the file, the line:col and the key.

mod common;

use common::{assert_at, assert_mentions, fail, pos_of, remove, rename_table, set, MINIMAL};
use config::{ConfigError, LineCol};

#[test]
fn syntax_error_names_file_and_line_col() {
    let text = set(MINIMAL, "axes.y", "velocity", "= 3");
    let (err, shown) = fail(&text);
    assert!(matches!(err, ConfigError::Syntax { .. }), "{err:?}");
    // The error is at the second `=` of `velocity = = 3`.
    let mut pos = pos_of(&text, "velocity = = 3");
    pos.column += "velocity = ".len();
    assert_at(&shown, pos);
    assert_mentions(&shown, &["TOML syntax error"]);
}

#[test]
fn duplicate_key_is_a_syntax_error() {
    let text = MINIMAL.replacen("jerk = 10000.0", "jerk = 10000.0\njerk = 1.0", 1);
    let (err, shown) = fail(&text);
    assert!(matches!(err, ConfigError::Syntax { .. }), "{err:?}");
    assert_mentions(&shown, &["duplicate key"]);
    assert_at(&shown, pos_of(&text, "jerk = 1.0"));
}

#[test]
fn wrong_type_names_key_and_line_col() {
    let text = set(MINIMAL, "axes.x", "velocity", "\"fast\"");
    let (err, shown) = fail(&text);
    assert!(matches!(err, ConfigError::Schema { .. }), "{err:?}");
    assert_eq!(err.key(), Some("axes.x.velocity"));
    assert_at(&shown, pos_of(&text, "\"fast\""));
    assert_mentions(
        &shown,
        &["axes.x.velocity: invalid type: string \"fast\", expected f64"],
    );
}

#[test]
fn wrong_type_inside_an_array_names_the_element() {
    let text = set(MINIMAL, "kinematics", "kind", "\"xyzac-trt\"");
    let text = set(&text, "kinematics", "a_axis_point", "[0, 0, \"deep\"]");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("kinematics.a_axis_point[2]"), "{shown}");
    assert_at(&shown, pos_of(&text, "\"deep\""));
}

#[test]
fn point_of_wrong_length_is_an_error() {
    let text = set(MINIMAL, "kinematics", "kind", "\"xyzac-trt\"");
    let text = set(&text, "kinematics", "a_axis_point", "[0, 0]");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("kinematics.a_axis_point"), "{shown}");
    assert_mentions(&shown, &["length 2", "length 3"]);
}

#[test]
fn unknown_key_is_an_error_naming_it() {
    let text = set(MINIMAL, "axes.x", "velocty", "100.0");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.x.velocty"));
    assert_at(&shown, pos_of(&text, "velocty"));
    assert_mentions(&shown, &["unknown field `velocty`", "`velocity`"]);
}

#[test]
fn unknown_key_in_every_table_is_an_error() {
    for table in ["machine", "kinematics", "axes.a", "axes.c"] {
        let text = set(MINIMAL, table, "typo", "1");
        let (err, shown) = fail(&text);
        assert_eq!(err.key(), Some(format!("{table}.typo").as_str()), "{shown}");
        assert_mentions(&shown, &[common::ORIGIN, "unknown field `typo`"]);
    }
    let text = format!("{MINIMAL}[interpolation]\nchord_tolerance = 0.01\n");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("interpolation.chord_tolerance"), "{shown}");
    assert_mentions(&shown, &["`chord_tolerance_mm`"]);
}

#[test]
fn unknown_table_is_an_error_naming_it() {
    let text = format!("{MINIMAL}[drive]\nnode = 1\n");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("drive"));
    assert_at(&shown, pos_of(&text, "drive]"));
    assert_mentions(&shown, &["unknown field `drive`", "`interpolation`"]);

    let text = rename_table(MINIMAL, "axes.z", "axes.w");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.w"), "{shown}");
}

#[test]
fn missing_key_names_it_and_its_table() {
    let text = remove(MINIMAL, "axes.z", "jerk");
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes.z"));
    assert_at(&shown, pos_of(&text, "[axes.z]"));
    assert_mentions(&shown, &["missing field `jerk`"]);

    let text = remove(MINIMAL, "machine", "name");
    let (_, shown) = fail(&text);
    assert_mentions(&shown, &["machine: missing field `name`"]);

    let text = remove(MINIMAL, "kinematics", "kind");
    let (_, shown) = fail(&text);
    assert_mentions(&shown, &["kinematics: missing field `kind`"]);
}

#[test]
fn missing_table_is_an_error_naming_it() {
    let text = MINIMAL.replacen("[machine]\nname = \"minimal\"\n", "", 1);
    let (err, shown) = fail(&text);
    // A missing top-level table has no position: the message names the file only.
    assert_eq!(
        shown,
        format!("{}: missing field `machine`", common::ORIGIN)
    );
    assert_eq!(err.location().and_then(|l| l.line_col), None);

    let start = MINIMAL.find("[axes.y]").unwrap();
    let end = MINIMAL.find("[axes.z]").unwrap();
    let text = format!("{}{}", &MINIMAL[..start], &MINIMAL[end..]);
    let (err, shown) = fail(&text);
    assert_eq!(err.key(), Some("axes"), "{shown}");
    assert_mentions(&shown, &["missing field `y`"]);
}

#[test]
fn empty_file_is_an_error() {
    let (_, shown) = fail("");
    assert_mentions(&shown, &[common::ORIGIN, "missing field `machine`"]);
}

#[test]
fn column_counts_characters_not_bytes() {
    // `ä` is two bytes: the stray `x` is at byte column 17 but character column 16.
    let text = set(MINIMAL, "machine", "name", "\"Fräse\" x");
    let (err, shown) = fail(&text);
    let line = pos_of(&text, "Fräse").line;
    assert_eq!(
        err.location().and_then(|l| l.line_col),
        Some(LineCol { line, column: 16 }),
        "{shown}"
    );
}
