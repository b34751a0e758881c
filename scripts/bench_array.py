#!/usr/bin/env python3
"""Speed of the Verilated array (sim/harness, plain C++) and of its builds, measured in
one run (these machines are noisy):

* simulated cycles/s for 1, 8 and 72 chips, single-threaded and with Verilator threads;
* seconds per 640x480 frame (800 x 525 = 420,000 cycles per colour) for one colour on
  72 chips and for three colours (three arrays, as three processes), with the Python
  golden models' time for the same frame in the same run;
* build time cold (no ccache, empty folder), cached (second `make`: a no-op) and
  rebuilt from a warm ccache;
* the cocotb overhead against the plain harness (tb/bench_cocotb, same 1-chip array).

Writes the "Verilated array speed" section of docs/performance.md with --write.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "sw"))
sys.path.insert(0, str(ROOT / "scripts"))

from bench_model import random_frame  # noqa: E402  (the golden-model bench's frame)
from diffengine import binfmt, functional, harness, isa, randgen, structural  # noqa: E402

SECTION = "## Verilated array speed"
LINE_SLOTS, LINES, TOTAL_LINES = 800, 480, 525


def log(msg: str) -> None:
    print(msg, flush=True)


def make(chips: int, threads: int, env=None) -> float:
    t = time.perf_counter()
    subprocess.run(["make", "-s", "-C", str(ROOT / "sim"), "harness", f"CHIPS={chips}",
                    f"THREADS={threads}", "TRACE=0"], check=True, env=env or dict(os.environ),
                   stdout=subprocess.DEVNULL)
    return time.perf_counter() - t


def build_times(chips: int) -> dict:
    """Cold (empty folder, ccache off), no-op (second make), warm ccache (empty folder)."""
    import fcntl

    name = harness.tag(chips, False, 1, False)
    folder = ROOT / "sim" / "build" / name
    with open(ROOT / "sim" / "build" / f".{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # the same lock as harness.build()
        shutil.rmtree(folder, ignore_errors=True)
        cold = make(chips, 1, dict(os.environ, CCACHE_DISABLE="1"))
        noop = make(chips, 1)
        shutil.rmtree(folder, ignore_errors=True)
        make(chips, 1)  # fills ccache (the cold build bypassed it)
        shutil.rmtree(folder, ignore_errors=True)
        warm = make(chips, 1)
    return {"cold": cold, "noop": noop, "ccache": warm}


def frame_slots(cmds) -> list[tuple[int, int]]:
    """A display frame as the access controller plays it: each line padded with Nops to
    800 slots and ended by its Refresh, then 45 blank lines of Nops."""
    slots = []
    for line in isa.split_lines(cmds):
        s = isa.serialise(line[:-1])
        if len(s) >= LINE_SLOTS:
            raise ValueError("a line does not fit in 800 slots")
        slots += s + [(isa.NOP, 0)] * (LINE_SLOTS - 1 - len(s)) + [(isa.REFRESH, 0)]
    return slots + [(isa.NOP, 0)] * (LINE_SLOTS * (TOTAL_LINES - LINES))


def run_exe(exe: Path, src: Path, repeat: int = 1) -> tuple[float, float]:
    """(simulated cycles/s of the clock loop, wall seconds of the whole process)."""
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        out = subprocess.run([str(exe), str(src), str(Path(tmp) / "o.depx"), "--repeat",
                              str(repeat)], check=True, capture_output=True, text=True).stdout
        wall = time.perf_counter() - t
    m = re.search(r"(\d+) cycles in ([\d.]+) s", out)
    return int(m.group(1)) / float(m.group(2)), wall


def cocotb_rate(chips: int, n_commands: int, seed: int) -> float:
    """The same kind of stream through cocotb (driver only, no checking)."""
    env = dict(os.environ, BENCH_CHIPS=str(chips), BENCH_N=str(n_commands),
               BENCH_SEED=str(seed))
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-s", "-p", "no:cacheprovider",
                          str(ROOT / "tb" / "bench_cocotb" / "bench_cocotb.py")],
                         cwd=ROOT / "tb", env=env, capture_output=True, text=True)
    m = re.search(r"BENCH cycles=(\d+) seconds=([\d.]+)", out.stdout + out.stderr)
    if not m:
        raise RuntimeError("cocotb bench failed:\n" + out.stdout[-3000:] + out.stderr[-3000:])
    return int(m.group(1)) / float(m.group(2))


def main(argv=None) -> int:
    import json

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2, help="threaded builds to compare")
    ap.add_argument("--parts", default="builds,rates,frame,models,cocotb",
                    help="what to measure this time (results merge into --json)")
    ap.add_argument("--thread-counts", default=None,
                    help="thread counts for the rates part (default: 1,<--threads>)")
    ap.add_argument("--short", action="store_true",
                    help="short runs (loaded machine): 1/8 chips ~30-60k cycles, 72 chips the "
                    "first 12 lines of the frame; the frame part runs 1/5 of the frame and "
                    "scales by 5")
    ap.add_argument("--json", default=str(ROOT / "sim" / "out" / "bench_array.json"))
    ap.add_argument("--write", action="store_true")
    a = ap.parse_args(argv)
    parts = set(a.parts.split(","))
    jpath = Path(a.json)
    res: dict = json.loads(jpath.read_text()) if jpath.exists() else {}
    res.update({"threads": a.threads, "cpus": os.cpu_count()})
    if a.short and "rates" in parts:
        res["short"] = True
    rates = {tuple(map(int, k.split(","))): v for k, v in res.get("rates", {}).items()}

    def save():
        res["rates"] = {f"{c},{t}": v for (c, t), v in rates.items()}
        jpath.parent.mkdir(parents=True, exist_ok=True)
        jpath.write_text(json.dumps(res, indent=1))

    if "builds" in parts:
        for chips in (8, 72):
            res[f"build{chips}"] = b = build_times(chips)
            log(f"build {chips:2d} chips: cold {b['cold']:.1f} s, no-op {b['noop']:.2f} s, "
                f"warm ccache {b['ccache']:.1f} s")
            save()

    tmp = Path(tempfile.mkdtemp())
    frame_cmds = random_frame(np.random.default_rng(a.seed), mixed=True)
    fslots = frame_slots(frame_cmds)
    (tmp / "frame.de48").write_bytes(binfmt.encode_de48(fslots))
    (tmp / "part.de48").write_bytes(binfmt.encode_de48(fslots[:LINE_SLOTS * LINES // 5]))
    (tmp / "rate.de48").write_bytes(binfmt.encode_de48(fslots[:LINE_SLOTS * 12]))
    for chips in (1, 8):
        cmds = randgen.stream(a.seed, 4000, 9 * chips, (1, 40))
        (tmp / f"r{chips}.de48").write_bytes(binfmt.encode_de48(isa.serialise(cmds)))
    if "rates" in parts:
        counts = [int(t) for t in (a.thread_counts or f"1,{a.threads}").split(",")]
        for threads in counts:
            for chips in (1, 8, 72):
                t = time.perf_counter()
                exe = harness.build(chips, threads=threads)
                bt = time.perf_counter() - t
                if chips == 72:
                    src = tmp / ("rate.de48" if a.short else "frame.de48")
                    rate, wall = run_exe(exe, src)
                    if not a.short:
                        res[f"frame_t{threads}"] = wall
                else:
                    rep = (4 if chips == 1 else 2) if a.short else (40 if chips == 1 else 8)
                    rate, wall = run_exe(exe, tmp / f"r{chips}.de48", repeat=rep)
                rates[(chips, threads)] = rate
                log(f"harness {chips:2d} chips, {threads} thread(s): {rate:12,.0f} cycles/s "
                    f"(build/check {bt:.0f} s, run {wall:.1f} s{', short' if a.short else ''})")
                save()

    if "frame" in parts:
        # Three colours = three arrays: three processes at once (the best thread count).
        best_t = 1 if rates.get((72, 1), 0) >= rates.get((72, a.threads), 0) else a.threads
        exe = harness.build(72, threads=best_t)
        src, scale = (tmp / "part.de48", 5) if a.short else (tmp / "frame.de48", 1)
        t = time.perf_counter()
        procs = [subprocess.Popen([str(exe), str(src), str(tmp / f"c{i}.depx"), "--quiet"])
                 for i in range(3)]
        for p in procs:
            if p.wait():
                raise RuntimeError("harness failed")
        res["frame3"] = (time.perf_counter() - t) * scale
        res["frame3_threads"] = best_t
        res["frame3_scaled"] = scale
        log(f"three colours (3 processes, {best_t} thread(s) each): {res['frame3']:.1f} s"
            + (f" (1/{scale} of the frame x {scale})" if scale > 1 else ""))
        got = harness.read_depx(tmp / "c0.depx")
        ref = functional.render([c for ln in isa.split_lines(frame_cmds)[:got.shape[0]]
                                 for c in ln], 648)
        res["frame_equal"] = bool(np.array_equal(got, ref))
        res["frame_equal_lines"] = int(got.shape[0])
        save()

    if "models" in parts:
        t = time.perf_counter()
        functional.render(frame_cmds, 648)
        res["functional"] = time.perf_counter() - t
        lines = isa.split_lines(frame_cmds)[:8]
        t = time.perf_counter()
        structural.render([c for ln in lines for c in ln], 648)
        res["structural"] = (time.perf_counter() - t) / len(lines) * LINES
        log(f"golden models, same frame: functional {res['functional']:.2f} s, structural "
            f"{res['structural']:.0f} s (8 lines x 60)")
        save()

    if "cocotb" in parts:
        t = time.perf_counter()
        res["cocotb"] = cocotb_rate(1, 1000, a.seed)
        log(f"cocotb 1 chip: {res['cocotb']:,.0f} cycles/s (wall {time.perf_counter() - t:.0f} s)")
        save()
    shutil.rmtree(tmp, ignore_errors=True)
    if a.write:
        write_doc(res, rates, "build72" in res)
    return 0


def write_doc(r: dict, rates: dict, with_builds: bool) -> None:
    import platform

    path = ROOT / "docs" / "performance.md"
    text = path.read_text()
    t = r["threads"]
    rows = "\n".join(
        f"| {c} | {9 * c} | {rates[(c, 1)]:,.0f} | {rates[(c, t)]:,.0f} | "
        f"{rates[(c, t)] / rates[(c, 1)]:.3g}x | {rates[(c, 1)] * 9 * c / 1e6:,.1f} |"
        for c in (1, 8, 72))
    cycles = LINE_SLOTS * TOTAL_LINES
    short_note = (" (the threaded rates are short runs: 1 chip ~60k cycles, 8 chips ~30k, "
                  "72 chips the first 12 lines of the frame)" if r.get("short") else "")
    frame_t = (f"{r[f'frame_t{t}']:.1f}" if f"frame_t{t}" in r else
               f"{cycles / rates[(72, t)]:,.0f} (cycles / the rate above)")
    f3_note = (f", 1/{r['frame3_scaled']} of the frame timed, x{r['frame3_scaled']}"
               if r.get("frame3_scaled", 1) > 1 else "")
    note = f" ({r['note']})" if r.get("note") else ""
    passes = r.get("passes", "one run")
    thr_default = ("`THREADS_FROM_CHIPS = None`" if harness.THREADS_FROM_CHIPS is None
                   else f"2 from {harness.THREADS_FROM_CHIPS} chips")
    builds = ""
    if with_builds:
        builds = "\n".join(
            f"| {c} | {r[f'build{c}']['cold']:.0f} s | {r[f'build{c}']['noop']:.2f} s | "
            f"{r[f'build{c}']['ccache']:.0f} s |" for c in (8, 72))
        builds = f"""
