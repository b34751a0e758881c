# Carries out of block 0 (bits 11..0) into block 1, and from there on into block 2 in the
# same cycle chain: block 0 at 0xfff plus 1, and steps that overflow block 0 every column.
Eval2 (0, 4095, 0x000.000fff, 0x000.000001);
Refresh;
Eval2 (0, 4095, 0x001.000fff, 0x000.001001);
Eval2 (3, 12, 0x004.ffffff, 0x000.000fff);
Refresh;
Eval3 (0, 4095, 0x002.fffffe, 0x000.000fff, 0x000.000001);
Refresh;
