//! Is `dnurbs simulate` linear in the program, and bounded in memory? The wiggle of the
//! bench `stream` (0.05 mm G01 moves at F3000, `N`, `X Y Z`, `I J K`) is written to a file
//! in the temporary directory and simulated as `simulate` does it past 8 MiB: read a line
//! at a time, compressed when asked, built, planned and interpolated through the rolling
//! window (`simulate::roll`), every setpoint into the summary (`Summarizer`). Per size: the
//! time to the first setpoint that moves, the whole run, its lines a second, the peak
//! resident memory (reset before each size with `/proc/self/clear_refs`), and the ratio to
//! the size before (10x the moves should cost at most 11x the time).
//!
//! Run: `cargo bench -p dnurbs-tools --bench linear` (10^5 and 10^6 moves);
//! `BENCH_MOVES=100000,1000000,10000000` for 10^7 (a 700 MB file, deleted afterwards);
//! `BENCH_COMPRESS=1` to compress the runs of moves on the way (`--compress`).

mod common;

use dnurbs_tools::simulate::{roll, stepping, Summarizer};
use nc_lang::{Entries, Setup};
use nc_plan::interp::Method;
use std::time::Instant;

fn main() {
    if !common::benching() {
        return;
    }
    let sizes = common::sizes("100000,1000000");
    let compress = common::compressing();
    let (_, setup) = common::paper_machine();
    let setup = setup.with_compress(Some(compress));
    let shop = Setup::default();
    println!(
        "simulate streamed (read, {}build, plan, interpolate, summary) on {} sizes, paper-ac-table:",
        if compress { "compress, " } else { "" },
        sizes.len()
    );
    let mut before: Option<(usize, f64)> = None;
    for &n in &sizes {
        let (path, _) = common::wiggle_file("linear", n);
        common::reset_peak();
        let clock = Instant::now();
        let lines = common::read_lines(&path);
        let mut summary = Summarizer::new(&setup);
        let mut first = None;
        let step = stepping(&setup, Method::ArcLength);
        let rolled = roll(Entries::new(lines, &shop), &setup, step, |sp, w| {
            if sp.cycle == 1 {
                first = Some(clock.elapsed().as_secs_f64());
            }
            summary.push(sp, w);
        })
        .expect("the wiggle plans");
        let s = summary.finish(
            &rolled.plan,
            rolled.rolling.last_segment(),
            Method::ArcLength,
            rolled.blocks,
        );
        let secs = clock.elapsed().as_secs_f64();
        let peak = common::peak_mb();
        let _ = std::fs::remove_file(&path);
        assert!(s.end_position_error_mm < 1e-3, "the run ends at the end");
        let lines = n + 5;
        print!(
            "{n:>9} moves: first setpoint {:.3} s, all {secs:.2} s ({:.0} s of machining, {} blocks), {:.0} lines/s, window {} segments, peak resident {peak:.1} MB",
            first.unwrap_or(f64::NAN),
            s.machining_time_s,
            rolled.blocks,
            lines as f64 / secs,
            rolled.rolling.most_held(),
        );
        common::end_line(&mut before, n, secs);
    }
}
