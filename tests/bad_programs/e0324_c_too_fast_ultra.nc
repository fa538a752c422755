(bad program: C at 10000 rpm in inverse time)
(machine moore_nanotech_450fg: ultra_precision_lathe_gcode slow-tool-servo lathe)
(units mm; X is the radius, C the spindle angle in degrees, Z carries the surface, +Z out of the material)
G18 G71 G90 G40
T0101
M19
G0 X2. C0.
G0 Z1.
G93 G1 Z0.1 F60.
G1 X1.99 Z0.1 C10. F100.
G1 X1.98 Z0.1 C36020. F100.
G0 Z1.
M18
M30
