//! The operator's control socket: `dnurbs run --control PATH` (or `[control] socket`)
//! serves it, `dnurbs ctl PATH ...` is its client.
//!
//! A Unix stream socket, mode 0660 (the owner and the group may operate the machine),
//! carrying newline-delimited JSON, one request per line and one answer per request:
//!
//! ```text
//! {"cmd":"status"}                     -> {"ok":true,"status":{...}}
//! {"cmd":"pause"} / {"cmd":"resume"} / {"cmd":"stop"}
//! {"cmd":"override","percent":50}      -> {"ok":true,"status":{...}}
//! {"cmd":"override","percent":120}     -> {"ok":false,"error":"..."}
//! ```
//!
//! The server runs in a thread of its own and hands commands to the real-time thread
//! through the lock-free queue of [`rt_loop::control`]; it reads the status the loop
//! publishes there. It serves any number of clients at once (a `status --watch` does not
//! block a `stop`) and ends with the run, removing the socket file.

use anyhow::Context;
use rt_loop::control::{Command, Producer, Progress, Snapshot};
use serde::{Deserialize, Serialize};
use std::io::{BufRead, BufReader, ErrorKind, Read, Write};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// A request line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(tag = "cmd", rename_all = "lowercase")]
pub enum Request {
    Status,
    Pause,
    Resume,
    Stop,
    Override { percent: u32 },
}

/// The status in an answer.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
pub struct Status {
    pub stage: String,
    pub paused: bool,
    /// The line of the operator stop (`M00`, `M01`, `M06`) the path waits at: resume
    /// goes on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub awaiting_operator: Option<u32>,
    /// Source line and block (N number, or index) being machined.
    pub line: u32,
    pub block: u32,
    /// Axis names in joint order, and their commanded positions (mm, degrees).
    pub axis_names: Vec<String>,
    pub axes: Vec<f64>,
    pub feed_mm_min: f64,
    pub override_pct: u8,
    pub cycles: u64,
    pub overruns: u64,
    pub feed_holds: u64,
    /// Fraction of the program's segments done.
    pub progress: f64,
}

/// An answer line.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
pub struct Answer {
    pub ok: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub status: Option<Status>,
}

impl Status {
    fn of(s: &Snapshot, names: &[String]) -> Status {
        Status {
            stage: s.stage.to_owned(),
            paused: s.paused,
            awaiting_operator: s.awaiting,
            line: s.line,
            block: s.block,
            axis_names: names.to_vec(),
            axes: s.axes.to_vec(),
            feed_mm_min: s.feed_mm_min,
            override_pct: s.override_pct,
            cycles: s.cycles,
            overruns: s.overruns,
            feed_holds: s.feed_holds,
            progress: s.progress,
        }
    }

    /// One line for `dnurbs ctl status`.
    pub fn line(&self) -> String {
        let axes: Vec<String> = self
            .axis_names
            .iter()
            .zip(&self.axes)
            .map(|(n, v)| format!("{n} {v:.4}"))
            .collect();
        format!(
            "{}{}  line {}  block {}  {}  F {:.1} mm/min  override {} %  cycle {}  overruns {}  feed holds {}  {:.1} %",
            self.stage,
            match (self.awaiting_operator, self.paused) {
                (Some(l), _) => format!(" (stopped for the operator at line {l}: resume)"),
                (None, true) => " (paused)".to_owned(),
                (None, false) => String::new(),
            },
            self.line,
            self.block,
            axes.join(" "),
            self.feed_mm_min,
            self.override_pct,
            self.cycles,
            self.overruns,
            self.feed_holds,
            self.progress * 100.0
        )
    }
}

/// The server's socket; the file is removed when it is dropped.
pub struct Server {
    listener: UnixListener,
    path: PathBuf,
    names: Vec<String>,
}

/// One connected client and the bytes of its unfinished line.
struct Client {
    stream: UnixStream,
    pending: Vec<u8>,
}

/// Longest request line accepted, bytes.
const MAX_LINE: usize = 1024;

impl Server {
    /// Bind `path` (mode 0660). A socket file left by a run that is gone is replaced; one
    /// that answers belongs to a run still going, and is an error.
    pub fn bind(path: &Path, axis_names: [&str; 5]) -> anyhow::Result<Server> {
        if path.exists() {
            if UnixStream::connect(path).is_ok() {
                anyhow::bail!(
                    "{}: another dnurbs run is serving this control socket",
                    path.display()
                );
            }
            std::fs::remove_file(path)
                .with_context(|| format!("{}: cannot remove the stale socket", path.display()))?;
        }
        // Bound beside its name, given its mode, then renamed into place: the socket never
        // appears under `path` with the umask's mode.
        let mut staging = path.as_os_str().to_owned();
        staging.push(format!(".{}.new", std::process::id()));
        let staging = std::path::PathBuf::from(staging);
        let _ = std::fs::remove_file(&staging);
        let listener = UnixListener::bind(&staging)
            .with_context(|| format!("{}: cannot create the control socket", path.display()))?;
        let placed = std::fs::set_permissions(&staging, std::fs::Permissions::from_mode(0o660))
            .with_context(|| format!("{}: cannot set mode 0660", path.display()))
            .and_then(|()| {
                std::fs::rename(&staging, path)
                    .with_context(|| format!("{}: cannot put the socket in place", path.display()))
            });
        if let Err(e) = placed {
            let _ = std::fs::remove_file(&staging);
            return Err(e);
        }
        listener.set_nonblocking(true)?;
        Ok(Server {
            listener,
            path: path.to_path_buf(),
            names: axis_names.iter().map(|s| (*s).to_owned()).collect(),
        })
    }

