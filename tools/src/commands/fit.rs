//! `fit`: runs of G01 moves into G06.5 blocks ([`nc_fit`]), the result measured against
//! the input before it is written.

use crate::exit::{InputError, Outcome, StoppedUnfinished};
use crate::load_machine;
use crate::setup::MachineSetup;
use crate::shop::parse_setup;
use anyhow::{bail, Context};
use nc_fit::deviation::Deviation;
use nc_fit::options::Options;
use nc_fit::rewrite::rewrite;
use nc_fit::runs::Summary;
use nc_fit::Tolerance;
use nc_lang::ReadLines;
use std::io::{BufRead, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// The command line's tolerances.
#[derive(Clone, Copy, Debug)]
pub struct Tolerances {
    pub mm: f64,
    pub deg: f64,
    pub corner_deg: f64,
}

/// Most samples per path the deviation check takes (it lengthens the step beyond).
const MAX_SAMPLES: f64 = 4e6;
/// Sampling step of the deviation check, mm (or degrees on rotary-only moves).
const STEP: f64 = 0.005;

fn check_range(name: &str, x: f64, lo: f64, hi: f64) -> Result<(), InputError> {
    if x.is_finite() && (lo..=hi).contains(&x) {
        Ok(())
    } else {
        Err(InputError::Usage(format!(
            "{name} {x} is outside {lo}..={hi}"
        )))
    }
}

pub fn fit(
    program: &Path,
    machine: &Path,
    output: Option<&Path>,
    tol: Tolerances,
    json: bool,
    tools: Option<PathBuf>,
) -> anyhow::Result<Outcome> {
    check_range("--tol-mm", tol.mm, 1e-5, 1.0)?;
    check_range("--tol-deg", tol.deg, 1e-4, 5.0)?;
    check_range("--corner-deg", tol.corner_deg, 0.0, 180.0)?;
    let machine = load_machine(machine)?;
    let setup = MachineSetup::new(&machine);
    let shop = crate::shop::ShopArgs {
        tools,
        ..Default::default()
    }
    .load()?;
    // No work offsets: the program's own numbers are what the fit reads and writes.
    let mut parse = parse_setup(&machine, &shop)?;
    parse.work_offsets = [Some([0.0; 3]); 6];
    let file = program.display().to_string();
    let unreadable = |error| InputError::ReadProgram {
        file: file.clone(),
        error,
    };
    // The program is read twice (checked, then fitted): a pipe, which can be read once, is
    // read into memory first.
    let piped = match std::fs::metadata(program) {
        Ok(m) if m.is_file() => None,
        _ => Some(std::fs::read(program).map_err(unreadable)?),
    };
    // From here on SIGINT or SIGTERM stops the fit at the next line it reads and removes
    // what it wrote (a pipe, read above, is left to the signal's default: a read that waits
    // is not ended by a handler).
    rt_loop::os::install_stop_handler()?;
    let stop = rt_loop::os::stop_requested();
    let stopped = || StoppedUnfinished {
        doing: format!("fitting {file}: nothing written"),
    };
    let open = || -> Result<Box<dyn std::io::BufRead + '_>, InputError> {
        Ok(match &piped {
            Some(bytes) => Box::new(Stoppable(bytes.as_slice(), stop)),
            None => Box::new(Stoppable(
                std::io::BufReader::with_capacity(
                    1 << 16,
                    std::fs::File::open(program).map_err(unreadable)?,
                ),
                stop,
            )),
        })
    };
    // The whole program is checked first, as `simulate` checks it (every parse error, the
    // first the segment builder refuses), without the travel: the fit reads the program's
    // own numbers.
    let anywhere = [(f64::NEG_INFINITY, f64::INFINITY); 5];
    let passed = nc_plan::prepass::check(
        ReadLines::new(open()?),
        &parse,
        &setup.kin,
        &setup.build,
        &anywhere,
    )
    .map_err(|error| match error {
        _ if stop.load(Ordering::Relaxed) => anyhow::Error::new(stopped()),
        nc_plan::prepass::Refused::Parse(errors) => InputError::Parse {
            file: file.clone(),
            errors,
        }
        .into(),
        error => InputError::Checked {
            file: file.clone(),
            error,
        }
        .into(),
    })?;
    let opts = Options {
        tol: Tolerance {
            mm: tol.mm,
            rad: tol.deg.to_radians(),
        },
        corner_deg: tol.corner_deg,
        ..Options::default()
    };
    let step = STEP.max(passed.length / MAX_SAMPLES);
    // Written to a file beside the output (or in the temporary directory for standard
    // output) and moved there only once the whole program is within the tolerances.
    let mut partial = Partial::new(output)?;
    let writer = std::io::BufWriter::with_capacity(1 << 16, partial.create()?);
    let done = rewrite(
        open()?,
        &parse,
        &setup.kin,
        &setup.build,
        &opts,
        step,
        writer,
    )
    .map_err(|e| match stop.load(Ordering::Relaxed) {
        true => anyhow::Error::new(stopped()),
        false => anyhow::anyhow!("{file}: {e}; nothing written"),
    })?;
    if done.lines != passed.lines {
        bail!(
            "{file}: the program changed while it was read ({} lines checked, {} fitted); \
             nothing written",
            passed.lines,
            done.lines
        );
    }
    let report = Report {
        file: &file,
        summary: &done.summary,
        dev: &done.dev,
        fit_s: done.fit_s,
        step,
        tol,
    };
    if json {
        eprintln!("{}", serde_json::to_string_pretty(&report.json())?);
    } else {
        eprint!("{}", report.text());
    }
    let dev = &done.dev;
    // Half a micrometre of slack for the six decimals written and the sampling.
    if dev.point_mm > tol.mm + 5e-7 || dev.point_deg > tol.deg * (1.0 + 1e-3) {
        bail!(
            "{file}: the fitted program is off its input beyond the tolerances (a point {:.6} mm \
             off at line {}, a tool axis {:.5} deg off at line {}); nothing written",
            dev.point_mm,
            dev.point_mm_line,
            dev.point_deg,
            dev.point_deg_line
        );
    }
    if stop.load(Ordering::Relaxed) {
        return Err(stopped().into());
    }
    partial.keep()?;
    Ok(Outcome::Completed)
}

