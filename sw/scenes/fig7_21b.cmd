# Kuijk 1995, Fig. 7.21(b): measured video signal on the prototype ("Measured video
# signals (using a digital oscilloscope) and the commands used to generate these signals").
# The DAC is on the 6 least significant pixel bits, so 1.0 = full scale of window 0.
# The source prints one command list per row of panels: (a)/(b), (c)/(d), (e)/(f).
# Panels (b), (d), (f) are the carry-bug-compensated versions of the same command list as
# (a), (c), (e): the commands are identical; compensation is applied by the frame-store
# data mapper (asm -f framestore --compensate, or model/plot --compensate):
#   diffengine model fig7_21b.cmd -o out.png --carry-bug --compensate --window 0
.unit dac 0
Eval2 (1, 17, 0.0625, 0.015625);
Eval2 (21, 17, 0.0625, 0.0078125);
Refresh;
