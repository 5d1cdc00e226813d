//! Every Linux real-time call dnurbs makes, in one place.
//!
//! * [`lock_memory`]: `mlockall(MCL_CURRENT | MCL_FUTURE)`, so no page of the process is
//!   ever paged out or faulted in lazily during the loop.
//! * [`prefault_stack`]: touch the stack the loop will use, so its pages exist before the
//!   first period.
//! * [`set_fifo`]: `SCHED_FIFO` at a priority (needs CAP_SYS_NICE or an rtprio limit).
//! * [`pin_to_cpu`]: CPU affinity (pair it with `isolcpus=` on the kernel command line).
//! * [`IdlePoller`]: a `SCHED_IDLE` thread that keeps the real-time CPU busy between
//!   periods (user-space `idle=poll`), and [`avoid_cpu`] to keep other threads off it.
//! * [`set_timer_slack`]: 1 ns, instead of the 50 us normal threads get.
//! * [`now`], [`sleep_until`]: `CLOCK_MONOTONIC` and `clock_nanosleep(TIMER_ABSTIME)`, so
//!   periods do not drift with the time spent computing.
//!
//! * [`install_stop_handler`], [`stop_requested`]: SIGINT and SIGTERM set a flag that the
//!   loop reads each period (a controlled stop, never an abrupt exit).
//!
//! A missing privilege is an [`RtError`] that says which one and how to grant it.

use nix::sys::mman::{mlockall, MlockAllFlags};
use nix::sys::resource::{getrlimit, Resource};
use nix::sys::time::TimeSpec;
use nix::time::{clock_gettime, clock_nanosleep, ClockId, ClockNanosleepFlags};

/// A real-time set-up step that failed, with the way to fix it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RtError {
    #[error(
        "cannot lock memory (mlockall: {errno}); RLIMIT_MEMLOCK is {limit}: raise it with \
         `ulimit -l unlimited`, `LimitMEMLOCK=infinity` in the systemd unit, or a `memlock` \
         line in /etc/security/limits.conf; or run with --no-rt for development"
    )]
    MemoryLock {
        errno: nix::errno::Errno,
        limit: String,
    },
    #[error(
        "cannot switch to SCHED_FIFO priority {priority} ({errno}): grant CAP_SYS_NICE \
         (`setcap cap_sys_nice,cap_ipc_lock+ep $(which dnurbs)`), an `rtprio` limit in \
         /etc/security/limits.conf, or `LimitRTPRIO=99` in the systemd unit; or run with --no-rt"
    )]
    Scheduler {
        priority: i32,
        errno: nix::errno::Errno,
    },
    #[error("cannot pin the real-time thread to CPU {cpu} ({errno})")]
    Affinity {
        cpu: usize,
        errno: nix::errno::Errno,
    },
    #[error("cannot start the idle poller on CPU {cpu} ({errno})")]
    IdlePoll {
        cpu: usize,
        errno: nix::errno::Errno,
    },
    #[error("the real-time thread {0}")]
    Thread(&'static str),
    #[error("cannot install the SIGINT/SIGTERM handler ({0})")]
    Signal(nix::errno::Errno),
}

static STOP: std::sync::LazyLock<std::sync::Arc<std::sync::atomic::AtomicBool>> =
    std::sync::LazyLock::new(Default::default);

/// Make SIGINT and SIGTERM request a controlled stop instead of killing the process: each
/// sets [`stop_requested`] (signal-hook's handler, one async-signal-safe atomic store).
pub fn install_stop_handler() -> Result<(), RtError> {
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, std::sync::Arc::clone(&STOP)).map_err(|e| {
            RtError::Signal(nix::errno::Errno::from_raw(e.raw_os_error().unwrap_or(0)))
        })?;
    }
    Ok(())
}

/// The flag SIGINT/SIGTERM set (after [`install_stop_handler`]).
pub fn stop_requested() -> &'static std::sync::atomic::AtomicBool {
    &STOP
}

fn memlock_limit() -> String {
    match getrlimit(Resource::RLIMIT_MEMLOCK) {
        Ok((soft, _)) if soft == nix::libc::RLIM_INFINITY => "unlimited".into(),
        Ok((soft, _)) => format!("{} KiB", soft / 1024),
        Err(e) => format!("unknown ({e})"),
    }
}

