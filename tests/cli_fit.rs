//! `dnurbs fit` through the real binary: a G01 program in, a G06.5 program out that
//! `simulate` runs, the summary on stderr (text and JSON), and bad input refused with exit 2.

mod common;
use common::*;
use std::fmt::Write;

/// A helix of `n` moves of about 0.1 mm with the tool leaning as it turns, as a post writes it.
fn helix(n: usize) -> String {
    let mut s = String::from("%\n(helix)\nG90 G21 G94\nS6000 M3\n");
    for k in 0..=n {
        let t = k as f64 * 0.1 / 20.0;
        let (x, y, z) = (20.0 * t.cos(), 20.0 * t.sin(), 30.0 + 0.5 * t);
        let lean = (10.0 + 5.0 * t.sin()).to_radians();
        let (i, j, kk) = (lean.sin() * t.cos(), lean.sin() * t.sin(), lean.cos());
        let g = if k < 2 { "G01 " } else { "" };
        let f = if k == 0 { " F2000" } else { "" };
        let _ = writeln!(s, "{g}X{x:.4} Y{y:.4} Z{z:.4} I{i:.6} J{j:.6} K{kk:.6}{f}");
    }
    s.push_str("M5\nM30\n%\n");
    s
}

/// `dnurbs CMD FILE` on the posts' machine and tool table (`tests/data/posts`), `EXTRA...`.
fn on_posts_machine(cmd: &str, file: &std::path::Path, extra: &[&str]) -> std::process::Output {
    let posts = root().join("tests/data/posts");
    let (mach, tools) = (posts.join("machine.toml"), posts.join("tool.tbl"));
    let mut args = vec![cmd, file.to_str().unwrap(), "-m", mach.to_str().unwrap()];
    args.extend_from_slice(&["--tools", tools.to_str().unwrap()]);
    args.extend_from_slice(extra);
    dnurbs(&args)
}

/// `dnurbs CMD FILE -m paper-ac-table.toml EXTRA...`.
fn on_paper_machine(cmd: &str, file: &std::path::Path, extra: &[&str]) -> std::process::Output {
    let mach = machine("paper-ac-table.toml");
    let mut args = vec![cmd, file.to_str().unwrap(), "-m", mach.to_str().unwrap()];
    args.extend_from_slice(extra);
    dnurbs(&args)
}

