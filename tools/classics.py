#!/usr/bin/env python3
"""Write the benchmark curves of the NURBS-interpolation literature as NC programs into
tests/data/classics/ (run from the repository root: python3 tools/classics.py).

Published data, copied as the papers' supplementary code gives it:
  butterfly    degree 3, 51 control points, weights 1..5: the butterfly of the NURBS
               interpolation literature (e.g. Hu, Jiang, Huo et al., Int J Adv Manuf Technol
               129 (2023) 2843-2860), as published with open interpolator code.
  fan-5axis    25 five-axis G01 points with tool vectors: the fan-shaped path of Zhang et
               al., "Feedrate blending method for five-axis linear tool path...", Int J Mech
               Sci 2021, Table B.1; F3000 as in the paper (50 mm/s).
  dual-spline  a cubic tool-tip curve and a cubic second curve on one knot vector (8
               points each): the five-axis path of Ma et al., J Comput Des Eng 2022,
               Appendix 1; exactly the paper's double NURBS (G06.5).
Our own equivalents of the others (their published control points were not available):
  figure-eight-circles  two exact circles (rational quadratic, 9 points) tangent at the
               origin, one each way round;
  figure-eight-weights  a degree-2 figure eight whose turns carry weight 100 (near-corners);
  star         a five-pointed star, cubic, tips pulled sharp by weight 4;
  helix-500    a G06.5 helix of 500 control points (10 turns), the tool leaning 15 degrees
               towards the axis, so C turns ten times: a block far over one real-time piece.
"""

import math
import os

OUT = os.path.join("tests", "data", "classics")

BUTTERFLY_CTRL = [
    (54.493, 52.139), (55.507, 52.139), (56.082, 49.615), (56.78, 44.971), (69.575, 51.358),
    (77.786, 58.573), (90.526, 67.081), (105.973, 63.801), (100.4, 47.326), (94.567, 39.913),
    (92.369, 30.485), (83.44, 33.757), (91.892, 28.509), (89.444, 20.393), (83.218, 15.446),
    (87.621, 4.83), (80.945, 9.267), (79.834, 14.535), (76.074, 8.522), (70.183, 12.55),
    (64.171, 16.865), (59.993, 22.122), (55.68, 36.359), (56.925, 24.995), (59.765, 19.828),
    (54.493, 14.94), (49.22, 19.828), (52.06, 24.994), (53.305, 36.359), (48.992, 22.122),
    (44.814, 16.865), (38.802, 12.551), (32.911, 8.521), (29.152, 14.535), (28.04, 9.267),
    (21.364, 4.83), (25.768, 15.447), (19.539, 20.391), (17.097, 28.512), (25.537, 33.75),
    (16.602, 30.496), (14.199, 39.803), (8.668, 47.408), (3.0, 63.794), (18.465, 67.084),
    (31.197, 58.572), (39.411, 51.358), (52.204, 44.971), (52.904, 49.614), (53.478, 52.139),
    (54.492, 52.139),
]
BUTTERFLY_W = [
    1.0, 1.0, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 5.0, 3.0, 1.0, 1.1,
    1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.1, 1.0, 3.0,
    5.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.2, 1.0, 1.0, 1.0,
]
BUTTERFLY_K = [
    0.0, 0.0, 0.0, 0.0, 0.008286, 0.014978, 0.036118, 0.085467, 0.129349, 0.150871, 0.193075,
    0.227259, 0.243467, 0.25608, 0.269242, 0.288858, 0.316987, 0.331643, 0.348163, 0.355261,
    0.364853, 0.383666, 0.400499, 0.426851, 0.451038, 0.465994, 0.489084, 0.499973, 0.510862,
    0.533954, 0.54891, 0.573096, 0.599447, 0.61628, 0.635094, 0.644687, 0.651784, 0.668304,
    0.682958, 0.711087, 0.730703, 0.743865, 0.756479, 0.772923, 0.806926, 0.84913, 0.870652,
    0.914534, 0.963883, 0.985023, 0.991714, 1.0, 1.0, 1.0, 1.0,
]

