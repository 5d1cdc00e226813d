//! HDR histograms of one run, allocated before the loop starts and only recorded into inside
//! it (`saturating_record` on a histogram with fixed bounds never allocates or panics: a value
//! beyond the highest trackable one is counted at the top).
//!
//! Three histograms, all in nanoseconds: wake-up latency (actual wake-up minus the scheduled
//! one), compute (the paper's metric: from the start of the basis computation to the final
//! axis positions), and whole cycle (wake-up to the last frame written).

use hdrhistogram::Histogram;

/// Highest value the histograms track exactly, ns (10 s); larger values count as this.
pub const HIGHEST_NS: u64 = 10_000_000_000;
/// Significant decimal digits kept (0.1 % resolution).
pub const SIGFIG: u8 = 3;

/// The histograms and counters of a run.
#[derive(Clone, Debug)]
pub struct Stats {
    pub wakeup: Histogram<u64>,
    pub compute: Histogram<u64>,
    pub cycle: Histogram<u64>,
    pub cycles: u64,
    /// Periods whose work was not done before the next wake-up was due (one or more missed).
    pub overruns: u64,
    /// Longest run of consecutive overrun periods (kept as a maximum, not summed, when
    /// statistics are added).
    pub max_consecutive_overruns: u64,
    /// Periods in which the interpolator had no data (feed hold).
    pub underruns: u64,
    /// Minor page faults of the process while the loop ran (getrusage), -1 if unknown.
    pub minor_faults: i64,
}

impl Stats {
    pub fn new() -> Stats {
        let h = || {
            let mut h = Histogram::new_with_bounds(1, HIGHEST_NS, SIGFIG)
                .expect("constant, valid histogram bounds");
            // The counts come zeroed from the allocator, possibly as untouched pages;
            // writing every count now faults them in before the loop, not during it.
            h.reset();
            h
        };
        Stats {
            wakeup: h(),
            compute: h(),
            cycle: h(),
            cycles: 0,
            overruns: 0,
            max_consecutive_overruns: 0,
            underruns: 0,
            minor_faults: -1,
        }
    }

    /// Empty every histogram and counter (writes every count: no page faults later).
    pub fn clear(&mut self) {
        self.wakeup.reset();
        self.compute.reset();
        self.cycle.reset();
        self.cycles = 0;
        self.overruns = 0;
        self.max_consecutive_overruns = 0;
        self.underruns = 0;
        self.minor_faults = -1;
    }

    /// Add another run's or interval's statistics (outside the real-time thread).
    pub fn add(&mut self, other: &Stats) {
        // Same bounds on both sides: the additions cannot fail.
        let _ = self.wakeup.add(&other.wakeup);
        let _ = self.compute.add(&other.compute);
        let _ = self.cycle.add(&other.cycle);
        self.cycles += other.cycles;
        self.overruns += other.overruns;
        self.max_consecutive_overruns = self
            .max_consecutive_overruns
            .max(other.max_consecutive_overruns);
        self.underruns += other.underruns;
    }

    /// Record one period. Allocation-free.
    #[inline]
    pub fn record(&mut self, wakeup_ns: u64, compute_ns: u64, cycle_ns: u64) {
        self.wakeup.saturating_record(wakeup_ns.max(1));
        self.compute.saturating_record(compute_ns.max(1));
        self.cycle.saturating_record(cycle_ns.max(1));
        self.cycles += 1;
    }

    /// A period without interpolation (drives enabling or disabling): no compute sample.
    pub fn record_idle(&mut self, wakeup_ns: u64, cycle_ns: u64) {
        self.wakeup.saturating_record(wakeup_ns.max(1));
        self.cycle.saturating_record(cycle_ns.max(1));
        self.cycles += 1;
    }

    pub fn summary(&self) -> Summary {
        Summary {
            cycles: self.cycles,
            overruns: self.overruns,
            max_consecutive_overruns: self.max_consecutive_overruns,
            underruns: self.underruns,
            minor_faults_in_loop: self.minor_faults,
            histograms: Histograms {
                wakeup_latency_ns: Percentiles::of(&self.wakeup),
                compute_ns: Percentiles::of(&self.compute),
                cycle_ns: Percentiles::of(&self.cycle),
            },
        }
    }
}

/// Consecutive overruns, counted across the statistics intervals of a loop.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OverrunRun {
    current: u64,
}

