# Spans that start and end at chip boundaries (chips of 9 PEs: columns 8|9, 17|18, ...),
# protect flags and Dis on the boundary columns, Eval0 across a boundary.
Eval2 (8, 2, 0x010.000000, 0x001.000000);
Eval3 (7, 4, 0x020.000000, 0xfff.800000, 0x000.100000);
Eval2 (17, 1, 0x040.000000, 0x000.000000);
Refresh;
SetI (9, 0x100.000000);
Eval2 (0, 18, 0x008.000000, 0x002.000000);
Refresh;
Dis (8, 2);
Eval2 (0, 18, 0x030.000000, 0x000.400000);
Eval0 (6, 6, 77);
Eval2 (0, 18, 0x001.000000, 0x000.000000);
Refresh;
SetPI (0, 9, 0x050.000000);
Eval2 (0, 4095, 0x000.000000, 0x001.000000);
Refresh;
SetdI (8, 0x004.000000);
SetddI (9, 0xffe.000000);
Eval4 (0, 4095, 0x000.000000, 0x000.800000, 0x000.010000, 0x000.000100);
Refresh;
