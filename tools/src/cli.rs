//! The command line: every subcommand and option, with one syntax for durations
//! ([`duration`]: a number and a unit, `500us`, `10ms`, `5s`, `2min`) and ranges stated in
//! every range error.

use crate::demo::DemoLink;
use crate::simdrives;
use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "dnurbs",
    version,
    about = "Real-time 5-axis double-NURBS interpolation (Wang et al. 2007)",
    long_about = "Real-time 5-axis double-NURBS interpolation (Wang et al. 2007).\n\n\
        An NC program (G01 5-axis lines, G06.2 NURBS, G06.5 double NURBS) is parsed, planned \
        with jerk-limited look-ahead and interpolated period by period into X Y Z A C setpoints, \
        sent to CiA-402 drives over SocketCAN.\n\n\
        Durations take a unit: 500us, 10ms, 5s, 2min (also ns, µs).",
    after_help = crate::exit::TABLE,
    after_long_help = crate::exit::TABLE
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// `dnurbs ctl --help`'s exit codes.
const CTL_HELP: &str = "Exit codes: 0 done, 1 cannot reach the run (no socket, run ended), \
    2 the run refused the command (the reason is printed).";

#[derive(Clone, Copy, ValueEnum)]
pub enum MethodArg {
    /// Advance the cutter by the commanded arc length each period (arc-length table + Newton).
    Arclength,
    /// Paper eq. 9: first-order Taylor update of u.
    Taylor1,
    /// Paper eq. 10 with the feed-acceleration term: second-order Taylor update of u.
    Taylor2,
}

