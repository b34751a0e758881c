"""Baselines for image reconstruction: Eval0 rasters and JPEG at matched bytes.

* `raster`: one `Eval0 (x, 1, v)` per pixel - what a frame buffer would send, n + 1
  instructions per line whatever the image.
* `rle`: one `Eval0 (x, dx, v)` per run of equal pixels (lossless at tol = 0). With a
  tolerance t, a run is extended while max - min <= 2t and shows the rounded mid value
  (max error t): the lossy run-length raster.
* `jpeg_*`: baseline JPEG (8 bits per channel, OpenImageIO) at a quality chosen to
  match a byte budget; the comparison is bytes of the 48-bit stream (6 per instruction)
  against bytes of the JPEG file.
"""
from __future__ import annotations

import os
import tempfile

import numpy as np

from ..isa import Command

PIXEL_MAX = 4095


def raster_line(row: np.ndarray) -> list[Command]:
    return [Command("EVAL0", i, 1, (int(v),)) for i, v in enumerate(row)] + [Command("REFRESH")]


def rle_line(row: np.ndarray, tol: int = 0) -> tuple[list[Command], np.ndarray]:
    """Run-length Eval0 line with max error `tol`; returns commands and decoded pixels."""
    row = np.asarray(row, dtype=np.int64)
    n = len(row)
    cmds: list[Command] = []
    out = np.empty(n, dtype=np.int64)
    i = 0
    while i < n:
        lo = hi = int(row[i])
        j = i + 1
        while j < n:
            v = int(row[j])
            nlo, nhi = min(lo, v), max(hi, v)
            if nhi - nlo > 2 * tol:
                break
            lo, hi = nlo, nhi
            j += 1
        val = (lo + hi + 1) // 2
        cmds.append(Command("EVAL0", i, j - i, (val,)))
        out[i:j] = val
        i = j
    cmds.append(Command("REFRESH"))
    return cmds, out


def raster_frame(x: np.ndarray) -> list[Command]:
    out: list[Command] = []
    for row in x:
        out.extend(raster_line(row))
    return out


def rle_frame(x: np.ndarray, tol: int = 0) -> tuple[list[Command], np.ndarray]:
    out: list[Command] = []
    pix = np.empty_like(np.asarray(x, dtype=np.int64))
    for r, row in enumerate(x):
        c, p = rle_line(row, tol)
        out.extend(c)
        pix[r] = p
    return out, pix


# ---- JPEG ----------------------------------------------------------------------------


def to8(x12: np.ndarray) -> np.ndarray:
    return ((np.asarray(x12, dtype=np.int64) * 255 + PIXEL_MAX // 2) // PIXEL_MAX).astype(np.uint8)


def from8(x8: np.ndarray) -> np.ndarray:
    return (np.asarray(x8, dtype=np.int64) * PIXEL_MAX + 127) // 255


def jpeg_roundtrip(x12: np.ndarray, quality: int, path: str | None = None,
                   subsampling: str = "4:4:4") -> tuple[int, np.ndarray]:
    """Encode (rows, cols[, 3]) 12-bit pixels as an 8-bit JPEG at `quality`; return the
    file size in bytes and the decoded image back on the 12-bit scale.

    Colour is coded without chroma subsampling by default (4:4:4: every channel at full
    resolution, as the spline streams are); OpenImageIO's own default is 4:2:0, which
    caps the shaded-spheres image at 39.1 dB even at quality 100."""
    import OpenImageIO as oiio

    data = to8(x12)
    if data.ndim == 2:
        data = data[:, :, None]
    h, w, c = (int(v) for v in data.shape)
    spec = oiio.ImageSpec(w, h, c, oiio.UINT8)
    spec.attribute("Compression", f"jpeg:{int(quality)}")
    if c == 3 and subsampling:
        spec.attribute("jpeg:subsampling", subsampling)
    buf = oiio.ImageBuf(spec)
    buf.set_pixels(oiio.ROI(), np.ascontiguousarray(data))
    tmp = None
    if path is None:
        fd, tmp = tempfile.mkstemp(suffix=".jpg")
        os.close(fd)
        path = tmp
    try:
        if not buf.write(path):
            raise RuntimeError(f"{path}: JPEG write failed: {buf.geterror()}")
        size = os.path.getsize(path)
        back = oiio.ImageBuf(path)
        dec = back.get_pixels(oiio.UINT8)
        if dec is None:
            raise RuntimeError(f"{path}: JPEG read failed: {back.geterror()}")
    finally:
        if tmp is not None:
            os.unlink(tmp)
    dec = from8(dec)
    return size, (dec[:, :, 0] if np.asarray(x12).ndim == 2 else dec[:, :, :c])


def jpeg_matched(x12: np.ndarray, max_bytes: int, path: str | None = None):
    """Highest JPEG quality (1..100) whose file is at most max_bytes (bisection on q).

    Returns (quality, bytes, decoded). If even quality 1 is larger, returns quality 1
    (the caller can see bytes > max_bytes)."""
    lo, hi = 1, 100
    best = None
    size_hi, dec_hi = jpeg_roundtrip(x12, hi)
    if size_hi <= max_bytes:
        best = (hi, size_hi, dec_hi)
    else:
        while hi - lo > 1:
            mid = (lo + hi) // 2
            size, dec = jpeg_roundtrip(x12, mid)
            if size <= max_bytes:
                lo, best = mid, (mid, size, dec)
            else:
                hi = mid
        if best is None:
            size, dec = jpeg_roundtrip(x12, 1)
            best = (1, size, dec)
    if path is not None:
        jpeg_roundtrip(x12, best[0], path)
    return best