Build of the fast harness (`make -C sim harness CHIPS=N`, Verilator `-O3`, g++ `-O2`,
`-j 2`): cold = empty build folder with ccache off; cached = the second `make`, which
only checks timestamps and the flags stamp; ccache = empty build folder again with a warm
ccache (what a `make clean` or a fresh checkout of the same RTL costs).

| chips | cold | cached (no-op) | empty folder, warm ccache |
|---|---|---|---|
{builds}
"""
    body = f"""{SECTION}

The C++ harness (`sim/harness/array_harness.cpp`, no Python in the clock loop) on
`de_array`, Verilator 5.48 `-O3`, g++ `-O2`, {platform.machine()} with {r['cpus']} cores shared
with other jobs while measuring{note}. 1 and 8 chips: constrained-random streams
(`randgen`), Refreshes padded to the array width; 72 chips: the display frame below. All
figures come from `scripts/bench_array.py` ({passes}); absolute numbers move with the load,
the ratios much less.

| chips | PEs | cycles/s, 1 thread | cycles/s, {t} threads | threads speed-up | PE-cycles/s (M), 1 thread |
|---|---|---|---|---|---|
{rows}

**Where threads help.** `--threads N` is a separate cached build
(`sim/build/array_c<N>_b<B>_t<T>_tr<0|1>`), same frames (tested). On this machine it helped
nowhere: Verilator's threads meet at a barrier every cycle and spin while they wait, so
with more runnable threads than idle cores (two cores, shared with other jobs) every
cycle waits for a descheduled thread{short_note}. `harness.default_threads()` therefore
returns 1 for every array size ({thr_default}); pass `threads=` / `THREADS=` /
`--threads` on a machine with idle cores and measure again with this script.

