%
(dnurbs test program: 5-axis linear moves on an A/C table machine.)
(The tool orientation is given first as I J K tool vectors, then as A C machine angles.)
G90 G21
N10 G00 X0 Y0 Z50 I0 J0 K1
N20 X20 Y10 Z30
N30 G01 Z5 F1000
N40 X30 Y15 Z4 I0 J0.2588 K0.9659 (15 deg tilt towards +Y)
N50 X40 Y20 Z3.5 I0.1 J0.3 K0.9487
N60 X50 Y22 Z3 I0.2 J0.3 K0.9327 F2000
N70 X60 Y25 Z3 I0 J0 K1
N80 A10 C0 ; from here on machine angles
N90 X70 Y25 A15 C30
N100 X80 C45
N110 G00 Z50
M30
%