    /// Serve until `done`: accept clients, answer their lines, queue their commands.
    pub fn serve(&self, tx: &mut Producer<'_, Command>, progress: &Progress, done: &AtomicBool) {
        let mut clients: Vec<Client> = Vec::new();
        while !done.load(Ordering::Acquire) {
            while let Ok((stream, _)) = self.listener.accept() {
                if stream.set_nonblocking(true).is_ok() {
                    clients.push(Client {
                        stream,
                        pending: Vec::new(),
                    });
                }
            }
            clients.retain_mut(|c| self.poll(c, tx, progress));
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Read what the client sent, answer every complete line; false when it is gone.
    fn poll(&self, c: &mut Client, tx: &mut Producer<'_, Command>, progress: &Progress) -> bool {
        let mut buf = [0u8; 512];
        loop {
            match c.stream.read(&mut buf) {
                Ok(0) => return false,
                Ok(n) => c.pending.extend_from_slice(&buf[..n]),
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(_) => return false,
            }
        }
        while let Some(i) = c.pending.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = c.pending.drain(..=i).collect();
            let answer = self.answer(&line, tx, progress);
            let mut out = serde_json::to_vec(&answer).unwrap_or_default();
            out.push(b'\n');
            // Answers are small; a client that does not read them is dropped.
            if c.stream.set_nonblocking(false).is_err()
                || c.stream
                    .set_write_timeout(Some(Duration::from_millis(200)))
                    .is_err()
                || c.stream.write_all(&out).is_err()
                || c.stream.set_nonblocking(true).is_err()
            {
                return false;
            }
        }
        c.pending.len() <= MAX_LINE
    }

    fn answer(&self, line: &[u8], tx: &mut Producer<'_, Command>, progress: &Progress) -> Answer {
        let refuse = |error: String| Answer {
            ok: false,
            error: Some(error),
            status: None,
        };
        let req: Request = match serde_json::from_slice(line) {
            Ok(r) => r,
            Err(e) => {
                return refuse(format!(
                    "not a request ({e}): send {{\"cmd\":\"status\"}}, pause, resume, stop, \
                     or {{\"cmd\":\"override\",\"percent\":0..100}}"
                ))
            }
        };
        let cmd = match req {
            Request::Status => None,
            Request::Pause => Some(Command::Pause),
            Request::Resume => Some(Command::Resume),
            Request::Stop => Some(Command::Stop),
            Request::Override { percent } if percent <= 100 => {
                Some(Command::Override(percent as u8))
            }
            Request::Override { percent } => {
                return refuse(format!(
                    "override {percent} % refused: the plan already runs at the machine's \
                     limits (0..=100 %)"
                ))
            }
        };
        if let Some(c) = cmd {
            if tx.enqueue(c).is_err() {
                return refuse("the command queue is full: the run is not taking commands".into());
            }
        }
        Answer {
            ok: true,
            error: None,
            status: Some(Status::of(&progress.snapshot(), &self.names)),
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// A client connection (`dnurbs ctl`).
pub struct Connection {
    reader: BufReader<UnixStream>,
    writer: UnixStream,
}

impl Connection {
    pub fn connect(path: &Path) -> anyhow::Result<Connection> {
        let s = UnixStream::connect(path).with_context(|| {
            format!(
                "{}: cannot connect to the control socket (is a dnurbs run with --control \
                 going?)",
                path.display()
            )
        })?;
        s.set_read_timeout(Some(Duration::from_secs(5)))?;
        Ok(Connection {
            reader: BufReader::new(s.try_clone()?),
            writer: s,
        })
    }

    /// Send one request; its answer, or `None` when the run has ended (connection closed).
    pub fn ask(&mut self, req: Request) -> anyhow::Result<Option<Answer>> {
        let mut line = serde_json::to_vec(&req)?;
        line.push(b'\n');
        if self.writer.write_all(&line).is_err() {
            return Ok(None);
        }
        let mut answer = String::new();
        match self.reader.read_line(&mut answer) {
            Ok(0) | Err(_) => Ok(None),
            Ok(_) => Ok(Some(
                serde_json::from_str(&answer).context("the run answered something unreadable")?,
            )),
        }
    }
}