**A 640x480 frame.** The mixed random frame of the golden-model bench
(`scripts/bench_model.py`, ~100 commands per line), each line padded to the 800-slot line
period, 45 blank lines: {cycles:,} cycles per colour (+ drain).

| what | seconds per frame |
|---|---|
| RTL, one colour, 72 chips, 1 thread (whole process) | {r['frame_t1']:.1f} |
| RTL, one colour, 72 chips, {t} threads | {frame_t} |
| RTL, three colours = three arrays as three processes at once ({r['frame3_threads']} thread(s) each){f3_note} | {r['frame3']:.1f} |
| Python functional golden model, the same frame, one colour | {r['functional']:.2f} |
| Python structural (cycle-level) model, one colour (8 lines, x60) | {r['structural']:.0f} |

The RTL frame equals the functional model's pixel for pixel ({r.get('frame_equal_lines', 480)} lines compared): {r['frame_equal']}.
{builds}
cocotb 2.1 driving the same kind of stream into the same 1-chip build
(`tb/bench_cocotb/bench_cocotb.py`, driver only):
**{r['cocotb']:,.0f} cycles/s, {rates[(1, 1)] / r['cocotb']:,.0f}x slower** than the C++ harness,
which is why the scoreboards and `make sim` run through the harness and cocotb keeps
the cycle-level checks on small arrays.

Reproduce: `source .venv/env.sh; .venv/bin/python scripts/bench_array.py --write` (all
parts; about an hour on two busy cores, most of it the cold 72-chip builds).
`--parts builds,rates,frame,models,cocotb` picks parts (results merge into
`sim/out/bench_array.json`), `--short` runs the short variants used for the threaded
rates here, `--thread-counts 2` measures only the threaded builds.
"""
    pat = re.compile(re.escape(SECTION) + r".*?(?=^## |\Z)", re.S | re.M)
    text = pat.sub(body + "\n", text) if pat.search(text) else text.rstrip("\n") + "\n\n" + body
    path.write_text(text)
    log(f"updated {path}")


if __name__ == "__main__":
    sys.exit(main())
