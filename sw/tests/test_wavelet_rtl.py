"""2-D wavelet decoding through the RTL: the Verilated display controller (sim/dc,
diffengine.rtl.dc_harness) plays the per-line commands of a wavelet file and its frame
must equal the golden model's decode (and so the floating-point decoder's) bit for bit.

One build: 8 chips (72 PEs per colour), test mode 64x64 with a 640x480-length line of
800 slots, 1 y-processor. Images: a 64x64 RGB crop of `spheres` (three streams, one per
colour array) and a 64x64 grey crop of `natural` (the same stream on R, G, B), each at a
coarse and a fine quantiser step (knot lines and Eval0-run lines both occur).
"""
from __future__ import annotations

import numpy as np
import pytest

from diffengine import REPO, isa
from diffengine.encode import image as EN
from diffengine.encode import wavelet as WV
from diffengine.model import functional
from diffengine.rtl import dc_harness as dh

W = H = 64
CFG = dh.Config(chips=8, num_buf=1, test=(W, 16, 96, 800 - W - 112, H, 1, 2, 2))


@pytest.fixture(scope="module")
def exe():
    return dh.build(CFG)[0]


def _crop(name):
    x = EN.load_image(REPO / "sw" / "images" / f"{name}.png")
    return x[20:20 + H, 40:40 + W]


@pytest.mark.parametrize("name,delta", [("spheres", 512.0), ("spheres", 16.0),
                                        ("natural", 128.0)])
def test_rtl_decode_equals_model_decode(exe, name, delta):
    x = _crop(name)
    data = WV.encode_file(x, delta)
    streams, sim, st = WV.decode_file(data)
    if len(streams) == 1:
        streams = streams * 3
        sim = np.stack([sim] * 3, -1)
    for s in streams:
        lines = isa.split_lines(s)
        assert len(lines) == H
        assert max(len(isa.serialise(ln)) - 1 for ln in lines) <= 799   # no late line
    frames, stats = dh.run(streams, CFG, mode=3)
    assert frames.shape == (1, H, W, 3)
    for c in range(3):
        gold = functional.render(streams[c], W)
        np.testing.assert_array_equal(frames[0, :, :, c], gold,
                                      err_msg=f"{name} delta {delta} colour {'RGB'[c]}")
        np.testing.assert_array_equal(gold, sim[:, :, c])
    fd = WV.float_decode(data)
    np.testing.assert_array_equal(frames[0].astype(np.int64),
                                  fd if fd.ndim == 3 else np.stack([fd] * 3, -1))
    assert stats["ok"] and not stats["errors"]
    for c in "RGB":
        assert stats["load_monitor"][c]["late_lines"] == 0
    print(name, delta, st)
    assert st["spline_px"] > 0                       # Eval2 + SetdI segments went through
    if delta <= 16:
        assert st["spline_px"] < 0.9 * x.size                    # and Eval0 runs