#[test]
fn fit_writes_a_program_that_simulate_runs() {
    let src = temp("fit-helix.nc");
    let out = temp("fit-helix-out.nc");
    std::fs::write(&src, helix(600)).unwrap();
    let r = on_paper_machine("fit", &src, &["-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    assert_eq!(r.status.code(), Some(0), "{err}");
    assert!(
        err.contains("600 in, 600 fitted into 1 G06.5 blocks"),
        "{err}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("G06.5 P3"), "{text}");
    assert!(text.contains("S6000 M3") && text.contains("M5"), "{text}");
    let sim = on_paper_machine("simulate", &out, &[]);
    assert_eq!(
        sim.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&sim.stderr)
    );
    let _ = std::fs::remove_file(&src);
    let _ = std::fs::remove_file(&out);
}

#[test]
fn fit_summarises_in_json_and_writes_to_stdout() {
    let src = temp("fit-helix-json.nc");
    std::fs::write(&src, helix(200)).unwrap();
    let r = on_paper_machine("fit", &src, &["--json", "--tol-mm", "0.002"]);
    assert_eq!(r.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&r.stderr).unwrap();
    assert_eq!(v["moves_in"], 200);
    assert_eq!(v["fitted_blocks"], 1);
    assert!(v["point_mm"].as_f64().unwrap() <= 0.002 + 5e-7);
    assert!(v["point_deg"].as_f64().unwrap() <= 0.01 * 1.001);
    let out = String::from_utf8_lossy(&r.stdout);
    assert!(out.contains("G06.5 P3"), "{out}");
    let _ = std::fs::remove_file(&src);
}

#[test]
fn fit_refuses_bad_input_with_exit_2() {
    let src = temp("fit-bad.nc");
    std::fs::write(&src, "G90 G21\nG01 X0 Y0 Z0 F100\nG01 X1 Q5\nM30\n").unwrap();
    let r = on_paper_machine("fit", &src, &[]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("fit-bad.nc:3:"), "{err}");
    for (flag, value) in [
        ("--tol-mm", "0"),
        ("--tol-deg", "NaN"),
        ("--corner-deg", "200"),
    ] {
        let r = on_paper_machine("fit", &src, &[flag, value]);
        let err = String::from_utf8_lossy(&r.stderr).to_string();
        assert_eq!(r.status.code(), Some(2), "{flag} {value}: {err}");
        assert!(err.contains(flag), "{err}");
    }
    let _ = std::fs::remove_file(&src);
}

/// The program is read as `simulate` reads it: a UTF-8 byte-order mark is dropped (and the
/// output has none), a byte that is not UTF-8 is refused at its line and column.
#[test]
fn fit_reads_the_encoding_as_simulate_does() {
    let src = temp("fit-bom.nc");
    let out = temp("fit-bom-out.nc");
    let mut bytes = b"\xef\xbb\xbf".to_vec();
    bytes.extend_from_slice(helix(100).as_bytes());
    std::fs::write(&src, &bytes).unwrap();
    let r = on_paper_machine("fit", &src, &["-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    assert_eq!(r.status.code(), Some(0), "{err}");
    let text = std::fs::read(&out).unwrap();
    assert!(text.starts_with(b"%\n(helix)"), "{:?}", &text[..12]);
    // Latin-1 in a comment on line 2, column 4.
    std::fs::write(&src, b"%\n(ma\xdftab 1)\nG01 X1 F100\nM30\n").unwrap();
    let r = on_paper_machine("fit", &src, &[]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("fit-bom.nc") && err.contains("2:4: byte 0xdf"),
        "{err}"
    );
    let _ = std::fs::remove_file(&src);
    let _ = std::fs::remove_file(&out);
}

#[test]
fn simulate_compresses_on_request_and_says_so() {
    let src = temp("fit-helix-compress.nc");
    std::fs::write(&src, helix(400)).unwrap();
    let plain = on_paper_machine("simulate", &src, &["--json"]);
    let packed = on_paper_machine("simulate", &src, &["--json", "--compress"]);
    assert_eq!(plain.status.code(), Some(0));
    assert_eq!(
        packed.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&packed.stderr)
    );
    let p: serde_json::Value = serde_json::from_slice(&plain.stdout).unwrap();
    let c: serde_json::Value = serde_json::from_slice(&packed.stdout).unwrap();
    assert!(p.get("compressed").is_none());
    assert_eq!(c["compressed"]["moves_fitted"], 400);
    assert_eq!(c["compressed"]["fitted_blocks"], 1);
    let time = |v: &serde_json::Value| v["machining_time_s"].as_f64().unwrap();
    assert!(time(&c) < time(&p), "{} vs {}", time(&c), time(&p));
    let both = on_paper_machine("simulate", &src, &["--compress", "--no-compress"]);
    assert_eq!(both.status.code(), Some(2));
    let _ = std::fs::remove_file(&src);
}

/// The program's `G64 Q` turns the compressor on where the machine file leaves it off, and
/// says so with its line; `G61` before the moves keeps them; `--no-compress` overrides the
/// program.
#[test]
fn simulate_follows_the_programs_g64_q_and_says_so() {
    let src = temp("fit-helix-g64q.nc");
    let with = |word: &str| helix(400).replace("G90 G21 G94\n", &format!("G90 G21 G94\n{word}\n"));
    let json = |out: &std::process::Output| -> serde_json::Value {
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    std::fs::write(&src, with("G64 P0.01 Q0.005")).unwrap();
    let q = json(&on_paper_machine("simulate", &src, &["--json"]));
    assert_eq!(q["compressed"]["moves_fitted"], 400, "{}", q["compressed"]);
    let text = on_paper_machine("simulate", &src, &[]);
    let text = String::from_utf8_lossy(&text.stdout).to_string();
    assert!(
        text.contains("4:1  G64 P0.01 mm Q0.005 mm: the on-line compressor merges runs of moves after it within 0.005 mm"),
        "{text}"
    );
    let off = json(&on_paper_machine(
        "simulate",
        &src,
        &["--json", "--no-compress"],
    ));
    assert!(off.get("compressed").is_none(), "{}", off["compressed"]);
    std::fs::write(&src, with("G61")).unwrap();
    let exact = json(&on_paper_machine(
        "simulate",
        &src,
        &["--json", "--compress"],
    ));
    assert_eq!(
        exact["compressed"]["moves_fitted"], 0,
        "{}",
        exact["compressed"]
    );
    let _ = std::fs::remove_file(&src);
}

/// A post's program (NX's swarf pass: machine angles on every move, a `G28 Z` with the
/// table still tilted after it) is fitted, the move that ends the run stays as written so
/// the angles are modal after the block, and what is written runs in `simulate` on the
/// post's machine. A refused program leaves no file, and no partial one.
#[test]
fn fit_writes_a_posts_program_that_simulate_runs_and_nothing_when_refused() {
    let posts = root().join("tests/data/posts");
    let dir = temp("fit-posts");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("nx-fitted.nc");
    let nx = posts.join("nx-5axis-g43-4.nc");
    let r = on_posts_machine("fit", &nx, &["-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    assert_eq!(r.status.code(), Some(0), "{err}");
    assert!(
        err.contains("63 in, 60 fitted into 1 G06.5 blocks"),
        "{err}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("K1 K1 K1 K1\nN0750 X56.643 Y32.355 Z-9.281 F2000. A25 C73.737\n"),
        "{text}"
    );
    let sim = on_posts_machine("simulate", &out, &[]);
    let serr = String::from_utf8_lossy(&sim.stderr).to_string();
    assert_eq!(sim.status.code(), Some(0), "{serr}");
    let summary = String::from_utf8_lossy(&sim.stdout).to_string();
    assert!(
        summary.contains("axis velocity and acceleration within limits"),
        "{summary}"
    );
    // Refused: the output is not written, and nothing is left beside it.
    let bad = dir.join("bad.nc");
    std::fs::write(&bad, "G90 G21\nG01 X0 Y0 Z0 F100\nG01 X1 Q5\nM30\n").unwrap();
    let refused = dir.join("refused.nc");
    let r = on_posts_machine("fit", &bad, &["-o", refused.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(2));
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(!refused.exists(), "{left:?}");
    assert!(!left.iter().any(|f| f.contains("partial")), "{left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A post in inverse time (hyperMILL's 5-axis pass in `G93`, F on every move): its run
/// becomes one block written in `G94` with `G93` back after it, and `simulate` runs the
/// result within the limits, faster than the posted moves; `simulate --compress` fits the
/// same run of the posted program on line (and one move more: the parsed program has no
/// line to keep the run's last move on) and takes the fitted program's time.
#[test]
fn fit_writes_a_g93_posts_program_that_simulate_runs() {
    let posts = root().join("tests/data/posts");
    let out = temp("hm-fitted.nc");
    let hm = posts.join("hypermill-5axis-g93.nc");
    let r = on_posts_machine("fit", &hm, &["-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    assert_eq!(r.status.code(), Some(0), "{err}");
    assert!(
        err.contains("62 in, 59 fitted into 1 G06.5 blocks"),
        "{err}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("N11 G93\nN12 G94 G06.5 P3 "), "{text}");
    assert!(text.contains("K1 K1 K1 K1\nF800\nG93\nN71 G1 "), "{text}");
    let time = |file: &std::path::Path, extra: &[&str]| {
        let sim = on_posts_machine("simulate", file, &[&["--json"], extra].concat());
        assert_eq!(
            sim.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&sim.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&sim.stdout).unwrap();
        let exceeded = v["limits_exceeded"].as_array().expect("limits_exceeded");
        assert!(exceeded.is_empty(), "{v}");
        assert_eq!(v["axis_travel_ok"], serde_json::Value::Bool(true), "{v}");
        if extra.contains(&"--compress") {
            let c = &v["compressed"];
            assert_eq!(
                (&c["moves_fitted"], &c["fitted_blocks"]),
                (&60.into(), &1.into()),
                "{c}"
            );
        }
        v["machining_time_s"].as_f64().unwrap()
    };
    let (posted, fitted) = (time(&hm, &[]), time(&out, &[]));
    assert!(fitted < posted, "{fitted} s fitted, {posted} s posted");
    let online = time(&hm, &["--compress"]);
    assert!(
        (online - fitted).abs() <= 0.01 * fitted,
        "{online} s compressed on line, {fitted} s fitted"
    );
    let _ = std::fs::remove_file(&out);
}

/// A program that can be read once (a pipe: `dnurbs fit /dev/stdin`, or `<(...)`) is read
/// into memory and fitted as a file is; it is never taken for an empty program.
#[test]
fn fit_reads_a_pipe_as_a_file() {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let mach = machine("paper-ac-table.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_dnurbs"))
        .args(["fit", "/dev/stdin", "-m", mach.to_str().unwrap()])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("dnurbs runs");
    let text = helix(300);
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(text.as_bytes()));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("300 in, 300 fitted into 1 G06.5 blocks"),
        "{err}"
    );
    let written = String::from_utf8_lossy(&out.stdout);
    assert!(
        written.contains("G06.5 P3") && written.contains("M30"),
        "{written}"
    );
}

/// An output that is not a regular file (`-o /dev/null`, a link, a FIFO) is written into
/// once the program is checked, and stays what it is: a link stays a link to the file that
/// gets the program (a rename over it would have replaced `/dev/null` by a file).
#[test]
fn fit_writes_into_a_link_and_keeps_it_a_link() {
    let dir = temp("fit-link");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (src, real, link) = (dir.join("in.nc"), dir.join("real.nc"), dir.join("link.nc"));
    std::fs::write(&src, helix(200)).unwrap();
    std::fs::write(&real, "old\n").unwrap();
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let r = on_paper_machine("fit", &src, &["-o", link.to_str().unwrap()]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let meta = std::fs::symlink_metadata(&link).unwrap();
    assert!(meta.file_type().is_symlink(), "{meta:?}");
    let text = std::fs::read_to_string(&real).unwrap();
    assert!(
        text.contains("G06.5 P3") && !text.starts_with("old"),
        "{text}"
    );
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(left.len(), 3, "{left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// SIGINT while `dnurbs fit` works ends it with exit 4 and says so: the output it replaces
/// is left as it was and the partial file beside it is removed. (The signal is sent once
/// the partial file exists, so the fit is under way; on a loaded machine the test thread
/// can be held off until the fit has ended, exit 0 in a clean-clone CI run: then it tries
/// again with a program three times longer, at most twice.)
#[test]
fn fit_stopped_by_sigint_writes_nothing_and_leaves_nothing() {
    use std::io::Read;
    use std::process::{Command, Stdio};
    let dir = temp("fit-sigint");
    for n in [100_000, 300_000, 900_000] {
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let (src, out) = (dir.join("long.nc"), dir.join("out.nc"));
        std::fs::write(&src, helix(n)).unwrap();
        std::fs::write(&out, "old\n").unwrap();
        let mach = machine("paper-ac-table.toml");
        let mut child = Command::new(env!("CARGO_BIN_EXE_dnurbs"))
            .args(["fit", src.to_str().unwrap(), "-m", mach.to_str().unwrap()])
            .args(["-o", out.to_str().unwrap()])
            .stderr(Stdio::piped())
            .spawn()
            .expect("dnurbs runs");
        let partial = || {
            std::fs::read_dir(&dir).unwrap().any(|e| {
                e.unwrap()
                    .file_name()
                    .to_string_lossy()
                    .ends_with(".partial")
            })
        };
        while !partial() {
            if let Some(status) = child.try_wait().unwrap() {
                panic!("dnurbs fit ended ({status}) before it began to write");
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
        let mut err = String::new();
        child
            .stderr
            .take()
            .unwrap()
            .read_to_string(&mut err)
            .unwrap();
        let status = child.wait().unwrap();
        if status.code() == Some(0) && n < 900_000 {
            // The fit ended before the signal came: not what this test is about.
            assert!(err.contains("fitted into"), "{err}");
            continue;
        }
        assert_eq!(status.code(), Some(4), "{err}");
        assert!(
            err.contains("stop requested (SIGINT/SIGTERM) while fitting")
                && err.contains("nothing written"),
            "{err}"
        );
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "old\n");
        assert!(!partial(), "a partial file is left");
        let _ = std::fs::remove_dir_all(&dir);
        return;
    }
}

/// A file `-o` replaces keeps its permissions (the fitted program is written beside it and
/// renamed over it).
#[test]
fn fit_keeps_the_permissions_of_the_file_it_replaces() {
    use std::os::unix::fs::PermissionsExt;
    let dir = temp("fit-mode");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (src, out) = (dir.join("in.nc"), dir.join("out.nc"));
    std::fs::write(&src, helix(200)).unwrap();
    std::fs::write(&out, "old\n").unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
    let r = on_paper_machine("fit", &src, &["-o", out.to_str().unwrap()]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let meta = std::fs::metadata(&out).unwrap();
    assert_eq!(meta.permissions().mode() & 0o777, 0o640);
    assert!(std::fs::read_to_string(&out).unwrap().contains("G06.5 P3"));
    let _ = std::fs::remove_dir_all(&dir);
}