#[derive(Subcommand)]
pub enum Command {
    /// The main job on built-in defaults: the paper's example on simulated drives.
    ///
    /// The paper's example program on the paper's machine, its five CiA-402 drives simulated
    /// on an in-process CAN link (no hardware, no root). The real-time thread runs with
    /// SCHED_FIFO and locked memory when the privileges allow, without them otherwise (said
    /// in the output and the report); the simulated drives' thread runs SCHED_FIFO one
    /// priority below it. Prints the latency report.
    #[command(after_help = crate::exit::TABLE)]
    Demo {
        /// Write summary.txt, summary.json, latency.hlog and latency.svg into this directory.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
        /// Do not even try SCHED_FIFO and mlockall.
        #[arg(long)]
        no_rt: bool,
        /// The in-process bus between the master and the simulated drives: `memory` (lock-free
        /// queues, no system call per frame) or `socketpair` (a kernel socket carrying
        /// can_frame structs through the same socketcan calls as a CAN interface).
        #[arg(long, value_enum, default_value_t = DemoLink::Memory)]
        link: DemoLink,
        #[command(flatten)]
        cpu: CpuArgs,
        /// Wake this long before each 2 ms deadline: rehearse the interpolation step (warm
        /// caches), compute it in a quiet moment, wait on the clock and send the frames at the
        /// deadline. Costs the lead in CPU time per period. 0 sleeps to the deadline and
        /// computes after it. 0..=1ms.
        #[arg(long, default_value = "60us", value_parser = lead)]
        lead: u64,
        /// Serve the control socket here (see `dnurbs ctl`).
        #[arg(long, value_name = "SOCKET")]
        control: Option<PathBuf>,
        /// Run this NC program instead of the paper's example, on the same machine and
        /// simulated drives, read a line at a time as it runs (as `dnurbs run` does).
        #[arg(long, value_name = "FILE")]
        program: Option<PathBuf>,
        /// Write every target as sent to the drives, one row a period (cycle, t, stage,
        /// the axes' positions, each node's target), to this CSV file; written outside the
        /// real-time thread.
        #[arg(long, value_name = "FILE")]
        trace: Option<PathBuf>,
    },
    /// Run a program on the machine's CiA-402 drives over SocketCAN.
    ///
    /// Sets up the drives on the machine file's CAN interfaces (SDO, PDO mapping, NMT
    /// start), enables them (CiA-402), interpolates in the real-time thread while a planner
    /// thread streams planned segments, disables them, prints the report.
    ///
    /// The axes must be at the program's start pose (its first block) unless --approach is
    /// given. SIGINT (Ctrl-C), SIGTERM or `dnurbs ctl SOCKET stop` stops along the path,
    /// then disables the drives. A drive fault quick-stops and disables every drive and
    /// names the node and the cause. Real-time
    /// settings come from the machine file's [realtime] section.
    #[command(after_help = crate::exit::TABLE)]
    Run {
        /// NC program.
        program: PathBuf,
        /// Machine file (TOML) with [[bus]] and [axes.*.drive].
        #[arg(long, short)]
        machine: PathBuf,
        /// Write summary.txt, summary.json, latency.hlog and latency.svg into this directory.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
        /// Before the program, move all axes from where the drives are to the program's start
        /// in one jerk-limited straight move in axis space (mind the fixtures).
        #[arg(long)]
        approach: bool,
        /// Run without mlockall and SCHED_FIFO (development machines; timing not guaranteed).
        #[arg(long)]
        no_rt: bool,
        /// Serve the control socket here (mode 0660; overrides the machine file's
        /// [control] socket). See `dnurbs ctl`.
        #[arg(long, value_name = "SOCKET")]
        control: Option<PathBuf>,
        /// Write every target as sent to the drives, one row a period (cycle, t, stage,
        /// the axes' positions, each node's target), to this CSV file; written outside the
        /// real-time thread.
        #[arg(long, value_name = "FILE")]
        trace: Option<PathBuf>,
        #[command(flatten)]
        shop: crate::shop::ShopArgs,
    },
    /// Operate `dnurbs serve`, or a running `dnurbs run` or `demo`, through its control socket.
    ///
    /// Every controller takes `status` (`--watch` repeats it), `pause` (decelerate along
    /// the path and hold), `resume`, `stop`, `override PCT` (0..=100 % of the planned feed,
    /// reached with jerk-limited transitions; above 100 % is refused: the plan already runs
    /// at the machine's limits). `serve` also takes `on`, `off`, `home`, `jog`, `mdi`,
    /// `load`, `run`, `reset`, `estop`. A refusal says why, exit 2.
    #[command(after_help = CTL_HELP)]
    Ctl {
        /// The socket given to `serve` or `run --control` (or the machine file's [control]
        /// socket).
        socket: PathBuf,
        #[command(subcommand)]
        command: CtlCommand,
    },
    /// The long-lived machine controller: homes, jogs, takes MDI, runs programs.
    ///
    /// Sets up the machine's drives once and keeps them for its whole life: off until
    /// `dnurbs ctl SOCKET on`, then homing, jogging, MDI lines and programs from where the
    /// machine stands, the drives held enabled between them; a fault or the e-stop
    /// quick-stops and disables every drive until `reset`. Operated through the control
    /// socket (`dnurbs ctl`, protocol in docs/serve.md). SIGINT or SIGTERM stops what
    /// moves, disables the drives and ends.
    Serve(crate::serve::args::ServeArgs),
    /// Interpolate a program offline, exactly as the real-time thread does, and report.
    ///
    /// Reports machining time, feed fluctuation, chord error and each axis's velocity,
    /// acceleration and jerk against its limits. The machine file's buses are not used: a
    /// bus over its load at this period is only warned about.
    #[command(after_help = crate::exit::TABLE)]
    Simulate {
        /// NC program (G-code with G01 / G06.2 / G06.5 blocks).
        program: PathBuf,
        /// Machine file (TOML), e.g. config/machines/paper-ac-table.toml.
        #[arg(long, short)]
        machine: PathBuf,
        /// Parameter update method [default: the machine file's, else arclength].
        #[arg(long, value_enum)]
        method: Option<MethodArg>,
        /// Write one CSV row per period:
        /// cycle,t,block,u,x,y,z,i,j,k,feed,X,Y,Z,A,C (mm, mm/min, degrees).
        #[arg(long, value_name = "OUT.csv")]
        trace: Option<PathBuf>,
        /// Print the summary as one JSON object instead of text.
        #[arg(long)]
        json: bool,
        /// Replay an operator's actions through the real-time thread's follower, one a
        /// line, in order: `at 2.31s pause`, `after 1.5s resume`, `at line 40 override 30`,
        /// `at 3s stop` (`#` starts a comment). Every setpoint, holds and overrides
        /// included, is checked against every axis's velocity and acceleration limit, its
        /// jerk inside a segment and its travel; a setpoint over one exits 2. Arc length
        /// only.
        #[arg(long, value_name = "SCRIPT", conflicts_with = "method")]
        operator: Option<PathBuf>,
        /// Restart the program from line N, as after a broken tool: the lines before it
        /// are read without moving, and the spindle, coolant, outputs and path mode they
        /// left come on before the tool comes down (their stops and dwells are skipped);
        /// the tool, standing where the program starts, goes back along its axis by
        /// --clearance, over above the pose where line N's first move starts, and down
        /// onto it (at the feed in effect there). The summary says what was restored and
        /// the approach. Refused inside a NURBS block's control points, on a line run in a
        /// loop or a subroutine, and after the last move.
        #[arg(long, value_name = "N", conflicts_with = "operator", value_parser = clap::value_parser!(u32).range(1..))]
        from_line: Option<u32>,
        /// With --from-line: how far the tool backs off along its axis, and stands above
        /// the restart pose before it comes down, mm (0 < MM <= 1000).
        #[arg(
            long,
            value_name = "MM",
            default_value_t = 10.0,
            requires = "from_line"
        )]
        clearance: f64,
        #[command(flatten)]
        shop: crate::shop::ShopArgs,
    },
    /// Check a program before anything moves, without planning it (the pre-pass).
    ///
    /// Reads the program as a stream, in the memory of one line whatever its length, and
    /// checks every rule of the NC language (every error, up to 50), the geometry the
    /// builder checks (NURBS tool vectors, tool-axis steps, angle words for the machine),
    /// and that the machine's axes at every programmed point (the start pose and the end
    /// of every block, through the machine's kinematics) lie within their travel. Not
    /// checked: the feeds, and the path between programmed points (a curve's bulge, an
    /// arc), against the axis limits: `dnurbs simulate` plans them. Prints the lines read
    /// per second.
    #[command(after_help = crate::exit::TABLE)]
    Check {
        /// NC program.
        program: PathBuf,
        /// Machine file (TOML), e.g. config/machines/paper-ac-table.toml.
        #[arg(long, short)]
        machine: PathBuf,
        /// Print the result as one JSON object instead of text.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        shop: crate::shop::ShopArgs,
    },
    /// Simulate a machine's drives on a CAN interface (tests without hardware).
    ///
    /// Boot-up, NMT slave, SDO server, PDO mapping, CiA-402 state machine, CSP motor model,
    /// homing mode (methods 35/37, 19/21, 3/5, on a home switch and an index pulse where the
    /// machine file's [axes.*.home] puts the home point, else at 0 counts), heartbeats, with
    /// fault injection. Stop it with Ctrl-C or --duration.
    #[command(after_help = crate::exit::TABLE)]
    SimDrives {
        /// CAN interface, e.g. vcan0 (`ip link add dev vcan0 type vcan`).
        #[arg(long)]
        iface: String,
        /// Machine file whose [[bus]] on this interface (or only bus) lists the drives.
        #[arg(long, short)]
        machine: PathBuf,
        /// Write every target received: CSV sync,node,target_counts,actual_counts,statusword.
        #[arg(long, value_name = "FILE.csv")]
        record: Option<PathBuf>,
        /// Motor lag: time constant of the actual position following the target, 0..=10s.
        #[arg(long, default_value = "0ms", value_parser = lag)]
        lag: u64,
        /// Exit after this long, 1ms..=30days (default: run until stopped).
        #[arg(long, value_parser = sim_duration)]
        duration: Option<u64>,
        /// Drive fault (EMCY 0x8611, statusword Fault) on NODE at SYNC count N.
        #[arg(long, value_name = "NODE:N", value_parser = simdrives::node_value::<u64>)]
        fault_at: Vec<(u8, u64)>,
        /// NODE stops sending heartbeats after SYNC count N.
        #[arg(long, value_name = "NODE:N", value_parser = simdrives::node_value::<u64>)]
        heartbeat_stops: Vec<(u8, u64)>,
        /// NODE never boots: silent from power-on.
        #[arg(long, value_name = "NODE")]
        never_boots: Vec<u8>,
        /// NODE drops every N-th frame it sends.
        #[arg(long, value_name = "NODE:N", value_parser = simdrives::node_value::<u32>)]
        drop_every: Vec<(u8, u32)>,
        /// NODE sends nothing from SYNC count N on (a broken cable).
        #[arg(long, value_name = "NODE:N", value_parser = simdrives::node_value::<u64>)]
        silent_from: Vec<(u8, u64)>,
        /// NODE's home switch is not wired: its homing search fails with the drive's
        /// homing error after a tenth of the axis's travel.
        #[arg(long, value_name = "NODE")]
        no_home_switch: Vec<u8>,
    },
    /// Measure this computer's real-time wake-up latency (like cyclictest).
    ///
    /// The real-time loop with nothing to do, with the same set-up and report as `dnurbs
    /// run`. Run it on a controller PC before deploying.
    #[command(after_help = crate::exit::TABLE)]
    Latency {
        /// Period, 100us..=100ms.
        #[arg(long, default_value = "1ms", value_parser = period)]
        period: u64,
        /// How long to measure, 1ms..=7days.
        #[arg(long, default_value = "10s", value_parser = measure_duration)]
        duration: u64,
        /// SCHED_FIFO priority of the loop thread (1..=99).
        #[arg(long, default_value_t = 80, value_parser = clap::value_parser!(i32).range(1..=99))]
        priority: i32,
        #[command(flatten)]
        cpu: CpuArgs,
        /// Run the same loop without mlockall and SCHED_FIFO (development machines).
        #[arg(long)]
        no_rt: bool,
        /// Write summary.txt, summary.json, latency.hlog (HdrHistogram interval log) and
        /// latency.svg (percentile plot) into this directory.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
    },
    /// Print the worst-case CAN bus load of a machine file, per bus.
    ///
    /// SYNC plus one 6-byte RPDO and TPDO per drive each cycle, at 55 + 10 n bits per frame
    /// (stuffing and interframe space included). vcan has no bit timing, so this is
    /// computed, not measured. Exit 2 if a bus is over its max_load.
    #[command(after_help = crate::exit::TABLE)]
    Busload {
        /// Machine file (TOML) with [[bus]] tables and [axes.*.drive] mappings.
        #[arg(long, short)]
        machine: PathBuf,
    },
    /// Fit runs of G01 moves into G06.5 double-NURBS blocks (the paper's section 4).
    ///
    /// Each run of G01 moves (consecutive lines holding only the move, one feed, absolute
    /// millimetres, feed per minute or in inverse time (G93: the moves' speeds within 1 %;
    /// the block is written in G94 at the run's length over its time, G93 after it), no
    /// corner above --corner-deg, each move turning the tool by at most 10 degrees) becomes
    /// one G06.5 block: a cubic cutter curve and an orientation
    /// curve on one knot vector, weights 1, with every programmed point within --tol-mm of
    /// the cutter curve and every programmed tool axis within --tol-deg of the interpolated
    /// one. Every other line passes through as it was. A run given in machine angles is
    /// followed by a line that gives both angles, so the angles stay modal as in the
    /// program: a move after it that leaves one modal is written with it (`X1 C5` becomes
    /// `X1 C5 A15`), else the run's last move is kept as written.
    ///
    /// The program is read as a stream, in the memory of a few thousand moves whatever its
    /// length (a run longer than 5 000 moves becomes several blocks that join on programmed
    /// points). As it is written, the result is parsed again, both programs are built into
    /// paths on the machine, and their deviations are measured by dense sampling,
    /// independently of the fit; over the tolerances, nothing is written (OUT.nc is created
    /// only at the end, standard output only gets a checked program) and the exit code is 1.
    /// A file OUT.nc replaces keeps its permissions. SIGINT or SIGTERM stops the fit at the
    /// next line with exit 4, and nothing is written. A summary goes to standard error.
    #[command(after_help = crate::exit::TABLE)]
    Fit {
        /// NC program with G01 moves (X Y Z with I J K, or with the machine's angles).
        program: PathBuf,
        /// Machine file (TOML): its kinematics turn angle words into tool axes.
        #[arg(long, short)]
        machine: PathBuf,
        /// Write the fitted program here (default: standard output).
        #[arg(long, short, value_name = "OUT.nc")]
        output: Option<PathBuf>,
        /// Largest distance of a programmed point from the cutter curve, mm (1e-5..=1).
        #[arg(long, default_value_t = 0.001)]
        tol_mm: f64,
        /// Largest angle between a programmed tool axis and the interpolated one, degrees
        /// (1e-4..=5).
        #[arg(long, default_value_t = 0.01)]
        tol_deg: f64,
        /// A turn of the path between two moves above this many degrees is a corner, where
        /// one block ends and the next begins (0..=180).
        #[arg(long, default_value_t = 10.0)]
        corner_deg: f64,
        /// Print the summary as one JSON object (on standard error).
        #[arg(long)]
        json: bool,
        /// Tool table in LinuxCNC's format, for programs with `G43 H` (see `simulate`).
        #[arg(long, value_name = "TOOL.TBL")]
        tools: Option<PathBuf>,
    },
    /// Compare the parameter-update methods on programs (a Markdown table).
    ///
    /// Simulates each program with taylor1, taylor2 and arclength and prints feed
    /// fluctuation, chord error and the axis velocities and accelerations over their limits
    /// (the plan is checked on the arclength setpoints; the Taylor methods drift from it).
    #[command(after_help = crate::exit::TABLE)]
    Compare {
        /// NC programs to compare on.
        #[arg(required = true)]
        programs: Vec<PathBuf>,
        /// Machine file (TOML).
        #[arg(long, short)]
        machine: PathBuf,
        #[command(flatten)]
        shop: crate::shop::ShopArgs,
    },
}

