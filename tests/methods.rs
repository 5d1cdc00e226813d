//! Issue 56: whatever the method, machine file or option, a setpoint over a limit is never
//! reported as a success. Every shipped machine file, with every method, on the classics,
//! the test programs and two real 5-axis table-tilting programs (LinuxCNC's boat, A/C and
//! B/C, G93): `simulate` exits 0 only with every axis within its limits, and a Taylor
//! method over a limit exits 2 (arc length, the method `run` sends, is never over one).
//! The shipped files name arc length, what `run` sends.

mod common;

use common::{data, dnurbs, root};

/// Beside the planner's test programs and classics (`nc_plan::fixtures::TEST_PROGRAMS`).
const MORE: [&str; 1] = ["classics/helix-500.nc"];

const REAL: [&str; 2] = ["linuxcnc-boat-xyzac.ngc", "linuxcnc-boat-xyzbc.ngc"];

#[test]
fn no_method_on_any_shipped_machine_reports_a_setpoint_over_a_limit_as_success() {
    let mut files: Vec<_> = std::fs::read_dir(root().join("config/machines"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 4, "{files:?}");
    let programs: Vec<_> = nc_plan::fixtures::TEST_PROGRAMS
        .iter()
        .chain(&MORE)
        .map(|p| data(p))
        .chain(
            REAL.iter()
                .map(|p| root().join("tests/corpus/programs").join(p)),
        )
        .collect();
    let (mut ran, mut over) = (0, Vec::new());
    for m in &files {
        let text = std::fs::read_to_string(m).unwrap();
        assert!(
            text.contains("method = \"arclength\""),
            "{}: a shipped machine uses what run sends",
            m.display()
        );
        for p in &programs {
            for method in ["taylor1", "taylor2", "arclength"] {
                let out = dnurbs(&[
                    "simulate",
                    p.to_str().unwrap(),
                    "--machine",
                    m.to_str().unwrap(),
                    "--method",
                    method,
                    "--json",
                ]);
                // Refused for the machine (another tilting axis, the travel): no summary.
                let Ok(s) = serde_json::from_slice::<serde_json::Value>(&out.stdout) else {
                    assert_ne!(out.status.code(), Some(0), "{p:?} {m:?}");
                    continue;
                };
                ran += 1;
                let listed = s["limits_exceeded"].as_array().map_or(0, Vec::len);
                let what = format!("{} on {} with {method}", p.display(), m.display());
                match out.status.code() {
                    Some(0) => assert_eq!(listed, 0, "{what}: exit 0 over a limit: {s}"),
                    Some(2) => {
                        assert!(listed > 0, "{what}: exit 2 within the limits");
                        assert_ne!(method, "arclength", "{what}");
                        over.push(what);
                    }
                    c => panic!(
                        "{what}: exit {c:?}: {}",
                        String::from_utf8_lossy(&out.stderr)
                    ),
                }
            }
        }
    }
    // Enough ran, and the Taylor excess the issue measured (the boat on the A/C mill) is
    // among those refused.
    assert!(ran >= 40, "only {ran} simulations had a summary");
    assert!(
        over.iter()
            .any(|w| w.contains("boat-xyzac") && w.contains("xyzac-trt-mill")),
        "{over:#?}"
    );
    eprintln!(
        "{ran} simulations with a summary, {} over a limit (exit 2)",
        over.len()
    );
}
