//! Is `dnurbs simulate` linear in the program? A wiggly G01 path of 0.05 mm moves (the
//! dense CAM program of issue 12) through each stage on the paper machine: parse, build
//! (segments), plan (S-curves and the setpoint check's rounds), and interpolate with the
//! summary streamed as simulate does it. Prints each stage's time (the best of
//! `BENCH_REPEAT` runs, default 3) per size, the ratio to the size before (10x the moves
//! should cost at most 11x), and the peak resident memory from the parse on.
//!
//! Run: `cargo bench -p dnurbs-tools --bench linear` (10 000 and 100 000 moves);
//! `BENCH_MOVES=10000,100000,1000000` for other sizes (1 000 000 needs about 0.8 GB).

use dnurbs_tools::setup::MachineSetup;
mod common;

use dnurbs_tools::simulate::{each_setpoint, Summarizer};
use nalgebra::Vector3;
use nc::interp::{Method, Window};
use nc::plan::Finished;
use std::time::{Duration, Instant};

/// The n-move wiggle ([`common::wiggle_point`]) as a G01 program.
fn wiggle(n: usize) -> String {
    let points: Vec<_> = (0..=n)
        .map(|k| {
            let (x, y) = common::wiggle_point(k);
            (Vector3::new(x, y, 0.0), Vector3::z())
        })
        .collect();
    nc::fixtures::g01_program(&points, 3000.0)
}

#[derive(Clone, Copy, Default)]
struct Times {
    parse: Duration,
    build: Duration,
    plan: Duration,
    run: Duration,
    /// Peak resident memory from the parse on, MB (the program text, already read, in it).
    peak_mb: f64,
}

impl Times {
    fn stages(&self) -> [(&'static str, Duration); 4] {
        [
            ("parse", self.parse),
            ("build", self.build),
            ("plan", self.plan),
            ("interpolate+summarize", self.run),
        ]
    }
}

fn once(src: &str, setup: &MachineSetup) -> Times {
    let mut t = Times::default();
    common::reset_peak();
    let clock = Instant::now();
    let program = nc::parse::parse(src).expect("the wiggle parses");
    t.parse = clock.elapsed();
    let clock = Instant::now();
    let path = nc::segment::build(&program, &setup.kin, &setup.build).expect("it builds");
    t.build = clock.elapsed();
    let clock = Instant::now();
    let profile = nc::plan::plan(&path, &setup.kin, &setup.plan).expect("it plans");
    t.plan = clock.elapsed();
    // As `dnurbs simulate` does it: each setpoint into the summary as it is made.
    let clock = Instant::now();
    let mut summary = Summarizer::new(setup);
    let whole = Window {
        segments: &path.segments,
        first: 0,
    };
    each_setpoint(&path, &profile, setup, Method::ArcLength, |sp| {
        summary.push(sp, whole)
    })
    .expect("it ends");
    let plan = Finished {
        length: profile.length,
        duration: profile.duration,
        margins: profile.margins,
    };
    let summary = summary.finish(
        &plan,
        path.segments.last(),
        Method::ArcLength,
        program.blocks.len(),
    );
    t.run = clock.elapsed();
    t.peak_mb = common::peak_mb();
    assert!(
        summary.end_position_error_mm < 1e-3,
        "the run ends at the program's end"
    );
    t
}

fn main() {
    if !common::benching() {
        return;
    }
    let sizes = common::sizes("10000,100000");
    let repeat: usize = std::env::var("BENCH_REPEAT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let (_, setup) = common::paper_machine();
    println!(
        "simulate's stages on {n} sizes (best of {repeat}), paper-ac-table:",
        n = sizes.len()
    );
    let mut before: Option<(usize, Times)> = None;
    for &n in &sizes {
        let src = wiggle(n);
        let best = (0..repeat)
            .map(|_| once(&src, &setup))
            .fold(None, |b: Option<Times>, t| {
                Some(match b {
                    None => t,
                    Some(b) => Times {
                        parse: b.parse.min(t.parse),
                        build: b.build.min(t.build),
                        plan: b.plan.min(t.plan),
                        run: b.run.min(t.run),
                        peak_mb: b.peak_mb.max(t.peak_mb),
                    },
                })
            });
        let best = best.expect("BENCH_REPEAT >= 1");
        let total: Duration = best.stages().iter().map(|s| s.1).sum();
        print!("{n:>9} moves: total {:>9.3} s", total.as_secs_f64());
        for (name, d) in best.stages() {
            print!("  {name} {:.3} s", d.as_secs_f64());
            if let Some((m, b)) = before {
                let prev = b
                    .stages()
                    .iter()
                    .find(|s| s.0 == name)
                    .map_or(Duration::ZERO, |s| s.1);
                let r = d.as_secs_f64() / prev.as_secs_f64().max(1e-9);
                print!(" ({r:.1}x for {:.0}x)", n as f64 / m as f64);
            }
        }
        println!("  peak resident {:.0} MB", best.peak_mb);
        before = Some((n, best));
    }
}
