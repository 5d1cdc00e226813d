//! `dnurbs serve`: the long-lived controller process. It sets up the machine's buses once,
//! then runs three kinds of threads for its whole life:
//!
//! * the real-time thread: [`rt_loop::life::life_loop`], one [`rt_loop::life::Life::cycle`]
//!   a period, whatever the machine is doing;
//! * this thread, the hub's ([`super::hub::Hub`]): each request from the sockets, each
//!   report of the real-time thread, the planning of MDI lines and programs, the chunks fed;
//! * the sockets' threads ([`super::server`]): one accepting, one per client.
//!
//! With `--sim` the drives are simulated in a thread on the far end of an in-memory bus, as
//! `dnurbs demo` does. SIGINT or SIGTERM winds the machine down (what moves stops, the
//! drives are disabled) and the process ends.

use super::machine::{Fixed, SIM_QUEUE_FRAMES};
use super::server::{Listener, Msg};
use crate::simdrives::{sim_threads, write_records, FaultArgs, RECORD_HEADER};
use anyhow::Context;
use drives::link::{CanLink, MemLink, SocketLink};
use drives::master::WallClock;
use rt_loop::clock::OsClock;
use rt_loop::life::{life_loop, LoopCounts};
use rt_loop::os;
use std::collections::HashMap;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::Duration;

/// What `serve` was asked for.
pub struct ServeOptions {
    pub machine: config::Machine,
    pub shop: nc_lang::Setup,
    pub sim: bool,
    pub control: PathBuf,
    pub watch: Option<PathBuf>,
    pub record: Option<PathBuf>,
    pub faults: FaultArgs,
    pub rt: rt_loop::thread::RtSettings,
}

/// Serve until SIGINT or SIGTERM.
pub fn serve(opts: ServeOptions) -> anyhow::Result<()> {
    os::install_stop_handler()?;
    let control = Listener::bind(&opts.control, false)?;
    let watch = match &opts.watch {
        Some(p) => Some(Listener::bind(p, true)?),
        None => None,
    };
    let m = &opts.machine;
    eprintln!(
        "dnurbs serve: {} ({} drives, {} ms period){}; control socket {}{}",
        m.name,
        m.drives.len(),
        m.period_s * 1000.0,
        if opts.sim { ", drives simulated" } else { "" },
        opts.control.display(),
        opts.watch
            .as_ref()
            .map_or(String::new(), |w| format!(", watch socket {}", w.display()))
    );
    if opts.sim {
        let pair = || Ok(MemLink::pair(SIM_QUEUE_FRAMES));
        let (links, sims) = sim_threads(m, &opts.faults, opts.rt.priority, pair)?;
        let r = run(&opts, links, control, watch);
        let records: Vec<_> = sims.into_iter().flat_map(|s| s.finish()).collect();
        if let Some(path) = &opts.record {
            let mut f = std::io::BufWriter::new(
                std::fs::File::create(path)
                    .with_context(|| format!("{}: cannot create", path.display()))?,
            );
            writeln!(f, "{RECORD_HEADER}")?;
            write_records(&mut f, &records)?;
            f.flush()?;
        }
        r
    } else {
        let mut links = Vec::new();
        for b in &m.buses {
            links.push(SocketLink::open(&b.interface).with_context(|| {
                format!(
                    "cannot open CAN interface {:?} (bus {:?}); is it up? `ip link set {} up \
                     type can bitrate {}`",
                    b.interface, b.name, b.interface, b.bitrate
                )
            })?);
        }
        run(&opts, links, control, watch)
    }
}

/// Set the buses up on `links` and run the threads until the stop request has wound the
/// machine down.
fn run<L: CanLink + Send>(
    opts: &ServeOptions,
    links: Vec<L>,
    control: Listener,
    watch: Option<Listener>,
) -> anyhow::Result<()> {
    let m = &opts.machine;
    let stop = os::stop_requested();
    let mut buses = Vec::new();
    for (bi, link) in links.into_iter().enumerate() {
        let now = |_: &WallClock| os::now() as f64 * 1e-9;
        buses.push(crate::run::buses::set_up(
            m,
            bi,
            link,
            &mut WallClock::default(),
            now,
        )?);
    }
    let mut fixed = Fixed::new(m.clone(), opts.shop.clone());
    let (mut life, mut hub) = fixed.split(buses);
    let status = hub.published();
    let (tx, rx) = mpsc::channel::<Msg>();
    static IDS: AtomicU64 = AtomicU64::new(1);
    let _control = control.spawn(tx.clone(), &IDS)?;
    let _watch = match watch {
        Some(w) => Some(w.spawn(tx.clone(), &IDS)?),
        None => None,
    };
    drop(tx);
    let period_ns = (m.period_s * 1e9).round() as u64;
    let counts = LoopCounts::default();
    let done = AtomicBool::new(false);
    std::thread::scope(|scope| -> anyhow::Result<()> {
        let (counts, done) = (&counts, &done);
        let life = &mut life;
        let rt = rt_loop::thread::spawn_rt(
            scope,
            opts.rt,
            true,
            move |mode| {
                life_loop(
                    life,
                    &mut OsClock,
                    period_ns,
                    stop,
                    status,
                    counts,
                    u64::MAX,
                );
                mode
            },
            move || done.store(true, Ordering::Release),
        )?;
        let mut waiting: HashMap<u64, mpsc::Sender<super::protocol::Reply>> = HashMap::new();
        while !done.load(Ordering::Acquire) {
            match rx.recv_timeout(Duration::from_millis(1)) {
                Ok(Msg::Request {
                    client,
                    envelope,
                    answer,
                }) => {
                    let who = super::hub::Asker {
                        client,
                        id: envelope.id,
                    };
                    match hub.request(who, envelope.request) {
                        Some(r) => {
                            let _ = answer.send(r);
                        }
                        None => {
                            waiting.insert(client, answer);
                        }
                    }
                }
                Ok(Msg::Gone(client)) => {
                    waiting.remove(&client);
                    hub.gone(client);
                }
                Err(_) => {}
            }
            for (who, reply) in hub.poll() {
                if let Some(a) = waiting.remove(&who.client) {
                    let _ = a.send(reply);
                }
            }
        }
        let mode = rt
            .join()
            .map_err(|_| anyhow::anyhow!("the real-time thread panicked"))?
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        eprintln!(
            "dnurbs serve: stopped after {} periods ({} overruns); real-time: {}",
            counts.cycles.load(Ordering::Relaxed),
            counts.overruns.load(Ordering::Relaxed),
            mode.text()
        );
        Ok(())
    })
}
