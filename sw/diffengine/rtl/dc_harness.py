"""Run full-colour command streams through the Verilated `display_controller`
(sim/dc/dc_harness.cpp, plain C++, no Python in the clock loop) and read back the frames
and the Load Monitor summary. Builds are cached per configuration by make
(sim/build/dc_*); a lock file per configuration serialises concurrent callers.

Modes (docs/display-controller.md §3): 0 = 640x480, 1 = 640x485, 2 = 1280x1024,
3 = the test mode whose geometry is the build's `test` tuple
(HActive, HFp, HSync, HBp, VActive, VFp, VSync, VBp).
"""
from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import isa, REPO
from ..formats import binfmt

DEFAULT_TEST = (16, 2, 3, 3, 6, 1, 2, 2)
# Each fixed mode's (HActive, VActive), from spec/video.toml.
MODES = {i: (h[0], v[0]) for i, (_, h, v, _, _) in isa.VIDEO_MODES.items()}


@dataclass(frozen=True)
class Config:
    chips: int = 72
    num_buf: int = 1
    buf_depth: int = 16
    carry_bug: bool = False
    threads: int = 1
    test: tuple[int, ...] = DEFAULT_TEST
    # True: Verilate rtl/array/de_array.sv whole; False: the fast array (sim/fast).
    flat: bool = False

    def make_vars(self) -> list[str]:
        return [f"CHIPS={self.chips}", f"NUMBUF={self.num_buf}", f"BUFDEPTH={self.buf_depth}",
                f"CARRY_BUG={int(self.carry_bug)}", f"THREADS={self.threads}",
                "TEST=" + " ".join(str(t) for t in self.test), f"FLAT={int(self.flat)}"]

    @property
    def tag(self) -> str:
        return (f"dc_c{self.chips}_n{self.num_buf}_d{self.buf_depth}_b{int(self.carry_bug)}"
                f"_t{self.threads}_m" + "-".join(str(t) for t in self.test)
                + ("_flat" if self.flat else ""))

    def size(self, mode: int) -> tuple[int, int]:
        """(width, height) of the frame in `mode`."""
        return MODES[mode] if mode in MODES else (self.test[0], self.test[4])


def build(cfg: Config, quiet: bool = True) -> tuple[Path, bool, float]:
    """Build (or reuse) the harness; returns (executable, rebuilt?, seconds spent)."""
    import fcntl

    exe = REPO / "sim" / "build" / cfg.tag / "Vdisplay_controller"
    lock_dir = REPO / "sim" / "build"
    lock_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    before = exe.stat().st_mtime if exe.exists() else None
    with open(lock_dir / f".{cfg.tag}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        res = subprocess.run(["make", "-s", "-C", str(REPO / "sim" / "dc"), "harness",
                              *cfg.make_vars()], env=dict(os.environ),
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if res.returncode:
        raise RuntimeError(f"sim/dc build failed ({cfg.tag}):\n{res.stdout[-3000:]}")
    if not quiet and res.stdout.strip():
        print(res.stdout.strip(), file=sys.stderr)
    after = exe.stat().st_mtime
    return exe, before != after, time.monotonic() - t0


def read_dcf(path) -> np.ndarray:
    """A .dcf file -> uint16 array (frames, height, width, 3), 12-bit values."""
    data = Path(path).read_bytes()
    if data[:4] != b"DCF1":
        raise ValueError(f"{path}: not a DCF1 frame file")
    w, h, f, ch, bits = struct.unpack("<5I", data[4:24])
    n = f * h * w * ch
    if len(data) != 24 + 2 * n:
        raise ValueError(f"{path}: {len(data)} bytes, header says {24 + 2 * n}")
    return np.frombuffer(data[24:], dtype="<u2").reshape(f, h, w, ch).copy()


def _write_stream(path: Path, stream) -> Path:
    """stream: a path (.de48 used as is), a list of Commands, or a list of slots."""
    if isinstance(stream, (str, Path)):
        return Path(stream)
    items = list(stream)
    slots = isa.serialise(items) if items and isinstance(items[0], isa.Command) else items
    path.write_bytes(binfmt.encode_de48(slots))
    return path


def run(streams, cfg: Config = Config(), mode: int = 0, progress=None,
        workdir=None) -> tuple[np.ndarray, dict]:
    """Play three streams (R, G, B) through the controller.

    Returns (frames uint16 (F, H, W, 3), stats dict from the harness JSON, with the
    harness's wall time). `progress(done, total)` is called with simulated cycles while it
    runs. Raises RuntimeError if the harness reports a failed check (frame or sync
    mismatch, align_err, pixel collision); late lines are not an error here (see
    stats["load_monitor"][c]["total_late_lines"]).
    """
    if len(streams) != 3:
        raise ValueError("need three streams (R, G, B)")
    exe, _, _ = build(cfg)
    with tempfile.TemporaryDirectory(dir=workdir) as tmp:
        tmp = Path(tmp)
        paths = [str(_write_stream(tmp / f"{c}.de48", s)) for c, s in zip("rgb", streams)]
        out, stats = tmp / "out.dcf", tmp / "stats.json"
        cmd = [str(exe), *paths, "-o", str(out), "--mode", str(mode), "--stats", str(stats),
               "--quiet"]
        if progress:
            cmd.append("--progress")
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        other = []
        for line in proc.stderr:
            if line.startswith("progress ") and progress:
                done, total = (int(t) for t in line.split()[1:3])
                progress(done, total)
            else:
                other.append(line.rstrip())
        proc.wait()
        if proc.returncode == 2 or not out.exists():
            raise RuntimeError("dc_harness failed: " + "\n".join(other))
        st = json.loads(stats.read_text())
        st["stderr"] = other
        st["threads"] = cfg.threads          # the build's Verilator --threads
        if proc.returncode:
            raise RuntimeError("dc_harness check failed: " + "; ".join(st.get("errors", other)))
        return read_dcf(out), st


def monitor_summary(stats: dict) -> str:
    """A few lines of Load Monitor figures per colour for a terminal."""
    lm = stats["load_monitor"]
    window = (stats["h_total"] - 1) * stats["height"]
    rows = [f"load monitor (frame {lm['R']['frame_count']}, {stats['height']} lines x "
            f"{stats['h_total'] - 1} slots):"]
    for c in "RGB":
        m = lm[c]
        rows.append(f"  {c}: issued {m['issued']} ({100 * m['issued'] / window:.1f} % of the "
                    f"windows), free {m['free']}, max/line {m['max_issued']}, late lines "
                    f"{m['late_lines']}, dropped {m['dropped']}")
    return "\n".join(rows)
