//! Report files: `latency.hlog` (HdrHistogram V2 interval log, readable by the standard
//! HdrHistogram tools such as HistogramLogProcessor; one line per histogram and interval,
//! tagged `wakeup`, `compute` and `cycle`, values in ns) and `latency.svg` (the percentile
//! distribution of each histogram, with the paper's 28 us line).

use crate::interval::Interval;
use crate::stats::Stats;
use hdrhistogram::serialization::interval_log::{IntervalLogWriterBuilder, Tag};
use hdrhistogram::serialization::V2DeflateSerializer;
use hdrhistogram::Histogram;
use std::io::{self, BufWriter, Write};
use std::path::Path;
use std::time::{Duration, SystemTime};

/// An interval log being written.
pub struct HlogFile {
    out: BufWriter<std::fs::File>,
    serializer: V2DeflateSerializer,
}

impl HlogFile {
    /// Create the file and write the log's header: a comment naming the contents, the
    /// format version, the start time and the legend line, as the Java HdrHistogram's
    /// `HistogramLogWriter` writes them.
    pub fn create(path: &Path) -> io::Result<HlogFile> {
        let mut out = BufWriter::new(std::fs::File::create(path)?);
        let start = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .unwrap_or_default()
            .as_secs_f64();
        writeln!(
            out,
            "#[dnurbs: wake-up latency (Tag=wakeup), compute (Tag=compute) and whole-cycle \
             time (Tag=cycle) per interval, values in ns, Interval_Max in ms]"
        )?;
        writeln!(out, "#[Histogram log format version 1.3]")?;
        writeln!(out, "#[StartTime: {start:.3} (seconds since epoch)]")?;
        writeln!(out, "#[BaseTime: {start:.3} (seconds since epoch)]")?;
        writeln!(
            out,
            "\"StartTimestamp\",\"Interval_Length\",\"Interval_Max\",\"Interval_Compressed_Histogram\""
        )?;
        out.flush()?;
        Ok(HlogFile {
            out,
            serializer: V2DeflateSerializer::new(),
        })
    }

    /// Append one interval's three histograms; `t0` is the run's start (monotonic ns).
    pub fn append(&mut self, iv: &Interval, t0: u64) -> io::Result<()> {
        let mut builder = IntervalLogWriterBuilder::new();
        builder.with_max_value_divisor(1_000_000.0);
        let mut log = builder.begin_log_with(&mut self.out, &mut self.serializer)?;
        let start = Duration::from_nanos(iv.start_ns.saturating_sub(t0));
        let length = Duration::from_nanos(iv.end_ns.saturating_sub(iv.start_ns));
        for (tag, h) in [
            ("wakeup", &iv.stats.wakeup),
            ("compute", &iv.stats.compute),
            ("cycle", &iv.stats.cycle),
        ] {
            if h.is_empty() {
                continue;
            }
            log.write_histogram(h, start, length, Tag::new(tag))
                .map_err(|e| io::Error::other(format!("{e:?}")))?;
        }
        self.out.flush()
    }
}

