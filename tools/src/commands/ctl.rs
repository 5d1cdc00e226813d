//! `ctl`: the client of a run's control socket ([`crate::control`]).

use crate::cli::CtlCommand;
use crate::control::{Connection, Request};
use crate::exit::{InputError, Outcome};
use std::path::Path;
use std::time::Duration;

pub fn ctl(socket: &Path, command: CtlCommand) -> anyhow::Result<Outcome> {
    let mut conn = Connection::connect(socket)?;
    let req = match command {
        CtlCommand::Status { .. } => Request::Status,
        CtlCommand::Pause => Request::Pause,
        CtlCommand::Resume => Request::Resume,
        CtlCommand::Stop => Request::Stop,
        CtlCommand::Override { percent } => Request::Override {
            percent: u32::from(percent),
        },
    };
    let watch = matches!(command, CtlCommand::Status { watch: true });
    loop {
        let Some(answer) = conn.ask(req)? else {
            if watch {
                eprintln!("the run has ended");
                return Ok(Outcome::Completed);
            }
            anyhow::bail!("{}: the run closed the connection", socket.display());
        };
        if !answer.ok {
            return Err(InputError::Usage(answer.error.unwrap_or_default()).into());
        }
        if let Some(s) = &answer.status {
            println!("{}", s.line());
        }
        if !watch {
            return Ok(Outcome::Completed);
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}
