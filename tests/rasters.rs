//! The finishing rasters of issue 12, written by `tests/data/fit/raster.py` as the README's
//! measurements write them (32 rows of 60 mm, 19 510 G01 moves of 0.1 mm at F3000), through
//! the real binary on the xyzac-trt-mill: with compression the 3-axis raster runs within
//! 1.1x of its programmed-feed time, every programmed point on the commanded path within the
//! fit's and the chord's tolerances, every axis within its limits; the tilted A/C raster is
//! accepted as posted and compressed, within the limits.

mod common;
use common::*;
use std::path::PathBuf;

/// The raster `raster.py MODE` writes, in a temporary file.
fn raster(mode: &str) -> PathBuf {
    let out = std::process::Command::new("python3")
        .arg(data("fit/raster.py"))
        .arg(mode)
        .output()
        .expect("python3 runs tests/data/fit/raster.py");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let path = temp(&format!("raster-{mode}.nc"));
    std::fs::write(&path, &out.stdout).unwrap();
    path
}

/// The programmed points (X Y Z of every move) of a raster.py program.
fn programmed_points(path: &PathBuf) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(path).unwrap();
    let word = |l: &str, w: char| -> f64 {
        let i = l.find(w).unwrap_or_else(|| panic!("no {w} in {l}"));
        let v = l[i + 1..].split(' ').next().unwrap();
        v.parse().unwrap_or_else(|_| panic!("{w} of {l}"))
    };
    text.lines()
        .filter(|l| l.contains('X') && l.contains('Y'))
        .map(|l| [word(l, 'X'), word(l, 'Y'), word(l, 'Z')])
        .collect()
}

/// Distance from `p` to the segment a-b.
fn to_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d: [f64; 3] = core::array::from_fn(|i| b[i] - a[i]);
    let w: [f64; 3] = core::array::from_fn(|i| p[i] - a[i]);
    let dd: f64 = d.iter().map(|x| x * x).sum();
    let t = if dd > 0.0 {
        (d.iter().zip(&w).map(|(x, y)| x * y).sum::<f64>() / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|i| (w[i] - t * d[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The largest distance of a programmed point from the polyline of the commanded tool tips
/// (the trace, one point a period). Both run along the path in order: each point is looked
/// for from where the last one was found, a window of periods on.
fn largest_point_off_path(points: &[[f64; 3]], rows: &[Row]) -> f64 {
    const WINDOW: usize = 4000;
    let mut from = 0;
    let mut worst: f64 = 0.0;
    for p in points {
        let end = (from + WINDOW).min(rows.len() - 1);
        let (mut best, mut at) = (f64::INFINITY, from);
        for k in from..end {
            let d = to_segment(*p, rows[k].p, rows[k + 1].p);
            if d < best {
                (best, at) = (d, k);
            }
        }
        worst = worst.max(best);
        from = at;
    }
    worst
}

#[test]
fn the_3axis_raster_compressed_runs_within_1_1x_of_its_programmed_feed_time() {
    let program = raster("3axis");
    let points = programmed_points(&program);
    assert_eq!(points.len(), 19_511);
    let length: f64 = points
        .windows(2)
        .map(|w| {
            (0..3)
                .map(|i| (w[1][i] - w[0][i]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum();
    let programmed = length / 50.0; // F3000 mm/min
    let (s, rows) = simulate(
        program.to_str().unwrap(),
        "xyzac-trt-mill.toml",
        &["--compress"],
    );
    let _ = std::fs::remove_file(&program);
    assert_within_limits(&s);
    let c = &s["compressed"];
    assert_eq!(c["fitted_blocks"], 63, "{c}");
    assert!(f(c, "fit_mm") <= 0.001, "{c}");
    let time = f(&s, "machining_time_s");
    let ratio = time / programmed;
    eprintln!("3-axis raster: {time} s against {programmed:.3} s at the feed, {ratio:.4}x");
    assert!(ratio <= 1.1, "{time} s against {programmed} s: {ratio}x");
    // Every programmed point within the fit's tolerance (1 um) plus the chord tolerance of
    // the setpoints' polyline against the curve (2 um on this machine).
    let off = largest_point_off_path(&points, &rows);
    eprintln!(
        "largest programmed point off the commanded path: {:.3} um",
        off * 1e3
    );
    assert!(off <= 0.001 + f(&s, "chord_tolerance_mm"), "{off} mm");
}

/// The tool tilted 15 degrees: A and C turn on every move. As posted, every G01 junction
/// kinks A's and C's rates a little, and the setpoints' jerk across it is more than the path
/// jerk alone: the planner lowers the path's share of the axis's jerk where the check finds
/// it over (with the share never lowered the program was refused, C's jerk 1.13x its limit
/// at 0.76 mm/s).
#[test]
fn the_tilted_ac_raster_is_accepted_as_posted_and_compressed_within_the_limits() {
    let program = raster("tilted-ac");
    let path = program.to_str().unwrap();
    let (posted, _) = simulate(path, "xyzac-trt-mill.toml", &[]);
    assert_within_limits(&posted);
    let (compressed, _) = simulate(path, "xyzac-trt-mill.toml", &["--compress"]);
    let _ = std::fs::remove_file(&program);
    assert_within_limits(&compressed);
    assert_eq!(compressed["compressed"]["fitted_blocks"], 63);
    let (t0, t1) = (
        f(&posted, "machining_time_s"),
        f(&compressed, "machining_time_s"),
    );
    eprintln!("tilted A/C raster: {t0} s as posted, {t1} s compressed");
    assert!(t1 < t0);
}
