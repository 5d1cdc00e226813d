//! The interpreter over long programs with parameters on every line: lines read per second
//! and the process's peak resident memory, per size, beside the same moves written as plain
//! numbers. Each line of the parametric program assigns a numbered and a named parameter and
//! moves to an expression of them (the moves of the wiggle `prepass` reads):
//!
//! ```text
//! #1=[#1+1] #<y>=[0.5*SIN[[-290+[#1*0.05] MOD 580]*28.6478897565]]
//! G01 X[-290+[#1*0.05] MOD 580] Y[2*FIX[[#1*0.05]/580]+#<y>] Z0
//! ```
//!
//! (two lines a move). The file is written to the temporary directory, then read through
//! `nc_lang::Entries` (the interpreter and the modal state machine, as `check`, `simulate`
//! and `run` read programs) counting the blocks. The peak is reset before each size; it should
//! not grow with the program, and the time should grow as the program.
//!
//! Run: `cargo bench -p dnurbs-tools --bench interp` (10^5 and 10^6 lines); `BENCH_MOVES` for
//! other sizes (lines of the parametric program).

mod common;

use std::io::{BufWriter, Write};
use std::time::Instant;

fn write_parametric(path: &std::path::Path, lines: usize) -> std::io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    w.write_all(b"%\nG90 G21 G94\nG01 X-290 Y0 Z0 F3000\n#1=0 #<y>=0\n")?;
    for _ in 0..lines / 2 {
        w.write_all(
            b"#1=[#1+1] #<y>=[0.5*SIN[[-290+[#1*0.05] MOD 580]*28.6478897565]]\n\
              G01 X[-290+[#1*0.05] MOD 580] Y[[2*FIX[[#1*0.05]/580]] MOD 240+#<y>] Z0\n",
        )?;
    }
    w.write_all(b"M30\n%\n")?;
    w.flush()
}

fn read(path: &std::path::Path) -> (usize, u32) {
    let setup = nc_lang::Setup::default();
    let mut entries = nc_lang::Entries::new(common::read_lines(path), &setup);
    let mut blocks = 0;
    for e in entries.by_ref() {
        if let nc_lang::Entry::Block(..) = e.expect("the program reads") {
            blocks += 1;
        }
    }
    (blocks, entries.eof().line)
}

fn main() {
    if !common::benching() {
        return;
    }
    let sizes = common::sizes("100000,1000000");
    println!("the interpreter on {} sizes:", sizes.len());
    let mut before: Option<(usize, f64)> = None;
    for &n in &sizes {
        let path = std::env::temp_dir().join(format!("dnurbs-bench-interp-{n}.nc"));
        write_parametric(&path, n).expect("the program is written");
        let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
        common::reset_peak();
        let clock = Instant::now();
        let (blocks, lines) = read(&path);
        let secs = clock.elapsed().as_secs_f64();
        let peak = common::peak_mb();
        let _ = std::fs::remove_file(&path);
        assert_eq!(blocks, n / 2 + 1, "every move is read");
        print!(
            "{n:>9} lines with parameters ({:.0} MB): {secs:.3} s, {:.2} M lines/s, peak resident {peak:.1} MB",
            bytes as f64 / 1e6,
            f64::from(lines) / secs / 1e6
        );
        common::end_line(&mut before, n, secs);
        // The same moves as plain numbers (the wiggle), for the interpreter's cost.
        let (plain, _) = common::wiggle_file("interp", n / 2);
        common::reset_peak();
        let clock = Instant::now();
        let (blocks, lines) = read(&plain);
        let secs = clock.elapsed().as_secs_f64();
        let peak = common::peak_mb();
        let _ = std::fs::remove_file(&plain);
        assert!(blocks > n / 2, "every move is read");
        println!(
            "{:>9} lines of plain numbers: {secs:.3} s, {:.2} M lines/s, peak resident {peak:.1} MB",
            lines,
            f64::from(lines) / secs / 1e6
        );
    }
}
