# A finishing raster as a CAM system posts it: rows of 0.1 mm G01 moves over a wavy
# surface, 1 mm step-overs (also 0.1 mm moves) between them, F3000.
#   python3 raster.py 3axis   > raster-3axis.nc   (tool vertical)
#   python3 raster.py 5axis   > raster-5axis.nc   (tool along the surface normal, I J K)
#   python3 raster.py tilted-ac [--linuxcnc] > raster-tilted-ac.nc
#       the tool inclined 15 degrees toward -Y (as a ball-end mill is, to keep the cutting
#       off its tip) and following a third of the surface's slope: A and C turn a little on
#       every move (A about 12 to 19 degrees, C within about 35 degrees), never through the
#       vertical; machine angles as for 5axis-ac.
#   python3 raster.py lean-ac [--linuxcnc] > raster-lean-ac.nc
#       the same lean following a tenth of the slope: A and C turn less (A within about 14
#       to 16 degrees, C within about 5.4, at most 0.014 and 0.07 degrees a move). The
#       issue's A/C variant ran 1.010x its 3-axis raster's time in the dnurbs of its day
#       (80.9 against 80.1 s as posted, paper-ac-table); that dnurbs (971ebac) runs this one
#       1.014x its 3-axis time and refuses tilted-ac (C's jerk at its slowest feed).
#   python3 raster.py 5axis-ac [--linuxcnc] > raster-5axis-ac.nc
#       the same tool axes as machine angles A C (degrees) for an xyzac-trt machine (A tilts
#       about X, C turns the table; X Y Z stay the tool tip in the workpiece frame, RTCP).
#       dnurbs: tool axis t = (-sin A sin C, sin A cos C, cos A). LinuxCNC's xyzac-trt-kins
#       turns the table the other way, t = (sin A sin C, sin A cos C, cos A): --linuxcnc
#       negates C. Of the two solutions (A, C) and (-A, C + 180) the one nearest the previous
#       move's angles is taken (C unwrapped, |A| <= 110), as dnurbs itself does; a vertical
#       tool keeps the previous C.
import math, sys
mode = sys.argv[1] if len(sys.argv) > 1 else "3axis"
if mode not in ("3axis", "5axis", "tilted-ac", "lean-ac", "5axis-ac"):
    sys.exit("raster.py: unknown mode %r: 3axis, 5axis, tilted-ac, lean-ac or 5axis-ac" % mode)
c_sign = -1.0 if "--linuxcnc" in sys.argv[2:] else 1.0
def ac_angles(t, prev):
    # (A, C) in degrees for unit tool axis t (dnurbs convention), nearest prev = (A, C)
    rho = math.hypot(t[0], t[1])
    a = math.degrees(math.atan2(rho, t[2]))
    if rho < 1e-12:
        return (-a if prev[0] < 0 else a, prev[1])
    c1 = math.degrees(math.atan2(-t[0], t[1]))
    best, cost_best = None, float("inf")
    for ca, cc in ((a, c1), (-a, c1 + 180.0)):
        near = cc + 360.0 * round((prev[1] - cc) / 360.0)
        for c in (near, near - 360.0, near + 360.0):
            cost = abs(ca - prev[0]) + abs(c - prev[1]) + (1e6 if abs(ca) > 110.0 else 0.0)
            if cost < cost_best:
                best, cost_best = (ca, c), cost
    return best
rows, length, step, over = 32, 60.0, 0.1, 1.0
def z(x, y): return 2.0 * math.sin(x / 8.0) * math.cos(y / 10.0)
def normal(x, y):
    dzdx = 2.0 / 8.0 * math.cos(x / 8.0) * math.cos(y / 10.0)
    dzdy = -2.0 / 10.0 * math.sin(x / 8.0) * math.sin(y / 10.0)
    n = (-dzdx, -dzdy, 1.0); l = math.sqrt(sum(c * c for c in n))
    return tuple(c / l for c in n)
def tilted(x, y, follow):
    n = normal(x, y)
    lean = math.radians(15.0)
    t = (n[0] * follow, n[1] * follow - math.sin(lean), math.cos(lean))
    l = math.sqrt(sum(c * c for c in t))
    return tuple(c / l for c in t)
pts = []
for r in range(rows):
    y = r * over
    xs = [k * step for k in range(int(round(length / step)) + 1)]
    if r % 2: xs = xs[::-1]
    if r > 0:  # the step-over from the last row's end
        for k in range(1, int(round(over / step))):
            yy = (r - 1) * over + k * step
            pts.append((xs[0], yy))
    pts += [(x, y) for x in xs]
print("%%\n(finishing raster, %s, %d moves of %.1f mm, F3000)\nG90 G21 G94" % (mode, len(pts) - 1, step))
prev = (0.0, 0.0)
for k, (x, y) in enumerate(pts):
    w = "G01 " if k < 2 else ""
    f = " F3000" if k == 0 else ""
    if mode == "5axis":
        n = normal(x, y)
        print("%sX%.4f Y%.4f Z%.4f I%.6f J%.6f K%.6f%s" % (w, x, y, z(x, y), n[0], n[1], n[2], f))
    elif mode in ("5axis-ac", "tilted-ac", "lean-ac"):
        t = {"5axis-ac": lambda: normal(x, y), "tilted-ac": lambda: tilted(x, y, 1.0 / 3.0),
             "lean-ac": lambda: tilted(x, y, 0.1)}[mode]()
        prev = ac_angles(t, prev)
        print("%sX%.4f Y%.4f Z%.4f A%.6f C%.6f%s" % (w, x, y, z(x, y), prev[0], c_sign * prev[1], f))
    else:
        print("%sX%.4f Y%.4f Z%.4f%s" % (w, x, y, z(x, y), f))
print("M30\n%")