#[derive(Subcommand, Clone, Debug, PartialEq)]
pub enum CtlCommand {
    /// Print the state: for serve, the machine's state, homed axes, axes, program line,
    /// override, the last message (one JSON line); for a run, its stage, line and axes.
    Status {
        /// Print it again every 200 ms when it has changed (under serve it always has: its
        /// periods count) until the controller
        /// ends (Ctrl-C to leave).
        #[arg(long)]
        watch: bool,
    },
    /// Decelerate along the path within the limits and hold there.
    Pause,
    /// Go on after a pause (or an M00/M01 stop).
    Resume,
    /// Stop what moves: a program along its path, a jog jerk-limited, homing. (A run then
    /// disables the drives and ends, exit 4; serve holds them enabled.)
    Stop,
    /// Feed override, 0..=100 % of the planned feed.
    Override {
        /// Percent, 0..=100.
        #[arg(value_parser = clap::value_parser!(u8).range(0..=100))]
        percent: u8,
    },
    /// serve: enable the drives, holding where they stand.
    On,
    /// serve: disable the drives (at rest).
    Off,
    /// serve: home AXIS, or every axis in the machine file's sequence.
    Home {
        /// X, Y, Z, A, B or C.
        axis: Option<String>,
    },
    /// serve: jog AXIS + or -: by --step (incremental), or continuously while ctl holds
    /// the key (--for), renewing the controller's 200 ms dead-man every 50 ms; ctl ended
    /// (Ctrl-C) stops it at once.
    Jog {
        /// X, Y, Z, A, B or C.
        axis: String,
        /// + or -.
        #[arg(value_parser = ["+", "-"], allow_hyphen_values = true)]
        dir: String,
        /// Distance, mm or degrees: an incremental jog.
        #[arg(long)]
        step: Option<f64>,
        /// Speed, mm/s or degrees/s (default a tenth of the axis's velocity limit).
        #[arg(long)]
        speed: Option<f64>,
        /// `machine`: the axis itself; `work`: the workpiece's X, Y or Z at the table's
        /// angles; `tool`: along the tool axis (axis Z). For work and tool X Y Z move
        /// together, the rotary axes still.
        #[arg(long, default_value = "machine", value_parser = ["machine", "work", "tool"])]
        frame: String,
        /// A continuous jog lasts this long, then ctl lets go, 1ms..=1h.
        #[arg(long = "for", default_value = "1s", value_parser = hold, conflicts_with = "step")]
        hold_ns: u64,
    },
    /// serve: one NC line, run from where the machine stands (the modes carry on).
    Mdi {
        /// The line (its words may be given as separate arguments).
        #[arg(required = true, allow_hyphen_values = true, num_args = 1..)]
        line: Vec<String>,
    },
    /// serve: read and check a program (the controller reads the file).
    Load { file: PathBuf },
    /// serve: run the loaded program from where the machine stands; or restart it from a
    /// line: the lines before read without moving, the spindle and coolant they left
    /// restored, the tool backing off along its axis, over, and down onto the restart
    /// pose. Without --confirm the answer says what that approach would be and nothing
    /// moves.
    Run {
        /// Restart from this line (from 1).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        from_line: Option<u32>,
        /// With --from-line: how far the tool backs off along its axis and stands above the
        /// restart pose, mm (0 < MM <= 1000; default 10).
        #[arg(long, value_name = "MM", requires = "from_line")]
        clearance: Option<f64>,
        /// With --from-line: the operator has seen the approach; go.
        #[arg(long, requires = "from_line")]
        confirm: bool,
    },
    /// serve: single block: from rest, the loaded program a block at a time (each block ends
    /// at rest and waits); while it waits, the next block. `resume` runs on.
    Step,
    /// serve: acknowledge a fault or the e-stop (the CiA-402 fault-reset edge); the drives
    /// end disabled.
    Reset,
    /// serve: quick-stop and disable every drive.
    Estop,
}

