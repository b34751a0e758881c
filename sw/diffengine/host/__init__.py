"""Host: the C host software (sw/hsr: the scene readers and hidden-surface removal;
sw/yproc: the y-processor and the `yproc` command) from Python. `yproc` finds and builds `sw/yproc/build/yproc` once under a lock, and reads scenes
through it (`yproc read`: the one scene reader is the C library's, docs/hsr.md). Python
never re-implements what the C host does; it drives it, as rtl/ drives the Verilated RTL.
"""
