//! Is the fit linear in the program, and bounded in memory? A blade-like 5-axis sweep (a
//! climbing arc of 30 mm radius in moves of 0.1 mm, the tool leaning 5 to 25 degrees toward
//! the axis and swinging with it) is generated a line at a time, parsed and fitted into
//! G06.5 blocks as it is read (`nc_fit::online::Compressing`, the compressor `simulate
//! --compress` and `run` use: runs of at most 5 000 moves). Per size: moves fitted, blocks,
//! the time, moves a second and the peak resident memory (reset before each size), and
//! the ratio to the size before (10x the moves should cost at most 11x the time).
//!
//! Run: `cargo bench -p dnurbs-tools --bench fit_stream` (10^5 and 10^6 moves);
//! `BENCH_MOVES=100000,1000000,10000000` for 10^7.

mod common;

use nc_fit::online::Compressing;
use nc_fit::options::{Options, Policy};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::{Block, SrcPos};
use nc_lang::{Entries, Entry, LineSource, ParseError, Setup};
use std::fmt::Write;
use std::time::Instant;

/// The sweep's lines, made as they are read.
struct Sweep {
    moves: usize,
    line: u32,
    text: String,
}

impl LineSource for Sweep {
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>> {
        self.line += 1;
        self.text.clear();
        let k = self.line as usize - 2;
        match self.line {
            1 => self.text.push_str("G90 G21 G94"),
            _ if k <= self.moves => {
                let (r, pitch) = (30.0, 0.2);
                let dtheta = 0.1 / f64::hypot(r, pitch);
                let th = k as f64 * dtheta;
                let lean = (15.0 + 10.0 * (th / 3.0).sin()).to_radians();
                let (s, c) = th.sin_cos();
                let g = if k < 2 { "G01 " } else { "" };
                let _ = write!(
                    self.text,
                    "{g}X{:.4} Y{:.4} Z{:.4} I{:.6} J{:.6} K{:.6}{}",
                    r * c,
                    r * s,
                    pitch * th,
                    -lean.sin() * c,
                    -lean.sin() * s,
                    lean.cos(),
                    if k == 0 { " F3000" } else { "" }
                );
            }
            _ if k == self.moves + 1 => self.text.push_str("M30"),
            _ => return None,
        }
        Some(Ok((self.line, &self.text)))
    }

    fn eof(&self) -> SrcPos {
        SrcPos {
            line: self.line,
            col: 1,
        }
    }
}

fn main() {
    if !common::benching() {
        return;
    }
    let sizes = common::sizes("100000,1000000");
    let setup = Setup::default();
    println!(
        "the fit streamed (generate, parse, fit) on {} sizes, 1 um / 0.01 deg:",
        sizes.len()
    );
    let mut before: Option<(usize, f64)> = None;
    for &n in &sizes {
        common::reset_peak();
        let clock = Instant::now();
        let lines = Sweep {
            moves: n,
            line: 0,
            text: String::new(),
        };
        let kin = MachineKinematics::Paper;
        let mut c = Compressing::new(
            Entries::new(lines, &setup),
            &kin,
            Policy::on(Options::default()),
        );
        let mut blocks = 0;
        for e in c.by_ref() {
            if let Entry::Block(_, Block::Nurbs(_)) = e.expect("the sweep parses") {
                blocks += 1;
            }
        }
        let secs = clock.elapsed().as_secs_f64();
        let peak = common::peak_mb();
        let done = c.compressed().expect("compression is on");
        assert_eq!(done.runs_kept, 0, "every run fits: {done:?}");
        print!(
            "{n:>9} moves: {} fitted into {blocks} blocks ({:.2} um, {:.4} deg at most) in {secs:.2} s, {:.0} moves/s, peak resident {peak:.1} MB",
            done.moves_fitted,
            done.fit_mm * 1e3,
            done.fit_deg,
            n as f64 / secs,
        );
        common::end_line(&mut before, n, secs);
    }
}
