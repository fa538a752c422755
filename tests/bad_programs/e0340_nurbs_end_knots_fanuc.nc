%
O1 (LIN_SPLINE)
(bad program: a NURBS curve whose end knots differ, Fanuc alarm 1007)
(machine generic_3axis_mill: fanuc_0i_mill 3-axis mill)
(units mm; X Y Z of the control point, +Z out of the material; no cutter compensation)
G17 G21 G40 G49 G80 G90 G94 G54
G05.1 Q1
T1 M6
M19
G43 H1 G0 Z0.5
G0 X-0.1137 Y-0.81
G94 G1 Z-0.1403 F100.
G06.2 P4 K0. X-0.1137 Y-0.81 Z-0.1403
K0. X-0.0379 Y-0.81 Z-0.1379
K0. X0.0379 Y-0.81 Z-0.1379
K0. X0.1137 Y-0.81 Z-0.1403
K0.2275
K0.2275
K0.2275
K0.3
G0 Z0.5
M5
G05.1 Q0
G91 G28 Z0.
M30
%
