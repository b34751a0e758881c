"""Image reconstruction through the Verilated array (§7.7.2): spline-coded and raster
command files decode bit-identically in the RTL and in the golden model.

Two kinds of case, all on the cached 8-chip harness build (72 columns, sim/build via
diffengine.rtl.harness):

* 72x12 crops of the 256-wide test images, channel 0 (one per codec);
* the whole 72x54 colour image `tiny_rgb.png` (the rendered teapot frame, reduced), all
  three channels, in every spline emission - knots (merged / layered), one accumulated
  Eval per kept basis function (coefficient), and the per-function choice - plus the
  RLE raster. The three channels' streams are played as one 162-line frame per case
  (one harness run), and each channel is also checked against the image itself where
  the code is lossless.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from diffengine.encode import image as EN
from diffengine.model import functional

REPO = Path(__file__).resolve().parents[2]
WIDTH = 72  # 8 chips: the build is shared with the array scoreboard


def load(name: str, rows: int = 12) -> np.ndarray:
    img = EN.load_image(REPO / "sw" / "images" / f"{name}.png")
    grey = img if img.ndim == 2 else img[..., 0]
    return grey[:rows, :WIDTH]


@pytest.mark.parametrize("name,codec", [("natural", "spline2"), ("ramps", "spline1"),
                                        ("circles", "rle"), ("bars", "raster")])
def test_decoded_image_identical_in_rtl(name, codec):
    x = load(name)
    res = EN.ChannelEncoder(x).encode(codec, psnr=40.0 if codec != "raster" else None)
    ok, path = EN.rtl_bit_identity(res.commands, WIDTH, rtl=True)
    assert ok, f"{name}/{codec}: RTL and golden model differ ({path})"


@pytest.fixture(scope="module")
def tiny_rgb():
    x = EN.load_image(REPO / "sw" / "images" / "tiny_rgb.png")
    assert x.shape == (54, WIDTH, 3)
    return x


@pytest.mark.parametrize("codec,emission,target", [
    ("spline2", "merged", 45.0), ("spline2", "layered", 45.0),
    ("spline2", "coefficient", 45.0), ("spline2", "choice", 45.0),
    ("spline1", "coefficient", None), ("spline1", "choice", 40.0),
    ("rle", "auto", 40.0)])
def test_whole_colour_image_identical_in_rtl(tiny_rgb, codec, emission, target):
    streams = []
    for c in range(3):
        x = tiny_rgb[..., c]
        res = EN.ChannelEncoder(x, emission).encode(codec, psnr=target,
                                                    lossless=target is None)
        if target is None:
            assert np.array_equal(res.pixels, x), (codec, emission, c)
        else:
            assert res.psnr >= target, (codec, emission, c, res.psnr)
        streams += res.commands
    gold = functional.render(streams, WIDTH)
    assert gold.shape == (3 * 54, WIDTH)
    ok, path = EN.rtl_bit_identity(streams, WIDTH, rtl=True)
    assert ok, f"tiny_rgb {codec}/{emission}: RTL and golden model differ ({path})"