FAN_P = [
    (113.5608, 7.7353, -2.2093), (117.8649, -10.9501, -0.9741), (115.5029, -34.8088, 0.7796),
    (104.086, -55.8401, 2.6826), (95.2257, -63.9596, 4.0735), (88.8206, -65.9723, 6.0218),
    (80.1628, -65.0964, 7.0315), (72.4782, -61.1095, 6.8631), (65.9858, -54.6664, 6.143),
    (54.252, -39.5681, 4.9312), (38.039, -23.1115, 3.5361), (31.6791, -18.7113, 3.0176),
    (26.1926, -16.7813, 2.4549), (22.3378, -16.4864, 1.9074), (18.7698, -17.9379, 0.2587),
    (17.0042, -21.3334, -1.3755), (16.7631, -27.0829, -2.5738), (20.0593, -38.2107, -3.5736),
    (26.9912, -67.7863, -5.5703), (28.0807, -86.648, -6.2051), (21.8131, -103.5714, -4.4425),
    (6.1563, -114.1796, -2.0441), (-12.6615, -117.9888, -0.8723), (-31.8162, -116.324, 0.5145),
    (-49.4389, -108.7844, 2.0895),
]
FAN_T = [
    (-0.1073, 0.6249, 0.7733), (-0.003, 0.653, 0.7573), (0.135, 0.6488, 0.7489),
    (0.2639, 0.5968, 0.7578), (0.3172, 0.5518, 0.7713), (0.3295, 0.5161, 0.7906),
    (0.3268, 0.478, 0.8153), (0.3137, 0.4461, 0.8382), (0.2887, 0.4164, 0.8621),
    (0.217, 0.3575, 0.9084), (0.1295, 0.2618, 0.9564), (0.1055, 0.2209, 0.9696),
    (0.0968, 0.1849, 0.978), (0.0979, 0.1597, 0.9823), (0.1106, 0.1379, 0.9843),
    (0.1335, 0.1275, 0.9828), (0.1711, 0.1277, 0.9769), (0.239, 0.1533, 0.9588),
    (0.3999, 0.2013, 0.8942), (0.4879, 0.2082, 0.8477), (0.5679, 0.1822, 0.8027),
    (0.6287, 0.0985, 0.7714), (0.6542, -0.0066, 0.7563), (0.652, -0.1172, 0.7491),
    (0.6189, -0.2239, 0.7529),
]

DUAL_P = [(5, 0, 0), (-10, 20, 0), (10, 20, 0), (20, 30, 0), (30, 30, 0), (40, 30, 0),
          (50, 20, 0), (55, 0, 0)]
DUAL_H = [(0, 0, 15), (-15, 20, 15), (5, 25, 15), (15, 35, 15), (30, 35, 15), (45, 35, 15),
          (55, 25, 15), (60, 0, 15)]
DUAL_K = [0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1, 1]


def f(x):
    s = f"{x:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


def start(p, t=(0.0, 0.0, 1.0)):
    return f"N10 G01 X{f(p[0])} Y{f(p[1])} Z{f(p[2])} I{f(t[0])} J{f(t[1])} K{f(t[2])} F1000\n"


def g062(n, degree, ctrl, w, k, feed):
    """A G06.2 block: each line K X Y Z R, the last degree+1 knots on their own line."""
    lines = [f"N{n} G06.2 P{degree + 1} F{feed}"]
    for i, (p, wi) in enumerate(zip(ctrl, w)):
        lines.append(f" K{f(k[i])} X{f(p[0])} Y{f(p[1])} Z{f(p[2])} R{f(wi)}")
    text = lines[0] + lines[1] + "\n" + "\n".join(l.strip() for l in lines[2:]) + "\n"
    return text + " ".join(f"K{f(x)}" for x in k[len(ctrl):]) + "\n"


def g065(n, degree, ctrl, top, w, k, feed):
    """A G06.5 block: each line X Y Z U V W R K, then the trailing knots."""
    rows = [
        f"X{f(p[0])} Y{f(p[1])} Z{f(p[2])} U{f(q[0])} V{f(q[1])} W{f(q[2])} R{f(wi)} K{f(k[i])}"
        for i, (p, q, wi) in enumerate(zip(ctrl, top, w))
    ]
    text = f"N{n} G06.5 P{degree} F{feed} " + rows[0] + "\n" + "\n".join(rows[1:]) + "\n"
    return text + " ".join(f"K{f(x)}" for x in k[len(ctrl):]) + "\n"


def uniform(n, p):
    inner = [i / (n - p) for i in range(1, n - p)]
    return [0.0] * (p + 1) + inner + [1.0] * (p + 1)


