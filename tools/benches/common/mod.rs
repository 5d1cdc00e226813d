//! What the benches `linear`, `prepass` and `stream` share: the program sizes to run, the
//! dense G01 path they run (in memory, or written to a file), and the process's peak
//! resident memory.
#![allow(dead_code)] // each bench uses part of it

use std::io::{BufWriter, Write};

/// The paper machine (`config/machines/paper-ac-table.toml`) and its nc types.
pub fn paper_machine() -> (config::Machine, dnurbs_tools::setup::MachineSetup) {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../config/machines/paper-ac-table.toml"
    );
    let machine = config::load(std::path::Path::new(file)).expect("the paper machine loads");
    let setup = dnurbs_tools::setup::MachineSetup::new(&machine);
    (machine, setup)
}

/// `cargo bench` passes `--bench`; `cargo test --benches` does not, and only builds it.
pub fn benching() -> bool {
    std::env::args().any(|a| a == "--bench")
}

/// The sizes (moves) in `BENCH_MOVES`, comma-separated, else `default`.
pub fn sizes(default: &str) -> Vec<usize> {
    std::env::var("BENCH_MOVES")
        .unwrap_or_else(|_| default.into())
        .split(',')
        .map(|s| {
            s.trim()
                .parse()
                .expect("BENCH_MOVES: sizes separated by commas")
        })
        .collect()
}

/// The k-th point of the wiggle: moves of 0.05 mm along a sine in XY, in rows of 580 mm
/// 2 mm apart, starting over after 120 rows (240 mm: the paper machine's Y travel is +-250),
/// so any number of moves stays inside the travel.
pub fn wiggle_point(k: usize) -> (f64, f64) {
    let d = k as f64 * 0.05;
    let x = -290.0 + d % 580.0;
    let y = 2.0 * ((d / 580.0).floor() % 120.0) + 0.5 * (x / 2.0).sin();
    (x, y)
}

/// Forget the peak resident memory so far: [`peak_mb`] then measures from here.
pub fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// The process's peak resident memory since the last reset (VmHWM), in MB.
pub fn peak_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// Writes the n-move wiggle ([`wiggle_point`]) as `g01_program` would.
pub fn write_wiggle(path: &std::path::Path, n: usize) -> std::io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    w.write_all(b"%\nG90 G21 G94\n")?;
    for k in 0..=n {
        let (x, y) = wiggle_point(k);
        let g = if k < 2 { "G01 " } else { "" };
        let f = if k == 0 { " F3000" } else { "" };
        writeln!(
            w,
            "N{} {g}X{x:.4} Y{y:.4} Z{:.4} I{:.6} J{:.6} K{:.6}{f}",
            10 * (k + 1),
            0.0,
            0.0,
            0.0,
            1.0
        )?;
    }
    w.write_all(b"M30\n%\n")?;
    w.flush()
}

/// End a size's line with the ratio of its time to the size before's (10x the moves should
/// cost at most 11x the time), and remember this one.
pub fn end_line(before: &mut Option<(usize, f64)>, n: usize, secs: f64) {
    if let Some((m, t)) = *before {
        print!(
            " ({:.1}x the time for {:.0}x)",
            secs / t,
            n as f64 / m as f64
        );
    }
    println!();
    *before = Some((n, secs));
}

/// `BENCH_COMPRESS=1`: compress the runs of moves on the way (`--compress`).
pub fn compressing() -> bool {
    std::env::var("BENCH_COMPRESS").is_ok_and(|v| v == "1")
}

/// The n-move wiggle written to a file of the temporary directory named for `bench`, and
/// its size in bytes (the caller removes it).
pub fn wiggle_file(bench: &str, n: usize) -> (std::path::PathBuf, u64) {
    let path = std::env::temp_dir().join(format!("dnurbs-{bench}-{}-{n}.nc", std::process::id()));
    write_wiggle(&path, n).expect("the program is written");
    let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
    (path, bytes)
}

/// The lines of a program file, read as `dnurbs run` and `simulate` read them.
pub fn read_lines(path: &std::path::Path) -> nc_lang::ReadLines<std::io::BufReader<std::fs::File>> {
    let file = std::fs::File::open(path).expect("the program opens");
    nc_lang::ReadLines::new(std::io::BufReader::with_capacity(1 << 16, file))
}
