# Kuijk 1995, Fig. 7.21(f): measured video signal on the prototype ("Measured video
# signals (using a digital oscilloscope) and the commands used to generate these signals").
# The DAC is on the 6 least significant pixel bits, so 1.0 = full scale of window 0.
# The source prints one command list per row of panels: (a)/(b), (c)/(d), (e)/(f).
# Panels (b), (d), (f) are the carry-bug-compensated versions of the same command list as
# (a), (c), (e): the commands are identical; compensation is applied by the frame-store
# data mapper (asm -f framestore --compensate, or model/plot --compensate):
#   diffengine model fig7_21f.cmd -o out.png --carry-bug --compensate --window 0
# Compensation halves the fraction only; the source's extra "set bit 23 when negative"
# would turn the falling dI = -0.0078125 below into a rising ramp under the fault
# (docs/isa.md §7, docs/formats.md "Carry-bug compensation").
.unit dac 0
Eval2 (1, 17, 0.5, -0.0078125);
Eval3 (21, 33, 0.984375, 0.0, -0.001953125);
Eval1 (55, 16, 0.046875);
Refresh;
