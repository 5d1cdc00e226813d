//! JSON forms of the real-time crate's report types. `rt-loop` stays free of serde (what may
//! run in the real-time thread is its crate graph); the report derives their serialisation
//! here, field for field, with serde's remote derive.

use rt_loop::stats::{Histograms, Percentiles, Summary};
use rt_loop::thread::RtMode;
use serde::Serialize;

#[derive(Serialize)]
#[serde(remote = "RtMode")]
pub struct RtModeDef {
    pub sched_fifo: bool,
    pub priority: Option<i32>,
    pub memory_locked: bool,
    pub cpu: Option<usize>,
    pub without_because: Option<String>,
}

#[derive(Serialize)]
#[serde(remote = "Summary")]
pub struct SummaryDef {
    pub cycles: u64,
    pub overruns: u64,
    pub max_consecutive_overruns: u64,
    pub underruns: u64,
    pub minor_faults_in_loop: i64,
    #[serde(with = "HistogramsDef")]
    pub histograms: Histograms,
}

#[derive(Serialize)]
#[serde(remote = "Histograms")]
pub struct HistogramsDef {
    #[serde(with = "PercentilesDef")]
    pub wakeup_latency_ns: Percentiles,
    #[serde(with = "PercentilesDef")]
    pub compute_ns: Percentiles,
    #[serde(with = "PercentilesDef")]
    pub cycle_ns: Percentiles,
}

#[derive(Serialize)]
#[serde(remote = "Percentiles")]
pub struct PercentilesDef {
    pub min: u64,
    pub p50: u64,
    pub p90: u64,
    pub p99: u64,
    pub p99_9: u64,
    pub p99_99: u64,
    pub max: u64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_loop::stats::Stats;

    #[derive(Serialize)]
    struct Json<'a>(#[serde(with = "SummaryDef")] &'a Summary);

    #[test]
    fn every_percentile_of_every_histogram_is_a_json_number() {
        let mut s = Stats::new();
        for i in 1..=1000u64 {
            s.record(i * 10_000, 500, i * 20_000);
        }
        let json = serde_json::to_value(Json(&s.summary())).unwrap();
        for h in ["wakeup_latency_ns", "compute_ns", "cycle_ns"] {
            for key in ["min", "p50", "p90", "p99", "p99_9", "p99_99", "max"] {
                assert!(json["histograms"][h][key].is_u64(), "{h} {key}");
            }
        }
        assert_eq!(json["cycles"], 1000);
    }
}
