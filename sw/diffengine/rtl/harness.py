"""Run command streams through the Verilated array (sim/harness, plain C++, no Python in
the clock loop) and read back the frame. Builds are cached per configuration by make
(sim/Makefile; docs/simulation.md).

Two build flavours per configuration: the fast one (trace=False) and the trace one
(trace=True: FST windows, per-PE state CSV, breakpoints; slower to build and to run).
"""
from __future__ import annotations

import os
import struct
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import isa, REPO
from ..formats import binfmt


PE_PER_CHIP = 9   # PEs per chip (rtl/array/de_chip.sv)
EXIT_BREAK = 3  # the harness stopped at a breakpoint

# Verilator threads per chip count where they were measured to help (docs/performance.md,
# "Verilated array speed"). On the 2-core build machines, shared by several jobs, no
# array size gained from a second thread: Verilator's threads spin-wait for each other
# every cycle, and with more runnable threads than cores 1, 8 and 72 chips ran 20-270x
# slower with 2 threads. So the default is 1 thread everywhere; `threads=` / THREADS=
# still build and run a threaded model for machines with idle cores.
THREADS_FROM_CHIPS: int | None = None


def default_threads(chips: int) -> int:
    """Verilator threads to use for `chips` chips when the caller does not say."""
    if THREADS_FROM_CHIPS is not None and chips >= THREADS_FROM_CHIPS:
        return 2
    return 1


def tag(chips: int, carry_bug: bool = False, threads: int = 1, trace: bool = False,
        flat: bool = False) -> str:
    return (f"array_c{chips}_b{int(carry_bug)}_t{threads}_tr{int(trace)}"
            + ("_flat" if flat and not trace else ""))


def build(chips: int, carry_bug: bool = False, threads: int | None = None,
          trace: bool = False, flat: bool = False) -> Path:
    """Build (or reuse) the harness for `chips` chips; returns the executable.

    The default (trace=False, flat=False) is the fast array (sim/fast: the chips compiled
    once and composed, docs/simulation.md); flat=True Verilates rtl/array/de_array.sv
    whole, as the trace build always does.

    A lock file per configuration serialises concurrent callers (pytest-xdist workers
    that need the same build), so make never runs twice in one build folder."""
    import fcntl

    threads = default_threads(chips) if threads is None else int(threads)
    name = tag(chips, carry_bug, threads, trace, flat)
    lock_dir = REPO / "sim" / "build"
    lock_dir.mkdir(parents=True, exist_ok=True)
    with open(lock_dir / f".{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        subprocess.run(["make", "-s", "-C", str(REPO / "sim"), "harness", f"CHIPS={chips}",
                        f"CARRY_BUG={int(carry_bug)}", f"THREADS={threads}",
                        f"TRACE={int(trace)}", f"FLAT={int(flat and not trace)}"],
                       check=True, env=dict(os.environ), stdout=subprocess.DEVNULL)
    return REPO / "sim" / "build" / name / "Vde_array"


def read_depx(path: Path) -> np.ndarray:
    data = Path(path).read_bytes()
    if data[:4] != b"DEPX":
        raise ValueError(f"{path}: not a DEPX frame")
    w, h = struct.unpack("<II", data[4:12])
    return np.frombuffer(data[12:12 + 2 * w * h], dtype="<u2").reshape(h, w).copy()


def run(commands: list[isa.Command] | None, chips: int, carry_bug: bool = False,
        slots=None, threads: int | None = None, extra_args: tuple[str, ...] = (),
        trace: bool = False) -> tuple[np.ndarray, str]:
    """Play commands (or raw slots) through the array; returns (frame, harness report)."""
    if slots is None:
        slots = isa.serialise(commands)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "in.de48"
        src.write_bytes(binfmt.encode_de48(slots))
        return run_file(src, chips, carry_bug, threads=threads, extra_args=extra_args,
                        trace=trace)


def run_file(src: Path, chips: int, carry_bug: bool = False, threads: int | None = None,
             extra_args: tuple[str, ...] = (), trace: bool = False) -> tuple[np.ndarray, str]:
    """Play a .de48 file through the array (streams too long to hold as Python objects);
    returns (frame, harness report)."""
    exe = build(chips, carry_bug, threads, trace)
    with tempfile.TemporaryDirectory() as tmp:
        dst = Path(tmp) / "out.depx"
        res = subprocess.run([str(exe), str(src), str(dst), *extra_args],
                             capture_output=True, text=True)
        if res.returncode:
            raise RuntimeError(f"harness failed: {res.stderr.strip()}")
        return read_depx(dst), res.stdout.strip()


@dataclass
class TraceRun:
    """What a trace-build run left: exit status (0, or EXIT_BREAK at a breakpoint), its
    stdout (report or breakpoint print-out), stderr, the trace CSV text (if asked for),
    the frame (None when stopped at a breakpoint)."""
    returncode: int
    stdout: str
    stderr: str
    csv: str | None
    frame: np.ndarray | None


def run_traced(slots, chips: int, carry_bug: bool = False, *, pes: str | None = None,
               window: tuple[int | None, int | None] | None = None, line: int | None = None,
               fst: Path | None = None, col: int | None = None,
               break_cycle: int | None = None, break_line: int | None = None,
               break_pe: int | None = None, break_op: str | int | None = None,
               threads: int = 1) -> TraceRun:
    """Run `slots` through the trace build with the harness's trace options
    (docs/simulation.md). A harness error (exit status other than 0 and 3) raises."""
    exe = build(chips, carry_bug, threads, trace=True)
    args: list[str] = []
    if window is not None:
        if window[0] is not None:
            args += ["--from-cycle", str(window[0])]
        if window[1] is not None:
            args += ["--to-cycle", str(window[1])]
    if line is not None:
        args += ["--line", str(line)]
    if fst is not None:
        args += ["--fst", str(fst)]
    if col is not None:
        args += ["--col", str(col)]
    if break_cycle is not None:
        args += ["--break-cycle", str(break_cycle)]
    if break_line is not None:
        args += ["--break-line", str(break_line)]
    if break_pe is not None:
        args += ["--break-pe", str(break_pe), "--break-op", str(break_op)]
    with tempfile.TemporaryDirectory() as tmp:
        src, dst, csv = Path(tmp) / "in.de48", Path(tmp) / "out.depx", Path(tmp) / "t.csv"
        src.write_bytes(binfmt.encode_de48(slots))
        if pes is not None:
            args += ["--trace-pes", pes, "--trace-csv", str(csv)]
        res = subprocess.run([str(exe), str(src), str(dst), *args],
                             capture_output=True, text=True)
        if res.returncode not in (0, EXIT_BREAK):
            raise RuntimeError(f"harness failed ({res.returncode}): {res.stderr.strip()}")
        return TraceRun(res.returncode, res.stdout, res.stderr,
                        csv.read_text() if pes is not None and csv.exists() else None,
                        read_depx(dst) if res.returncode == 0 else None)