/// `ctl jog --for`: 1 ms..=1 h.
fn hold(s: &str) -> Result<u64, String> {
    let ns = duration(s)?;
    if !(MS..=60 * MIN).contains(&ns) {
        return Err(format!("{s}: must be in 1ms..=1h"));
    }
    Ok(ns)
}

/// `--cpu N [--idle-poll]` of `demo` and `latency`.
#[derive(clap::Args, Clone, Copy)]
pub struct CpuArgs {
    /// Pin the real-time thread to this CPU (pair with isolcpus= on the kernel command
    /// line) and keep dnurbs's other threads off it. Must be one this process may use.
    #[arg(long, value_parser = cpu)]
    pub cpu: Option<usize>,
    /// Keep the --cpu CPU busy between periods with a SCHED_IDLE polling thread, so it
    /// never halts (a user-space idle=poll for that CPU). Helps on virtual machines and PCs
    /// without a cpuidle driver; costs that CPU's power. Needs --cpu.
    #[arg(long, requires = "cpu")]
    pub idle_poll: bool,
}

impl CpuArgs {
    pub fn settings(&self, priority: Option<i32>) -> rt_loop::thread::RtSettings {
        rt_loop::thread::RtSettings {
            priority,
            cpu: self.cpu,
            idle_poll: self.idle_poll,
        }
    }
}