/// The program's reader: once SIGINT or SIGTERM has asked for a stop, every read fails.
struct Stoppable<R>(R, &'static AtomicBool);

impl<R> Stoppable<R> {
    fn go_on(&self) -> std::io::Result<()> {
        if self.1.load(Ordering::Relaxed) {
            // Not `Interrupted`, which the readers of lines retry.
            Err(std::io::Error::other("stop requested"))
        } else {
            Ok(())
        }
    }
}

impl<R: Read> Read for Stoppable<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.go_on()?;
        self.0.read(buf)
    }
}

impl<R: BufRead> BufRead for Stoppable<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.go_on()?;
        self.0.fill_buf()
    }

    fn consume(&mut self, n: usize) {
        self.0.consume(n);
    }
}

/// Where the checked output goes.
enum Dest {
    Stdout,
    /// A file that does not exist yet, or a regular file: replaced by a rename.
    Replace(PathBuf),
    /// Anything else (`/dev/null`, a FIFO, a link): opened and written only at the end, so
    /// the device, the pipe or the link stays what it is.
    Into(PathBuf),
}

/// The output as it is written: a new file beside the destination it replaces (or in the
/// temporary directory, for standard output and what is written into), removed unless
/// [`Partial::keep`] moves it there.
struct Partial {
    path: PathBuf,
    dest: Dest,
    /// Whether this run created the file (only then is it removed).
    created: bool,
    kept: bool,
}

impl Partial {
    fn new(dest: Option<&Path>) -> anyhow::Result<Partial> {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let name = format!("dnurbs-fit-{}-{nanos}.partial", std::process::id());
        let in_temp = std::env::temp_dir().join(&name);
        let (path, dest) = match dest {
            None => (in_temp, Dest::Stdout),
            Some(d) => match std::fs::symlink_metadata(d) {
                Ok(m) if !m.file_type().is_file() => (in_temp, Dest::Into(d.to_path_buf())),
                _ => {
                    let dir = d.parent().filter(|p| !p.as_os_str().is_empty());
                    let file = d.file_name().map(|f| f.to_string_lossy().into_owned());
                    let name = format!(".{}.{name}", file.unwrap_or_default());
                    let beside = dir.map_or_else(|| PathBuf::from(&name), |dir| dir.join(&name));
                    (beside, Dest::Replace(d.to_path_buf()))
                }
            },
        };
        Ok(Partial {
            path,
            dest,
            created: false,
            kept: false,
        })
    }

    fn shown(&self) -> std::path::Display<'_> {
        match &self.dest {
            Dest::Replace(d) | Dest::Into(d) => d.display(),
            Dest::Stdout => self.path.display(),
        }
    }

    fn create(&mut self) -> anyhow::Result<std::fs::File> {
        // A new file only: nothing already there (a file, a link) is written through.
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&self.path)
            .with_context(|| {
                format!(
                    "{}: cannot write the fitted program ({})",
                    self.shown(),
                    self.path.display()
                )
            })?;
        self.created = true;
        Ok(file)
    }

    /// The whole output checked: moved to its destination, or copied into it.
    fn keep(mut self) -> anyhow::Result<()> {
        let cannot = || format!("{}: cannot write the fitted program", self.shown());
        let copy = |to: &mut dyn Write| -> std::io::Result<()> {
            let mut f = std::fs::File::open(&self.path)?;
            std::io::copy(&mut f, to)?;
            to.flush()
        };
        match &self.dest {
            Dest::Replace(dest) => {
                // A file replaced keeps its permissions (a new one gets the umask's).
                if let Ok(m) = std::fs::metadata(dest) {
                    std::fs::set_permissions(&self.path, m.permissions()).with_context(cannot)?;
                }
                std::fs::rename(&self.path, dest).with_context(cannot)?;
                self.kept = true;
            }
            Dest::Into(dest) => {
                let mut to = std::fs::OpenOptions::new()
                    .write(true)
                    .truncate(true)
                    .open(dest)
                    .with_context(cannot)?;
                copy(&mut to).with_context(cannot)?;
            }
            Dest::Stdout => copy(&mut std::io::stdout().lock()).with_context(cannot)?,
        }
        Ok(())
    }
}

