#!/usr/bin/env python3
"""Measure a commanded-position trace against its G-code program, the same way for LinuxCNC
and for dnurbs, so the two can be compared side by side.

  python3 tools/linuxcnc/measure.py TRACE.csv PROGRAM.nc --machine xyzac-trt-mill \\
      --period 0.001 --format linuxcnc|dnurbs [--json] [--convention linuxcnc|dnurbs]

TRACE.csv: --format linuxcnc: tools/linuxcnc/run's output (t,X,Y,Z,A,C);
           --format dnurbs: `dnurbs simulate --trace` (cycle,t,block,u,x,y,z,i,j,k,feed,X,Y,Z,A,C).
Only the machine joints X Y Z A C (mm, deg) are used; for a dnurbs trace the script also checks
that its forward kinematics give back the trace's own x y z and i j k.

Figures:
  time       machining time: from the last period at rest before the first motion to the
             first period at rest after the last one, periods x period
  v a j      largest |dq/T|, |d2q/T^2|, |d3q/T^3| per axis (finite differences of the joint
             samples), as fractions of the machine's limits
  deviation  the largest distance of a programmed point (every G00/G01 end point, workpiece
             frame) from the commanded path (the polyline through the commanded tool tips,
             workpiece frame: forward kinematics of the joints);
  tool axis  (5-axis programs) the largest angle between a programmed tool axis and the
             commanded one at the nearest point of that path.

Kinematics (xyzac-trt): A tilts the table about machine X through the machine file's
a_axis_point, C turns it about the table normal through c_axis_point (at A = 0). dnurbs:
machine = Ra(A) (Rz(-C) (p - c) + c - a) + a, tool axis (-sin A sin C, sin A cos C, cos A).
LinuxCNC's xyzac-trt-kins turns C the other way (Rz(+C)): with --convention linuxcnc (the
default for --format linuxcnc) C is negated, both in the trace and in the program's C words.
A machine of kind "paper" is the identity for positions.

Machine limits come from config/machines/NAME.toml of this repository (or a path to a file).
Needs Python 3.11 (tomllib) and numpy.
"""
import argparse, json, math, os, re, sys

import numpy as np

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None

HERE = os.path.dirname(os.path.abspath(__file__))
AXES = "XYZAC"


def load_machine(name):
    path = name if os.path.exists(name) else os.path.join(HERE, "..", "..", "config", "machines", name + ".toml")
    if tomllib is None:
        sys.exit("measure: needs Python 3.11 (tomllib) to read %s" % path)
    with open(path, "rb") as f:
        m = tomllib.load(f)
    kin = m.get("kinematics", {})
    lim = {}
    for ax in AXES:
        a = m["axes"][ax.lower()]
        lim[ax] = (a["velocity"], a["acceleration"], a["jerk"])
    return {
        "name": m["machine"]["name"],
        "kind": kin.get("kind", "paper"),
        "a_point": np.array(kin.get("a_axis_point", [0.0, 0.0, 0.0]), float),
        "c_point": np.array(kin.get("c_axis_point", [0.0, 0.0, 0.0]), float),
        "limits": lim,
    }


def read_trace(path, fmt):
    with open(path) as f:
        header = f.readline().strip().split(",")
    cols = [header.index(ax) for ax in AXES]
    data = np.loadtxt(path, delimiter=",", skiprows=1, usecols=cols, ndmin=2)
    extra = None
    if fmt == "dnurbs":
        ecols = [header.index(c) for c in "xyzijk"]
        extra = np.loadtxt(path, delimiter=",", skiprows=1, usecols=ecols, ndmin=2)
    return data, extra