const NS: u64 = 1;
const US: u64 = 1_000;
const MS: u64 = 1_000_000;
const S: u64 = 1_000_000_000;
const MIN: u64 = 60 * S;
const DAY: u64 = 24 * 60 * MIN;

/// A duration as written on the command line: a number and a unit (`ns`, `us`/`µs`, `ms`,
/// `s`, `min`), into nanoseconds. `0` alone is accepted (it is zero in every unit); any
/// other bare number is refused with a hint.
pub fn duration(s: &str) -> Result<u64, String> {
    let t = s.trim();
    if t == "0" {
        return Ok(0);
    }
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let value: f64 = num
        .parse()
        .map_err(|_| format!("{s:?} is not a duration: write a number and a unit, like 10ms"))?;
    let scale = match unit.trim() {
        "" => {
            return Err(format!(
                "{s:?} has no unit: write {num}ms, {num}s, {num}us, ... (units ns, us, ms, s, min)"
            ))
        }
        "ns" => NS,
        "us" | "µs" => US,
        "ms" => MS,
        "s" => S,
        "min" => MIN,
        other => {
            return Err(format!(
                "{s:?}: unknown unit {other:?}: use ns, us, ms, s or min"
            ))
        }
    };
    let ns = value * scale as f64;
    if !(ns.is_finite() && ns < 1e18) {
        return Err(format!("{s:?} is too long"));
    }
    Ok(ns.round() as u64)
}

