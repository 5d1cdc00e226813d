#!/usr/bin/python3
"""Regenerates the conformance suite's reference motion from LinuxCNC's own interpreter.

For every program under tests/conformance/programs/ this runs LinuxCNC's RS274/NGC
interpreter twice:

- through its Python module `gcode` (the interpreter core AXIS previews with), which reports
  every canonical motion call with full double precision; that is the reference written to
  tests/conformance/expected/<same path>.txt;
- through `rs274 -g`, the stand-alone interpreter, whose 4-decimal output must agree with
  the full-precision reference to within its rounding (a check that the two are the same
  interpreter and that this script reads both right).

Usage (Debian package linuxcnc-uspace, system Python):
    /usr/bin/python3 tests/conformance/regen.py            # all programs
    /usr/bin/python3 tests/conformance/regen.py FILE.ngc   # some (also tests/corpus/programs/*)

Reference format, one motion per line, lengths in mm (the module reports inches), angles in
degrees; positions are where the tool goes: the interpreter's program coordinates plus the
G5x and G92 offsets it sets (dnurbs's blocks are in that frame):
    T <line> x y z a b c                       rapid (STRAIGHT_TRAVERSE)
    F <line> x y z a b c                       feed (STRAIGHT_FEED)
    A <line> <plane> <turn> x y z c1 c2 a b c  arc (ARC_FEED): end point, centre in the plane's
                                               first and second axes (XY: X Y, YZ: Y Z, XZ: Z X)
    E <line> <message>                         LinuxCNC stops with this error
    P <mm>|full                                how exact the numbers are: full precision from
                                               the module, or rs274's 4 decimals where the
                                               module fails on the program or disagrees
"""
import math
import os
import re
import subprocess
import sys
import tempfile

import gcode

MM = 25.4
HERE = os.path.dirname(os.path.abspath(__file__))
PROGRAMS = os.path.join(HERE, "programs")
EXPECTED = os.path.join(HERE, "expected")
PLANES = {1: "XY", 2: "YZ", 3: "XZ"}


def offset_of(g5x, g92, rot):
    """How program coordinates become the tool's: LinuxCNC's canon adds the G92 offset,
    turns X Y by the rotation, adds the G5x offset. Without a rotation: the two offsets'
    sum (in the order the references were first written with)."""
    if rot == 0.0:
        return [g + h for g, h in zip(g5x, g92)]
    return list(g5x) + list(g92) + [rot]


def place(vals, off):
    """Program X Y Z A B C (mm, degrees) where the tool goes."""
    if len(off) == 6:
        return [v + o for v, o in zip(vals, off)]
    g5x, g92, rot = off[0:6], off[6:12], off[12]
    x, y = vals[0] + g92[0], vals[1] + g92[1]
    c, s = math.cos(math.radians(rot)), math.sin(math.radians(rot))
    x, y = c * x - s * y, s * x + c * y
    return ([x + g5x[0], y + g5x[1], vals[2] + g92[2] + g5x[2]]
            + [v + g + h for v, g, h in zip(vals[3:6], g92[3:6], g5x[3:6])])


