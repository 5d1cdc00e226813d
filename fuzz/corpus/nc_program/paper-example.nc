%
(dnurbs test program: the double-NURBS G06.5 example of)
(Wang Yongzhang, Ma Xiongbo, Chen Liangji, Han Zhenyu, "Realization Methodology of a)
(5-axis Spline Interpolator in an Open CNC System", Chinese Journal of Aeronautics)
(20 [2007] 362-369, section 6.2: one G06.5 block replaces 20 five-axis G01 lines.)
(Degree 3, 5 control points, knots 0 0 0 0 0.5046 1 1 1 1, all weights 1, F400 mm/min.)
(N20 is not in the paper: it moves to the block's start pose, X Y Z = the first cutter)
(control point and I J K = first U V W minus first X Y Z, the tool axis at the start.)
G90 G21
N20 G01 X47.7773 Y71.0202 Z58.8006 I0.0293 J0.9589 K0.2822 F400
N30 G06.5 P3 X47.7773 Y71.0202 Z58.8006 U47.8066\
V71.9791 W59.0828 R1.0000 K0.0000 F400
X44.3229 Y75.6066 Z54.4778 U44.3651\
V76.5494 W54.8138 R1.0000 K0.0000
X37.2164 Y84.6443 Z44.5755 U37.2554\
V85.5421 W45.0342 R1.0000 K0.0000
X28.7567 Y101.5653 Z29.7151 U28.7081\
V102.3535 W30.3361 R1.0000 K0.0000
X-1.6963 Y163.6796 Z5.8369 U-1.8572\
V163.9906 W6.7762 R1.0000 K0.5046
K1.0000 K1.0000 K1.0000 K1.0000
M30
%
