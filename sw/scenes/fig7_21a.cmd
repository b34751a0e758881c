# Kuijk 1995, Fig. 7.21(a): measured video signal on the prototype ("Measured video
# signals (using a digital oscilloscope) and the commands used to generate these signals").
# The DAC is on the 6 least significant pixel bits, so 1.0 = full scale of window 0.
# The source prints one command list per row of panels: (a)/(b), (c)/(d), (e)/(f).
# Panels (a), (c), (e) show the unmodified data on the faulty prototype (§7.7 carry bug):
#   diffengine model fig7_21a.cmd -o out.png --carry-bug --window 0
.unit dac 0
Eval2 (1, 17, 0.0625, 0.015625);
Eval2 (21, 17, 0.0625, 0.0078125);
Refresh;