class Canon:
    """Records the motion the interpreter asks for (the module calls these methods)."""

    def __init__(self, var_file):
        self.parameter_file = var_file
        self.out = []
        self.line = 0
        self.plane = 1
        # The program's zero: the G5x and G92 offsets (mm). The interpreter reports program
        # coordinates; the reference is where the tool goes, the program's plus these.
        # X Y Z (mm) and A B C (degrees), and the XY rotation (degrees, G10 L2 R).
        self.g5x = [0.0] * 6
        self.g92 = [0.0] * 6
        self.rot = 0.0

    def offset(self):
        return offset_of(self.g5x, self.g92, self.rot)

    def set_xy_rotation(self, r):
        self.rot = r

    def set_g5x_offset(self, index, x, y, z, a=0.0, b=0.0, c=0.0, *rest):
        self.g5x = [x * MM, y * MM, z * MM, a, b, c]

    def set_g92_offset(self, x, y, z, a=0.0, b=0.0, c=0.0, *rest):
        self.g92 = [x * MM, y * MM, z * MM, a, b, c]

    # Queries the interpreter makes: rs274's answers (user units inch, XYZABC, no tools).
    def get_external_length_units(self):
        return 0.03937007874016

    def get_external_angular_units(self):
        return 1.0

    def get_axis_mask(self):
        return 0x3F

    def get_block_delete(self):
        return False

    def get_tool(self, idx):
        return (-1,) + (0.0,) * 12 + (0,)

    def check_abort(self):
        return False

    def next_line(self, st):
        self.line = st.sequence_number

    def set_plane(self, plane):
        self.plane = plane

    def straight_traverse(self, x, y, z, a, b, c, u, v, w):
        self.out.append(("T", self.line, [x * MM, y * MM, z * MM, a, b, c], self.offset()))

    def straight_feed(self, x, y, z, a, b, c, u, v, w):
        self.out.append(("F", self.line, [x * MM, y * MM, z * MM, a, b, c], self.offset()))

    def arc_feed(self, e1, e2, c1, c2, turn, axis_end, a, b, c, u, v, w):
        # End point back in X Y Z from the plane's first, second and axis coordinates.
        if self.plane == 1:
            xyz = (e1, e2, axis_end)
        elif self.plane == 2:
            xyz = (axis_end, e1, e2)
        else:
            xyz = (e2, axis_end, e1)
        vals = [v * MM for v in xyz] + [c1 * MM, c2 * MM, a, b, c]
        self.out.append(("A", self.line, PLANES[self.plane], turn, vals, self.offset()))

    def __getattr__(self, name):
        # Every other canonical call (feeds, spindle, comments, offsets): not motion.
        if name.startswith("__"):
            raise AttributeError(name)
        return lambda *args: None


def reference(path):
    """The full-precision motion of `path` from the module, run in a child process (the
    module crashes on some programs, such as a tool change without a tool table); `None`
    when it failed."""
    run = subprocess.run([sys.executable, __file__, "--module", path], capture_output=True,
                         text=True)
    if run.returncode != 0 or "@@motion@@" not in run.stdout:
        return None
    # Our own repr of a list of tuples of numbers and strings, after whatever the program
    # printed itself.
    return eval(run.stdout.rsplit("@@motion@@", 1)[1])


def module_motion(path):
    """The module's motion of `path` (in this process)."""
    with tempfile.TemporaryDirectory() as tmp:
        var = os.path.join(tmp, "empty.var")
        open(var, "w").close()
        canon = Canon(var)
        # Relative subroutine files are looked for from the program's directory.
        cwd = os.getcwd()
        os.chdir(os.path.dirname(path))
        try:
            gcode.parse(path, canon, "", "")
        finally:
            os.chdir(cwd)
    return canon.out


def fmt(v):
    return repr(float(v))


def rs274_error(path, stderr, motion):
    """rs274's error (its first line) and the line it stands on: rs274 echoes the line's
    text, looked for from the last move's line on."""
    lines = [l.rstrip() for l in stderr.splitlines() if l.strip() and l.strip() != "executing"]
    if not lines:
        return None
    message = lines[0].replace("executing", "").strip()
    text = lines[1] if len(lines) > 1 else ""
    program = open(path).read().splitlines()
    start = motion[-1][1] if motion else 1
    found = [i + 1 for i, l in enumerate(program) if l.rstrip() == text]
    after = [n for n in found if n >= start]
    line = (after or found or [0])[0]
    return (line, message)


