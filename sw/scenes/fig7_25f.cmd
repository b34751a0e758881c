# Kuijk 1995, Fig. 7.25(f): accumulate mode on (negative contributions are not accumulated).
# (command list verbatim from the source)
# Units: the source does not say how its decimals map onto the 12 pixel bits. From
# Fig. 7.22 on the prototype shows the 6 middlemost bits, pixel bits [8:3] (full scale
# 512 LSBs), to hide the pixel LSB that carry-bug compensation gets wrong. The largest
# curve, (a), peaks at 1.88 (column 52), (b) at 1.04, (d) at 0.98, so 1.0 cannot be the
# full scale of the displayed window: with 1.0 = 256 LSBs (".unit dac 2") every curve
# fits window 3 = bits [8:3] (full scale 2.0; (a) reaches 94%), and the operands fit the
# 27-bit frame-store operand at w = 3 (asm -f framestore --window 3 --round). (e) goes
# negative (to -2.25) and, accumulated without Acc_mode, wraps to large values; that is
# the difference from (f).
#   diffengine plot fig7_25f.cmd -o out.png --window 3
.unit dac 2
Acc_mode ();
Setddi (9, 1,-0.0078125);
Setddi (38, 1, 0.008789);
Eval3 (1, 55, 0.0957, 0, 0.008789);
Refresh;
