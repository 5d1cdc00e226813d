//! Each request parsed, each bad one refused with its key, value and rule.

use super::*;

const RUN: Request = Request::Run {
    from_line: None,
    clearance: DEFAULT_CLEARANCE_MM,
    confirm: false,
};

fn ok(line: &str) -> Request {
    Request::parse(line)
        .unwrap_or_else(|e| panic!("{line}: {e}"))
        .request
}

fn err(line: &str) -> String {
    Request::parse(line)
        .map(|e| panic!("{line}: accepted as {e:?}"))
        .unwrap_err()
        .to_string()
}

#[test]
fn every_command_parses() {
    assert_eq!(
        Request::parse(r#"{"v":1,"id":7,"cmd":"status"}"#),
        Ok(Envelope {
            id: Some(7),
            request: Request::Status
        })
    );
    for (cmd, want) in [
        ("on", Request::On),
        ("off", Request::Off),
        ("pause", Request::Pause),
        ("resume", Request::Resume),
        ("step", Request::Step),
        ("stop", Request::Stop),
        ("reset", Request::Reset),
        ("estop", Request::Estop),
    ] {
        assert_eq!(ok(&format!(r#"{{"v":1,"cmd":"{cmd}"}}"#)), want);
    }
    assert_eq!(ok(r#"{"v":1,"cmd":"home"}"#), Request::Home(None));
    assert_eq!(
        ok(r#"{"v":1,"cmd":"home","axis":"z"}"#),
        Request::Home(Some(Axis::Z))
    );
    assert_eq!(
        ok(r#"{"v":1,"cmd":"jog","axis":"X","dir":"+","step":10.0,"speed":5}"#),
        Request::Jog {
            axis: Axis::X,
            positive: true,
            step: Some(10.0),
            speed: Some(5.0),
            frame: Frame::Machine,
        }
    );
    assert_eq!(
        ok(r#"{"v":1,"cmd":"jog","axis":"C","dir":"-"}"#),
        Request::Jog {
            axis: Axis::C,
            positive: false,
            step: None,
            speed: None,
            frame: Frame::Machine,
        }
    );
    assert_eq!(
        ok(r#"{"v":1,"cmd":"jog","axis":"Z","dir":"-","frame":"tool","step":2}"#),
        Request::Jog {
            axis: Axis::Z,
            positive: false,
            step: Some(2.0),
            speed: None,
            frame: Frame::Tool,
        }
    );
    for bad in [
        r#"{"v":1,"cmd":"jog","axis":"X","dir":"+","frame":"tool"}"#,
        r#"{"v":1,"cmd":"jog","axis":"A","dir":"+","frame":"work"}"#,
        r#"{"v":1,"cmd":"jog","axis":"X","dir":"+","frame":"table"}"#,
    ] {
        assert!(Request::parse(bad).is_err(), "{bad}");
    }
    assert_eq!(
        ok(r#"{"v":1,"cmd":"mdi","line":" G0 X0 Y0 "}"#),
        Request::Mdi("G0 X0 Y0".into())
    );
    assert_eq!(
        ok(r#"{"v":1,"cmd":"load","file":"/tmp/a.nc"}"#),
        Request::Load("/tmp/a.nc".into())
    );
    assert_eq!(ok(r#"{"v":1,"cmd":"run"}"#), RUN);
    assert_eq!(
        ok(r#"{"v":1,"cmd":"run","from_line":240}"#),
        Request::Run {
            from_line: Some(240),
            clearance: 10.0,
            confirm: false,
        }
    );
    assert_eq!(
        ok(r#"{"v":1,"cmd":"run","from_line":240,"clearance":25,"confirm":true}"#),
        Request::Run {
            from_line: Some(240),
            clearance: 25.0,
            confirm: true,
        }
    );
    for bad in [
        r#"{"v":1,"cmd":"run","confirm":true}"#,
        r#"{"v":1,"cmd":"run","clearance":5}"#,
        r#"{"v":1,"cmd":"run","from_line":3,"clearance":0}"#,
        r#"{"v":1,"cmd":"run","from_line":3,"clearance":1001}"#,
        r#"{"v":1,"cmd":"run","from_line":3,"confirm":"yes"}"#,
    ] {
        assert!(Request::parse(bad).is_err(), "{bad}");
    }
    assert_eq!(
        ok(r#"{"v":1,"cmd":"override","percent":30}"#),
        Request::Override(30)
    );
}

#[test]
fn bad_requests_say_what_and_why() {
    for (line, says) in [
        ("", "not a request"),
        ("[1]", "not a request"),
        (
            r#"{"cmd":"on"}"#,
            "v = missing: must be the protocol version, 1",
        ),
        (
            r#"{"v":2,"cmd":"on"}"#,
            "protocol version 2: this dnurbs speaks version 1",
        ),
        (r#"{"v":"1","cmd":"on"}"#, "v = \"1\""),
        (r#"{"v":1,"id":-1,"cmd":"on"}"#, "id = -1"),
        (r#"{"v":1,"cmd":"jig"}"#, "unknown variant `jig`"),
        (r#"{"v":1}"#, "missing field `cmd`"),
        (r#"{"v":1,"cmd":"on","axis":"X"}"#, "unknown field `axis`"),
        (
            r#"{"v":1,"cmd":"jog","axis":"Q","dir":"+"}"#,
            "axis = \"Q\": must be one of X, Y, Z, A, B, C",
        ),
        (
            r#"{"v":1,"cmd":"jog","axis":"X","dir":"up"}"#,
            "dir = \"up\"",
        ),
        (
            r#"{"v":1,"cmd":"jog","axis":"X","dir":"+","step":-1}"#,
            "step = -1: must be a number more than 0",
        ),
        (
            r#"{"v":1,"cmd":"jog","axis":"X","dir":"+","speed":0}"#,
            "speed = 0",
        ),
        (r#"{"v":1,"cmd":"jog","axis":"X"}"#, "missing field `dir`"),
        (r#"{"v":1,"cmd":"mdi","line":"  "}"#, "must be one NC line"),
        (
            r#"{"v":1,"cmd":"mdi","line":"G0\nX1"}"#,
            "must be one NC line",
        ),
        (r#"{"v":1,"cmd":"load","file":""}"#, "must be a file path"),
        (r#"{"v":1,"cmd":"run","from_line":0}"#, "lines count from 1"),
        (
            r#"{"v":1,"cmd":"override","percent":150}"#,
            "percent = 150: must be a whole number in 0..=100",
        ),
        (
            r#"{"v":1,"cmd":"override","percent":12.5}"#,
            "percent = 12.5",
        ),
    ] {
        let e = err(line);
        assert!(e.contains(says), "{line}: {e:?} does not say {says:?}");
    }
    let long = format!(r#"{{"v":1,"cmd":"mdi","line":"{}"}}"#, "G".repeat(256));
    assert!(err(&long).contains("1..=255 characters"));
    assert_eq!(
        err(&"x".repeat(MAX_LINE + 1)),
        "request longer than 4096 bytes"
    );
}

#[test]
fn replies_are_one_json_line() {
    assert_eq!(
        Reply::ok(Some(7), "jog").line(),
        r#"{"v":1,"id":7,"ok":true,"state":"jog"}"#
    );
    let refused = crate::serve::Controller::new(false)
        .command(crate::serve::Command::Run)
        .unwrap_err();
    assert_eq!(
        Reply::refused(None, refused).line(),
        r#"{"v":1,"ok":false,"error":"run refused in state off: the machine is off: turn it on first"}"#
    );
}

proptest::proptest! {
    /// Any text, and any JSON object with the protocol's keys and junk values: an answer,
    /// never a panic.
    #[test]
    fn no_line_makes_the_parser_panic(
        text in ".{0,200}",
        cmd in proptest::sample::select(vec![
            "status", "on", "off", "home", "jog", "mdi", "load", "run", "pause", "resume",
            "step", "stop", "override", "reset", "estop", "x",
        ]),
        key in proptest::sample::select(vec![
            "axis", "dir", "step", "speed", "line", "file", "from_line", "percent", "id", "v",
        ]),
        value in proptest::sample::select(vec![
            "1", "-1", "0", "1e308", "-0.0", "\"+\"", "\"X\"", "null", "true", "[]", "{}",
            "\"\"", "4294967296", "18446744073709551616", "1.5",
        ]),
    ) {
        let _ = Request::parse(&text);
        let line = format!(r#"{{"v":1,"cmd":"{cmd}","{key}":{value}}}"#);
        let _ = Request::parse(&line);
    }
}
