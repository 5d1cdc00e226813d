//! The control protocol of `dnurbs serve`, version 1: JSON lines on the Unix socket. A client
//! sends one request object a line; the controller answers each with one reply line, and
//! sends event lines (state changes, faults) to every watcher.
//!
//! ```text
//! {"v":1,"id":7,"cmd":"jog","axis":"X","dir":"+","step":10.0,"speed":5.0}
//! {"v":1,"id":7,"ok":true,"state":"jog"}
//! {"v":1,"id":8,"cmd":"run"}
//! {"v":1,"id":8,"ok":false,"error":"run refused in state on: not every axis is homed: home first"}
//! ```
//!
//! Every request is validated before anything is done: the version, the command, each
//! argument's type and range, no unknown keys; a request that fails is answered with the
//! reason and changes nothing. [`Request::parse`] does that; [`Reply`] writes the answers.

use serde::{Deserialize, Serialize};

/// The protocol's version.
pub const VERSION: u32 = 1;
/// Longest request line, bytes (an MDI line is at most [`MAX_MDI`]).
pub const MAX_LINE: usize = 4096;
/// Longest MDI line, characters (LinuxCNC's is 255).
pub const MAX_MDI: usize = 255;
/// A restart's approach backs off and stands this far above the restart pose, mm.
pub const DEFAULT_CLEARANCE_MM: f64 = 10.0;

/// A request's command and arguments as they arrive (`v` and `id` taken off first). The
/// commands without arguments are struct variants so that extra keys are refused too.
#[derive(Debug, Deserialize)]
#[serde(tag = "cmd", rename_all = "kebab-case", deny_unknown_fields)]
enum RawCmd {
    Status {},
    On {},
    Off {},
    Home {
        #[serde(default)]
        axis: Option<String>,
    },
    Jog {
        axis: String,
        dir: String,
        #[serde(default)]
        step: Option<f64>,
        #[serde(default)]
        speed: Option<f64>,
        #[serde(default)]
        frame: Option<String>,
    },
    Mdi {
        line: String,
    },
    Load {
        file: String,
    },
    Run {
        #[serde(default)]
        from_line: Option<u32>,
        #[serde(default)]
        clearance: Option<f64>,
        #[serde(default)]
        confirm: Option<bool>,
    },
    Pause {},
    Resume {},
    Step {},
    Stop {},
    Override {
        percent: f64,
    },
    Reset {},
    Estop {},
}

/// An axis by its letter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
    Z,
    A,
    B,
    C,
}

/// What a jog moves along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Frame {
    /// The machine's axis itself (a joint).
    Machine,
    /// The workpiece's X, Y or Z at the table's angles: X Y Z move together, the rotary
    /// axes still.
    Work,
    /// The tool axis (the axis named must be Z): X Y Z move together, the rotary axes
    /// still, the tool centre point held on the line.
    Tool,
}

/// A validated request.
#[derive(Clone, Debug, PartialEq)]
pub enum Request {
    Status,
    On,
    Off,
    /// One axis, or every axis in the machine file's sequence.
    Home(Option<Axis>),
    /// `step`: an incremental jog of that distance; none: continuous (a dead-man, renewed
    /// by sending the same request again). `speed`: axis units/s; none: the axis's jog
    /// default.
    Jog {
        axis: Axis,
        positive: bool,
        step: Option<f64>,
        speed: Option<f64>,
        frame: Frame,
    },
    Mdi(String),
    Load(String),
    /// `from_line`: restart there, the approach `clearance` mm (default
    /// [`DEFAULT_CLEARANCE_MM`]) along the tool axis; the approach must be `confirm`ed
    /// (without, the answer says what it would do and nothing moves).
    Run {
        from_line: Option<u32>,
        clearance: f64,
        confirm: bool,
    },
    Pause,
    Resume,
    Step,
    Stop,
    Override(u8),
    Reset,
    Estop,
}

/// A request with its id.
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    pub id: Option<u64>,
    pub request: Request,
}

/// Why a request line is refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BadRequest {
    #[error("request longer than {MAX_LINE} bytes")]
    TooLong,
    #[error("not a request: {0}")]
    Json(String),
    #[error("protocol version {0}: this dnurbs speaks version {VERSION}")]
    Version(u32),
    #[error("{key} = {value}: {rule}")]
    Value {
        key: &'static str,
        value: String,
        rule: &'static str,
    },
}

