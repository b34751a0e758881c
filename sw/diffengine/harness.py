"""Run command streams through the Verilated array (sim/harness, plain C++, no Python in
the clock loop) and read back the frame. Builds are cached per configuration by make."""
from __future__ import annotations

import os
import struct
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from . import binfmt, isa

REPO = Path(__file__).resolve().parents[2]


def build(chips: int, carry_bug: bool = False, threads: int = 1) -> Path:
    """Build (or reuse) the harness for `chips` chips; returns the executable.

    A lock file per configuration serialises concurrent callers (pytest-xdist workers
    that need the same build), so make never runs twice in one build folder."""
    import fcntl

    tag = f"array_c{chips}_b{int(carry_bug)}_t{threads}"
    lock_dir = REPO / "sim" / "build"
    lock_dir.mkdir(parents=True, exist_ok=True)
    with open(lock_dir / f".{tag}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        subprocess.run(["make", "-s", "-C", str(REPO / "sim"), "harness", f"CHIPS={chips}",
                        f"CARRY_BUG={int(carry_bug)}", f"THREADS={threads}"],
                       check=True, env=dict(os.environ), stdout=subprocess.DEVNULL)
    return REPO / "sim" / "build" / tag / "Vde_array"


def read_depx(path: Path) -> np.ndarray:
    data = Path(path).read_bytes()
    if data[:4] != b"DEPX":
        raise ValueError(f"{path}: not a DEPX frame")
    w, h = struct.unpack("<II", data[4:12])
    return np.frombuffer(data[12:12 + 2 * w * h], dtype="<u2").reshape(h, w).copy()


def run(commands: list[isa.Command] | None, chips: int, carry_bug: bool = False,
        slots=None, threads: int = 1, extra_args: tuple[str, ...] = ()) -> tuple[np.ndarray, str]:
    """Play commands (or raw slots) through the array; returns (frame, harness report)."""
    exe = build(chips, carry_bug, threads)
    if slots is None:
        slots = isa.serialise(commands)
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = Path(tmp) / "in.de48", Path(tmp) / "out.depx"
        src.write_bytes(binfmt.encode_de48(slots))
        res = subprocess.run([str(exe), str(src), str(dst), *extra_args],
                             capture_output=True, text=True)
        if res.returncode:
            raise RuntimeError(f"harness failed: {res.stderr.strip()}")
        return read_depx(dst), res.stdout.strip()