/// Write `ns` with the largest unit that keeps it readable.
pub fn show(ns: u64) -> String {
    let units = [
        (DAY, "days"),
        (MIN, "min"),
        (S, "s"),
        (MS, "ms"),
        (US, "us"),
    ];
    for (scale, name) in units {
        if ns >= scale && ns % scale == 0 {
            return format!("{}{name}", ns / scale);
        }
    }
    format!("{ns}ns")
}

/// [`duration`] within `lo..=hi`; the error states the range.
fn within(s: &str, lo: u64, hi: u64) -> Result<u64, String> {
    let ns = duration(s)?;
    if ns < lo || ns > hi {
        return Err(format!(
            "{s:?} is out of range {}..={}",
            if lo == 0 { "0".to_owned() } else { show(lo) },
            show(hi)
        ));
    }
    Ok(ns)
}

/// `latency --period`: the machine file's range, 100us..=100ms.
pub fn period(s: &str) -> Result<u64, String> {
    within(s, 100 * US, 100 * MS)
}

fn measure_duration(s: &str) -> Result<u64, String> {
    within(s, MS, 7 * DAY)
}

fn sim_duration(s: &str) -> Result<u64, String> {
    within(s, MS, 30 * DAY)
}

fn lag(s: &str) -> Result<u64, String> {
    within(s, 0, 10 * S)
}

