%
O1 (BAD)
(bad program: X read as a diameter: X400. is a radius of 200 mm)
(machine linuxcnc_lathe: fanuc_0i_lathe lathe)
(units mm; X is the diameter, Z along the spindle axis, +Z out of the material)
G18 G21 G40 G80 G54 G98
T0101
G97 S500 M3
G0 X400. Z1.5
G0 X6.
G99 G1 Z0.1 F0.002
G2 X0. Z0.4693 I-3. K-12.
G0 Z1.5
M5
M30
%
