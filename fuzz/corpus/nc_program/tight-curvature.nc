; dnurbs test program: tight curvature and a turning tool axis
; Three quarter circles of radius 4 mm about X10 Y10 as one rational quadratic G06.5 block
; (weights 1, 0.70710678, 1 per quarter; double interior knots give a C1, G2 circle). The
; orientation curve sits 3 mm outward and 10 mm up from each control point, so the tool
; leans 16.7 deg outward all the way round and the C axis turns through 270 deg over 19 mm
; of path: the feed is limited by centripetal acceleration and by the C axis velocity.
N10 G90 G21
N20 G00 X14 Y10 Z5 I0.28734789 J0 K0.95782629
N30 G01 Z0 F500
N40 G06.5 P2 X14 Y10 Z0 U17 V10 W10 R1 K0 F3000
X14 Y14 Z0 U17 V17 W10 R0.70710678 K0
X10 Y14 Z0 U10 V17 W10 R1 K0
X6 Y14 Z0 U3 V17 W10 R0.70710678 K0.33333333
X6 Y10 Z0 U3 V10 W10 R1 K0.33333333
X6 Y6 Z0 U3 V3 W10 R0.70710678 K0.66666667
X10 Y6 Z0 U10 V3 W10 R1 K0.66666667
K1 K1 K1
N50 G01 Z5 F500
N60 M30
