//! `ctl`: the client of a control socket. It speaks protocol version 1
//! ([`crate::serve::protocol`]) to `dnurbs serve`; a `dnurbs run` or `demo` answers the
//! commands it has (status, pause, resume, stop, override) in its own protocol
//! ([`crate::control`]), which ctl reads too.

use crate::cli::CtlCommand;
use crate::exit::{InputError, Outcome};
use anyhow::Context;
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::Path;
use std::time::{Duration, Instant};

/// A continuous jog is renewed this often (the controller's dead-man is 200 ms).
const RENEW: Duration = Duration::from_millis(50);

struct Conn {
    reader: BufReader<UnixStream>,
    writer: UnixStream,
    id: u64,
    socket: String,
}

impl Conn {
    fn connect(socket: &Path) -> anyhow::Result<Conn> {
        let s = UnixStream::connect(socket).with_context(|| {
            format!(
                "{}: cannot connect to the control socket (is dnurbs serve, or a run with \
                 --control, going?)",
                socket.display()
            )
        })?;
        // Homing a long axis is answered once it has started; a program once it is planned.
        s.set_read_timeout(Some(Duration::from_secs(60)))?;
        Ok(Conn {
            reader: BufReader::new(s.try_clone()?),
            writer: s,
            id: 0,
            socket: socket.display().to_string(),
        })
    }

    /// Send `cmd` (an object with its arguments); the answer, or `None` once the other
    /// end has closed.
    fn ask(&mut self, mut cmd: Value) -> anyhow::Result<Option<Value>> {
        self.id += 1;
        cmd["v"] = json!(1);
        cmd["id"] = json!(self.id);
        let mut line = serde_json::to_vec(&cmd)?;
        line.push(b'\n');
        if self.writer.write_all(&line).is_err() {
            return Ok(None);
        }
        let mut answer = String::new();
        match self.reader.read_line(&mut answer) {
            Ok(0) => Ok(None),
            Err(e) => Err(anyhow::anyhow!("{}: no answer: {e}", self.socket)),
            Ok(_) => Ok(Some(
                serde_json::from_str(&answer)
                    .context("the controller answered something unreadable")?,
            )),
        }
    }
}

/// What an answer says: the line to print, or the refusal.
fn read(answer: &Value, status: bool) -> Result<String, InputError> {
    let ok = answer["ok"].as_bool().unwrap_or(false);
    if !ok {
        let e = answer["error"]
            .as_str()
            .unwrap_or("refused without a reason");
        return Err(InputError::Usage(e.to_owned()));
    }
    if answer.get("v").is_none() {
        // A run's socket: its own status line.
        let a: crate::control::Answer = serde_json::from_value(answer.clone())
            .map_err(|e| InputError::Usage(format!("unreadable answer: {e}")))?;
        return Ok(a.status.map(|s| s.line()).unwrap_or_default());
    }
    if status {
        return Ok(answer["status"].to_string());
    }
    Ok(answer["state"].as_str().unwrap_or("").to_owned())
}

pub fn ctl(socket: &Path, command: CtlCommand) -> anyhow::Result<Outcome> {
    let mut conn = Conn::connect(socket)?;
    let cmd = match &command {
        CtlCommand::Status { .. } => json!({"cmd": "status"}),
        CtlCommand::Pause => json!({"cmd": "pause"}),
        CtlCommand::Resume => json!({"cmd": "resume"}),
        CtlCommand::Stop => json!({"cmd": "stop"}),
        CtlCommand::Override { percent } => json!({"cmd": "override", "percent": percent}),
        CtlCommand::On => json!({"cmd": "on"}),
        CtlCommand::Off => json!({"cmd": "off"}),
        CtlCommand::Step => json!({"cmd": "step"}),
        CtlCommand::Reset => json!({"cmd": "reset"}),
        CtlCommand::Estop => json!({"cmd": "estop"}),
        CtlCommand::Home { axis } => match axis {
            Some(a) => json!({"cmd": "home", "axis": a}),
            None => json!({"cmd": "home"}),
        },
        CtlCommand::Jog {
            axis,
            dir,
            step,
            speed,
            frame,
            ..
        } => {
            let mut j = json!({"cmd": "jog", "axis": axis, "dir": dir, "frame": frame});
            if let Some(s) = step {
                j["step"] = json!(s);
            }
            if let Some(v) = speed {
                j["speed"] = json!(v);
            }
            j
        }
        CtlCommand::Mdi { line } => json!({"cmd": "mdi", "line": line.join(" ")}),
        CtlCommand::Load { file } => {
            // The controller reads the file: give it the whole path.
            let path = std::fs::canonicalize(file).unwrap_or_else(|_| file.clone());
            json!({"cmd": "load", "file": path.display().to_string()})
        }
        CtlCommand::Run {
            from_line,
            clearance,
            confirm,
        } => {
            let mut j = json!({"cmd": "run"});
            if let Some(n) = from_line {
                j["from_line"] = json!(n);
                j["confirm"] = json!(confirm);
            }
            if let Some(c) = clearance {
                j["clearance"] = json!(c);
            }
            j
        }
    };
    let status = matches!(command, CtlCommand::Status { .. });
    let watch = matches!(command, CtlCommand::Status { watch: true });
    let Some(answer) = conn.ask(cmd.clone())? else {
        anyhow::bail!("{}: the controller closed the connection", socket.display());
    };
    let mut last = read(&answer, status)?;
    println!("{last}");
    if let CtlCommand::Jog {
        step: None,
        hold_ns,
        ..
    } = command
    {
        // Hold the key: renew until the time is up, then let go (stop).
        let until = Instant::now() + Duration::from_nanos(hold_ns);
        while Instant::now() < until {
            std::thread::sleep(RENEW);
            let Some(a) = conn.ask(cmd.clone())? else {
                anyhow::bail!("{}: the controller closed the connection", socket.display());
            };
            read(&a, false)?;
        }
        if let Some(a) = conn.ask(json!({"cmd": "stop"}))? {
            println!("{}", read(&a, false)?);
        }
        return Ok(Outcome::Completed);
    }
    if !watch {
        return Ok(Outcome::Completed);
    }
    loop {
        std::thread::sleep(Duration::from_millis(200));
        let Some(a) = conn.ask(cmd.clone())? else {
            eprintln!("the controller has ended");
            break;
        };
        let line = read(&a, true)?;
        if line != last {
            println!("{line}");
            last = line;
        }
    }
    Ok(Outcome::Completed)
}
