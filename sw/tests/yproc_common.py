"""Shared helpers of the yproc tests (test_yproc_scan.py, test_yproc_anim.py):
build sw/hsr/build/yproc once, run it, read its outputs (docs/yproc.md)."""
from __future__ import annotations

import fcntl
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from diffengine.formats import binfmt
from diffengine.model import functional
from diffengine import isa

ROOT = Path(__file__).resolve().parents[2]
HSR = ROOT / "sw" / "hsr"
YPROC = HSR / "build" / "yproc"
SCENES = ROOT / "sw" / "scenes"


def build_yproc() -> Path:
    lock = Path(tempfile.gettempdir()) / "hsr_yproc_build.lock"
    with open(lock, "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        r = subprocess.run(["make", "-C", str(HSR), "build/yproc"], capture_output=True, text=True)
        fcntl.flock(fh, fcntl.LOCK_UN)
    assert r.returncode == 0, r.stdout + r.stderr
    return YPROC


def run(*args, ok=True) -> subprocess.CompletedProcess:
    r = subprocess.run([str(YPROC), *map(str, args)], capture_output=True, text=True, timeout=300)
    if ok:
        assert r.returncode == 0, r.stdout + r.stderr
    return r


def small_scene(src: Path, dst: Path, w: int, h: int, extra: str = "") -> Path:
    """copy of a scene file with another screen and absolute OBJ paths"""
    lines = []
    for ln in src.read_text().splitlines():
        t = ln.split()
        if t and t[0] == "screen":
            ln = f"screen {w} {h}"
        elif t and t[0] == "obj":
            t[1] = str((src.parent / t[1]).resolve())
            ln = " ".join(t)
        lines.append(ln)
    dst.write_text("\n".join(lines) + "\n" + extra)
    return dst


def read_ppm16(path: Path) -> np.ndarray:
    """expect.ppm (P6, maxval 4095, 16-bit BE) -> [3][H][W] int"""
    data = path.read_bytes()
    magic, dims, maxval, rest = data.split(b"\n", 3)
    assert magic == b"P6" and maxval == b"4095"
    w, h = map(int, dims.split())
    return np.frombuffer(rest, dtype=">u2").reshape(h, w, 3).transpose(2, 0, 1).astype(np.int64)


def read_ideal(path: Path, h: int, w: int) -> np.ndarray:
    return np.fromfile(path, dtype="<f8").reshape(3, h, w)


def stream_commands(path: Path):
    """a .de48 file -> commands, checking that the stream is one isa.serialise produces"""
    slots = binfmt.decode_de48(path.read_bytes(), str(path))
    cmds = binfmt.deserialise(slots, str(path))
    assert isa.serialise(cmds) == slots
    return cmds


def golden(path: Path, width: int) -> np.ndarray:
    """the golden model's frame for one colour stream"""
    return np.asarray(functional.render(stream_commands(path), width)).astype(np.int64)


def split_lines(data: bytes) -> list[bytes]:
    """.de48 body (without header) -> per-line word runs, each ending with its Refresh"""
    lines, cur = [], bytearray()
    for k in range(0, len(data), 6):
        w = data[k:k + 6]
        cur += w
        if ((w[0] << 4) | (w[1] >> 4)) == isa.REFRESH:
            lines.append(bytes(cur))
            cur = bytearray()
    assert not cur, "stream does not end with a Refresh"
    return lines
