(Five turns of a 1 mm helical ramp of radius 5, a half-turn helix by R, a steep helix)
(nc::parse::HELIX_TOL_MM holds their third axis to 1e-9 mm of the true helix)
G17 G90 G21
G00 X5 Y0 Z10
G03 X5 Y0 Z9 I-5 J0 F1500
G03 X5 Y0 Z8 I-5 J0
G03 X5 Y0 Z7 I-5 J0
G03 X5 Y0 Z6 I-5 J0
G03 X5 Y0 Z5 I-5 J0
G01 X20 Y0 F3000
G02 X-20 Y0 Z-30 R20 F6000
G02 X20 Y0 Z-47.5 I20 J0 F10772
M30
