# A finishing raster as a CAM system posts it: rows of 0.1 mm G01 moves over a wavy
# surface, 1 mm step-overs (also 0.1 mm moves) between them, F3000.
#   python3 raster.py 3axis   > raster-3axis.nc   (tool vertical)
#   python3 raster.py 5axis   > raster-5axis.nc   (tool along the surface normal, I J K)
import math, sys
mode = sys.argv[1] if len(sys.argv) > 1 else "3axis"
rows, length, step, over = 32, 60.0, 0.1, 1.0
def z(x, y): return 2.0 * math.sin(x / 8.0) * math.cos(y / 10.0)
def normal(x, y):
    dzdx = 2.0 / 8.0 * math.cos(x / 8.0) * math.cos(y / 10.0)
    dzdy = -2.0 / 10.0 * math.sin(x / 8.0) * math.sin(y / 10.0)
    n = (-dzdx, -dzdy, 1.0); l = math.sqrt(sum(c * c for c in n))
    return tuple(c / l for c in n)
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
for k, (x, y) in enumerate(pts):
    w = "G01 " if k < 2 else ""
    f = " F3000" if k == 0 else ""
    if mode == "5axis":
        n = normal(x, y)
        print("%sX%.4f Y%.4f Z%.4f I%.6f J%.6f K%.6f%s" % (w, x, y, z(x, y), n[0], n[1], n[2], f))
    else:
        print("%sX%.4f Y%.4f Z%.4f%s" % (w, x, y, z(x, y), f))
print("M30\n%")
