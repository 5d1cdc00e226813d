//! Is `dnurbs simulate` linear in the program? A wiggly G01 path of 0.05 mm moves (the
//! dense CAM program of issue 12) through each stage on the paper machine: parse, build
//! (segments), plan (S-curves and the setpoint check's rounds), interpolate, summarize.
//! Prints each stage's time (the best of `BENCH_REPEAT` runs, default 3) per size, and the
//! ratio to the size before: 10x the moves should cost at most 11x.
//!
//! Run: `cargo bench -p dnurbs-tools --bench linear` (10 000 and 100 000 moves);
//! `BENCH_MOVES=10000,100000,1000000` for other sizes (1 000 000 needs about 2 GB).

use dnurbs_tools::setup::MachineSetup;
use dnurbs_tools::simulate::{interpolate, summarize, Run};
use nalgebra::Vector3;
use nc::interp::Method;
use std::time::{Duration, Instant};

const MACHINE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../config/machines/paper-ac-table.toml"
);

/// n moves of 0.05 mm along a sine in XY, in rows of 580 mm inside the paper machine's travel.
fn wiggle(n: usize) -> String {
    let points: Vec<_> = (0..=n)
        .map(|k| {
            let d = k as f64 * 0.05;
            let x = -290.0 + d % 580.0;
            let y = 2.0 * (d / 580.0).floor() + 0.5 * (x / 2.0).sin();
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
    interpolate: Duration,
    summarize: Duration,
}

impl Times {
    fn stages(&self) -> [(&'static str, Duration); 5] {
        [
            ("parse", self.parse),
            ("build", self.build),
            ("plan", self.plan),
            ("interpolate", self.interpolate),
            ("summarize", self.summarize),
        ]
    }
}

fn once(src: &str, setup: &MachineSetup) -> Times {
    let mut t = Times::default();
    let clock = Instant::now();
    let program = nc::parse::parse(src).expect("the wiggle parses");
    t.parse = clock.elapsed();
    let clock = Instant::now();
    let path = nc::segment::build(&program, &setup.kin, &setup.build).expect("it builds");
    t.build = clock.elapsed();
    let clock = Instant::now();
    let profile = nc::plan::plan(&path, &setup.kin, &setup.plan).expect("it plans");
    t.plan = clock.elapsed();
    let clock = Instant::now();
    let setpoints = interpolate(&path, &profile, setup, Method::ArcLength).expect("it ends");
    t.interpolate = clock.elapsed();
    let run = Run {
        path,
        profile,
        setpoints,
        method: Method::ArcLength,
    };
    let clock = Instant::now();
    let summary = summarize(&run, setup, program.blocks.len());
    t.summarize = clock.elapsed();
    assert!(
        summary.end_position_error_mm < 1e-3,
        "the run ends at the program's end"
    );
    t
}

fn main() {
    // `cargo bench` passes `--bench`; `cargo test --benches` does not, and only builds it.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let sizes: Vec<usize> = std::env::var("BENCH_MOVES")
        .unwrap_or_else(|_| "10000,100000".into())
        .split(',')
        .map(|s| {
            s.trim()
                .parse()
                .expect("BENCH_MOVES: sizes separated by commas")
        })
        .collect();
    let repeat: usize = std::env::var("BENCH_REPEAT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let machine = config::load(std::path::Path::new(MACHINE)).expect("the paper machine loads");
    let setup = MachineSetup::new(&machine);
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
                        interpolate: b.interpolate.min(t.interpolate),
                        summarize: b.summarize.min(t.summarize),
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
        println!();
        before = Some((n, best));
    }
}