def circle(cx, cy, r, ccw, phase):
    """Full circle, rational quadratic: 9 points, double interior knots."""
    s = math.sqrt(0.5)
    pts, w = [], []
    for i in range(9):
        a = phase + (1 if ccw else -1) * i * math.pi / 4
        rr = r if i % 2 == 0 else r / s  # corner points of the circumscribed square
        pts.append((cx + rr * math.cos(a), cy + rr * math.sin(a), 0.0))
        w.append(1.0 if i % 2 == 0 else s)
    k = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]
    return pts, w, k


def programs():
    out = {}
    bc = [(x, y, 0.0) for x, y in BUTTERFLY_CTRL]
    out["butterfly"] = ("; butterfly: degree 3, 51 control points (published data), F6000\n"
                        + start(bc[0]) + g062(20, 3, bc, BUTTERFLY_W, BUTTERFLY_K, 6000))

    body = "; fan-shaped five-axis G01 path (Zhang et al. 2021, Table B.1), F3000\n"
    body += start(FAN_P[0], unit(FAN_T[0]))
    for i, (p, t) in enumerate(zip(FAN_P[1:], FAN_T[1:])):
        t = unit(t)
        body += (f"N{20 + 10 * i} G01 X{f(p[0])} Y{f(p[1])} Z{f(p[2])}"
                 f" I{f(t[0])} J{f(t[1])} K{f(t[2])} F3000\n")
    out["fan-5axis"] = body

    t0 = unit(tuple(h - p for h, p in zip(DUAL_H[0], DUAL_P[0])))
    out["dual-spline"] = ("; dual cubic B-spline five-axis path (Ma et al. 2022), F3000\n"
                          + start(DUAL_P[0], t0)
                          + g065(20, 3, DUAL_P, DUAL_H, [1.0] * 8, DUAL_K, 3000))

    c1, w1, k1 = circle(20, 0, 20, True, math.pi)
    c2, w2, k2 = circle(-20, 0, 20, False, 0.0)
    out["figure-eight-circles"] = ("; figure eight of two exact circles, radius 20, F6000\n"
                                   + start(c1[0]) + g062(20, 2, c1, w1, k1, 6000)
                                   + g062(30, 2, c2, w2, k2, 6000))

    pts = [(0, 0), (20, 20), (40, 0), (20, -20), (0, 0), (-20, 20), (-40, 0), (-20, -20), (0, 0)]
    pts = [(x, y, 0.0) for x, y in pts]
    w = [1, 1, 100, 1, 1, 1, 100, 1, 1]
    out["figure-eight-weights"] = ("; degree-2 figure eight, weight 100 at its turns, F6000\n"
                                   + start(pts[0]) + g062(20, 2, pts, w, uniform(9, 2), 6000))

    star = []
    for i in range(11):
        a = math.pi / 2 + i * math.pi / 5
        r = 40 if i % 2 == 0 else 15
        star.append((r * math.cos(a), r * math.sin(a), 0.0))
    w = [4.0 if i % 2 == 0 else 1.0 for i in range(11)]
    w[0] = w[-1] = 1.0
    out["star"] = ("; five-pointed star, cubic, tips weighted 4, F6000\n"
                   + start(star[0]) + g062(20, 3, star, w, uniform(11, 3), 6000))

    n, turns, r, pitch, lean = 500, 10, 20.0, 2.0, math.radians(15)
    helix, top = [], []
    for i in range(n):
        a = 2 * math.pi * turns * i / (n - 1)
        p = (r * math.cos(a), r * math.sin(a), pitch * turns * i / (n - 1))
        t = (-math.sin(lean) * math.cos(a), -math.sin(lean) * math.sin(a), math.cos(lean))
        helix.append(p)
        top.append(tuple(pc + 20 * tc for pc, tc in zip(p, t)))
    # The interpolating curve of these points sits slightly inside them; the tool axis at
    # the start is the curve's own (its first two nets' points coincide with the start).
    t_start = unit(tuple(q - p for q, p in zip(top[0], helix[0])))
    out["helix-500"] = ("; G06.5 helix, 500 control points, 10 turns, tool leaning 15 deg, F3000\n"
                        + start(helix[0], t_start)
                        + g065(20, 3, helix, top, [1.0] * n, uniform(n, 3), 3000))
    return out


def main():
    os.makedirs(OUT, exist_ok=True)
    for name, body in programs().items():
        with open(os.path.join(OUT, name + ".nc"), "w") as fh:
            fh.write("%\n" + body + "M30\n%\n")
        print(os.path.join(OUT, name + ".nc"))


if __name__ == "__main__":
    main()
