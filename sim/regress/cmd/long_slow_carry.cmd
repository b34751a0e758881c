# Long spans (the whole array) whose carries out of block 1 come only after hundreds of
# columns: a slope of 16 LSBs per column crosses block 1 after 256 columns, a gentle
# quadratic after ~500. At 2 chips nothing carries; at 72 chips (648 columns) it does.
Eval2 (0, 4095, 0x005.fff000, 0x000.000010);
Refresh;
Eval3 (0, 4095, 0x100.ff0000, 0x000.000100, 0x000.000002);
Refresh;
Eval2 (0, 4095, 0x7ff.000000, 0x000.0fffff);
Eval2 (300, 348, 0xf00.000000, 0x000.010000);
Refresh;
