//! `dnurbs fit`'s throughput: a blade-like sweep of 0.1 mm moves fitted into G06.5 blocks
//! (`nc_fit::runs::fit_program`, the parse excluded), at 3 000, 30 000 and 300 000 moves
//! (the cost should grow linearly). Run: `cargo bench -p nc --bench fit`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nc_fit::options::Options;
use nc_fit::runs::fit_program;
use nc_geom::kinematics::MachineKinematics;
use nc_plan::fixtures::{blade, g01_program, resample};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    for n in [3_000usize, 30_000, 300_000] {
        // 0.1 mm moves; the sweep climbs as it turns, so a long one never meets itself.
        let points = resample(blade, n as f64 * 0.1 / 35.0, n, 0.1);
        let src = g01_program(&points, 3000.0);
        let program = nc_lang::parse(&src).unwrap();
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(format!("{n} moves"), |b| {
            b.iter(|| {
                fit_program(
                    &src,
                    &program,
                    &MachineKinematics::Paper,
                    &Options::default(),
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
