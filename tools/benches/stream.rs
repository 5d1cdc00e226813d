//! `dnurbs run`'s planner over long programs: the program read from a file, parsed, built,
//! planned and cut into chunks a line at a time (`nc_plan::stream::Source`, what the planner
//! thread runs), the chunks dropped as the real-time thread would free them. The wiggle of
//! the bench `linear` (0.05 mm G01 moves at F3000, `N`, `X Y Z`, `I J K`) is written to a
//! file in the temporary directory. Per size: the time to the first chunk (when motion could
//! start), the time to plan the whole program and its lines a second, the chunks, and the
//! peak resident memory (reset before each size with `/proc/self/clear_refs`): it should not
//! grow with the program, and the time should grow as the program (10x the lines, at most
//! 11x the time).
//!
//! Run: `cargo bench -p dnurbs-tools --bench stream` (10^5 and 10^6 moves);
//! `BENCH_MOVES=100000,1000000,10000000` for 10^7 (a 700 MB file, deleted afterwards);
//! `BENCH_COMPRESS=1` to compress the runs of moves on the way (`--compress`).

mod common;

use nc_fit::online::Compressing;
use nc_lang::{Entries, Setup};
use nc_plan::stream::Source;
use std::time::Instant;

fn main() {
    if !common::benching() {
        return;
    }
    let sizes = common::sizes("100000,1000000");
    let (machine, setup) = common::paper_machine();
    let compress = common::compressing();
    let setup = setup.with_compress(Some(compress));
    let shop = Setup::default();
    let depth = machine.realtime.queue_depth;
    println!(
        "run's planner (parse, {}build, plan, cut) on {} sizes, paper-ac-table, queue depth {depth}:",
        if compress { "compress, " } else { "" },
        sizes.len()
    );
    let mut before: Option<(usize, f64)> = None;
    for &n in &sizes {
        let (path, bytes) = common::wiggle_file("stream", n);
        common::reset_peak();
        let clock = Instant::now();
        let lines = common::read_lines(&path);
        let m = setup.machine();
        let entries = Compressing::new(Entries::new(lines, &shop), &setup.kin, setup.compress);
        let mut source = Source::new(entries, m, depth);
        let mut first = None;
        let (mut chunks, mut segments) = (0usize, 0usize);
        while let Some(c) = source.next_chunk().expect("the wiggle plans") {
            first.get_or_insert_with(|| clock.elapsed().as_secs_f64());
            chunks += 1;
            segments += c.segments.len();
        }
        let secs = clock.elapsed().as_secs_f64();
        let peak = common::peak_mb();
        let _ = std::fs::remove_file(&path);
        if !compress {
            assert_eq!(segments, n, "every move is planned");
        }
        let lines = n + 5;
        print!(
            "{n:>9} moves ({:.0} MB): first chunk {:.3} s, all {secs:.2} s, {:.0} lines/s, {chunks} chunks, peak resident {peak:.1} MB",
            bytes as f64 / 1e6,
            first.unwrap_or(f64::NAN),
            lines as f64 / secs,
        );
        common::end_line(&mut before, n, secs);
    }
}
