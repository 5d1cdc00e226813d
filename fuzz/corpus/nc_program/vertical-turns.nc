; dnurbs test program: the tool passes through the vertical and leaves it in a new direction.
; With the tool vertical, C is free; leaving the vertical towards +Y after arriving from +X
; needs C to turn by 90 degrees first. dnurbs turns C at rest while the tool stays vertical
; (a rotary-only move planned under the C axis limits) instead of letting C jump.
N10 G90 G21
N20 G01 X0 Y0 Z10 I0 J0 K1 F1000
N30 G01 X20 I0.5 J0 K0.8660254
N40 G01 X40 I0 J0 K1
N50 G01 Y20 I0 J0.5 K0.8660254
N60 M30