def forward(q, mach, c_sign):
    """Workpiece tool tip p and tool axis t for joint rows q (N x 5, mm and deg)."""
    a = np.radians(q[:, 3])
    c = np.radians(q[:, 4]) * c_sign  # dnurbs's C
    sa, ca, sc, cc = np.sin(a), np.cos(a), np.sin(c), np.cos(c)
    t = np.stack([-sa * sc, sa * cc, ca], axis=1)
    m = q[:, :3]
    if mach["kind"] == "paper":
        return m.copy(), t
    if mach["kind"] != "xyzac-trt":
        sys.exit("measure: kinematics %r not supported" % mach["kind"])
    ap, cp = mach["a_point"], mach["c_point"]
    r = m - ap
    # untilt: Rx(-A) r
    u = np.stack([r[:, 0], ca * r[:, 1] + sa * r[:, 2], -sa * r[:, 1] + ca * r[:, 2]], axis=1) + ap - cp
    # unturn: Rz(C) u (dnurbs's C)
    p = np.stack([cc * u[:, 0] - sc * u[:, 1], sc * u[:, 0] + cc * u[:, 1], u[:, 2]], axis=1) + cp
    return p, t


def read_program(path, c_sign):
    """Programmed end points (workpiece frame) and tool axes (None for a 3-axis program)."""
    pos = {k: 0.0 for k in "XYZAC"}
    ijk = None
    pts, axes = [], []
    five = False
    motion = None
    for line in open(path):
        line = re.sub(r"\(.*?\)|;.*", "", line).upper()
        words = re.findall(r"([A-Z])\s*([-+]?[0-9]*\.?[0-9]+)", line)
        moved = False
        for k, v in words:
            if k == "G" and float(v) in (0.0, 1.0):
                motion = int(float(v))
            if k in pos:
                pos[k] = float(v); moved = True
                if k in "AC":
                    five = True
            if k in "IJK":
                ijk = dict(ijk or {"I": 0.0, "J": 0.0, "K": 1.0}); ijk[k] = float(v); moved = True
                five = True
        if moved and motion in (0, 1):
            pts.append([pos["X"], pos["Y"], pos["Z"]])
            if ijk is not None:
                t = np.array([ijk["I"], ijk["J"], ijk["K"]]); t /= np.linalg.norm(t)
            else:
                a, c = math.radians(pos["A"]), math.radians(pos["C"]) * c_sign
                t = np.array([-math.sin(a) * math.sin(c), math.sin(a) * math.cos(c), math.cos(a)])
            axes.append(t)
    return np.array(pts), (np.array(axes) if five else None)