/// `demo --lead`: 0 or up to half the demo's 2 ms period.
fn lead(s: &str) -> Result<u64, String> {
    within(s, 0, MS)
}

/// `--cpu N`: a CPU this process may run on.
fn cpu(s: &str) -> Result<usize, String> {
    let n: usize = s
        .parse()
        .map_err(|_| format!("{s:?} is not a CPU number"))?;
    let allowed = rt_loop::os::allowed_cpus();
    if allowed.contains(&n) {
        return Ok(n);
    }
    Err(format!(
        "CPU {n} is not one this process may use (allowed: {})",
        allowed
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_need_a_unit_and_state_their_range() {
        assert_eq!(duration("500us"), Ok(500 * US));
        assert_eq!(duration("1.5ms"), Ok(1_500 * US));
        assert_eq!(duration("2min"), Ok(2 * MIN));
        assert_eq!(duration("0"), Ok(0));
        let bare = duration("5").unwrap_err();
        assert!(bare.contains("no unit") && bare.contains("5ms"), "{bare}");
        assert!(duration("5 parsec").unwrap_err().contains("unknown unit"));
        assert!(duration("ms").unwrap_err().contains("not a duration"));
        let zero = period("0ms").unwrap_err();
        assert!(zero.contains("100us..=100ms"), "{zero}");
        assert!(lead("2ms").unwrap_err().contains("0..=1ms"));
        assert_eq!(show(7 * DAY), "7days");
        assert_eq!(show(1_500 * US), "1500us");
    }

    #[test]
    fn a_cpu_this_process_cannot_use_is_refused() {
        let allowed = rt_loop::os::allowed_cpus();
        assert!(cpu(&allowed[0].to_string()).is_ok());
        let e = cpu("4095").unwrap_err();
        assert!(e.contains("allowed"), "{e}");
    }
}