impl OverrunRun {
    /// One period, overrun or not: counts it into `stats` and returns how many periods in a
    /// row have overrun up to this one (0 if this one did not). Allocation-free.
    #[inline]
    pub fn period(&mut self, overrun: bool, stats: &mut Stats) -> u64 {
        if overrun {
            self.current += 1;
            stats.overruns += 1;
            stats.max_consecutive_overruns = stats.max_consecutive_overruns.max(self.current);
        } else {
            self.current = 0;
        }
        self.current
    }
}

impl Default for Stats {
    fn default() -> Self {
        Stats::new()
    }
}

/// What `summary.json` and `summary.txt` say of the loop (keys in docs/latency.md).
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub cycles: u64,
    pub overruns: u64,
    pub max_consecutive_overruns: u64,
    pub underruns: u64,
    pub minor_faults_in_loop: i64,
    pub histograms: Histograms,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Histograms {
    pub wakeup_latency_ns: Percentiles,
    pub compute_ns: Percentiles,
    pub cycle_ns: Percentiles,
}

/// One histogram's distribution, ns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Percentiles {
    pub min: u64,
    pub p50: u64,
    pub p90: u64,
    pub p99: u64,
    pub p99_9: u64,
    pub p99_99: u64,
    pub max: u64,
}

impl Percentiles {
    pub fn of(h: &Histogram<u64>) -> Percentiles {
        if h.is_empty() {
            return Percentiles {
                min: 0,
                p50: 0,
                p90: 0,
                p99: 0,
                p99_9: 0,
                p99_99: 0,
                max: 0,
            };
        }
        Percentiles {
            min: h.min(),
            p50: h.value_at_quantile(0.5),
            p90: h.value_at_quantile(0.9),
            p99: h.value_at_quantile(0.99),
            p99_9: h.value_at_quantile(0.999),
            p99_99: h.value_at_quantile(0.9999),
            max: h.max(),
        }
    }
}

impl Summary {
    /// `summary.txt`, also printed at the end of every run.
    pub fn text(&self) -> String {
        let mut s = format!(
            "cycles {}   overruns {} (at most {} in a row)   underruns {}   minor page faults in loop {}\n\
             {:<18} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}   (us)\n",
            self.cycles,
            self.overruns,
            self.max_consecutive_overruns,
            self.underruns,
            self.minor_faults_in_loop,
            "histogram",
            "min",
            "p50",
            "p90",
            "p99",
            "p99.9",
            "p99.99",
            "max"
        );
        let h = &self.histograms;
        for (name, p) in [
            ("wakeup latency", &h.wakeup_latency_ns),
            ("compute", &h.compute_ns),
            ("whole cycle", &h.cycle_ns),
        ] {
            let us = |v: u64| v as f64 / 1000.0;
            s.push_str(&format!(
                "{:<18} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2}\n",
                name,
                us(p.min),
                us(p.p50),
                us(p.p90),
                us(p.p99),
                us(p.p99_9),
                us(p.p99_99),
                us(p.max)
            ));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_of_a_known_distribution() {
        let mut s = Stats::new();
        for v in 1..=10_000u64 {
            s.record(v * 1000, 500, 2 * v * 1000);
        }
        let p = s.summary();
        assert_eq!(p.cycles, 10_000);
        let w = p.histograms.wakeup_latency_ns;
        // HDR keeps 3 significant digits: within 0.1 % of the exact quantiles.
        for (got, want) in [
            (w.p50, 5_000_000u64),
            (w.p90, 9_000_000),
            (w.p99, 9_900_000),
            (w.max, 10_000_000),
        ] {
            assert!(
                (got as f64 - want as f64).abs() <= want as f64 * 1e-3,
                "{got} vs {want}"
            );
        }
        assert_eq!(p.histograms.compute_ns.p99, 500);
        let text = p.text();
        assert!(
            text.contains("wakeup latency") && text.contains("p99.99"),
            "{text}"
        );
    }

    #[test]
    fn out_of_range_values_saturate_instead_of_panicking() {
        let mut s = Stats::new();
        s.record(u64::MAX, 0, HIGHEST_NS * 10);
        assert_eq!(s.cycles, 1);
        assert!(s.summary().histograms.wakeup_latency_ns.max >= HIGHEST_NS);
    }
}
