# Carries out of block 1 into block 2 (the integer part) in the difference adders and in
# the accumulator: the path the §7.7 fault breaks (the carry out of bit 23 lands in bit 25).
# Line 1: A starts one LSB below an integer and steps by one LSB: the very first step carries.
Eval2 (0, 4095, 0x003.ffffff, 0x000.000001);
Refresh;
# Line 2: two overlapping spans whose sum in D crosses an integer in every column.
Eval2 (0, 4095, 0x002.800000, 0x000.100000);
Eval2 (0, 4095, 0x001.7fffff, 0x000.0fffff);
Refresh;
# Line 3: a quadratic whose second difference pushes the first across block 1 every column.
Eval3 (2, 4093, 0x010.fff000, 0x000.fff000, 0x000.001000);
Refresh;
# Line 4: negative steps: borrows through block 1 (carry out of bit 23 in two's complement).
Eval2 (0, 4095, 0x008.000000, 0xfff.ffffff);
Eval2 (5, 9, 0x001.000000, 0xfff.f00000);
Refresh;
