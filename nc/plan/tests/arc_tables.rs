//! The arc-length tables of every NURBS program the project ships (tests/data and the
//! published classics): each is accurate enough for the interpolated inverse alone (no
//! Newton step in the real-time thread), and its length agrees with an independent
//! integration of |C'| over the same curve.

use nc_geom::segment::{build, Geometry};

fn programs() -> Vec<String> {
    let root = format!("{}/../../tests/data", env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    for dir in [root.clone(), format!("{root}/classics")] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "nc") {
                out.push(p.display().to_string());
            }
        }
    }
    out.sort();
    out
}

/// Composite 8-point Gauss-Legendre over `n` equal steps of every knot span, through the
/// curve's own A2.3 evaluation (not the Bezier pieces the table is built from).
fn length(curve: &nc_geom::nurbs::DoubleNurbs, n: usize) -> f64 {
    let k = curve.knots();
    let mut s = 0.0;
    for w in k.windows(2).filter(|w| w[1] > w[0]) {
        for i in 0..n {
            let a = w[0] + (w[1] - w[0]) * i as f64 / n as f64;
            let b = w[0] + (w[1] - w[0]) * (i + 1) as f64 / n as f64;
            let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
            s += nc_geom::arclen::GL8
                .iter()
                .map(|&(x, wt)| wt * curve.speed(m + h * x))
                .sum::<f64>()
                * h;
        }
    }
    s
}

#[test]
fn every_shipped_table_inverts_within_the_tolerance_without_newton() {
    let (_, limits) = nc_plan::fixtures::adversarial_mill(0.002);
    let kin = nc_geom::kinematics::MachineKinematics::Paper;
    let mut tables = 0;
    for f in programs() {
        let src = std::fs::read_to_string(&f).unwrap();
        let program = nc_lang::parse(&src).unwrap_or_else(|e| panic!("{f}: {e}"));
        let path = build(&program, &kin, &limits).unwrap_or_else(|e| panic!("{f}: {e}"));
        for seg in &path.segments {
            if let Geometry::Nurbs { curve, table } = &seg.geometry {
                tables += 1;
                assert!(
                    !table.uses_newton()
                        && table.interpolation_error() <= nc_geom::arclen::TOLERANCE,
                    "{f}: line {}: inverse error {:e}",
                    seg.src.line,
                    table.interpolation_error()
                );
                let exact = length(curve, 512);
                assert!(
                    (table.length() - exact).abs() <= 1e-9 * (1.0 + exact),
                    "{f}: line {}: table {} vs {exact}",
                    seg.src.line,
                    table.length()
                );
            }
        }
    }
    assert!(tables > 300, "{tables} tables");
}
