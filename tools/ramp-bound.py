#!/usr/bin/env python3
"""Estimate how much of a program's time above the programmed-feed time the machine's axes
themselves impose where the path slows to a near stop (the corners a program keeps), from a
`dnurbs simulate --trace`.

  python3 tools/ramp-bound.py TRACE.csv --machine config/machines/xyzac-trt-mill.toml [--feed F]

Each stretch at the feed (path speed within 1 % of F, mm/s; default: the trace's highest
speed) that follows a slow point (below 10 % of F) starts with a ramp in which every axis
changes its rate by the difference between the slow point and the feed. An axis with
acceleration A and jerk J needs at least T = dw / A + A / J (or 2 sqrt(dw / J) for a small
dw) for a change dw between two moments without acceleration; a symmetric ramp of T covers
half the distance the feed would, so it costs T / 2 against the feed. The estimate takes
the slowest axis at each ramp, likewise for the ramp down into the next slow point. A move
between two slow points that never reaches the feed (a step-over between two corners)
takes at least the slowest axis's time from rest to rest over its displacement, within its
velocity, acceleration and jerk. All of it is added up against the time at the feed. An
estimate, not a proof: it takes each axis's rate as following the path speed through a
ramp and the slow points as at rest.
"""
import argparse
import csv
import math
import tomllib

AXES = "xyzac"


def least_change_time(dw, a, j):
    dw = abs(dw)
    return dw / a + a / j if dw >= a * a / j else 2.0 * math.sqrt(dw / j)


def least_move_time(d, v, a, j):
    """Rest to rest over d: up to a peak speed and down again, cruising at v if needed."""
    d = abs(d)
    if d == 0.0:
        return 0.0
    covers = lambda vp: vp * least_change_time(vp, a, j)  # up to vp and down again
    if covers(v) <= d:
        return 2.0 * least_change_time(v, a, j) + (d - covers(v)) / v
    lo, hi = 0.0, v
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if covers(mid) < d else (lo, mid)
    return 2.0 * least_change_time(hi, a, j)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("trace")
    ap.add_argument("--machine", required=True)
    ap.add_argument("--feed", type=float, help="programmed feed, mm/s")
    args = ap.parse_args()
    with open(args.machine, "rb") as f:
        m = tomllib.load(f)
    lim = []
    for k in AXES:
        ax = m["axes"][k]
        lim.append((ax["velocity"], ax["acceleration"], ax["jerk"]))
    with open(args.trace) as f:
        rows = list(csv.reader(f))[1:]
    t = [float(r[1]) for r in rows]
    p = [tuple(float(x) for x in r[4:7]) for r in rows]
    q = [tuple(float(x) for x in r[11:16]) for r in rows]
    ts = t[1] - t[0]
    v = [0.0] + [math.dist(p[k], p[k - 1]) / ts for k in range(1, len(p))]
    w = [(0.0,) * 5] + [
        tuple((q[k][j] - q[k - 1][j]) / ts for j in range(5)) for k in range(1, len(q))
    ]
    feed = args.feed or max(v)
    at_feed = [x >= 0.99 * feed for x in v]
    total, ramps, length = 0.0, 0, sum(v) * ts
    moves, between = 0.0, 0

    def cost(k_slow, k_fast):
        return max(
            least_change_time(w[k_fast][j] - w[k_slow][j], *lim[j][1:]) for j in range(5)
        ) / 2.0

    slow = None  # the slowest period since the last stretch at the feed
    k = 1
    while k < len(v):
        if not at_feed[k]:
            if slow is None or v[k] < v[slow]:
                slow = k
            k += 1
            continue
        start = k
        while k < len(v) and at_feed[k]:
            k += 1
        end = k - 1
        if slow is not None and v[slow] < 0.1 * feed:
            total += cost(slow, start)
            ramps += 1
        # The ramp down: to the slowest period before the next stretch at the feed.
        nxt, kk = None, k
        while kk < len(v) and not at_feed[kk]:
            if nxt is None or v[kk] < v[nxt]:
                nxt = kk
            kk += 1
        if nxt is not None and v[nxt] < 0.1 * feed:
            total += cost(nxt, end)
            ramps += 1
            # Between this near stop and the next one before the feed again (a step-over
            # between two corners): every axis rest to rest, against the feed's time.
            stops = [
                i for i in range(k, kk)
                if v[i] < 0.1 * feed and v[i] <= v[i - 1] and v[i] <= v[min(i + 1, len(v) - 1)]
            ]
            for a, b in zip(stops, stops[1:]):
                if b - a < 2:
                    continue
                least = max(least_move_time(q[b][j] - q[a][j], *lim[j]) for j in range(5))
                moves += max(least - sum(v[a + 1 : b + 1]) * ts / feed, 0.0)
                between += 1
        slow = None
    programmed = length / feed
    print(f"feed {feed:.3f} mm/s, path {length:.3f} mm, {programmed:.3f} s at the feed")
    print(f"{ramps} ramps between a near stop and the feed: at least {total:.3f} s more")
    print(f"{between} moves between two near stops, rest to rest: at least {moves:.3f} s more")
    least = programmed + total + moves
    print(f"estimate: at least {least:.3f} s ({least / programmed:.4f}x the time at the feed)")


if __name__ == "__main__":
    main()