/// Lock all current and future pages of the process into RAM.
pub fn lock_memory() -> Result<(), RtError> {
    mlockall(MlockAllFlags::MCL_CURRENT | MlockAllFlags::MCL_FUTURE).map_err(|errno| {
        RtError::MemoryLock {
            errno,
            limit: memlock_limit(),
        }
    })
}

/// Touch `bytes` of stack below the caller so those pages are resident before the loop.
#[inline(never)]
pub fn prefault_stack(bytes: usize) {
    const CHUNK: usize = 16 * 1024;
    let buf = [0u8; CHUNK];
    std::hint::black_box(&buf);
    if bytes > CHUNK {
        prefault_stack(bytes - CHUNK);
    }
}

/// Switch the calling thread to SCHED_FIFO at `priority` (1..=99).
pub fn set_fifo(priority: i32) -> Result<(), RtError> {
    let param = nix::libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: sched_setscheduler reads `param` during the call only; pid 0 is this thread.
    let rc = unsafe { nix::libc::sched_setscheduler(0, nix::libc::SCHED_FIFO, &param) };
    if rc == 0 {
        Ok(())
    } else {
        Err(RtError::Scheduler {
            priority,
            errno: nix::errno::Errno::last(),
        })
    }
}

/// Timer slack of the calling thread, ns. Normal threads get 50 us by default, which makes
/// every wake-up up to 50 us late; SCHED_FIFO threads have none. The loop sets 1 ns in every
/// mode so that `--no-rt` measures the machine, not the default slack.
pub fn set_timer_slack(ns: u64) {
    // Fails only for a value the kernel rejects; the loop then just keeps the default.
    let _ = nix::sys::prctl::set_timerslack(ns as _);
}

/// Pin the calling thread to one CPU.
pub fn pin_to_cpu(cpu: usize) -> Result<(), RtError> {
    let mut set = nix::sched::CpuSet::new();
    set.set(cpu)
        .map_err(|errno| RtError::Affinity { cpu, errno })?;
    nix::sched::sched_setaffinity(nix::unistd::Pid::from_raw(0), &set)
        .map_err(|errno| RtError::Affinity { cpu, errno })
}

/// The CPUs the calling thread may run on (its affinity mask), in order; empty if the
/// mask cannot be read.
pub fn allowed_cpus() -> Vec<usize> {
    match nix::sched::sched_getaffinity(nix::unistd::Pid::from_raw(0)) {
        Ok(set) => (0..nix::sched::CpuSet::count())
            .filter(|&c| set.is_set(c).unwrap_or(false))
            .collect(),
        Err(_) => Vec::new(),
    }
}

/// Take `cpu` out of the calling thread's affinity (threads it spawns later inherit it), so
/// the non-real-time threads leave that CPU to the real-time thread. Nothing changes if
/// `cpu` is the only CPU allowed.
pub fn avoid_cpu(cpu: usize) -> Result<(), RtError> {
    let me = nix::unistd::Pid::from_raw(0);
    let err = |errno| RtError::Affinity { cpu, errno };
    let mut set = nix::sched::sched_getaffinity(me).map_err(err)?;
    let others =
        (0..nix::sched::CpuSet::count()).any(|c| c != cpu && set.is_set(c).unwrap_or(false));
    if !others {
        return Ok(());
    }
    set.unset(cpu).map_err(err)?;
    nix::sched::sched_setaffinity(me, &set).map_err(err)
}