impl Request {
    /// Parse and validate one request line.
    pub fn parse(line: &str) -> Result<Envelope, BadRequest> {
        if line.len() > MAX_LINE {
            return Err(BadRequest::TooLong);
        }
        let json = |e: serde_json::Error| BadRequest::Json(e.to_string());
        let mut obj: serde_json::Map<String, serde_json::Value> =
            serde_json::from_str(line).map_err(json)?;
        let bad = |key, value: String, rule| BadRequest::Value { key, value, rule };
        match obj.remove("v") {
            Some(serde_json::Value::Number(n)) if n.as_u64() == Some(u64::from(VERSION)) => {}
            Some(serde_json::Value::Number(n)) => {
                return Err(BadRequest::Version(
                    n.as_u64()
                        .and_then(|v| u32::try_from(v).ok())
                        .unwrap_or(u32::MAX),
                ))
            }
            other => {
                return Err(bad(
                    "v",
                    other.map_or("missing".into(), |v| v.to_string()),
                    "must be the protocol version, 1",
                ))
            }
        }
        let id = match obj.remove("id") {
            None => None,
            Some(serde_json::Value::Number(n)) if n.as_u64().is_some() => n.as_u64(),
            Some(other) => {
                return Err(bad(
                    "id",
                    other.to_string(),
                    "must be a whole number 0..=2^64-1",
                ))
            }
        };
        let cmd: RawCmd = serde_json::from_value(serde_json::Value::Object(obj)).map_err(json)?;
        let request = match cmd {
            RawCmd::Status {} => Request::Status,
            RawCmd::On {} => Request::On,
            RawCmd::Off {} => Request::Off,
            RawCmd::Home { axis } => Request::Home(axis.map(|a| axis_of(&a)).transpose()?),
            RawCmd::Jog {
                axis,
                dir,
                step,
                speed,
                frame,
            } => {
                let frame = match frame.as_deref() {
                    None | Some("machine") => Frame::Machine,
                    Some("work") => Frame::Work,
                    Some("tool") => Frame::Tool,
                    Some(other) => {
                        return Err(bad(
                            "frame",
                            format!("{other:?}"),
                            "must be \"machine\", \"work\" or \"tool\"",
                        ))
                    }
                };
                let positive = match dir.as_str() {
                    "+" => true,
                    "-" => false,
                    _ => return Err(bad("dir", format!("{dir:?}"), "must be \"+\" or \"-\"")),
                };
                for (key, v) in [("step", step), ("speed", speed)] {
                    if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
                        return Err(bad(key, v.to_string(), "must be a number more than 0"));
                    }
                }
                let axis = axis_of(&axis)?;
                let linear = matches!(axis, Axis::X | Axis::Y | Axis::Z);
                if (frame == Frame::Work && !linear) || (frame == Frame::Tool && axis != Axis::Z) {
                    return Err(bad(
                        "frame",
                        format!("{frame:?} with axis {axis:?}"),
                        "work jogs X, Y or Z; tool jogs Z (the tool axis)",
                    ));
                }
                Request::Jog {
                    axis,
                    positive,
                    step,
                    speed,
                    frame,
                }
            }
            RawCmd::Mdi { line } => {
                let trimmed = line.trim();
                if trimmed.is_empty()
                    || line.chars().count() > MAX_MDI
                    || line.contains(['\n', '\r'])
                {
                    return Err(bad(
                        "line",
                        format!("{line:?}"),
                        "must be one NC line of 1..=255 characters",
                    ));
                }
                Request::Mdi(trimmed.to_owned())
            }
            RawCmd::Load { file } => {
                if file.is_empty() || file.contains('\0') {
                    return Err(bad("file", format!("{file:?}"), "must be a file path"));
                }
                Request::Load(file)
            }
            RawCmd::Run {
                from_line,
                clearance,
                confirm,
            } => {
                if from_line == Some(0) {
                    return Err(bad("from_line", "0".into(), "lines count from 1"));
                }
                if from_line.is_none() && (clearance.is_some() || confirm.is_some()) {
                    let key = if clearance.is_some() {
                        "clearance"
                    } else {
                        "confirm"
                    };
                    return Err(bad(key, "given".into(), "only with from_line"));
                }
                let clearance = clearance.unwrap_or(DEFAULT_CLEARANCE_MM);
                if !(clearance > 0.0 && clearance <= nc_lang::restart::MAX_CLEARANCE_MM) {
                    return Err(bad(
                        "clearance",
                        clearance.to_string(),
                        "must be more than 0 and at most 1000 (mm)",
                    ));
                }
                Request::Run {
                    from_line,
                    clearance,
                    confirm: confirm.unwrap_or(false),
                }
            }
            RawCmd::Pause {} => Request::Pause,
            RawCmd::Resume {} => Request::Resume,
            RawCmd::Step {} => Request::Step,
            RawCmd::Stop {} => Request::Stop,
            RawCmd::Override { percent } => {
                if !(0.0..=100.0).contains(&percent) || percent.fract() != 0.0 {
                    return Err(bad(
                        "percent",
                        percent.to_string(),
                        "must be a whole number in 0..=100 (of the planned feed)",
                    ));
                }
                Request::Override(percent as u8)
            }
            RawCmd::Reset {} => Request::Reset,
            RawCmd::Estop {} => Request::Estop,
        };
        Ok(Envelope { id, request })
    }
}

fn axis_of(name: &str) -> Result<Axis, BadRequest> {
    Ok(match name {
        "X" | "x" => Axis::X,
        "Y" | "y" => Axis::Y,
        "Z" | "z" => Axis::Z,
        "A" | "a" => Axis::A,
        "B" | "b" => Axis::B,
        "C" | "c" => Axis::C,
        _ => {
            return Err(BadRequest::Value {
                key: "axis",
                value: format!("{name:?}"),
                rule: "must be one of X, Y, Z, A, B, C",
            })
        }
    })
}

/// One reply line.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reply {
    pub v: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub id: Option<u64>,
    pub ok: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The status, in the answer to `status`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub status: Option<serde_json::Value>,
}

impl Reply {
    pub fn ok(id: Option<u64>, state: &'static str) -> Self {
        Reply {
            v: VERSION,
            id,
            ok: true,
            state: Some(state),
            error: None,
            status: None,
        }
    }

    /// The answer with the status.
    pub fn with_status(mut self, status: serde_json::Value) -> Self {
        self.status = Some(status);
        self
    }

    pub fn refused(id: Option<u64>, error: impl ToString) -> Self {
        Reply {
            v: VERSION,
            id,
            ok: false,
            state: None,
            error: Some(error.to_string()),
            status: None,
        }
    }

    /// The line to send (no newline).
    pub fn line(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|_| {
            format!("{{\"v\":{VERSION},\"ok\":false,\"error\":\"reply not encodable\"}}")
        })
    }
}

#[cfg(test)]
mod tests;