/// Percentile distribution plot: x = percentile on the usual 1/(1-p) log scale, y = time
/// in us on a log scale, one line per histogram. Each curve ends at the highest percentile
/// its sample count resolves (1 - 1/n), not at a fixed axis end. The deadline (the period)
/// is drawn across; the paper's ~28 us figure is the compute time, so it is drawn in the
/// compute curve's colour and named so; the overruns and their longest run are stated.
pub fn write_svg(path: &Path, stats: &Stats, title: &str, period_ns: u64) -> io::Result<()> {
    const W: f64 = 860.0;
    const H: f64 = 480.0;
    const L: f64 = 70.0;
    const R: f64 = 190.0;
    const T: f64 = 40.0;
    const B: f64 = 50.0;
    // The x axis reaches the highest percentile any curve resolves (at least 99.9 %).
    let resolved = |h: &Histogram<u64>| (h.len().max(1) as f64).log10();
    let series: [(&str, &str, &Histogram<u64>); 3] = [
        ("wake-up latency", "#d62728", &stats.wakeup),
        ("compute", "#1f77b4", &stats.compute),
        ("whole cycle", "#2ca02c", &stats.cycle),
    ];
    let x_max = series
        .iter()
        .map(|s| resolved(s.2))
        .fold(3.0f64, f64::max)
        .ceil()
        .min(9.0);
    let all_max = series
        .iter()
        .map(|s| s.2.max())
        .max()
        .unwrap_or(1)
        .max(28_000)
        .max(period_ns) as f64
        / 1000.0;
    let all_min = series
        .iter()
        .filter(|s| !s.2.is_empty())
        .map(|s| s.2.min())
        .min()
        .unwrap_or(1)
        .max(1) as f64
        / 1000.0;
    let (y_lo, y_hi) = (
        all_min.log10().floor(),
        all_max.log10().ceil().max(all_min.log10().floor() + 1.0),
    );
    let px = |x: f64| L + (W - L - R) * (x / x_max).clamp(0.0, 1.0);
    let py = |us: f64| {
        T + (H - T - B) * (1.0 - ((us.max(1e-9).log10() - y_lo) / (y_hi - y_lo)).clamp(0.0, 1.0))
    };
    let mut s = String::new();
    s.push_str(&format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{W}\" height=\"{H}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"{L}\" y=\"22\" font-size=\"15\">{}</text>\n",
        escape(title)
    ));
    for i in 0..=(x_max as usize) {
        let label = match i {
            0 => "0%".to_owned(),
            1 => "90%".to_owned(),
            _ => format!("99.{}%", "9".repeat(i - 2)).replace("99.%", "99%"),
        };
        let x = px(i as f64);
        s.push_str(&format!(
            "<line x1=\"{x:.1}\" y1=\"{T}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#ddd\"/><text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{label}</text>\n",
            H - B,
            H - B + 18.0
        ));
    }
    let mut decade = y_lo;
    while decade <= y_hi {
        let us = 10f64.powf(decade);
        let y = py(us);
        s.push_str(&format!(
            "<line x1=\"{L}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/><text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{} us</text>\n",
            W - R,
            L - 6.0,
            y + 4.0,
            fmt_us(us)
        ));
        decade += 1.0;
    }
    s.push_str(&format!(
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">percentile</text>\n",
        (L + W - R) / 2.0,
        H - 12.0
    ));
    let hline = |s: &mut String, us: f64, color: &str, dash: &str, label: &str| {
        let y = py(us);
        s.push_str(&format!(
            "<line x1=\"{L}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"{color}\" stroke-dasharray=\"{dash}\"/>\n\
             <text x=\"{:.1}\" y=\"{:.1}\" fill=\"{color}\" text-anchor=\"end\">{label}</text>\n",
            W - R,
            W - R - 6.0,
            y - 5.0
        ));
    };
    if period_ns > 0 {
        let us = period_ns as f64 / 1000.0;
        hline(
            &mut s,
            us,
            "#000",
            "2 0",
            &format!("deadline: period {} us", fmt_us(us)),
        );
    }
    hline(&mut s, 28.0, "#1f77b4", "6 4", "paper: compute ~28 us");
    let over = if stats.overruns > 0 {
        "#d62728"
    } else {
        "#555"
    };
    s.push_str(&format!(
        "<text x=\"{:.1}\" y=\"22\" text-anchor=\"end\" fill=\"{over}\">{} periods, overruns {} (longest run {})</text>\n",
        W - 10.0,
        stats.cycles,
        stats.overruns,
        stats.max_consecutive_overruns,
    ));
    for (k, (name, color, h)) in series.iter().enumerate() {
        if h.is_empty() {
            continue;
        }
        let mut points = Vec::new();
        let end = resolved(h);
        for v in h.iter_quantiles(2) {
            let q = v.quantile_iterated_to();
            let x = if q >= 1.0 {
                end
            } else {
                (1.0 / (1.0 - q)).log10().min(end)
            };
            points.push(format!(
                "{:.1},{:.1}",
                px(x),
                py(h.highest_equivalent(v.value_iterated_to()) as f64 / 1000.0)
            ));
        }
        s.push_str(&format!(
            "<polyline fill=\"none\" stroke=\"{color}\" stroke-width=\"2\" points=\"{}\"/>\n",
            points.join(" ")
        ));
        let ly = T + 20.0 * k as f64 + 10.0;
        s.push_str(&format!(
            "<line x1=\"{:.1}\" y1=\"{ly:.1}\" x2=\"{:.1}\" y2=\"{ly:.1}\" stroke=\"{color}\" stroke-width=\"2\"/><text x=\"{:.1}\" y=\"{:.1}\">{name}</text>\n",
            W - R + 6.0,
            W - R + 26.0,
            W - R + 30.0,
            ly + 4.0
        ));
    }
    s.push_str("</svg>\n");
    std::fs::write(path, s)
}

fn fmt_us(us: f64) -> String {
    if us >= 1.0 {
        format!("{us:.0}")
    } else {
        format!("{us}")
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
