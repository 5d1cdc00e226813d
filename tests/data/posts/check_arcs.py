#!/usr/bin/env python3
"""Arc consistency check for the dnurbs post-style test programs.

For every G02/G03 block it tracks the modal state (G90/G91, G17/G18/G19,
motion mode) and the current position, then prints the start radius, the end
radius and |r_start - r_end|.  Arcs with a difference above TOL (or an R word
shorter than half the chord, or an unknown start position) are flagged.

Assumptions (Fanuc / LinuxCNC defaults): I J K are incremental from the arc
start point whatever G90/G91 says; G04 X/P is a dwell time, not a position;
G28 and G53 leave the named axes at an unknown work position.

usage: python3 check_arcs.py [file.nc ...]   (default: every *.nc beside it)
"""
import glob
import math
import os
import re
import sys

TOL = 0.001
WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
PLANES = {17: ("X", "Y", "I", "J"), 18: ("Z", "X", "K", "I"), 19: ("Y", "Z", "J", "K")}


def strip(line):
    line = re.sub(r"\([^)]*\)", " ", line)
    line = line.split(";", 1)[0]
    line = line.strip()
    if line.startswith("/"):
        line = line[1:]  # block delete switch assumed off: the block runs
    return line.upper()


def check(path):
    pos = {"X": None, "Y": None, "Z": None}
    absolute = True
    plane = 17
    motion = None
    arcs = []
    problems = 0
    for lineno, raw in enumerate(open(path), 1):
        line = strip(raw)
        if not line or line.startswith("%") or line.startswith("O"):
            continue
        words = [(l, float(v)) for l, v in WORD.findall(line)]
        gs = [v for l, v in words if l == "G"]
        ax = {l: v for l, v in words if l in "XYZIJKR"}
        nonmodal = None
        for g in gs:
            if g in (0, 1, 2, 3):
                motion = int(g)
            elif g == 80:
                motion = None
            elif g == 90:
                absolute = True
            elif g == 91:
                absolute = False
            elif g in (17, 18, 19):
                plane = int(g)
            elif g in (4, 28, 53):
                nonmodal = int(g)
        if nonmodal == 4:
            continue  # dwell: X/P is a time
        if nonmodal in (28, 53):
            for a in "XYZ":
                if a in ax:
                    pos[a] = None  # now at a machine position
            continue
        targets = {a: ax[a] for a in "XYZ" if a in ax}
        if not targets or motion is None:
            continue
        start = dict(pos)
        end = dict(pos)
        for a, v in targets.items():
            if absolute:
                end[a] = v
            else:
                end[a] = None if pos[a] is None else pos[a] + v
        if motion in (2, 3):
            h, v, ih, iv = PLANES[plane]
            tag = f"{os.path.basename(path)}:{lineno} G0{motion} G{plane}"
            if start[h] is None or start[v] is None or end[h] is None or end[v] is None:
                print(f"  {tag}  UNKNOWN START/END POSITION  <-- FLAG")
                problems += 1
            elif "R" in ax:
                r = abs(ax["R"])
                chord = math.hypot(end[h] - start[h], end[v] - start[v])
                short = max(0.0, chord / 2 - r)
                bad = short > TOL or chord < 1e-9
                arcs.append(short)
                print(f"  {tag}  R={r:.4f} chord/2={chord / 2:.4f} |r_start-r_end|={short:.6f}"
                      + ("  <-- FLAG" if bad else ""))
                problems += bad
            else:
                ch = start[h] + ax.get(ih, 0.0)
                cv = start[v] + ax.get(iv, 0.0)
                rs = math.hypot(start[h] - ch, start[v] - cv)
                re_ = math.hypot(end[h] - ch, end[v] - cv)
                d = abs(rs - re_)
                full = math.hypot(end[h] - start[h], end[v] - start[v]) < 1e-9
                arcs.append(d)
                print(f"  {tag}  r_start={rs:.4f} r_end={re_:.4f} |diff|={d:.6f}"
                      + (" (full circle)" if full else "")
                      + ("  <-- FLAG" if d > TOL else ""))
                problems += d > TOL
        pos = end
    worst = max(arcs) if arcs else 0.0
    print(f"{os.path.basename(path)}: {len(arcs)} arcs, max |r_start-r_end| = {worst:.6f} mm, "
          f"{problems} flagged")
    return len(arcs), problems


def main():
    files = sys.argv[1:] or sorted(glob.glob(os.path.join(os.path.dirname(os.path.abspath(__file__)), "*.nc")))
    total = bad = 0
    for f in files:
        print(f"== {f}")
        n, p = check(f)
        total += n
        bad += p
    print(f"TOTAL: {total} arcs in {len(files)} files, {bad} flagged (tolerance {TOL} mm)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