def rs274_run(path):
    """What `rs274 -g` prints: each move (canon name, mm per program unit, plane, numbers),
    its motion in this script's records (to its 4 decimals, in mm), and its error."""
    run = subprocess.run(["rs274", "-g"] + TOOLS + [path], capture_output=True, text=True,
                         cwd=os.path.dirname(path))
    scale = 1.0
    plane = "XY"
    printed = []
    motion = []
    g5x, g92, rot = [0.0] * 6, [0.0] * 6, 0.0
    for line in run.stdout.splitlines():
        m = re.search(r"SET_XY_ROTATION\((.*)\)", line)
        if m:
            rot = float(m.group(1))
        # X Y Z scaled to mm, A B C in degrees.
        m = re.search(r"SET_G5X_OFFSET\(\d+, (.*)\)", line)
        if m:
            t = [float(t) for t in m.group(1).split(",")[:6]]
            g5x = [v * scale for v in t[:3]] + t[3:]
        m = re.search(r"SET_G92_OFFSET\((.*)\)", line)
        if m:
            t = [float(t) for t in m.group(1).split(",")[:6]]
            g92 = [v * scale for v in t[:3]] + t[3:]
        offset = offset_of(g5x, g92, rot)
        if "USE_LENGTH_UNITS(CANON_UNITS_INCHES)" in line:
            scale = MM
        elif "USE_LENGTH_UNITS(CANON_UNITS_MM)" in line:
            scale = 1.0
        m = re.search(r"SELECT_PLANE\(CANON_PLANE_(XY|YZ|XZ)\)", line)
        if m:
            plane = m.group(1)
        n = re.match(r"\s*\d+ N(\d*)", line)
        m = re.search(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED)\((.*)\)", line)
        if m:
            nums = [float(t) for t in m.group(2).split(",")]
            printed.append((m.group(1), scale, nums))
            if m.group(1) == "ARC_FEED":
                e1, e2, c1, c2, turn, ax, a, b, c = nums
                first, second, axis = {"XY": (0, 1, 2), "YZ": (1, 2, 0), "XZ": (2, 0, 1)}[plane]
                xyz = [0.0] * 3
                xyz[first], xyz[second], xyz[axis] = e1, e2, ax
                vals = [v * scale for v in xyz] + [c1 * scale, c2 * scale, a, b, c]
                motion.append(("A", 0, plane, int(turn), vals, offset))
            else:
                kind = "T" if m.group(1) == "STRAIGHT_TRAVERSE" else "F"
                motion.append((kind, 0, [v * scale for v in nums[:3]] + nums[3:6], offset))
    return run, printed, motion


def rs274_check(path, motion):
    """`rs274 -g` prints the same motion, to 4 decimals in the program's units, and stops
    where it stops (the module is the preview's interpreter: it does not check everything
    rs274 does, such as a G1 without feed). Returns the motion up to rs274's error, and the
    error; `None` for the motion when the module's does not agree with rs274's."""
    run, printed, _ = rs274_run(path)
    error = rs274_error(path, run.stderr, motion) if run.returncode != 0 else None
    if error:
        motion = motion[:len(printed)]
    if len(printed) != len(motion):
        return None, error
    for (name, scale, nums), move in zip(printed, motion):
        if move[0] == "A":
            _, _, plane, turn, vals = move[:5]
            e = vals[0:3]
            first, second, axis = {"XY": (0, 1, 2), "YZ": (1, 2, 0), "XZ": (2, 0, 1)}[plane]
            want = [e[first], e[second], vals[3], vals[4], turn, e[axis]] + vals[5:8]
            units = [scale, scale, scale, scale, None, scale, 1, 1, 1]
        else:
            want = move[2]
            units = [scale] * 3 + [1] * 3
        for got, w, unit in zip(nums, want, units):
            if unit is None:
                ok = got == w
            else:
                ok = abs(got * unit - w) <= (0.5e-4 + 1e-9) * unit
            if not ok:
                return None, error
    return motion, error


# Machine-defined M-codes of LinuxCNC's trunnion demos, which only switch its kinematics
# (M428 tool-centre-point, M429 trivial): the stand-alone interpreter has no such codes, and
# they move nothing, so they are blanked (in a copy, lines kept) for it.
SWITCHKINS = re.compile(r"\bM\s*4\s*2\s*[89]\b", re.IGNORECASE)


# rs274's tool table: its default (T1 T2 T3 T99999) for the conformance suite; the shipped
# machines' table for the real programs of tests/corpus/, which run on those machines.
# rs274's machine is an inch machine, whose tool table is in inches: the table's millimetres
# are converted for it (a G28 under G43 then ends where dnurbs's does).
TOOLS = []
MILL_TBL = os.path.join(HERE, "..", "..", "config", "machines", "mill.tbl")


