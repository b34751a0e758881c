"""Pipeline: the product end to end. `demo` is `make demo` (scene -> `yproc scan` -> the
Verilated display controller and the golden model -> PNGs, bit-exactness, PSNR against
the reference renderer; `diffengine demo`), `anim` is `make anim` (the frame deltas of
`yproc anim` applied to frame 0 and checked against full re-renders; `diffengine anim`).
"""
