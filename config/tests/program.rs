//! `[program]`: start-up modes read as the NC language reads them, the tool table and the
//! subroutine folders relative to the machine file, the loop limit; every rule with its
//! position.

mod common;

use common::{assert_at, assert_mentions, fail, pos_of, MINIMAL, ORIGIN};

fn with(program: &str) -> String {
    format!("{MINIMAL}\n[program]\n{program}\n")
}

#[test]
fn an_empty_program_table_and_none_give_the_defaults() {
    let none = common::parse(MINIMAL).unwrap();
    let empty = common::parse(&with("")).unwrap();
    assert_eq!(none.program, empty.program);
    assert_eq!(none.program.startup, "");
    assert!(none.program.tools.is_empty() && none.program.subroutine_dirs.is_empty());
    // One default for the machine file and the NC language.
    assert_eq!(none.program.max_loop_lines, nc_lang::MAX_LOOP_LINES);
}

#[test]
fn startup_modes_are_checked_where_they_are_written() {
    let m = common::parse(&with("startup = \" G20 G17 G40 G49 G90 G94 G64 P0.001 \"")).unwrap();
    assert_eq!(m.program.startup, "G20 G17 G40 G49 G90 G94 G64 P0.001");
    let text = with("startup = \"G20 G0 X1\"");
    let (_, shown) = fail(&text);
    assert_at(&shown, pos_of(&text, "\"G20 G0"));
    assert_mentions(
        &shown,
        &[
            "program.startup",
            "column 5",
            "G0",
            "only codes that set a mode",
        ],
    );
    // A work offset must be defined by the machine file.
    let (_, shown) = fail(&with("startup = \"G55\""));
    assert_mentions(&shown, &["program.startup", "G55"]);
    let text = format!(
        "{MINIMAL}\n[work_offsets]\nG55 = [1.0, 2.0, 3.0]\n\n[program]\nstartup = \"G55\"\n"
    );
    assert_eq!(common::parse(&text).unwrap().program.startup, "G55");
}