def inch_table(tmp):
    out = os.path.join(tmp, "mill-inch.tbl")
    with open(MILL_TBL) as f, open(out, "w") as g:
        for line in f:
            body, _, comment = line.partition(";")
            words = [w if w[:1].upper() not in "XYZD" else
                     "%s%.6f" % (w[0], float(w[1:]) / MM) for w in body.split()]
            g.write(" ".join(words) + (" ;" + comment if comment else "\n"))
    return out


def write(path, out_path):
    if os.sep + "corpus" + os.sep not in path:
        TOOLS[:] = []
        return write_program(path, out_path)
    with tempfile.TemporaryDirectory() as tmp:
        TOOLS[:] = ["-t", inch_table(tmp)]
        return write_program(path, out_path)


def write_program(path, out_path):
    with open(path, errors="replace") as f:
        text = f.read()
    if SWITCHKINS.search(text):
        with tempfile.TemporaryDirectory() as tmp:
            copy = os.path.join(tmp, os.path.basename(path))
            with open(copy, "w") as f:
                f.write(SWITCHKINS.sub(lambda m: " " * len(m.group(0)), text))
            return write_from(copy, path, out_path)
    return write_from(path, path, out_path)


def write_from(path, named, out_path):
    full = reference(path)
    motion, error = rs274_check(path, full) if full is not None else (None, None)
    precision = "full"
    if motion is None:
        # The module failed or disagrees (its tool table, its feed checks): rs274's own
        # numbers, to the 4 decimals it prints.
        run, printed, motion = rs274_run(path)
        error = rs274_error(path, run.stderr, motion) if run.returncode != 0 else None
        inch = any(scale != 1.0 for _, scale, _ in printed)
        precision = "%.9g" % (0.5e-4 * (MM if inch else 1.0))
        # The line numbers come from rs274's N field only where lines carry N words;
        # leave them 0 (they only label messages).
    os.makedirs(os.path.dirname(out_path), exist_ok=True)
    with open(out_path, "w") as f:
        f.write("# LinuxCNC's interpreter on %s (tests/conformance/regen.py); mm, degrees\n"
                % os.path.relpath(named, HERE))
        f.write("P %s\n" % precision)
        for move in motion:
            # Program coordinates plus the program's zero (the G5x and G92 offsets).
            off = move[-1]
            if move[0] == "A":
                _, line, plane, turn, vals, _ = move
                first, second, _ = {"XY": (0, 1, 2), "YZ": (1, 2, 0), "XZ": (2, 0, 1)}[plane]
                # The centre is a point too: the end's, with the plane's two coordinates.
                centre = list(vals[0:3])
                centre[first], centre[second] = vals[3], vals[4]
                centre = place(centre + [0.0, 0.0, 0.0], off)
                end = place(vals[0:3] + vals[5:8], off)
                vals = end[0:3] + [centre[first], centre[second]] + end[3:6]
                f.write("A %d %s %d %s\n" % (line, plane, turn, " ".join(fmt(v) for v in vals)))
            else:
                kind, line, vals, _ = move
                vals = place(vals, off)
                f.write("%s %d %s\n" % (kind, line, " ".join(fmt(v) for v in vals)))
        if error:
            f.write("E %d %s\n" % (error[0], error[1].replace("\n", " ")))


def main():
    if sys.argv[1:2] == ["--module"]:
        motion = module_motion(sys.argv[2])
        print("@@motion@@" + repr(motion))
        return
    paths = sys.argv[1:]
    if not paths:
        for root, _, files in os.walk(PROGRAMS):
            paths += [os.path.join(root, f) for f in sorted(files) if f.endswith(".ngc")]
    for p in sorted(os.path.abspath(p) for p in paths):
        # The reference goes to the `expected` folder beside the `programs` folder the
        # program is under (tests/conformance/ or tests/corpus/), at the same relative path.
        root = p
        while os.path.basename(root) != "programs" and os.path.dirname(root) != root:
            root = os.path.dirname(root)
        if os.path.basename(root) != "programs":
            root = PROGRAMS
        rel = os.path.relpath(p, root)
        out = os.path.join(os.path.dirname(root), "expected", os.path.splitext(rel)[0] + ".txt")
        write(p, out)
    print(f"{len(paths)} references written (each beside its programs folder, in expected/)")


if __name__ == "__main__":
    main()