def deviation(prog, ptax, path, tax):
    """Largest distance of the programmed points from the polyline `path`, and largest angle
    (deg) between programmed and commanded tool axis at the nearest point. The search walks
    along the path (by arc length) with the program, then checks globally where it found a
    point farther than 0.05 mm."""
    seg = np.diff(path, axis=0)
    keep = np.linalg.norm(seg, axis=1) > 0
    # drop repeated samples (standstill) so every segment has a length
    idx = np.concatenate([[0], np.nonzero(keep)[0] + 1])
    P = path[idx]; T = tax[idx] if tax is not None else None
    if len(P) == 1:
        P = np.vstack([P, P]); T = None if T is None else np.vstack([T, T])
    D = np.diff(P, axis=0)
    L2 = np.maximum(np.einsum("ij,ij->i", D, D), 1e-300)
    S = np.concatenate([[0.0], np.cumsum(np.sqrt(L2))])

    def nearest(x, lo, hi):
        d = D[lo:hi]; p0 = P[lo:hi]
        u = np.clip(np.einsum("ij,ij->i", x - p0, d) / L2[lo:hi], 0.0, 1.0)
        q = p0 + u[:, None] * d
        dist = np.linalg.norm(q - x, axis=1)
        k = int(np.argmin(dist))
        return dist[k], lo + k, u[k]

    worst, worst_i, worst_ang, worst_ang_i = 0.0, -1, 0.0, -1
    s_prev = 0.0
    nseg = len(D)
    for i, x in enumerate(prog):
        lo = int(np.searchsorted(S, s_prev - 1.0)); lo = max(lo - 1, 0)
        hi = int(np.searchsorted(S, s_prev + 3.0)) + 1; hi = min(max(hi, lo + 1), nseg)
        dist, k, u = nearest(x, lo, hi)
        if dist > 0.05:
            dist, k, u = nearest(x, 0, nseg)
        s_prev = S[k] + u * (S[k + 1] - S[k])
        if dist > worst:
            worst, worst_i = dist, i
        if ptax is not None:
            tc = T[k] + u * (T[k + 1] - T[k]); tc /= np.linalg.norm(tc)
            ang = math.degrees(math.atan2(np.linalg.norm(np.cross(tc, ptax[i])), float(np.dot(tc, ptax[i]))))
            if ang > worst_ang:
                worst_ang, worst_ang_i = ang, i
    return worst, worst_i, worst_ang, worst_ang_i


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("trace"); ap.add_argument("program")
    ap.add_argument("--machine", default="xyzac-trt-mill")
    ap.add_argument("--period", type=float, default=0.001)
    ap.add_argument("--format", choices=["linuxcnc", "dnurbs"], required=True)
    ap.add_argument("--convention", choices=["linuxcnc", "dnurbs"],
                    help="C direction of the trace's joints and the program's C words "
                         "(default: that of --format)")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    conv = args.convention or args.format
    c_sign = -1.0 if conv == "linuxcnc" else 1.0
    mach = load_machine(args.machine)
    T = args.period

    q, extra = read_trace(args.trace, args.format)
    moving = np.nonzero(np.any(np.diff(q, axis=0) != 0.0, axis=1))[0]
    if len(moving) == 0:
        sys.exit("measure: no motion in %s" % args.trace)
    first, last = int(moving[0]), int(moving[-1]) + 1  # rest before, rest after
    res = {"trace": args.trace, "program": args.program, "format": args.format,
           "convention": conv, "machine": mach["name"], "period_s": T,
           "samples": int(len(q)), "machining_time_s": round((last - first) * T, 6)}

    for name, order in (("velocity", 1), ("acceleration", 2), ("jerk", 3)):
        d = np.abs(np.diff(q, n=order, axis=0)).max(axis=0) / T ** order if len(q) > order else np.zeros(5)
        res["axis_%s_fraction" % name] = {ax: float(d[i] / mach["limits"][ax][order - 1]) for i, ax in enumerate(AXES)}

    p, t = forward(q, mach, c_sign)
    if extra is not None:
        res["fk_check_tip_mm"] = float(np.abs(p - extra[:, :3]).max())
        res["fk_check_axis"] = float(np.abs(t - extra[:, 3:6]).max())
    prog, ptax = read_program(args.program, c_sign)
    five = ptax is not None
    dev, dev_i, ang, ang_i = deviation(prog, ptax, p, t if five else None)
    res["programmed_points"] = int(len(prog))
    res["path_length_mm"] = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    res["deviation_max_um"] = dev * 1000.0
    res["deviation_max_at_point"] = dev_i
    if five:
        res["tool_axis_deviation_max_deg"] = ang
        res["tool_axis_deviation_max_at_point"] = ang_i
    if args.json:
        print(json.dumps(res, indent=2))
        return
    print("%s (%s, C as %s) on %s, machine %s" % (args.trace, args.format, conv, args.program, mach["name"]))
    print("  machining time      %.3f s (%d samples)" % (res["machining_time_s"], len(q)))
    print("  path length         %.3f mm" % res["path_length_mm"])
    print("  max deviation       %.3f um (programmed point %d of %d)" % (res["deviation_max_um"], dev_i, len(prog)))
    if five:
        print("  max tool axis dev.  %.5f deg (programmed point %d)" % (ang, ang_i))
    print("  fraction of limit   " + "  ".join("%8s" % ax for ax in AXES))
    for name in ("velocity", "acceleration", "jerk"):
        f = res["axis_%s_fraction" % name]
        print("  %-19s " % name + "  ".join("%8.3f" % f[ax] for ax in AXES))
    if extra is not None:
        print("  forward kinematics vs trace x y z: %.2e mm, i j k: %.2e" % (res["fk_check_tip_mm"], res["fk_check_axis"]))


if __name__ == "__main__":
    main()