#[test]
fn the_tool_table_and_subroutines_are_found_beside_the_machine_file() {
    let dir = std::env::temp_dir().join(format!("dnurbs-config-program-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("subs")).unwrap();
    std::fs::write(dir.join("mill.tbl"), "T1 P1 Z50 D6 ;flat\nT2 P2 Z75.5\n").unwrap();
    let file = dir.join("mill.toml");
    let text =
        with("tool_table = \"mill.tbl\"\nsubroutine_path = [\"subs\"]\nmax_loop_lines = 1000");
    std::fs::write(&file, &text).unwrap();
    let m = config::load(&file).unwrap();
    assert_eq!(m.program.tools[&1].diameter_mm, Some(6.0));
    assert_eq!(m.program.tools[&2].length_mm, 75.5);
    assert_eq!(m.program.tool_table, Some(dir.join("mill.tbl")));
    assert_eq!(m.program.subroutine_dirs, [dir.join("subs")]);
    assert_eq!(m.program.max_loop_lines, 1000);

    // A table that is not there, a folder that is not there: the key, the path tried.
    let missing = with("tool_table = \"nowhere.tbl\"");
    std::fs::write(&file, &missing).unwrap();
    let shown = config::load(&file).unwrap_err().to_string();
    assert_mentions(
        &shown,
        &[
            "program.tool_table",
            "nowhere.tbl",
            "relative to the machine file",
        ],
    );
    let missing = with("subroutine_path = [\"subs\", \"gone\"]");
    std::fs::write(&file, &missing).unwrap();
    let shown = config::load(&file).unwrap_err().to_string();
    assert_mentions(
        &shown,
        &["program.subroutine_path", "entry 2", "gone", "not a folder"],
    );
    // An error in the table names the table's own line and column.
    std::fs::write(dir.join("mill.tbl"), "T1 P1 Z50\nT1 P2 Z60\n").unwrap();
    std::fs::write(&file, with("tool_table = \"mill.tbl\"")).unwrap();
    let shown = config::load(&file).unwrap_err().to_string();
    assert_mentions(&shown, &["mill.tbl:2:1", "already in the table"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_loop_limit_is_in_range_and_unknown_keys_are_refused() {
    for bad in ["0", "-5", "1000000000001"] {
        let text = with(&format!("max_loop_lines = {bad}"));
        let (_, shown) = fail(&text);
        let mut at = pos_of(&text, "max_loop_lines = ");
        at.column += "max_loop_lines = ".len();
        assert_at(&shown, at);
        assert_mentions(&shown, &[ORIGIN, "program.max_loop_lines", "1..="]);
    }
    let (_, shown) = fail(&with("startup_code = \"G21\""));
    assert_mentions(&shown, &["startup_code"]);
}

#[test]
fn io_counts_and_machine_m_codes() {
    let m = common::parse(&format!(
        "{MINIMAL}\n[io]\ndigital_outputs = 4\ndigital_inputs = 1\nanalog_inputs = 2\n\n[mcodes]\nM428 = \"tcp-on\"\nM100 = \"ignore\"\n\
         M110 = \"output 3 on\"\nM111 = \"wait 0 rise 2.5\"\n"
    ))
    .unwrap();
    assert_eq!(
        m.program.mcodes[&110],
        config::McodeAction::Output {
            output: 3,
            on: true
        }
    );
    assert_eq!(
        m.program.mcodes[&111],
        config::McodeAction::Wait {
            input: 0,
            level: config::Level::Rise,
            timeout_s: 2.5
        }
    );
    assert_eq!(m.program.io.digital_outputs, 4);
    assert_eq!(m.program.io.analog_inputs, 2);
    assert_eq!(m.program.io.digital_inputs, 1);
    assert_eq!(m.program.mcodes[&428], config::McodeAction::TcpOn);
    assert_eq!(m.program.mcodes[&100], config::McodeAction::Ignore);
    for (text, parts) in [
        (
            "[io]\ndigital_outputs = 65\n",
            &["io.digital_outputs", "0..=64"][..],
        ),
        (
            "[mcodes]\nM3 = \"ignore\"\n",
            &["mcodes.M3", "the language's own"][..],
        ),
        ("[mcodes]\nM70 = \"ignore\"\n", &["mcodes.M70"][..]),
        (
            "[mcodes]\nX1 = \"ignore\"\n",
            &["mcodes.X1", "keys are M-codes"][..],
        ),
        (
            "[mcodes]\nM101 = \"dance\"\n",
            &[
                "mcodes.M101",
                "\"dance\"",
                "ignore, tcp-on, tcp-off, stop, output <n> on|off",
            ][..],
        ),
        (
            "[io]\ndigital_outputs = 2\n[mcodes]\nM101 = \"output 2 on\"\n",
            &[
                "mcodes.M101",
                "digital_outputs 2",
                "[io] digital_outputs is 2",
            ][..],
        ),
        (
            "[mcodes]\nM101 = \"wait 0 high 1\"\n",
            &["mcodes.M101", "digital_inputs is 0"][..],
        ),
        (
            "[io]\ndigital_inputs = 1\n[mcodes]\nM101 = \"wait 0 high 0\"\n",
            &["mcodes.M101", "0 < seconds <= 3600"][..],
        ),
        (
            "[mcodes]\nM101 = \"stop\"\nm101 = \"ignore\"\n",
            &["given twice"][..],
        ),
    ] {
        let (_, shown) = fail(&format!("{MINIMAL}\n{text}"));
        assert_mentions(&shown, parts);
    }
    // A simulated machine's I/O has no module bits.
    let (_, shown) = fail(&format!(
        "{MINIMAL}\n[io]\ndigital_outputs = 1\nfirst_output = 3\n"
    ));
    assert_mentions(&shown, &["io.first_output", "machine with a bus"]);
    let (_, shown) = fail(&format!("{MINIMAL}\n[io]\nestop_input = 1\n"));
    assert_mentions(&shown, &["io.estop_input", "machine with a bus"]);
}

/// A machine with a bus and `[io]`: its digital outputs and inputs are consecutive bits of
/// its I/O module, the coolant's when it has one; analog channels and overlaps are refused.
#[test]
fn io_on_a_bus_is_bits_of_the_one_io_module() {
    let with_bus = |extra: &str| {
        format!(
            "{MINIMAL}\n[[bus]]\nname = \"can0\"\ninterface = \"vcan0\"\n{}\n{extra}",
            ["x", "y", "z", "a", "c"]
                .iter()
                .enumerate()
                .map(|(i, ax)| format!(
                    "\n[axes.{ax}.drive]\nbus = \"can0\"\nnode = {}\ncounts_per_unit = 1000.0\n",
                    i + 1
                ))
                .collect::<String>()
        )
    };
    let m = common::parse(&with_bus(
        "[io]\nbus = \"can0\"\nnode = 9\ndigital_outputs = 3\nfirst_output = 4\ndigital_inputs = 2\n",
    ))
    .unwrap();
    let io = m.bus_io.expect("on the bus");
    assert_eq!(
        (
            io.at.node,
            io.first_output,
            io.outputs,
            io.first_input,
            io.inputs
        ),
        (9, 4, 3, 1, 2)
    );
    assert_eq!(
        (m.program.io.digital_outputs, m.program.io.digital_inputs),
        (3, 2)
    );
    assert_eq!(m.io_module(0), Some(9));
    // With coolant: the same module, bus and node may be omitted.
    let coolant = "[coolant]\nbus = \"can0\"\nnode = 7\nmist_output = 1\nflood_output = 2\n";
    let m = common::parse(&with_bus(&format!(
        "{coolant}\n[io]\ndigital_outputs = 4\nfirst_output = 3\ndigital_inputs = 4\nfirst_input = 3\n"
    )))
    .unwrap();
    assert_eq!(m.bus_io.map(|b| (b.at.node, b.first_output)), Some((7, 3)));
    assert_eq!(m.io_module(0), Some(7));
    // The e-stop chain on an input of its own.
    let m = common::parse(&with_bus(
        "[io]\nbus = \"can0\"\nnode = 9\ndigital_inputs = 2\nestop_input = 8\n",
    ))
    .unwrap();
    assert_eq!(m.bus_io.and_then(|b| b.estop_input), Some(8));
    for (extra, parts) in [
        (
            "[io]\nbus = \"can0\"\nnode = 9\nestop_input = 9\n",
            &["io.estop_input", "9", "module input 1..=8"][..],
        ),
        (
            "[io]\nbus = \"can0\"\nnode = 9\ndigital_inputs = 2\nestop_input = 2\n",
            &["io.estop_input", "M66 inputs (module inputs 1..=2)"][..],
        ),
        ("[io]\ndigital_outputs = 1\n", &["io.bus", "bus and node"][..]),
        (
            "[io]\nbus = \"can0\"\nnode = 9\nanalog_outputs = 1\n",
            &["io.analog_outputs", "M67"][..],
        ),
        (
            "[io]\nbus = \"can0\"\nnode = 9\ndigital_outputs = 4\nfirst_output = 6\n",
            &["io.first_output", "6", "within the module's 8"][..],
        ),
        (
            "[io]\nbus = \"can0\"\nnode = 9\ndigital_inputs = 9\n",
            &["io.first_input", "within the module's 8"][..],
        ),
        (
            "[io]\nbus = \"can0\"\nnode = 2\ndigital_outputs = 1\n",
            &["io.node", "unique on bus"][..],
        ),
        (
            &format!("{coolant}\n[io]\ndigital_outputs = 2\n"),
            &["io.first_output", "mist_output"][..],
        ),
        (
            &format!("{coolant}\n[io]\nbus = \"can0\"\nnode = 8\ndigital_outputs = 1\nfirst_output = 3\n"),
            &["io.node", "the coolant's I/O module"][..],
        ),
    ] {
        let (_, shown) = fail(&with_bus(extra));
        assert_mentions(&shown, parts);
    }
}
