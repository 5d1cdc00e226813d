//! The real-time thread, set up one way for every loop ([`spawn_rt`]): `dnurbs latency`'s
//! empty loop and the machine's loop of `dnurbs run` and `demo`.
//!
//! In the new thread, before the caller's body: lock the process's memory (`mlockall`),
//! SCHED_FIFO at the priority asked for, pin to the CPU asked for, timer slack 1 ns, touch
//! [`STACK_PREFAULT`] of stack so the loop never faults it in. What it got is the
//! [`RtMode`] handed to the body, also for the report.

use crate::os::{self, RtError};
use std::thread::{Scope, ScopedJoinHandle};

/// How the loop thread is set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RtSettings {
    /// SCHED_FIFO priority; `None` runs the same loop without real-time privileges (--no-rt).
    pub priority: Option<i32>,
    /// Pin the loop to this CPU.
    pub cpu: Option<usize>,
    /// Keep `cpu` busy between periods with an [`os::IdlePoller`] (needs `cpu`).
    pub idle_poll: bool,
}

impl RtSettings {
    /// Start the idle poller these settings ask for, if any; it polls until dropped.
    pub fn idle_poller(&self) -> Result<Option<os::IdlePoller>, RtError> {
        match (self.idle_poll, self.cpu) {
            (false, _) => Ok(None),
            (true, Some(cpu)) => os::IdlePoller::start(cpu).map(Some),
            (true, None) => Err(RtError::Thread(
                "needs a CPU to poll on: idle polling is only for a pinned loop (set the CPU)",
            )),
        }
    }
}

/// Stack the loop may use, touched before the first period.
pub const STACK_PREFAULT: usize = 256 * 1024;

/// How the real-time thread runs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RtMode {
    pub sched_fifo: bool,
    /// SCHED_FIFO priority, when it runs with it.
    pub priority: Option<i32>,
    pub memory_locked: bool,
    /// CPU the thread is pinned to.
    pub cpu: Option<usize>,
    /// Why it runs without real-time privileges, if it does.
    pub without_because: Option<String>,
}

impl RtMode {
    pub fn text(&self) -> String {
        let cpu = self.cpu.map_or(String::new(), |c| format!(", CPU {c}"));
        match (&self.without_because, self.priority) {
            (None, Some(p)) if self.sched_fifo && self.memory_locked => {
                format!("SCHED_FIFO priority {p}, memory locked{cpu}")
            }
            (Some(why), _) => format!("no ({why}){cpu}"),
            _ => format!("no{cpu}"),
        }
    }
}

/// Set the calling thread up as `rt` asks. Without `fallback` a missing privilege is an
/// error (saying how to grant it); with it, the mode says what the thread runs without,
/// and why. Pinning to a CPU that cannot be had is always an error.
pub fn set_up(rt: RtSettings, fallback: bool) -> Result<RtMode, RtError> {
    let mut mode = RtMode {
        cpu: rt.cpu,
        ..RtMode::default()
    };
    match rt.priority {
        Some(priority) => {
            let locked = os::lock_memory();
            mode.memory_locked = locked.is_ok();
            match locked.and_then(|()| os::set_fifo(priority)) {
                Ok(()) => {
                    mode.sched_fifo = true;
                    mode.priority = Some(priority);
                }
                Err(e) if fallback => mode.without_because = Some(e.to_string()),
                Err(e) => return Err(e),
            }
        }
        None => mode.without_because = Some("--no-rt".to_owned()),
    }
    if let Some(cpu) = rt.cpu {
        os::pin_to_cpu(cpu)?;
    }
    os::set_timer_slack(1);
    os::prefault_stack(STACK_PREFAULT);
    Ok(mode)
}

/// Start the real-time thread `dnurbs-rt` in `scope`: [`set_up`], then `body` with the mode
/// it got. A set-up that fails ends the thread with the error, without running `body`;
/// `on_exit` runs in the thread either way, last (to tell the other threads it is over).
pub fn spawn_rt<'scope, T: Send + 'scope>(
    scope: &'scope Scope<'scope, '_>,
    rt: RtSettings,
    fallback: bool,
    body: impl FnOnce(RtMode) -> T + Send + 'scope,
    on_exit: impl FnOnce() + Send + 'scope,
) -> Result<ScopedJoinHandle<'scope, Result<T, RtError>>, RtError> {
    std::thread::Builder::new()
        .name("dnurbs-rt".into())
        .stack_size(STACK_PREFAULT * 2)
        .spawn_scoped(scope, move || {
            let result = set_up(rt, fallback).map(body);
            on_exit();
            result
        })
        .map_err(|_| RtError::Thread("could not be started"))
}
