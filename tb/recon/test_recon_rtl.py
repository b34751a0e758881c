"""Image reconstruction through the Verilated array (§7.7.2): spline-coded and raster
command files decode bit-identically in the RTL and in the golden model."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from diffengine import encode as EN

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
