"""Models: what the hardware must compute, in Python. The functional golden model
(`functional`: a command at a time, vectorised over columns, with the carry-bug model),
the cycle-level structural model (`structural`: every PE, every clock, 12-bit blocks and
their registered carries), the independent numpy reference renderer of scenes
(`reference`: z-buffer, 16x16 supersampling, docs/shading.md), the capacity model of
Tables 7.3/7.4 (`capacity`), and where commands land (`lines`). A change to how the
array computes goes into both golden models here and into rtl/.
"""
