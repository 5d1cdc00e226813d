%
(dnurbs test program: a 3-axis Fanuc-style G06.2 NURBS block after its start move.)
(G06.2 P is the rank = degree + 1: P4 is a cubic. 6 control points, so 6 + 4 = 10 knots,)
(clamped: 0 0 0 0 0.3333 0.6667 1 1 1 1. The tool stays vertical.)
G90 G21
N10 G00 X0 Y0 Z5
N20 G01 Z0 F800
N30 G06.2 P4 K0 X0 Y0 Z0 R1.0 F1500
N31 K0 X10 Y20 Z0 R1.0
N32 K0 X30 Y25 Z-1 R0.8
N33 K0 X45 Y10 Z-2 R1.2
N34 K0.3333 X60 Y5 Z-2
N35 K0.6667 X70 Y20 Z-1 R1.0
N36 K1 K1 K1 K1
N40 G01 Z5
M30
%
