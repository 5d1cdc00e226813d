; dnurbs test program: two G06.5 blocks joined with C2 continuity
; Block 1 is the cubic Bezier P0..P3; block 2 starts at P3 with Q1 = 2 P3 - P2 and
; Q2 = P1 - 4 P2 + 4 P3, so position, first and second derivative agree at the joint (both
; blocks on u in [0, 1]). The tool-axis offsets grow linearly in u (0..3 mm, then 3..6 mm
; in X over 10 mm in Z), so the orientation is C2 as well. Look-ahead must pass the joint
; at the programmed feed and stop exactly at the end.
N10 G90 G21
N20 G01 X0 Y0 Z0 I0 J0 K1 F2000
N30 G06.5 P3 X0 Y0 Z0 U0 V0 W10 K0
X10 Y5 Z0 U11 V5 W10 K0
X20 Y5 Z0 U22 V5 W10 K0
X30 Y0 Z0 U33 V0 W10 K0
K1 K1 K1 K1
N40 G06.5 P3 X30 Y0 Z0 U33 V0 W10 K0
X40 Y-5 Z0 U44 V-5 W10 K0
X50 Y-15 Z0 U55 V-15 W10 K0
X60 Y-10 Z0 U66 V-10 W10 K0
K1 K1 K1 K1
N50 M30
