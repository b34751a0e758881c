"""Incremental animation frames from `yproc anim` (docs/yproc.md): apply the frame deltas
(.delta, "YPD1") to frame 0's streams and check every frame against a full re-render.

Delta format (written by sw/hsr/tools/yproc_scan.c): "YPD1", u16 version 1, u16 frame,
u16 width, u16 height (big-endian); then per colour r, g, b: u32 number of changed lines
and per changed line u16 line, u32 words, words x 6-byte .de48 words (the line's commands
and its closing Refresh).
"""
from __future__ import annotations

import struct
from pathlib import Path

from . import binfmt, isa

Line = list[bytes]   # the 6-byte words of one line, its Refresh last


def lines_of_de48(path) -> list[bytes]:
    """A .de48 stream as one bytes object per line (Refresh included)."""
    data = Path(path).read_bytes()
    binfmt.decode_de48(data, str(path))          # validates header and length
    words = data[8:]
    out, start = [], 0
    for i in range(0, len(words), 6):
        if (int.from_bytes(words[i:i + 2], "big") >> 4) == isa.REFRESH:
            out.append(words[start:i + 6])
            start = i + 6
    if start != len(words):
        raise ValueError(f"{path}: {(len(words) - start) // 6} word(s) after the last Refresh")
    return out


def read_delta(path) -> tuple[int, int, int, list[dict[int, bytes]]]:
    """(frame, width, height, [ {line: words} for r, g, b ])."""
    data = Path(path).read_bytes()
    if data[:4] != b"YPD1":
        raise ValueError(f"{path}: not a YPD1 frame delta")
    ver, frame, w, h = struct.unpack(">4H", data[4:12])
    if ver != 1:
        raise ValueError(f"{path}: delta version {ver}")
    pos, chans = 12, []
    for _ in range(3):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        pos += 4
        ch = {}
        for _ in range(n):
            y, k = struct.unpack(">HI", data[pos:pos + 6])
            pos += 6
            ch[y] = data[pos:pos + 6 * k]
            if len(ch[y]) != 6 * k or (int.from_bytes(ch[y][-6:-4], "big") >> 4) != isa.REFRESH:
                raise ValueError(f"{path}: line {y} is truncated or lacks its Refresh")
            pos += 6 * k
        chans.append(ch)
    if pos != len(data):
        raise ValueError(f"{path}: {len(data) - pos} trailing bytes")
    return frame, w, h, chans


def frames(outdir) -> list[list[list[bytes]]]:
    """Every frame's streams, frame 0 from frame000/ and the others by applying the
    deltas in order: result[f][c] = list of the lines of colour c in frame f."""
    outdir = Path(outdir)
    cur = [lines_of_de48(outdir / "frame000" / f"{c}.de48") for c in "rgb"]
    seq = [[list(ch) for ch in cur]]
    f = 1
    while (outdir / f"frame{f:03d}.delta").exists():
        fr, _, h, chans = read_delta(outdir / f"frame{f:03d}.delta")
        if fr != f:
            raise ValueError(f"frame{f:03d}.delta says frame {fr}")
        for c in range(3):
            for y, words in chans[c].items():
                if not 0 <= y < h or y >= len(cur[c]):
                    raise ValueError(f"frame{f:03d}.delta: line {y} outside the frame")
                cur[c][y] = words
        seq.append([list(ch) for ch in cur])
        f += 1
    return seq


def to_de48(lines: list[bytes]) -> bytes:
    return b"DE48" + struct.pack(">HH", 1, 0) + b"".join(lines)
