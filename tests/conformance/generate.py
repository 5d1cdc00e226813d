#!/usr/bin/env python3
"""Generates the conformance suite's programs under tests/conformance/programs/gen/.

Deterministic (seeded): running it again writes the same files. Families:

- expr:  parameter assignments (numbered, named local and global, indirection) and moves
         whose words are random expressions over every operator and function; some lines
         break a rule (divide by zero, an undefined name, a function's domain) on purpose;
- flow:  nested while, do-while and repeat loops, if/elseif/else, break and continue;
- subs:  subroutines with arguments and return values, nested calls, recursion with a
         counter, calls before the definition (after M2);
- arcs:  G02/G03 in G17, G18 and G19, centre (IJK) and radius (R, both signs) forms,
         helices, full circles, G90 and G91, mm and inch;
- units: G20/G21 and G90/G91 switched along a program, with parameters and rotary axes;
- comp:  cutter radius compensation on random closed contours of lines and arcs.

Then run regen.py (system Python with LinuxCNC's `gcode` module) for the references.
"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "programs", "gen")

FUNCS = ["ABS", "ACOS", "ASIN", "COS", "EXP", "FIX", "FUP", "LN", "ROUND", "SIN", "SQRT", "TAN"]
OPS = ["**", "*", "/", "MOD", "+", "-", "EQ", "NE", "GT", "GE", "LT", "LE", "AND", "OR", "XOR"]


def num(r, lo=-20.0, hi=20.0, digits=4):
    v = round(r.uniform(lo, hi), digits)
    return ("%." + str(digits) + "f") % v


class Expr:
    """Random expressions over the parameters that exist."""

    def __init__(self, r, params):
        self.r = r
        self.params = params  # names (with #) that have been set

    def value(self, depth):
        r = self.r
        k = r.random()
        if depth <= 0 or k < 0.3:
            if self.params and r.random() < 0.5:
                return r.choice(self.params)
            return num(r, -9, 9, r.choice([0, 1, 2, 4]))
        if k < 0.45:
            f = r.choice(FUNCS)
            arg = self.bracketed(depth - 1)
            if f in ("ACOS", "ASIN"):
                arg = "[%s MOD 1]" % arg  # mostly in the domain
            elif f in ("LN", "SQRT"):
                arg = "[ABS%s + 0.5]" % arg
            elif f == "EXP":
                arg = "[%s MOD 5]" % arg
            return f + arg
        if k < 0.52:
            return "ATAN%s/%s" % (self.bracketed(depth - 1), self.bracketed(depth - 1))
        if k < 0.58:
            return "-" + self.value(depth - 1)
        return self.bracketed(depth - 1)

    def bracketed(self, depth):
        r = self.r
        n = r.randint(1, 3)
        parts = [self.value(depth)]
        for _ in range(n):
            op = r.choice(OPS)
            rhs = self.value(depth)
            if op == "**":
                rhs = r.choice(["2", "3", "0.5", "[ABS%s MOD 3]" % self.bracketed(0)])
                parts[-1] = "ABS[%s]" % parts[-1] if not parts[-1].startswith("[") else "ABS" + parts[-1]
            if op in ("/", "MOD"):
                rhs = "[%s + 0.37]" % rhs if r.random() < 0.95 else rhs
            parts += [op, rhs]
        return "[" + " ".join(parts) + "]"

    def bounded(self, depth):
        """An expression kept to a machine-sized value (mod 200)."""
        return "[%s MOD 200 - 100]" % self.bracketed(depth)


def expr_program(r, k):
    lines = ["(expressions and parameters %d)" % k, "G21 G90 G17", "G0 X0 Y0 Z0"]
    params = []
    e = Expr(r, params)
    feed = False
    for _ in range(r.randint(8, 18)):
        c = r.random()
        mark = len(lines)
        if c < 0.4:
            name = r.choice(["#%d" % r.randint(1, 60), "#<p%d>" % r.randint(1, 8),
                             "#<_g%d>" % r.randint(1, 4), "#[%d + 2]" % r.randint(1, 30)])
            rhs = e.bounded(2)
            # Several assignments on a line: they take effect together, after it.
            extra = ""
            if r.random() < 0.3:
                extra = " #%d=%s" % (r.randint(1, 60), e.value(1))
            lines.append("%s=%s%s" % (name, rhs, extra))
            if len(lines[-1]) <= 200 and (name.startswith("#<") or name[1:].isdigit()):
                params.append(name)
        else:
            words = ["X" + e.bounded(2), "Y" + e.bounded(1)]
            if r.random() < 0.6:
                words.append("Z" + e.bounded(1))
            if r.random() < 0.3:
                words.append("#%d=%s" % (r.randint(1, 60), e.value(1)))
            r.shuffle(words)
            g = r.choice(["G0", "G1"])
            if g == "G1" and not feed:
                words.append("F%d" % r.randint(100, 3000))
            lines.append(g + " " + " ".join(words))
            feed |= g == "G1" and len(lines[-1]) <= 200
        if len(lines[-1]) > 200:
            # Too long for LinuxCNC (252 characters): a shorter one of the same kind.
            del lines[mark:]
    if r.random() < 0.25:
        # A line that breaks a rule: LinuxCNC and dnurbs stop there.
        if True:
            bad = r.choice(["G0 X[1/[%s - %s]]" % ("#9", "#9"), "G0 X#<undefined%d>" % k,
                            "G0 X[SQRT[-1 - ABS[#3]]]", "G0 X[LN[0]]", "G0 X[ACOS[2]]",
                            "#0=1", "G0 X[-1 ** 0.5]", "G0 X[5 MOD 0]"])
            lines.append(bad)
    lines.append("M2")
    return lines


def flow_program(r, k):
    lines = ["(loops and branches %d)" % k, "G21 G90 G17", "G0 X0 Y0 Z0", "F600", "#1=0"]
    label = [100]

    def new_label():
        label[0] += 10
        return label[0]

    def block(depth, counter):
        out = []
        for _ in range(r.randint(1, 3)):
            c = r.random()
            if depth <= 0 or c < 0.4:
                out.append("#1=[#1+1]")
                out.append("G1 X[#1 MOD 50] Y[#%d * 2 + #1 * 0.1] Z[-#1 MOD 7]" % counter)
            elif c < 0.55:
                n = new_label()
                v = "#%d" % (10 + depth)
                out += ["%s=0" % v, "o%d while [%s LT %d]" % (n, v, r.randint(0, 4))]
                out += ["%s=[%s+1]" % (v, v)]
                out += block(depth - 1, 10 + depth)
                if r.random() < 0.4:
                    m = new_label()
                    out += ["o%d if [[#1 MOD 3] EQ 0]" % m,
                            "o%d %s" % (n, r.choice(["break", "continue"])), "o%d endif" % m]
                out += ["o%d endwhile" % n]
            elif c < 0.7:
                n = new_label()
                v = "#%d" % (10 + depth)
                out += ["%s=0" % v, "o%d do" % n, "%s=[%s+1]" % (v, v)]
                out += block(depth - 1, 10 + depth)
                out += ["o%d while [%s LT %d]" % (n, v, r.randint(1, 3))]
            elif c < 0.85:
                n = new_label()
                out += ["o%d repeat [%s]" % (n, r.choice(["0", "1", "2", "3", "2.5", "1.5", "#1 MOD 3"]))]
                out += block(depth - 1, counter)
                out += ["o%d endrepeat" % n]
            else:
                n = new_label()
                out += ["o%d if [[#1 MOD 4] %s %d]" % (n, r.choice(["EQ", "GT", "LT"]), r.randint(0, 3))]
                out += block(depth - 1, counter)
                if r.random() < 0.5:
                    out += ["o%d elseif [#1 GT %d]" % (n, r.randint(0, 6))]
                    out += block(depth - 1, counter)
                if r.random() < 0.6:
                    out += ["o%d else" % n]
                    out += block(depth - 1, counter)
                out += ["o%d endif" % n]
        return out

    lines += block(3, 1)
    lines.append("M2")
    return lines


def subs_program(r, k):
    lines = ["(subroutines %d)" % k]
    names = ["s%d" % i for i in range(r.randint(2, 4))]
    bodies = {}
    for i, name in enumerate(names):
        body = ["o<%s> sub" % name,
                "#<here> = [#1 + #2 * 0.5]",
                "G1 X[#<here> MOD 80] Y[#3 + %d] F%d" % (i, r.randint(200, 900))]
        # Call a later subroutine (depth stays bounded by the number of names).
        if i + 1 < len(names) and r.random() < 0.7:
            body += ["o<%s> call [#1 + 1] [#2 * 2] [%s]" % (names[i + 1], num(r, -5, 5)),
                     "G0 Y[#<_value> MOD 60] Z#<_value_returned>"]
        if r.random() < 0.4:
            body += ["o%d if [#1 GT 3]" % (i + 1), "o<%s> return [#1 * 10]" % name, "o%d endif" % (i + 1)]
        body += ["o<%s> endsub [#<here> + %s]" % (name, num(r, 0, 3))]
        bodies[name] = body
    after = r.random() < 0.5
    main = ["G21 G90 G17", "G0 X0 Y0 Z0"]
    if r.random() < 0.5:
        # Recursion with a counter, as LinuxCNC's factorial.ngc.
        bodies["fact"] = ["o<fact> sub", "o1 if [#1 LE 1]", "o<fact> return [1]", "o1 endif",
                          "o<fact> call [#1 - 1]", "o<fact> endsub [#1 * #<_value>]"]
        main += ["o<fact> call [%d]" % r.randint(1, 6), "G0 X[#<_value> MOD 90]"]
    for _ in range(r.randint(2, 5)):
        args = " ".join("[%s]" % num(r, -5, 5, 2) for _ in range(r.randint(0, 4)))
        main += ["#1=%s" % num(r, -3, 3), "o<%s> call %s" % (r.choice(names), args),
                 "G0 X[#1 + #<_value> MOD 70] Y#<_value_returned>"]
    defs = [l for n in bodies for l in bodies[n]]
    if after:
        lines += main + ["M2"] + defs
    else:
        lines += defs + main + ["M2"]
    return lines


def fmt(v, d=4):
    s = ("%." + str(d) + "f") % v
    return "0.0000" if s in ("-0.0000",) else s


def arcs_program(r, k):
    inch = r.random() < 0.3
    unit = 25.4 if inch else 1.0
    lines = ["(arcs %d)" % k, "G20" if inch else "G21", "G90", "G0 X0 Y0 Z0", "F%d" % r.randint(50, 500)]
    pos = [0.0, 0.0, 0.0]
    incremental = False
    absolute_centre = False
    plane = 17
    for _ in range(r.randint(4, 12)):
        if r.random() < 0.25:
            plane = r.choice([17, 18, 19])
            lines.append("G%d" % plane)
        if r.random() < 0.15:
            incremental = not incremental
            lines.append("G91" if incremental else "G90")
        if r.random() < 0.1:
            # Arc centres as absolute coordinates (G90.1) or offsets from the start (G91.1).
            absolute_centre = not absolute_centre
            lines.append("G90.1" if absolute_centre else "G91.1")
        first, second, axis = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}[plane]
        letters = "XYZ"
        offs = "IJK"
        if r.random() < 0.2:
            # A straight move in between.
            new = [p + r.uniform(-20, 20) / unit for p in pos]
            new = [round(v, 4) for v in new]
            words = " ".join("%s%s" % (letters[i], fmt(new[i] - pos[i] if incremental else new[i])) for i in range(3))
            lines.append("G1 " + words)
            pos = new
            continue
        rad = r.uniform(1, 30) / unit
        a0 = r.uniform(0, 2 * math.pi)
        centre = [pos[first] - rad * math.cos(a0), pos[second] - rad * math.sin(a0)]
        cw = r.random() < 0.5
        full = r.random() < 0.1
        sweep = 0 if full else r.uniform(0.05, 1.9 * math.pi)
        a1 = a0 - sweep if cw else a0 + sweep
        end = list(pos)
        end[first] = round(centre[0] + rad * math.cos(a1), 4)
        end[second] = round(centre[1] + rad * math.sin(a1), 4)
        if full:
            end[first], end[second] = pos[first], pos[second]
        if r.random() < 0.3:
            end[axis] = round(pos[axis] + r.uniform(-5, 5) / unit, 4)
        words = []
        for i in range(3):
            if end[i] != pos[i] or r.random() < 0.3:
                v = end[i] - pos[i] if incremental else end[i]
                words.append("%s%s" % (letters[i], fmt(v)))
        use_r = (not full) and r.random() < 0.35
        if use_r:
            radius = rad if (sweep <= math.pi) else -rad
            # R picks the arc; keep clear of the half circle where it is ambiguous.
            if abs(sweep - math.pi) < 0.05:
                continue
            words.append("R%s" % fmt(radius))
        elif absolute_centre:
            words.append("%s%s" % (offs[first], fmt(centre[0])))
            words.append("%s%s" % (offs[second], fmt(centre[1])))
        else:
            words.append("%s%s" % (offs[first], fmt(centre[0] - pos[first])))
            words.append("%s%s" % (offs[second], fmt(centre[1] - pos[second])))
        lines.append("%s %s" % ("G2" if cw else "G3", " ".join(words)))
        # What the program says is where it is (to 4 decimals).
        pos = [float(fmt(v)) for v in end]
    lines.append("M2")
    return lines


def units_program(r, k):
    lines = ["(units and distance modes %d)" % k, "G21 G90", "G0 X0 Y0 Z0 A0 C0", "F300"]
    inch, inc = False, False
    for _ in range(r.randint(6, 14)):
        c = r.random()
        if c < 0.2:
            inch = not inch
            lines.append("G20" if inch else "G21")
        elif c < 0.35:
            inc = not inc
            lines.append("G91" if inc else "G90")
        elif c < 0.45:
            lines.append("#%d=%s" % (r.randint(1, 9), num(r, -10, 10)))
        elif c < 0.5:
            lines.append(r.choice(["G64 P0.01 Q0.005", "G61", "G64", "G4 P0.2 G1 X%s" % num(r, -40, 40),
                                   "G[0.1 * 10] Y%s" % num(r, -40, 40), "G0.0001 X%s" % num(r, -9, 9)]))
        else:
            words = ["X" + r.choice([num(r, -40, 40), "#%d" % r.randint(1, 9), "[#%d * 2]" % r.randint(1, 9)]),
                     "Y" + num(r, -40, 40)]
            if r.random() < 0.5:
                words.append("Z" + num(r, -10, 10))
            if r.random() < 0.4:
                words.append("A" + num(r, -30, 30, 3))
                words.append("C" + num(r, -180, 180, 3))
            lines.append("%s %s" % (r.choice(["G0", "G1"]), " ".join(words)))
    lines.append("M2")
    return lines


def cycles_program(r, k):
    """Canned cycles in every plane, G90 and G91, G98 and G99, with L, sticky words, mm and
    inch."""
    inch = r.random() < 0.3
    unit = 25.4 if inch else 1.0
    lines = ["(canned cycles %d)" % k, "G20" if inch else "G21", "G90 G94",
             "G0 X0 Y0 Z%s" % fmt(r.uniform(5, 30) / unit), "F%d" % r.randint(50, 800),
             "S1000 M3"]
    plane = 17
    inc = False
    for _ in range(r.randint(2, 6)):
        if r.random() < 0.4:
            plane = r.choice([17, 18, 19])
            lines.append("G%d" % plane)
        if r.random() < 0.3:
            inc = not inc
            lines.append("G91" if inc else "G90")
        lines.append(r.choice(["G98", "G99", ""]))
        cycle = r.choice([73, 81, 82, 83, 85, 86, 89])
        first, second, axis = {17: "XYZ", 18: "ZXY", 19: "YZX"}[plane]
        words = []
        if inc:
            rr = r.uniform(-3, 2) / unit
            depth = -r.uniform(1, 10) / unit
            words += ["%s%s" % (first, fmt(r.uniform(-20, 20) / unit)), "%s%s" % (second, fmt(r.uniform(-20, 20) / unit))]
        else:
            rr = r.uniform(1, 8) / unit
            depth = rr - r.uniform(1, 12) / unit
            words += ["%s%s" % (first, fmt(r.uniform(-50, 50) / unit)), "%s%s" % (second, fmt(r.uniform(-50, 50) / unit))]
        words += ["R%s" % fmt(rr), "%s%s" % (axis, fmt(depth))]
        if cycle in (82, 86, 89):
            words.append("P%s" % fmt(r.uniform(0, 1), 2))
        if cycle in (73, 83):
            words.append("Q%s" % fmt(r.uniform(0.5, 4) / unit))
        if r.random() < 0.3:
            words.append("L%d" % r.randint(1, 4))
        lines.append("G%d %s" % (cycle, " ".join(words)))
        # More holes of the same cycle: positions only, the other words sticky.
        for _ in range(r.randint(0, 3)):
            lines.append("%s%s %s%s" % (first, fmt(r.uniform(-40, 40) / unit), second, fmt(r.uniform(-40, 40) / unit)))
        if r.random() < 0.5:
            lines.append("G80")
            lines.append("G0 %s%s" % (axis, fmt(r.uniform(5, 30) / unit)))
    lines.append("M2")
    return [l for l in lines if l]


def offsets_program(r, k):
    """G92, G92.1, G92.2, G92.3 among moves, arcs, G91, G20 and the parameters that read
    them (#5210, #<_x>)."""
    inch = r.random() < 0.3
    lines = ["(G92 offsets %d)" % k, "G20" if inch else "G21", "G90 G17",
             "G0 X%s Y%s Z%s" % (num(r, -5, 5), num(r, -5, 5), num(r, 1, 5)), "F%d" % r.randint(20, 400)]
    inc = False
    for _ in range(r.randint(6, 14)):
        c = r.random()
        if c < 0.3:
            axes = [a for a in "XYZ" if r.random() < 0.6] or ["X"]
            lines.append("G92 " + " ".join("%s%s" % (a, num(r, -10, 10)) for a in axes))
        elif c < 0.42:
            lines.append(r.choice(["G92.1", "G92.2", "G92.3"]))
        elif c < 0.5:
            inc = not inc
            lines.append("G91" if inc else "G90")
        elif c < 0.58:
            # Not #5211..: LinuxCNC keeps them in the machine's units, and rs274's machine is
            # an inch machine where dnurbs's are metric (tests/interp.rs checks them in mm).
            lines.append("G1 X[#<_x> + #5210] Y[#<_y> + 1] Z[#<_z> - #5210]")
        elif c < 0.68:
            # A quarter circle about a centre 3 units off, from wherever it is.
            d = r.choice([1, -1])
            lines.append("%s X[#<_x> + %d] Y[#<_y> + %d] I%d J0" % (r.choice(["G2", "G3"]), 3 * d, 3 * d, 3 * d))
        else:
            words = ["X" + num(r, -10, 10), "Y" + num(r, -10, 10)]
            if r.random() < 0.4:
                words.append("Z" + num(r, -3, 3))
            lines.append("%s %s" % (r.choice(["G0", "G1"]), " ".join(words)))
    lines.append("M2")
    return lines


def context_program(r, k):
    """M70/M71/M72 and M73 in subroutines: units, distance mode, plane and feed changed,
    then moves that read the restored state."""
    lines = ["(modal state saved and restored %d)" % k]
    modes = ["G20", "G21", "G90", "G91", "G17", "G18", "G19", "F%d" % r.randint(20, 400)]
    body = ["G20" if r.random() < 0.5 else "G21", "G91" if r.random() < 0.5 else "G90",
            r.choice(["G17", "G18", "G19"]), "F%d" % r.randint(20, 400)]
    lines += ["o<ctx%d> sub" % k, "M73"] + body + [
        "G1 X%s Y%s" % (num(r, -2, 2), num(r, -2, 2)),
        "G2 X[#<_x> + 1] Y[#<_y> + 1] R1" if r.random() < 0.3 else "G1 Z%s" % num(r, -1, 1),
        "o<ctx%d> endsub" % k]
    lines += ["G21 G90 G17", "G0 X0 Y0 Z0", "F%d" % r.randint(50, 500)]
    saved = False
    for _ in range(r.randint(5, 12)):
        c = r.random()
        if c < 0.15:
            lines.append("M70")
            saved = True
        elif c < 0.25 and saved:
            lines.append("M72")
            saved = False
        elif c < 0.3:
            lines.append("M71")
            saved = False
        elif c < 0.45:
            lines.append("o<ctx%d> call" % k)
        elif c < 0.65:
            lines.append(r.choice(modes))
        else:
            lines.append("G1 X%s Y%s Z%s" % (num(r, -30, 30), num(r, -30, 30), num(r, -5, 5)))
    lines.append("M2")
    return lines


def polar_program(r, k):
    """Polar coordinates (@ radius, ^ angle) in G90 and G91, on moves and in canned cycles
    with L repeats, in mm and inch."""
    inch = r.random() < 0.3
    lines = ["(polar coordinates %d)" % k, "G20" if inch else "G21", "G90 G17 G99",
             "G0 X%s Y%s Z2" % (num(r, 1, 5), num(r, 1, 5)), "F%d" % r.randint(20, 400)]
    inc = False
    for _ in range(r.randint(5, 12)):
        c = r.random()
        if c < 0.15:
            inc = not inc
            lines.append("G91" if inc else "G90")
        elif c < 0.3:
            words = r.choice(["@%s" % num(r, -3, 3), "^%s" % num(r, -90, 90),
                              "@%s ^%s" % (num(r, -3, 3), num(r, -90, 90))])
            lines.append("G81 %s R%s Z%s%s" % (words, "0.5" if inc else "1", "-1" if inc else "-0.5",
                                              " L%d" % r.randint(2, 5) if inc else ""))
            lines.append("G80")
        else:
            words = r.choice(["@%s" % num(r, 0.5, 20), "^%s" % num(r, -180, 180),
                              "@%s ^%s" % (num(r, 0.5, 20), num(r, -180, 180))])
            if inc:
                words = r.choice(["@%s" % num(r, -1, 1), "^%s" % num(r, -45, 45)])
            lines.append("%s %s" % (r.choice(["G0", "G1"]), words))
    lines.append("M2")
    return lines


def turns_program(r, k):
    """Arcs of several turns (P), full circles and helices, in every plane, IJK and R forms,
    G90 and G91, mm and inch."""
    inch = r.random() < 0.3
    unit = 25.4 if inch else 1.0
    lines = ["(multi-turn arcs %d)" % k, "G20" if inch else "G21", "G90", "G0 X0 Y0 Z0",
             "F%d" % r.randint(50, 500)]
    for _ in range(r.randint(2, 5)):
        plane = r.choice([17, 18, 19])
        lines.append("G%d" % plane)
        first, second = {17: ("X", "Y"), 18: ("Z", "X"), 19: ("Y", "Z")}[plane]
        offs = {17: ("I", "J"), 18: ("K", "I"), 19: ("J", "K")}[plane]
        axis = {17: "Z", 18: "Y", 19: "X"}[plane]
        rad = r.uniform(1, 20) / unit
        words = "%s%s %s%s" % (offs[0], fmt(rad), offs[1], fmt(0))
        g91 = r.random() < 0.3
        if r.random() < 0.5:
            # A full circle (or a helix) of several turns back over the start.
            end = "%s%s" % (axis, fmt(r.uniform(-5, 5) / unit)) if r.random() < 0.6 else ""
            if g91:
                lines.append("G91 %s %s %s P%d" % (r.choice(["G2", "G3"]), end, words, r.randint(2, 6)))
                lines.append("G90")
            else:
                lines.append("%s %s %s P%d" % (r.choice(["G2", "G3"]), end, words, r.randint(2, 6)))
            lines.append("G0 X0 Y0 Z0")
        else:
            # To a point a quarter round, then more turns.
            a = r.choice([1, -1])
            lines.append("G0 X0 Y0 Z0")
            lines.append("%s %s%s %s%s %s P%d" % (r.choice(["G2", "G3"]), first, fmt(rad), second,
                                               fmt(a * rad), words, r.randint(1, 4)))
            lines.append("G0 X0 Y0 Z0")
    lines.append("M2")
    return lines


def g10_program(r, k):
    """G10 L2 and L20 on every work offset (P0 the one in effect), G10 L1 tool lengths and
    radii used by G43 and G41, in mm and inch."""
    inch = r.random() < 0.3
    lines = ["(G10 tables %d)" % k, "G20" if inch else "G21", "G17 G90 G40 G49 G54",
             "G0 X0 Y0 Z0", "F%d" % r.randint(50, 500)]
    for _ in range(r.randint(3, 8)):
        c = r.random()
        if c < 0.35:
            p = r.randint(0, 6)
            axes = [a for a in "XYZ" if r.random() < 0.7] or ["X"]
            words = " ".join("%s%s" % (a, num(r, -20, 20)) for a in axes)
            lines.append("G10 L%d P%d %s" % (r.choice([2, 20]), p, words))
            lines.append("G%d" % r.choice([54, 55, 56, 57, 58, 59]))
            lines.append("G0 X%s Y%s Z%s" % (num(r, -10, 10), num(r, -10, 10), num(r, 0, 10)))
            # (The offsets' parameters, #5221.., are in the machine's units: rs274's are inches,
            # dnurbs's mm, so they are checked by nc-lang's unit tests, not here.)
            lines.append("G1 X%s Y%s" % (num(r, -10, 10), num(r, -5, 5)))
        elif c < 0.55:
            tool = r.randint(1, 3)
            lines.append("G10 L1 P%d Z%s R%s" % (tool, num(r, 0, 3), num(r, 0.05, 0.4)))
            lines.append("G43 H%d" % tool)
            lines.append("G1 Z%s" % num(r, 0, 5))
        elif c < 0.7:
            tool = r.randint(1, 3)
            lines.append("G10 L1 P%d R%s" % (tool, num(r, 0.05, 0.3)))
            lines.append("G0 X-15 Y-15")
            lines.append("G41 D%d G1 X0 Y0" % tool)
            lines.append("G1 X10")
            lines.append("G1 Y10")
            lines.append("G40 G1 X15 Y15")
        else:
            lines.append("G1 X%s Y%s" % (num(r, -10, 10), num(r, -10, 10)))
    lines.append("G54")
    lines.append("M2")
    return lines


def feedmode_program(r, k):
    """G93/G94/G95 switched along a program with F and S on and off their lines, and F0: where
    LinuxCNC has no feed (G94 and G95 set it to 0), the feed move is refused at its line."""
    lines = ["(feed modes %d)" % k, r.choice(["G20", "G21"]), "G17 G90 G94", "G0 X0 Y0 Z0",
             "S%d M3" % r.randint(100, 3000), "F%d" % r.randint(10, 300)]
    for _ in range(r.randint(4, 10)):
        c = r.random()
        if c < 0.15:
            lines.append(r.choice(["G94", "G95", "G93"]))
        elif c < 0.3:
            lines.append("%s F%s" % (r.choice(["G94", "G95"]), num(r, 0.01, 100, 3)))
        elif c < 0.4:
            lines.append("S%d" % r.choice([0, r.randint(100, 3000)]))
        elif c < 0.45:
            lines.append("F0")
        else:
            f = " F%s" % num(r, 0.1, 100, 3) if r.random() < 0.5 else ""
            lines.append("G1 X%s Y%s%s" % (num(r, -10, 10), num(r, -10, 10), f))
    lines.append("M2")
    return lines


def g92rot_program(r, k):
    """G92 on the rotary axes (A or B, and C) as a 3D printer's post resets its extruder
    axis, with G91, G92.1/G92.2/G92.3, and the angles then written."""
    tilt = r.choice("AB")
    lines = ["(G92 on rotary axes %d)" % k, "G21 G90", "G0 X0 Y0 Z0 %s0 C0" % tilt, "F%d" % r.randint(100, 900)]
    for _ in range(r.randint(4, 9)):
        c = r.random()
        if c < 0.3:
            words = " ".join("%s%s" % (a, num(r, -900, 900)) for a in r.sample([tilt, "C", "X"], r.randint(1, 3)))
            lines.append("G92 %s" % words)
        elif c < 0.4:
            lines.append(r.choice(["G92.1", "G92.2", "G92.3"]))
        elif c < 0.5:
            lines.append("G91 G1 %s%s C%s" % (tilt, num(r, -5, 5), num(r, -5, 5)))
            lines.append("G90")
        else:
            lines.append("G1 X%s %s%s C%s" % (num(r, -10, 10), tilt, num(r, -900, 900), num(r, -900, 900)))
    lines.append("M2")
    return lines


def rotation_program(r, k):
    """Rotated coordinate systems (G10 L2 R) on G54..G59: straight moves in G90 and G91,
    G17 arcs with I J (relative and G90.1 absolute) and R, the rotation switched with the
    work offset, in mm and inch."""
    inch = r.random() < 0.3
    lines = ["(rotated coordinate systems %d)" % k, "G20" if inch else "G21", "G17 G90 G54",
             "G0 X0 Y0 Z0", "F%d" % r.randint(50, 500)]
    for p in range(1, 4):
        lines.append("G10 L2 P%d X%s Y%s Z%s R%s" % (p, num(r, -20, 20), num(r, -20, 20),
                                                  num(r, -5, 5), num(r, -180, 180)))
    for _ in range(r.randint(4, 10)):
        c = r.random()
        if c < 0.15:
            lines.append("G%d" % r.choice([54, 55, 56, 57]))
            lines.append("G0 X%s Y%s" % (num(r, -10, 10), num(r, -10, 10)))
        elif c < 0.25:
            lines.append("G91 G1 X%s Y%s" % (num(r, -5, 5), num(r, -5, 5)))
            lines.append("G90")
        elif c < 0.35:
            lines.append("G1 %s%s" % (r.choice("XYZ"), num(r, -10, 10)))
        elif c < 0.6:
            # A quarter round from where the program is, about a centre r away.
            lines.append("G0 X0 Y0")
            rad = r.uniform(1, 10)
            if r.random() < 0.5:
                lines.append("%s X%s Y%s I%s J0" % (r.choice(["G2", "G3"]), fmt(rad), fmt(rad if r.random() < 0.5 else -rad), fmt(rad)))
            else:
                lines.append("G90.1 %s X%s Y%s I%s J0" % (r.choice(["G2", "G3"]), fmt(2 * rad), fmt(0), fmt(rad)))
                lines.append("G91.1")
        elif c < 0.7:
            lines.append("G0 X0 Y0")
            lines.append("%s X%s Y%s R%s" % (r.choice(["G2", "G3"]), num(r, 1, 5), num(r, 1, 5), num(r, 4, 8)))
        else:
            lines.append("G1 X%s Y%s" % (num(r, -10, 10), num(r, -10, 10)))
    lines.append("G54")
    lines.append("M2")
    return lines


def comp_program(r, k):
    """Cutter radius compensation on random closed contours of lines and arcs (convex and
    concave corners, tangent and sharp), G41/G42 by tool number (rs274's default table) and
    G41.1/G42.1 by diameter, entries by a line or an arc, Z moves, feeds and dwells between
    compensated moves, in mm and inch; some tools are too big for a corner on purpose."""
    inch = r.random() < 0.3
    unit = 25.4 if inch else 1.0
    lines = ["(cutter compensation %d)" % k, "G20" if inch else "G21", "G17 G90 G40",
             "G0 X0 Y0 Z5", "F%d" % r.randint(50, 500)]
    size = r.uniform(10, 30) / unit
    n = r.randint(3, 8)
    angles = sorted(r.uniform(0, 2 * math.pi) for _ in range(n))
    pts = []
    for a in angles:
        rad = size * r.uniform(0.4, 1.0)
        pts.append((round(rad * math.cos(a), 4), round(rad * math.sin(a), 4)))
    # The start: outside the contour, so the entry move is long.
    a0 = angles[0] + r.uniform(-0.3, 0.3)
    start = (round(2.2 * size * math.cos(a0), 4), round(2.2 * size * math.sin(a0), 4))
    lines.append("G0 X%s Y%s" % (fmt(start[0]), fmt(start[1])))
    lines.append("G1 Z%s" % fmt(-1 / unit))
    if r.random() < 0.5:
        dia = r.choice([0.5, 1, 2, 3, 6, 10]) / unit
        if r.random() < 0.1:
            dia = -dia
        code = "%s.1 D%s" % (r.choice(["G41", "G42"]), fmt(dia))
    else:
        code = "%s D%d" % (r.choice(["G41", "G42"]), r.choice([1, 2, 3]))
    lines.append(code)
    first = pts[0]
    if r.random() < 0.25:
        # An entry arc to the first point.
        mx, my = (start[0] + first[0]) / 2, (start[1] + first[1]) / 2
        dx, dy = first[0] - start[0], first[1] - start[1]
        h = r.uniform(0.3, 1.5) * math.hypot(dx, dy) / 2
        cx, cy = mx - dy / math.hypot(dx, dy) * h, my + dx / math.hypot(dx, dy) * h
        lines.append("%s X%s Y%s I%s J%s" % (r.choice(["G2", "G3"]), fmt(first[0]), fmt(first[1]),
                                            fmt(cx - start[0]), fmt(cy - start[1])))
    else:
        lines.append("G1 X%s Y%s" % (fmt(first[0]), fmt(first[1])))
    here = first
    for i in range(1, n + 1):
        nxt = pts[i % n]
        c = r.random()
        if c < 0.08:
            lines.append("G0 Z%s" % fmt(r.uniform(-1, 2) / unit))
        elif c < 0.12:
            lines.append("F%d" % r.randint(50, 500))
        elif c < 0.15:
            lines.append("G4 P0.%d" % r.randint(1, 9))
        if r.random() < 0.55:
            lines.append("G1 X%s Y%s" % (fmt(nxt[0]), fmt(nxt[1])))
        else:
            dx, dy = nxt[0] - here[0], nxt[1] - here[1]
            chord = math.hypot(dx, dy)
            if chord < 1e-3:
                continue
            h = r.uniform(-2.0, 2.0) * chord / 2
            cx = here[0] + dx / 2 - dy / chord * h
            cy = here[1] + dy / 2 + dx / chord * h
            lines.append("%s X%s Y%s I%s J%s" % (r.choice(["G2", "G3"]), fmt(nxt[0]), fmt(nxt[1]),
                                                fmt(cx - here[0]), fmt(cy - here[1])))
        here = nxt
    # Leave the contour outward, then turn compensation off and move clear.
    lines.append("G1 X%s Y%s" % (fmt(here[0] * 1.8), fmt(here[1] * 1.8)))
    lines.append("G40")
    lines.append("G0 Z5")
    lines.append("G0 X0 Y0")
    lines.append("M2")
    return lines


FAMILIES = [("expr", expr_program, 40), ("flow", flow_program, 30), ("subs", subs_program, 30),
            ("arcs", arcs_program, 40), ("units", units_program, 20), ("cycles", cycles_program, 40),
            ("offsets", offsets_program, 20), ("context", context_program, 15),
            ("polar", polar_program, 10), ("comp", comp_program, 40),
            ("turns", turns_program, 10), ("g10", g10_program, 15),
            ("feedmode", feedmode_program, 12), ("g92rot", g92rot_program, 8),
            ("rotation", rotation_program, 12)]


def main():
    os.makedirs(OUT, exist_ok=True)
    for f in os.listdir(OUT):
        if f.endswith(".ngc"):
            os.remove(os.path.join(OUT, f))
    total = 0
    for name, make, count in FAMILIES:
        for k in range(count):
            r = random.Random("%s-%d" % (name, k))
            with open(os.path.join(OUT, "%s-%02d.ngc" % (name, k)), "w") as f:
                f.write("\n".join(make(r, k)) + "\n")
            total += 1
    print("%d programs in %s" % (total, os.path.relpath(OUT)))


if __name__ == "__main__":
    main()
