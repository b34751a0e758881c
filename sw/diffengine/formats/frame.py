"""Frames on disk: 12-bit RGB frames -> 16-bit PNG (value << 4) and an 8-bit view via
OpenImageIO; raw .dcf frames of the display_controller harness (dc_harness.read_dcf);
frames as text (one row per line, the regression's rtl.txt) and as small in-memory PNGs
for self-contained HTML pages (the regression report, the inspector).

    diffengine frame IN.dcf OUT.png [--frame K] [--view8 OUT8.png]
"""
from __future__ import annotations

import base64
import struct
import sys
import zlib
from pathlib import Path

import numpy as np


def _write(path, arr: np.ndarray, fmt: str, software: str) -> None:
    import OpenImageIO as oiio

    h, w = arr.shape[:2]
    ch = 1 if arr.ndim == 2 else arr.shape[2]
    spec = oiio.ImageSpec(w, h, ch, fmt)
    spec.attribute("Software", software)
    out = oiio.ImageOutput.create(str(path))
    if out is None:
        raise OSError(f"{path}: cannot write this image type ({oiio.geterror()})")
    ok = out.open(str(path), spec) and out.write_image(np.ascontiguousarray(arr.reshape(h, w, ch)))
    err = out.geterror()
    out.close()
    if not ok:
        raise OSError(f"{path}: {err or 'write failed'}")


def write_png16(path, frame12: np.ndarray, software: str = "diffengine") -> None:
    """12-bit pixels (H, W[, 3]) -> 16-bit PNG/TIFF with all 12 bits as value << 4."""
    f = np.asarray(frame12)
    if f.min(initial=0) < 0 or f.max(initial=0) > 4095:
        raise ValueError("write_png16 wants 12-bit values 0..4095")
    _write(path, f.astype(np.uint16) << 4, "uint16", software)


def view8(frame12: np.ndarray) -> np.ndarray:
    """The 8-bit view: the top 8 of the 12 bits (pixel >> 4), as the DAC window w = 4."""
    return (np.asarray(frame12).astype(np.uint16) >> 4).astype(np.uint8)


def write_png8(path, frame12: np.ndarray, software: str = "diffengine") -> None:
    _write(path, view8(frame12), "uint8", software)


def write_rgb8(path, img8: np.ndarray, software: str = "diffengine") -> None:
    """An 8-bit picture as it is (diagrams, maps), no 12-bit view."""
    _write(path, np.asarray(img8, dtype=np.uint8), "uint8", software)


def read_png16(path) -> np.ndarray:
    """Inverse of write_png16: the 12-bit values."""
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise OSError(f"{path}: {oiio.geterror()}")
    arr = inp.read_image("uint16")
    inp.close()
    return (np.asarray(arr) >> 4).astype(np.uint16)


# ---- frames as text (one row per line) and as in-memory PNG for HTML pages -------------


def read_frame_text(path: Path) -> np.ndarray:
    rows = [[int(v) for v in ln.split()] for ln in Path(path).read_text().splitlines()
            if ln.strip()]
    return np.array(rows, dtype=np.uint16)


def write_frame_text(path: Path, frame: np.ndarray) -> None:
    Path(path).write_text("\n".join(" ".join(str(int(v)) for v in row) for row in frame) + "\n")


def png(rgb: np.ndarray) -> bytes:
    """Minimal PNG encoder: (h, w) grey or (h, w, 3) RGB, uint8."""
    a = np.ascontiguousarray(rgb, dtype=np.uint8)
    h, w = a.shape[:2]
    ctype = 2 if a.ndim == 3 else 0
    raw = b"".join(b"\0" + a[y].tobytes() for y in range(h))

    def chunk(tag: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + tag + data
                + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, ctype, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def data_uri(png_bytes: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png_bytes).decode()


def grey(frame: np.ndarray) -> tuple[np.ndarray, int]:
    """12-bit frame -> 8-bit grey, scaled so the frame's maximum is white."""
    top = int(frame.max()) if frame.size else 0
    if top == 0:
        return np.zeros(frame.shape, np.uint8), 0
    return (frame.astype(np.uint32) * 255 // top).astype(np.uint8), top



def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("input")
    ap.add_argument("output", help="16-bit PNG")
    ap.add_argument("--frame", type=int, default=-1, help="frame index (default: last)")
    ap.add_argument("--view8", help="also write an 8-bit view (pixel >> 4)")
    ap.set_defaults(func=command)


def command(a) -> int:
    from ..rtl.dc_harness import read_dcf
    try:
        frames = read_dcf(a.input)
        f = frames[a.frame]
    except OSError as e:
        print(f"diffengine frame: {a.input}: {e.strerror or e}", file=sys.stderr)
        return 1
    except (ValueError, IndexError) as e:   # not a .dcf (the message names it), no such frame
        print(f"diffengine frame: {e}" if isinstance(e, ValueError)
              else f"diffengine frame: {a.input}: {e}", file=sys.stderr)
        return 1
    write_png16(a.output, f)
    if a.view8:
        write_png8(a.view8, f)
    print(f"{a.output}: {f.shape[1]} x {f.shape[0]} RGB, frame {a.frame % len(frames)} of "
          f"{len(frames)}", file=sys.stderr)
    return 0
