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
    header: Option<SystemTime>,
}

impl HlogFile {
    pub fn create(path: &Path) -> io::Result<HlogFile> {
        Ok(HlogFile {
            out: BufWriter::new(std::fs::File::create(path)?),
            serializer: V2DeflateSerializer::new(),
            header: Some(SystemTime::now()),
        })
    }

    /// Append one interval's three histograms; `t0` is the run's start (monotonic ns).
    pub fn append(&mut self, iv: &Interval, t0: u64) -> io::Result<()> {
        let mut builder = IntervalLogWriterBuilder::new();
        if let Some(start) = self.header.take() {
            builder
                .add_comment(
                    "dnurbs: wake-up latency, compute and whole-cycle time per interval, in ns",
                )
                .with_start_time(start)
                .with_base_time(start);
        }
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
/// in us on a log scale, one line per histogram, and the paper's ~28 us per period.
pub fn write_svg(path: &Path, stats: &Stats, title: &str) -> io::Result<()> {
    const W: f64 = 820.0;
    const H: f64 = 480.0;
    const L: f64 = 70.0;
    const R: f64 = 160.0;
    const T: f64 = 40.0;
    const B: f64 = 50.0;
    let x_max = 6.0; // 99.9999 %
    let series: [(&str, &str, &Histogram<u64>); 3] = [
        ("wake-up latency", "#d62728", &stats.wakeup),
        ("compute", "#1f77b4", &stats.compute),
        ("whole cycle", "#2ca02c", &stats.cycle),
    ];
    let all_max = series
        .iter()
        .map(|s| s.2.max())
        .max()
        .unwrap_or(1)
        .max(28_000) as f64
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
    for (i, label) in ["0%", "90%", "99%", "99.9%", "99.99%", "99.999%", "99.9999%"]
        .iter()
        .enumerate()
    {
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
    let y28 = py(28.0);
    s.push_str(&format!(
        "<line x1=\"{L}\" y1=\"{y28:.1}\" x2=\"{:.1}\" y2=\"{y28:.1}\" stroke=\"#555\" stroke-dasharray=\"6 4\"/>\n\
         <text x=\"{:.1}\" y=\"{:.1}\">paper: ~28 us per period</text>\n",
        W - R,
        W - R + 6.0,
        y28 + 4.0
    ));
    for (k, (name, color, h)) in series.iter().enumerate() {
        if h.is_empty() {
            continue;
        }
        let mut points = Vec::new();
        for v in h.iter_quantiles(2) {
            let q = v.quantile_iterated_to();
            let x = if q >= 1.0 {
                x_max
            } else {
                (1.0 / (1.0 - q)).log10().min(x_max)
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