/// A thread pinned to one CPU at `SCHED_IDLE` that spins until dropped: the CPU never
/// halts between periods, as with the kernel's `idle=poll`, but for that CPU only and
/// without a reboot. Any other thread preempts it at once, the real-time thread included.
///
/// Halting costs twice on a virtual machine (and on PCs whose idle states
/// `/dev/cpu_dma_latency` cannot reach, e.g. no cpuidle driver): the wake-up goes through
/// the hypervisor, and while the virtual CPU is halted the host runs other work on the
/// physical core, so the real-time thread wakes to cold caches. Costs one CPU's worth of
/// power: meant for a CPU set aside for the real-time thread (`isolcpus=`).
pub struct IdlePoller {
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl IdlePoller {
    /// Start polling on `cpu`; fails if the thread cannot be pinned there or set to
    /// `SCHED_IDLE`.
    pub fn start(cpu: usize) -> Result<Self, RtError> {
        use std::sync::atomic::{AtomicBool, Ordering};
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let (tx, rx) = std::sync::mpsc::sync_channel(1);
        let flag = stop.clone();
        let thread = std::thread::Builder::new()
            .name("dnurbs-poll".into())
            .spawn(move || {
                let ready = pin_to_cpu(cpu).and_then(|()| set_idle_policy(cpu));
                let ok = ready.is_ok();
                let _ = tx.send(ready);
                while ok && !flag.load(Ordering::Relaxed) {
                    std::hint::spin_loop();
                }
            })
            .map_err(|_| RtError::Thread("idle poller could not be started"))?;
        let poller = IdlePoller {
            stop,
            thread: Some(thread),
        };
        match rx.recv() {
            Ok(Ok(())) => Ok(poller),
            Ok(Err(e)) => Err(e),
            Err(_) => Err(RtError::Thread("idle poller ended before it started")),
        }
    }
}

impl Drop for IdlePoller {
    fn drop(&mut self) {
        self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Switch the calling thread to `SCHED_IDLE` (no privilege needed).
fn set_idle_policy(cpu: usize) -> Result<(), RtError> {
    let param = nix::libc::sched_param { sched_priority: 0 };
    // SAFETY: sched_setscheduler reads `param` during the call only; pid 0 is this thread.
    let rc = unsafe { nix::libc::sched_setscheduler(0, nix::libc::SCHED_IDLE, &param) };
    if rc == 0 {
        Ok(())
    } else {
        Err(RtError::IdlePoll {
            cpu,
            errno: nix::errno::Errno::last(),
        })
    }
}

/// Monotonic time in nanoseconds.
pub fn now() -> u64 {
    // CLOCK_MONOTONIC cannot fail on Linux; 0 would only make one sample look late.
    clock_gettime(ClockId::CLOCK_MONOTONIC).map_or(0, |t| to_ns(&t))
}

fn to_ns(t: &TimeSpec) -> u64 {
    (t.tv_sec() as u64)
        .saturating_mul(1_000_000_000)
        .saturating_add(t.tv_nsec() as u64)
}

/// Sleep until the monotonic time `deadline_ns` (absolute; returns at once if past).
pub fn sleep_until(deadline_ns: u64) {
    let ts = TimeSpec::new(
        (deadline_ns / 1_000_000_000) as _,
        (deadline_ns % 1_000_000_000) as _,
    );
    // EINTR (a signal) just ends this sleep early; the loop measures the wake-up anyway.
    let _ = clock_nanosleep(
        ClockId::CLOCK_MONOTONIC,
        ClockNanosleepFlags::TIMER_ABSTIME,
        &ts,
    );
}

/// Wait on the clock, without sleeping, until the monotonic time `deadline_ns`; returns the
/// time read then. For the last microseconds before a deadline (the loop's lead), where a
/// sleep would add the wake-up latency again. When two clock reads are more than `gap_ns`
/// apart something else ran on this CPU (an interrupt, the hypervisor) and may have evicted
/// the caches: `on_gap(when)` is called then, with the time the pause began. Bounded: at
/// most `max_ns` clock reads, which take far longer than `max_ns` nanoseconds, so a stuck
/// clock cannot hold the thread.
pub fn spin_until(deadline_ns: u64, max_ns: u64, gap_ns: u64, mut on_gap: impl FnMut(u64)) -> u64 {
    let mut t = now();
    for _ in 0..max_ns {
        if t >= deadline_ns {
            break;
        }
        core::hint::spin_loop();
        let prev = t;
        t = now();
        if t.saturating_sub(prev) > gap_ns {
            on_gap(prev);
            t = now();
        }
    }
    t
}

/// Minor page faults of the calling thread so far (getrusage RUSAGE_THREAD): the loop
/// thread measures its own, not those of the planner or reporter threads.
pub fn minor_faults() -> i64 {
    nix::sys::resource::getrusage(nix::sys::resource::UsageWho::RUSAGE_THREAD)
        .map_or(-1, |u| u.minor_page_faults())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spin_until_waits_for_the_deadline_reports_pauses_and_is_bounded() {
        let t0 = now();
        let t = spin_until(t0 + 200_000, 10_000_000, u64::MAX, |_| panic!("no gap"));
        assert!(t >= t0 + 200_000);
        // Every two clock reads are more than 0 ns apart: each counts as a pause, and the
        // time given is that of the read before it.
        let mut seen = Vec::new();
        let t1 = now();
        spin_until(t1 + 20_000, 10_000_000, 0, |at| seen.push(at));
        assert!(!seen.is_empty() && seen.iter().all(|&at| at >= t1 && at < t1 + 20_000));
        // A deadline ten seconds away with a bound of 100 reads: back long before it.
        let t = spin_until(now() + 10_000_000_000, 100, u64::MAX, |_| {});
        assert!(t < t0 + 1_000_000_000);
    }

    #[test]
    fn sleep_until_is_absolute_and_monotonic() {
        let t0 = now();
        sleep_until(t0 + 2_000_000);
        let t1 = now();
        assert!(
            t1 >= t0 + 2_000_000,
            "woke {} ns early",
            t0 + 2_000_000 - t1
        );
        sleep_until(t0); // in the past: returns at once
        assert!(now() >= t1);
    }

    /// (policy, last CPU) of each thread of this process named `name`, from /proc.
    fn threads_named(name: &str) -> Vec<(i32, usize)> {
        let mut found = Vec::new();
        for task in std::fs::read_dir("/proc/self/task").unwrap().flatten() {
            let path = task.path();
            let comm = std::fs::read_to_string(path.join("comm")).unwrap_or_default();
            if comm.trim_end() != name {
                continue;
            }
            let stat = std::fs::read_to_string(path.join("stat")).unwrap();
            // Fields after "(comm)" start at field 3; processor is field 39, policy 41.
            let rest: Vec<&str> = stat[stat.rfind(')').unwrap() + 1..]
                .split_whitespace()
                .collect();
            found.push((rest[41 - 3].parse().unwrap(), rest[39 - 3].parse().unwrap()));
        }
        found
    }

    /// The threads named `name` once those that have ended are gone. `join` returns when
    /// the kernel wakes it at the thread's exit, a moment before /proc stops listing the
    /// task, so a thread that ended may still show; one that still spins shows all 5 s.
    fn threads_left(name: &str) -> Vec<(i32, usize)> {
        let deadline = now() + 5_000_000_000;
        loop {
            let found = threads_named(name);
            if found.is_empty() || now() > deadline {
                return found;
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }

    #[test]
    fn the_idle_poller_runs_at_sched_idle_on_its_cpu_until_dropped() {
        let poller = IdlePoller::start(0).unwrap();
        assert_eq!(threads_named("dnurbs-poll"), [(nix::libc::SCHED_IDLE, 0)]);
        drop(poller);
        assert_eq!(threads_left("dnurbs-poll"), []);
        // A CPU the machine does not have: an error naming it, and no thread left spinning.
        let e = IdlePoller::start(4095).err().unwrap();
        assert!(matches!(e, RtError::Affinity { cpu: 4095, .. }), "{e:?}");
        assert_eq!(threads_left("dnurbs-poll"), []);
    }

    #[test]
    fn avoid_cpu_leaves_that_cpu_to_the_real_time_thread() {
        let me = nix::unistd::Pid::from_raw(0);
        std::thread::spawn(move || {
            let before = nix::sched::sched_getaffinity(me).unwrap();
            let allowed =
                |s: &nix::sched::CpuSet| (0..64).filter(|&c| s.is_set(c).unwrap_or(false)).count();
            avoid_cpu(0).unwrap();
            let after = nix::sched::sched_getaffinity(me).unwrap();
            if allowed(&before) > 1 && before.is_set(0).unwrap() {
                assert!(!after.is_set(0).unwrap());
                assert_eq!(allowed(&after), allowed(&before) - 1);
            } else {
                assert_eq!(
                    allowed(&after),
                    allowed(&before),
                    "the only CPU stays allowed"
                );
            }
        })
        .join()
        .unwrap();
    }

    #[test]
    fn privilege_errors_say_how_to_grant_them() {
        let e = RtError::Scheduler {
            priority: 80,
            errno: nix::errno::Errno::EPERM,
        };
        let text = e.to_string();
        assert!(
            text.contains("CAP_SYS_NICE") && text.contains("rtprio") && text.contains("--no-rt"),
            "{text}"
        );
        let e = RtError::MemoryLock {
            errno: nix::errno::Errno::ENOMEM,
            limit: "8192 KiB".into(),
        };
        assert!(e.to_string().contains("ulimit -l unlimited"));
    }
}
