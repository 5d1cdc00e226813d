//! The pre-pass (`dnurbs check`, `nc_plan::prepass`) over long programs: lines read per second
//! and the process's peak resident memory, per size. A wiggly G01 path of 0.05 mm moves
//! (the bench `linear`'s, as `nc_plan::fixtures::g01_program` writes it: `N`, `X Y Z`, `I J K`)
//! is written to a file in the temporary directory line by line, then read back through
//! the pre-pass on the paper machine. The peak is reset before each size
//! (`/proc/self/clear_refs`), so it is the pre-pass's own; it should not grow with the
//! program, and the time should grow as the program (10x the lines, at most 11x the time).
//!
//! Run: `cargo bench -p dnurbs-tools --bench prepass` (10^5 and 10^6 moves);
//! `BENCH_MOVES=100000,1000000,10000000` for 10^7 (a 700 MB file, deleted afterwards).

mod common;

use nc_lang::Setup;
use std::time::Instant;

fn main() {
    if !common::benching() {
        return;
    }
    let sizes = common::sizes("100000,1000000");
    let (_, setup) = common::paper_machine();
    println!("the pre-pass on {} sizes, paper-ac-table:", sizes.len());
    let mut before: Option<(usize, f64)> = None;
    for &n in &sizes {
        let (path, bytes) = common::wiggle_file("prepass", n);
        // Reset the peak: what follows is the pre-pass's alone.
        common::reset_peak();
        let clock = Instant::now();
        let lines = common::read_lines(&path);
        let passed = nc_plan::prepass::check(
            lines,
            &Setup::default(),
            &setup.kin,
            &setup.build,
            &setup.plan.travel,
        )
        .expect("the wiggle passes");
        let secs = clock.elapsed().as_secs_f64();
        let peak = common::peak_mb();
        let _ = std::fs::remove_file(&path);
        assert_eq!(passed.blocks, n + 1, "every move is read");
        print!(
            "{n:>9} moves ({:.0} MB, {} lines): {secs:.3} s, {:.2} M lines/s, peak resident {peak:.1} MB",
            bytes as f64 / 1e6,
            passed.lines,
            f64::from(passed.lines) / secs / 1e6
        );
        common::end_line(&mut before, n, secs);
    }
}
