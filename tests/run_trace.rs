//! `run --trace`: every target as sent to the drives, one row a period, written outside the
//! real-time thread from the queue it fills. On simulated drives on simulated time (the
//! stages of `dnurbs run`), the trace's targets are, node by node and period by period,
//! those the simulated drives recorded taking effect (`sim-drives --record` writes the same
//! records), and its axis columns are those targets in mm and degrees.

mod common;

use dnurbs_tools::demo::DEMO_PROGRAM;

#[test]
fn the_trace_holds_every_target_the_drives_received() {
    let machine = dnurbs_tools::demo::demo_machine().expect("the demo machine");
    let file = common::temp("run-trace.csv");
    let opts = dnurbs_tools::run::RunOptions {
        trace: Some(file.clone()),
        ..common::run_options("paper-example.nc", None)
    };
    let (r, records) = common::run_simulated(
        DEMO_PROGRAM.as_bytes(),
        &machine,
        |_| Default::default(),
        &opts,
        |_, _| {},
    );
    let rep = r.report("paper-example.nc", &machine.name);
    assert_eq!(rep.exit_code, 0, "{}", rep.text());
    let notes = rep.trace.clone().expect("the report says what was traced");
    assert_eq!(notes.dropped, 0);
    assert!(rep.text().contains("periods' targets in"), "{}", rep.text());
    let text = std::fs::read_to_string(&file).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        [
            "cycle", "t", "stage", "X", "Y", "Z", "A", "C", "can0:1", "can0:2", "can0:3", "can0:4",
            "can0:5"
        ]
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len() as u64, notes.rows);
    // Every period, in order; the program ran.
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[0].parse::<u64>().unwrap(), k as u64 + 1, "{r:?}");
    }
    assert!(rows.iter().any(|r| r[2] == "running"));
    // The axis columns are the targets in axis units.
    for r in &rows {
        for (j, d) in machine.drives.iter().enumerate() {
            let counts: i32 = r[8 + j].parse().unwrap();
            let pos: f64 = r[3 + d.axis].parse().unwrap();
            assert!((d.position(counts) - pos).abs() < 1e-9, "{r:?}");
        }
    }
    // Node by node: the targets the drives took, in order, are the trace's, from the
    // first SYNC the drives recorded to the last.
    for (j, d) in machine.drives.iter().enumerate() {
        let took: Vec<i32> = records
            .iter()
            .filter(|rec| rec.node == d.node)
            .map(|rec| rec.target_counts)
            .collect();
        let sent: Vec<i32> = rows.iter().map(|r| r[8 + j].parse().unwrap()).collect();
        assert!(!took.is_empty());
        assert!(
            took.len() <= sent.len(),
            "{} records, {} rows",
            took.len(),
            sent.len()
        );
        // Period for period from the first: the drives record each target as the SYNC
        // after it takes effect, so the last period's is not recorded when the run ends.
        assert!(
            sent.len() - took.len() <= 1,
            "{} records, {} rows",
            took.len(),
            sent.len()
        );
        let first_diff = took.iter().zip(&sent).position(|(a, b)| a != b);
        assert_eq!(
            first_diff, None,
            "node {}: first differs at period {first_diff:?}",
            d.node
        );
    }
    let _ = std::fs::remove_file(&file);
}
