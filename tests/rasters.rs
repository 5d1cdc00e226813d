//! The finishing rasters of issue 12, written by `tests/data/fit/raster.py` as the README's
//! measurements write them (32 rows of 60 mm, 19 510 G01 moves of 0.1 mm at F3000), through
//! the real binary on the xyzac-trt-mill: with compression the 3-axis raster runs within
//! 1.1x of its programmed-feed time, every programmed point on the commanded path within the
//! fit's and the chord's tolerances, every axis within its limits; so does the A/C raster
//! that leans the tool and turns A and C a little on every move, its programmed tool axes
//! within the fit's angle too; the tilted A/C raster, whose C the mill's limits hold back at
//! every row end, is accepted as posted and compressed, within the limits.

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

/// One programmed move of a raster.py program: the tool tip X Y Z and, for the A/C modes,
/// the tool axis its machine angles give (dnurbs's convention, `raster.py`'s header).
struct Move {
    p: [f64; 3],
    tool: Option<[f64; 3]>,
}

/// The programmed moves of a raster.py program.
fn programmed_moves(path: &PathBuf) -> Vec<Move> {
    let text = std::fs::read_to_string(path).unwrap();
    let word = |l: &str, w: char| -> Option<f64> {
        let i = l.find(w)?;
        let v = l[i + 1..].split(' ').next().unwrap();
        Some(v.parse().unwrap_or_else(|_| panic!("{w} of {l}")))
    };
    let must = |l: &str, w: char| word(l, w).unwrap_or_else(|| panic!("no {w} in {l}"));
    text.lines()
        .filter(|l| l.contains('X') && l.contains('Y'))
        .map(|l| Move {
            p: [must(l, 'X'), must(l, 'Y'), must(l, 'Z')],
            tool: word(l, 'A').map(|a| {
                let (a, c) = (a.to_radians(), must(l, 'C').to_radians());
                [-a.sin() * c.sin(), a.sin() * c.cos(), a.cos()]
            }),
        })
        .collect()
}

/// Distance from `p` to the segment a-b, and where along it (0..=1) the nearest point is.
fn to_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> (f64, f64) {
    let d: [f64; 3] = core::array::from_fn(|i| b[i] - a[i]);
    let w: [f64; 3] = core::array::from_fn(|i| p[i] - a[i]);
    let dd: f64 = d.iter().map(|x| x * x).sum();
    let t = if dd > 0.0 {
        (d.iter().zip(&w).map(|(x, y)| x * y).sum::<f64>() / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let dist = (0..3)
        .map(|i| (w[i] - t * d[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    (dist, t)
}

/// Angle in degrees between two directions.
fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
    norm(cross).atan2(dot).to_degrees()
}

/// The largest distance of a programmed point from the polyline of the commanded tool tips
/// (the trace, one point a period), and the largest angle between a programmed tool axis
/// and the commanded one at that nearest point (interpolated between the two periods'). Both
/// run along the path in order: each point is looked for from where the last one was found,
/// a window of periods on. 256 periods are 25 mm at the feed, 250 moves (a smaller window
/// can only find a point farther off, never nearer: it cannot hide a deviation).
fn largest_move_off_path(moves: &[Move], rows: &[Row]) -> (f64, f64) {
    const WINDOW: usize = 256;
    let mut from = 0;
    let (mut worst, mut worst_deg): (f64, f64) = (0.0, 0.0);
    for m in moves {
        let end = (from + WINDOW).min(rows.len() - 1);
        let (mut best, mut at, mut along) = (f64::INFINITY, from, 0.0);
        for k in from..end {
            let (d, t) = to_segment(m.p, rows[k].p, rows[k + 1].p);
            if d < best {
                (best, at, along) = (d, k, t);
            }
        }
        worst = worst.max(best);
        if let Some(tool) = m.tool {
            let (a, b) = (rows[at].tool, rows[at + 1].tool);
            let there = core::array::from_fn(|i| a[i] + along * (b[i] - a[i]));
            worst_deg = worst_deg.max(angle_deg(tool, there));
        }
        from = at;
    }
    (worst, worst_deg)
}

/// The raster `mode` compressed on the mill: 63 G06.5 blocks within the fit's tolerances,
/// every axis within its limits, the machining time within 1.1x of the programmed-feed
/// time, every programmed point within the fit's tolerance (1 um) plus the chord tolerance
/// of the setpoints' polyline against the curve (2 um on this machine), and every programmed
/// tool axis within the fit's 0.01 degree (the commanded axis between two periods taken on
/// their chord, off the turn by the square of a period's turn, some 1e-7 degree here).
fn runs_within_1_1x_of_its_programmed_feed_time(mode: &str) {
    let program = raster(mode);
    let moves = programmed_moves(&program);
    assert_eq!(moves.len(), 19_511);
    let length: f64 = moves
        .windows(2)
        .map(|w| {
            (0..3)
                .map(|i| (w[1].p[i] - w[0].p[i]).powi(2))
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
    eprintln!("{mode} raster: {time} s against {programmed:.3} s at the feed, {ratio:.4}x");
    assert!(ratio <= 1.1, "{time} s against {programmed} s: {ratio}x");
    let (off, off_deg) = largest_move_off_path(&moves, &rows);
    eprintln!(
        "{mode}: largest programmed point off the commanded path {:.3} um, tool axis {off_deg:.5} deg",
        off * 1e3
    );
    assert!(off <= 0.001 + f(&s, "chord_tolerance_mm"), "{off} mm");
    assert!(off_deg <= 0.0101, "{off_deg} deg");
}

#[test]
fn the_3axis_raster_compressed_runs_within_1_1x_of_its_programmed_feed_time() {
    runs_within_1_1x_of_its_programmed_feed_time("3axis");
}

/// The A/C variant as the issue measured it: the tool leaning 15 degrees and following a
/// tenth of the slope, A and C turning a little on every move (`raster.py lean-ac`).
#[test]
fn the_lean_ac_raster_compressed_runs_within_1_1x_of_its_programmed_feed_time() {
    runs_within_1_1x_of_its_programmed_feed_time("lean-ac");
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