impl Drop for Partial {
    fn drop(&mut self) {
        if self.created && !self.kept {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// `x` to `digits` significant digits, without trailing zeros (0.005, 0.02516).
fn significant(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let decimals = (digits - 1 - x.abs().log10().floor() as i32).clamp(0, 17) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        text
    }
}

struct Report<'a> {
    file: &'a str,
    summary: &'a Summary,
    dev: &'a Deviation,
    fit_s: f64,
    step: f64,
    tol: Tolerances,
}

impl Report<'_> {
    fn text(&self) -> String {
        let (s, d) = (self.summary, self.dev);
        let ratio = |a: usize, b: usize| a as f64 / (b.max(1)) as f64;
        format!(
            "dnurbs fit: {file}\n\
             \x20 G01 moves: {mi} in, {mf} fitted into {fb} G06.5 blocks; runs kept as G01 (not within tolerance): {rk}\n\
             \x20 motion blocks: {bi} in, {bo} out ({br:.1}x fewer)\n\
             \x20 bytes: {yi} in, {yo} out ({yr})\n\
             \x20 tolerances: {tm} mm, {td} deg, corners above {tc} deg\n\
             \x20 measured on the result ({np} programmed points, {ns} samples every {st} mm):\n\
             \x20   points off the cutter path: {pm:.6} mm (line {pml}); tool axes off: {pd:.5} deg (line {pdl})\n\
             \x20   cutter path off the programmed moves: {pa:.6} mm\n\
             \x20 fit: {ft:.3} s, {rate:.0} moves/s\n",
            file = self.file,
            mi = s.moves_in,
            mf = s.moves_fitted,
            fb = s.fitted_blocks,
            rk = s.runs_kept,
            bi = s.blocks_in,
            bo = s.blocks_out,
            br = ratio(s.blocks_in, s.blocks_out),
            yi = s.bytes_in,
            yo = s.bytes_out,
            yr = if s.bytes_out <= s.bytes_in {
                format!("{:.1}x smaller", ratio(s.bytes_in, s.bytes_out))
            } else {
                format!("{:.2}x larger", ratio(s.bytes_out, s.bytes_in))
            },
            tm = self.tol.mm,
            td = self.tol.deg,
            tc = self.tol.corner_deg,
            np = d.points,
            ns = d.samples,
            st = significant(self.step, 4),
            pm = d.point_mm,
            pml = d.point_mm_line,
            pd = d.point_deg,
            pdl = d.point_deg_line,
            pa = d.path_mm,
            ft = self.fit_s,
            rate = s.moves_in as f64 / self.fit_s.max(1e-9),
        )
    }

    fn json(&self) -> serde_json::Value {
        let (s, d) = (self.summary, self.dev);
        serde_json::json!({
            "file": self.file,
            "moves_in": s.moves_in,
            "moves_fitted": s.moves_fitted,
            "fitted_blocks": s.fitted_blocks,
            "runs_kept": s.runs_kept,
            "blocks_in": s.blocks_in,
            "blocks_out": s.blocks_out,
            "bytes_in": s.bytes_in,
            "bytes_out": s.bytes_out,
            "tol_mm": self.tol.mm,
            "tol_deg": self.tol.deg,
            "corner_deg": self.tol.corner_deg,
            "fit_measured_mm": s.fit_mm,
            "fit_measured_deg": s.fit_deg,
            "point_mm": d.point_mm,
            "point_mm_line": d.point_mm_line,
            "point_deg": d.point_deg,
            "point_deg_line": d.point_deg_line,
            "path_mm": d.path_mm,
            "points": d.points,
            "samples": d.samples,
            "sample_step": self.step,
            "fit_seconds": self.fit_s,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::significant;

    #[test]
    fn the_sample_step_is_printed_to_four_significant_digits() {
        assert_eq!(significant(0.005, 4), "0.005");
        assert_eq!(significant(0.025_161_491_283_480_79, 4), "0.02516");
        assert_eq!(significant(0.25, 4), "0.25");
        assert_eq!(significant(1.0 / 3.0, 4), "0.3333");
        assert_eq!(significant(12.5, 4), "12.5");
        assert_eq!(significant(0.0, 4), "0");
    }
}
