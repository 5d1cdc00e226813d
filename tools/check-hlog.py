#!/usr/bin/env python3
"""Read a dnurbs latency.hlog with the Python HdrHistogram library (pip hdrhistogram), an
independent implementation of the log format, and check it against the run's summary.json:
every tag present, the wake-up histogram's total count equal to the cycles counted, and
each tag's maximum equal to the summary's (within the histograms' 0.1 % resolution).

    tools/check-hlog.py REPORT_DIR
"""
import json
import sys

from hdrh.histogram import HdrHistogram
from hdrh.log import HistogramLogReader


def main(report: str) -> int:
    summary = json.load(open(f"{report}/summary.json"))
    latency = summary["latency"]
    reader = HistogramLogReader(f"{report}/latency.hlog", HdrHistogram(1, 10_000_000_000, 3))
    total = {}
    intervals = 0
    while True:
        h = reader.get_next_interval_histogram()
        if h is None:
            break
        intervals += 1
        tag = h.get_tag()
        if tag not in total:
            total[tag] = HdrHistogram(1, 10_000_000_000, 3)
        total[tag].add(h)
    names = {"wakeup": "wakeup_latency_ns", "compute": "compute_ns", "cycle": "cycle_ns"}
    bad = []
    if set(total) - set(names) or "wakeup" not in total:
        bad.append(f"tags {sorted(total)}")
    if total.get("wakeup") and total["wakeup"].get_total_count() != latency["cycles"]:
        bad.append(f"wakeup count {total['wakeup'].get_total_count()} != cycles {latency['cycles']}")
    for tag, h in total.items():
        want = latency["histograms"][names[tag]]["max"]
        got = h.get_max_value()
        if abs(got - want) > 0.002 * want + 1:
            bad.append(f"{tag} max {got} != summary {want}")
    print(
        f"{report}/latency.hlog: {intervals} interval histograms, tags {sorted(total)}, "
        + ", ".join(
            f"{t} count {h.get_total_count()} p99 {h.get_value_at_percentile(99)} ns"
            for t, h in sorted(total.items())
        )
    )
    for b in bad:
        print(f"MISMATCH: {b}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
