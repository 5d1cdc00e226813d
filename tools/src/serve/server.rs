//! The control sockets of `dnurbs serve`: Unix stream sockets carrying protocol version 1
//! ([`super::protocol`]), a thread per client, every request handed to the hub's thread
//! and its answer written back.
//!
//! * The control socket (mode 0660): its owner and group operate the machine, the file's
//!   permissions decide who that is (as LinuxCNC's NML does, nothing is operated from
//!   outside the host).
//! * The watch socket (mode 0666, optional): `status` only; anything else is refused with
//!   the reason. For screens and metrics, which must not move the machine.
//!
//! A request line longer than [`MAX_LINE`] ends the connection after its refusal (what
//! follows could not be told from a request). A client that goes away is reported to the
//! hub: a continuous jog it held stops at once.

use super::protocol::{Envelope, Reply, Request, MAX_LINE};
use anyhow::Context;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, Sender};

/// What the client threads hand the hub's thread.
pub enum Msg {
    /// A request and where its answer goes.
    Request {
        client: u64,
        envelope: Envelope,
        answer: Sender<Reply>,
    },
    /// The client went away.
    Gone(u64),
}

/// A bound socket; the file is removed when it is dropped.
pub struct Listener {
    listener: UnixListener,
    path: PathBuf,
    read_only: bool,
}

impl Listener {
    /// Bind `path` (a stale socket file there is replaced; any other file is refused) with
    /// `mode`.
    pub fn bind(path: &Path, read_only: bool) -> anyhow::Result<Listener> {
        if let Ok(meta) = std::fs::symlink_metadata(path) {
            use std::os::unix::fs::FileTypeExt;
            anyhow::ensure!(
                meta.file_type().is_socket(),
                "{}: exists and is not a socket: refusing to replace it",
                path.display()
            );
            anyhow::ensure!(
                UnixStream::connect(path).is_err(),
                "{}: another controller serves this socket",
                path.display()
            );
            std::fs::remove_file(path)?;
        }
        let listener = UnixListener::bind(path)
            .with_context(|| format!("{}: cannot bind the socket", path.display()))?;
        let mode = if read_only { 0o666 } else { 0o660 };
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode))?;
        Ok(Listener {
            listener,
            path: path.to_path_buf(),
            read_only,
        })
    }

    /// Accept clients in a thread of their own for the process's life, each served by a
    /// thread that sends its requests on `hub`.
    pub fn spawn(self, hub: Sender<Msg>, ids: &'static AtomicU64) -> anyhow::Result<Listener> {
        let listener = self.listener.try_clone()?;
        let read_only = self.read_only;
        std::thread::Builder::new()
            .name("dnurbs-accept".into())
            .spawn(move || {
                for stream in listener.incoming() {
                    let Ok(stream) = stream else { continue };
                    let id = ids.fetch_add(1, Ordering::Relaxed);
                    let hub = hub.clone();
                    let _ = std::thread::Builder::new()
                        .name("dnurbs-client".into())
                        .spawn(move || serve_client(stream, id, read_only, &hub));
                }
            })?;
        Ok(self)
    }
}

impl Drop for Listener {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// One client: a request a line, each answered before the next is read.
fn serve_client(stream: UnixStream, client: u64, read_only: bool, hub: &Sender<Msg>) {
    let Ok(mut writer) = stream.try_clone() else {
        return;
    };
    let mut reader = BufReader::new(stream);
    loop {
        let mut line = String::new();
        let n = match reader
            .by_ref()
            .take(MAX_LINE as u64 + 1)
            .read_line(&mut line)
        {
            Ok(n) => n,
            Err(e) => {
                // Not UTF-8, or the connection failed.
                let r = Reply::refused(None, format!("not a request: {e}"));
                let _ = writeln!(writer, "{}", r.line());
                break;
            }
        };
        if n == 0 {
            break;
        }
        let too_long = !line.ends_with('\n') && n > MAX_LINE;
        let reply = if too_long {
            Reply::refused(None, super::protocol::BadRequest::TooLong)
        } else {
            match Request::parse(line.trim_end_matches(['\n', '\r'])) {
                Err(e) => Reply::refused(None, e),
                Ok(env) if read_only && env.request != Request::Status => Reply::refused(
                    env.id,
                    "this is the watch socket: status only (operate through the control \
                     socket)",
                ),
                Ok(envelope) => {
                    let (tx, rx) = mpsc::channel();
                    let msg = Msg::Request {
                        client,
                        envelope,
                        answer: tx,
                    };
                    if hub.send(msg).is_err() {
                        break;
                    }
                    match rx.recv() {
                        Ok(r) => r,
                        Err(_) => break,
                    }
                }
            }
        };
        if writeln!(writer, "{}", reply.line()).is_err() || too_long {
            break;
        }
    }
    let _ = hub.send(Msg::Gone(client));
}
