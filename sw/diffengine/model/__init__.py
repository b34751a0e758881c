"""Models: what the hardware must compute, in Python. The functional golden model
(`functional`: a command at a time, vectorised over columns, with the carry-bug model),
the cycle-level structural model (`structural`: every PE, every clock, 12-bit blocks and
their registered carries), the independent numpy reference renderer of scenes
(`reference`: z-buffer, 16x16 supersampling, docs/shading.md), the capacity model of
Tables 7.3/7.4 (`capacity`), and where commands land (`lines`). A change to how the
array computes goes into both golden models here and into rtl/ (and into sw/fmodel, the
C functional model, which sw/tests/test_fmodel.py holds equal to `functional`).

`fast`: the functional model in C (sw/fmodel, ctypes, built on first use), for whoever
needs pixels in milliseconds (make demo, make anim, the interactive viewer). It reads
.de48 instruction words directly and renders all three colours; `functional` stays the
readable reference and the default of every golden check that is not a speed path
(make sim, the RTL testbenches). The calls for a viewer:

    img = fast.render_frame([r, g, b], width, height)   # r, g, b: .de48 file bytes or
                                                        # paths -> (H, W, 3) uint16
    n = fast.render_lines(img, [dr, dg, db])            # incremental frame, in place:
                                                        # dX = {row: that line's 6-byte
                                                        # words, its Refresh last}

(the per-line words of a frame delta are what `pipeline.anim.read_delta` returns). Both
check every stream before writing a pixel and raise `fast.FastModelError` naming the
stream and the slot; the C call releases the GIL. About 15 CPU ms for the teapot's colour
frame (docs/performance.md, "Functional model in C").
"""
