//! `M62`..`M66` on a machine with a bus: the program's digital outputs are bits of its I/O
//! module as the drives' targets go out, and `M66` holds the path at rest until the
//! module's input answers or the wait's timeout passes. Against simulated drives on the
//! in-memory link on simulated time (the stages of `dnurbs run`), on the posts' machine,
//! whose coolant module carries the program's outputs 3..6 and inputs 3..6 (each input
//! wired to its output).

mod common;

/// Module output byte of the I/O module (node 7 on can1) at each SYNC, and X's targets.
fn run(src: &str) -> (dnurbs_tools::report::Report, Vec<i32>, Vec<i32>) {
    let m = config::load(&common::root().join("tests/data/posts/machine.toml"))
        .expect("the posts machine");
    let opts = common::run_options("io.ngc", None);
    let (r, records) =
        common::run_simulated(src.as_bytes(), &m, |_| Default::default(), &opts, |_, _| {});
    let rep = r.report("io.ngc", &m.name);
    // Node 7 is only on can1; node 1 (X) only on can0.
    let module: Vec<i32> = records
        .iter()
        .filter(|r| r.node == 7)
        .map(|r| r.target_counts)
        .collect();
    let x: Vec<i32> = records
        .iter()
        .filter(|r| r.node == 1)
        .map(|r| r.target_counts)
        .collect();
    (rep, module, x)
}

#[test]
fn outputs_reach_the_module_and_the_path_waits_for_its_inputs() {
    // P1 is module output 4 (bit 3); its input answers a period after it goes on. P2's
    // input never rises: the wait ends at its 0.5 s timeout and the path goes on.
    let src = "G21 G90 G94\nG0 X0 Y0 Z50\nM64 P1\nM66 P1 L3 Q5\nM66 P2 L1 Q0.5\n\
               G1 X20 F1200\nM65 P1\nM08\nG1 X40\nM9\nM2\n";
    let (rep, module, x) = run(src);
    assert_eq!(rep.exit_code, 0, "{}", rep.text());
    let t = rep.input_timeouts.expect("one wait timed out");
    assert_eq!((t.count, t.last_line), (1, Some(5)), "{}", rep.text());
    assert!(rep
        .text()
        .contains("M66 waits ended at their timeout: 1, the last at line 5"));
    // The output is on before X leaves 0, for at least the 0.5 s the path waited (2 ms
    // periods), and off with flood (output 2, bit 1) on for the last move.
    let on: Vec<usize> = (0..module.len())
        .filter(|&k| module[k] & 0x08 != 0)
        .collect();
    assert!(!on.is_empty(), "P1 never reached the module: {module:?}");
    let (first_on, last_on) = (on[0], *on.last().unwrap());
    assert!(
        module.iter().all(|b| b & !0x0a == 0),
        "only P1 and flood switch"
    );
    let x_leaves = x.iter().position(|&c| c != x[0]).expect("X moves");
    let x0 = x[0];
    let held = x[first_on.min(x.len() - 1)..]
        .iter()
        .take_while(|&&c| c == x0)
        .count();
    assert!(held >= 250, "the path waited {held} periods with P1 on");
    assert!(
        first_on < x_leaves,
        "P1 on at {first_on}, X left at {x_leaves}"
    );
    assert!(
        module.iter().any(|b| b & 0x02 != 0),
        "flood for the last move"
    );
    assert!(module.iter().skip(last_on + 1).all(|b| b & 0x08 == 0));
    assert_eq!(*module.last().unwrap(), 0, "all off at the end");
}

/// The posts' machine with its e-stop chain on module input 8 (`[io] estop_input`), and
/// the run of `src` with the simulated module's chain opening at SYNC `opens`.
fn run_with_estop(src: &str, opens: Option<u64>) -> dnurbs_tools::report::Report {
    let text = std::fs::read_to_string(common::root().join("tests/data/posts/machine.toml"))
        .expect("the posts machine")
        .replace("first_input = 3\n", "first_input = 3\nestop_input = 8\n");
    let path = common::temp("estop-machine.toml");
    std::fs::write(&path, text).expect("a temp file");
    let m = config::load(&path).expect("the posts machine with its e-stop");
    let _ = std::fs::remove_file(&path);
    assert_eq!(m.bus_io.and_then(|io| io.estop_input), Some(8));
    let opts = common::run_options("estop.ngc", None);
    let chain = drives::sim::EStopChain {
        bit: 7,
        opens,
        closes: None,
    };
    let faults = |n: u8| drives::sim::Faults {
        estop_chain: (n == 7).then_some(chain),
        ..Default::default()
    };
    let (r, _) = common::run_simulated(src.as_bytes(), &m, faults, &opts, |_, _| {});
    r.report("estop.ngc", &m.name)
}

#[test]
fn the_e_stop_chain_opening_stops_the_run_naming_the_module_and_its_input() {
    let src = "G21 G90 G94\nG0 X0 Y0 Z50\nG1 X200 F600\nG1 Y100\nM2\n";
    // Closed throughout: the run completes.
    let rep = run_with_estop(src, None);
    assert_eq!(rep.exit_code, 0, "{}", rep.text());
    // Opened mid-move: stopped by a fault that names the module and the input.
    let rep = run_with_estop(src, Some(3000));
    assert_eq!(
        rep.exit_code,
        dnurbs_tools::exit::STOPPED_FAULT,
        "{}",
        rep.text()
    );
    assert_eq!(rep.stop_node, Some(7), "{}", rep.text());
    let text = rep.text();
    assert!(text.contains("e-stop: input 8 open"), "{text}");
}
