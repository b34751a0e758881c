"""`make sim`: the RTL regression (docs/regression.md).

Every case of sim/regress/manifest.toml (command files, the seed's figures, random
streams from recorded seeds, long spans across the 12-bit carry boundaries, spans across
chip boundaries, scenes from `yproc`) is played through the Verilated array by the plain
C++ harness (sim/harness: no Python in the clock loop), and the frame must equal the
golden model (functional.py) bit for bit. Cases marked `bug_check` run a second time on
the carry-bug build, where they must FAIL: that proves the regression can fail, and the
report shows why it failed.

    python -m diffengine.regress [--tier smoke|full|nightly] [-j N] [-k TEXT] [--out DIR]
                                 [--shard K/N]
    python -m diffengine.regress --merge DIR... [--out DIR]

Builds: one per (chip count, carry bug), made before the runs start, reused by all runs.
Outputs in --out (default sim/out/): report.html (self-contained), junit.xml, and per case
cases/<name>/ (stream.cmd, stream.de48, rtl.txt, and on a failure the windowed FST of the
first bad line with its .gtkw save file). Exit status 0 when every case did what it was
expected to do, 1 otherwise.

--shard K/N runs the K-th of N shards, balanced on the durations recorded in
sim/regress/durations.json (greedy longest first), into OUT/shard-K-of-N/; --merge joins
the shard folders into one report.html and junit.xml, and exits 2 if a case is missing or
ran twice (docs/regression.md, "Shards and CI matrices").
"""
from __future__ import annotations

import argparse
import base64
import dataclasses
import fnmatch
import html
import json
import os
import random
import shutil
import struct
import subprocess
import sys
import time
import tomllib
import zlib
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from . import asm, binfmt, functional, harness, isa, randgen

REPO = Path(__file__).resolve().parents[2]
MANIFEST = REPO / "sim" / "regress" / "manifest.toml"
OUT = REPO / "sim" / "out"
YPROC = REPO / "sw" / "hsr" / "build" / "yproc"
TIERS = ("smoke", "full", "nightly")   # cumulative: full runs smoke's cases too
PE_PER_CHIP = 9
ONE = 1 << isa.FRAC_BITS
# The carry-bug golden model is a per-column Python path: only used to explain an
# expected failure when the frame is small enough (sum of Eval span lengths).
BUG_MODEL_BUDGET = 400_000


# ---- cases --------------------------------------------------------------------------


@dataclass
class Case:
    name: str
    kind: str            # file | random | carry | chipcross | scene
    chips: int
    source: str          # where the stream comes from, for people (path or generator+seed)
    bug: bool = False    # run on the carry-bug build (expected to fail)
    params: dict = field(default_factory=dict)
    reference: str | None = None   # stored frame (pixel text) instead of the golden model

    @property
    def width(self) -> int:
        return PE_PER_CHIP * self.chips

    @property
    def expect(self) -> str:
        return "fail" if self.bug else "pass"


def _safe(text: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in text)


def load_manifest(path: Path = MANIFEST, tier: str = "full") -> list[Case]:
    """Expand the manifest into cases for `tier` (tiers are cumulative)."""
    if tier not in TIERS:
        raise ValueError(f"tier {tier!r}: want one of {', '.join(TIERS)}")
    rank = TIERS.index(tier)
    doc = tomllib.loads(Path(path).read_text())
    base = Path(path).resolve().parent
    cases: list[Case] = []

    def wanted(entry) -> bool:
        t = entry.get("tier", "full")
        if t not in TIERS:
            raise ValueError(f"{path}: tier {t!r} not in {TIERS}")
        return TIERS.index(t) <= rank

    def add(case: Case, entry) -> None:
        if not entry.get("bug_only"):
            cases.append(case)
        if entry.get("bug_check") or entry.get("bug_only"):
            cases.append(Case(case.name + "+bug", case.kind, case.chips, case.source, True,
                              case.params, None))

    for e in doc.get("file", []):
        if not wanted(e):
            continue
        files = []
        for pat in e["paths"]:
            root = REPO if not pat.startswith(".") else base
            hits = sorted(root.glob(pat))
            if not hits:
                raise ValueError(f"{path}: {pat!r} matches no file")
            files += hits
        for f in files:
            for chips in e["chips"]:
                ref = e.get("reference")
                add(Case(_safe(f"{f.stem}_c{chips}"), "file", chips,
                         str(f.relative_to(REPO)) if f.is_relative_to(REPO) else str(f),
                         params={"path": str(f)},
                         reference=str((base / ref).resolve()) if ref else None), e)
    for kind in ("random", "carry", "chipcross"):
        for e in doc.get(kind, []):
            if not wanted(e):
                continue
            for seed in e["seeds"]:
                for chips in e["chips"]:
                    p = {k: v for k, v in e.items() if k not in ("seeds", "chips", "tier",
                                                                 "bug_check", "bug_only")}
                    p["seed"] = seed
                    add(Case(f"{kind}_s{seed}_c{chips}", kind, chips,
                             f"{kind}(seed={seed}, " + ", ".join(
                                 f"{k}={v}" for k, v in p.items() if k != "seed") + ")",
                             params=p), e)
    for e in doc.get("scene", []):
        if not wanted(e):
            continue
        scene = REPO / e["scene"]
        for chips in e["chips"]:
            for ch in e.get("channels", ["r", "g", "b"]):
                add(Case(_safe(f"scene_{scene.stem}_{ch}_c{chips}"), "scene", chips,
                         f"yproc scan {e['scene']} ({ch})",
                         params={"scene": str(scene), "channel": ch,
                                 "yproc_args": e.get("yproc_args",
                                                     ["scan", "{scene}", "-o", "{outdir}"])}), e)
    names = [c.name for c in cases]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise ValueError(f"{path}: duplicate case names {sorted(dup)}")
    return cases


# ---- stream generators (pure functions of their seed) ------------------------------------


def _fits(v: int) -> int:
    return max(-(1 << 35), min((1 << 35) - 1, v))


def carry_stream(seed: int, width: int, lines: int = 8, spans: tuple[int, int] = (2, 5)
                 ) -> list[isa.Command]:
    """Long spans whose accumulation crosses the 12-bit block boundaries again and again.

    Start intensities sit just below a block boundary (fractions 0xFFFFFF, 0xFFF000,
    0x000FFF: the block-1 -> block-2 carry of the §7.7 fault, and the block-0 -> block-1
    carry), increments are chosen so that the running value crosses an integer (block 2)
    every few columns, or crosses 0xFFF in block 0 every column, over spans that cover
    most of the array; several spans overlap so that D's own adder carries as well.
    """
    rng = random.Random(seed)
    out: list[isa.Command] = []
    for _ in range(lines):
        for _ in range(rng.randint(*spans)):
            x = rng.choice([0, 0, 1, rng.randrange(min(width, 9))])
            dx = rng.choice([width - x, width - x + rng.randrange(1, 9), 4095 - x])
            base = rng.randrange(0, 16) << isa.FRAC_BITS
            i0 = base | rng.choice([0xFFFFFF, 0xFFF000, 0x000FFF, 0xFFEFFF, 0x7FFFFF,
                                    0xFFFFFF - rng.randrange(1 << 12)])
            kind = rng.random()
            if kind < 0.35:   # crosses an integer every 1..40 columns
                di = (ONE // rng.randint(1, 40)) * rng.choice([1, -1])
            elif kind < 0.6:  # block 0 runs over 0xFFF every column
                di = rng.choice([0xFFF, 0x1001, 0xFFFF, 0x1FFF]) * rng.choice([1, -1])
            elif kind < 0.85:  # block-1 scale steps
                di = (rng.randint(1, 0xFFF) << isa.BLOCK_BITS) * rng.choice([1, -1])
            else:
                di = 0
            if rng.random() < 0.4:
                ddi = rng.randint(-0x400, 0x400) * rng.choice([1, 1 << 8])
                out.append(isa.Command("EVAL", x, dx, (_fits(i0), _fits(di), ddi)))
            else:
                out.append(isa.Command("EVAL", x, dx, (_fits(i0), _fits(di))))
        if rng.random() < 0.3:
            out.append(isa.Command("ACCMODE", values=(1,)))
            out.append(isa.Command("EVAL", 0, width, (-(1 << 20), ONE // 64)))
        out.append(isa.Command("REFRESH"))
    return out


def chipcross_stream(seed: int, width: int, lines: int = 8, per_line: int = 12
                     ) -> list[isa.Command]:
    """Short spans that start a few columns before a chip boundary (every 9 PEs) and end
    a few after it, with Set/Dis/Eval0 on the boundary columns themselves."""
    rng = random.Random(seed)
    bounds = list(range(PE_PER_CHIP, width + 1, PE_PER_CHIP)) or [PE_PER_CHIP]
    out: list[isa.Command] = []
    for _ in range(lines):
        for _ in range(per_line):
            b = rng.choice(bounds)
            x = max(0, b - rng.randint(1, 8))
            dx = b - x + rng.randint(0, 10)
            r = rng.random()
            if r < 0.55:
                p = rng.choice([0, 1, 1, 2, 2, 3])
                vals = [rng.randint(-64, 64) * ONE + rng.randrange(ONE)]
                vals += [rng.randint(-ONE * 4, ONE * 4) >> (4 * k) for k in range(1, p + 1)]
                out.append(isa.Command("EVAL", x, dx, tuple(_fits(v) for v in vals)))
            elif r < 0.7:
                out.append(isa.Command(rng.choice(["SETI", "SETDI", "SETDDI"]), b - 1 + rng.randint(0, 1),
                                       1, (rng.randint(-ONE * 8, ONE * 8),)))
            elif r < 0.8:
                out.append(isa.Command("DIS", b - 1, rng.randint(1, 3)))
            elif r < 0.9:
                out.append(isa.Command("EVAL0", x, dx, (rng.randrange(4096),)))
            else:
                out.append(isa.Command("SETPI", rng.randrange(PE_PER_CHIP), PE_PER_CHIP,
                                       (rng.randint(-ONE, ONE),)))
        out.append(isa.Command("REFRESH"))
    return out


class Unavailable(Exception):
    """A case whose input cannot be produced here (e.g. yproc has no `scan` yet)."""


def scene_stream(case: Case, workdir: Path) -> list[isa.Command]:
    """Run the y-processor (`yproc scan SCENE -o DIR`, sw/hsr) and take one colour's
    instruction stream, DIR/<channel>.de48."""
    if not YPROC.exists():
        raise Unavailable(f"{YPROC.relative_to(REPO)} not built (make -C sw/hsr)")
    outdir = workdir / "yproc"
    outdir.mkdir(exist_ok=True)
    args = [a.format(scene=case.params["scene"], outdir=outdir, width=case.width)
            for a in case.params["yproc_args"]]
    res = subprocess.run([str(YPROC), *args], capture_output=True, text=True, timeout=600)
    out = outdir / f"{case.params['channel']}.de48"
    if res.returncode or not out.exists():
        msg = (res.stderr.strip().splitlines() or ["no output"])[0]
        raise Unavailable(f"yproc {args[0]} failed ({res.returncode}): {msg}")
    return binfmt.load_commands(out.read_bytes(), str(out))[0]


def commands_for(case: Case, workdir: Path) -> list[isa.Command]:
    p = case.params
    if case.kind == "file":
        return binfmt.load_commands(Path(p["path"]).read_bytes(), p["path"])[0]
    if case.kind == "random":
        per = tuple(p.get("per_line", (1, 40)))
        return randgen.stream(p["seed"], p.get("commands", 2000), case.width, per)
    if case.kind == "carry":
        return carry_stream(p["seed"], case.width, p.get("lines", 8))
    if case.kind == "chipcross":
        return chipcross_stream(p["seed"], case.width, p.get("lines", 8))
    if case.kind == "scene":
        return scene_stream(case, workdir)
    raise ValueError(f"unknown case kind {case.kind!r}")


# ---- analysis helpers (also used by the inspector) -------------------------------------


def line_starts(commands) -> list[int]:
    """Stream index of the first command of every line (lines end with their Refresh)."""
    starts, k = [], 0
    for ln in isa.split_lines(commands):
        starts.append(k)
        k += len(ln)
    return starts


def covers(c: isa.Command, col: int) -> bool:
    """Does command c act on column `col`? (docs/isa.md §5: range, periodic.)"""
    if c.op in ("EVAL", "EVAL0", "DIS", "SETI", "SETDI", "SETDDI"):
        return c.x <= col < c.x + c.dx
    if c.op in ("SETPI", "SETPDI", "SETPDDI"):
        step = c.dx if c.dx else 4096
        return col >= c.x and (col - c.x) % step == 0
    return c.op in ("ACCMODE", "REFRESH")  # every column


def touching(commands, line: int, col: int) -> list[tuple[int, isa.Command]]:
    """(stream index, command) of every command of scanline `line` acting on `col`."""
    lines = isa.split_lines(commands)
    start = line_starts(commands)[line]
    return [(start + i, c) for i, c in enumerate(lines[line]) if covers(c, col)]


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


def heatmap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| as RGB: black = equal, dark red .. yellow = log2 of the difference."""
    if a.shape != b.shape:
        h, w = max(a.shape[0], b.shape[0]), max(a.shape[1], b.shape[1])
        out = np.zeros((h, w, 3), np.uint8)
        out[..., 2] = 160  # shape mismatch: blue everywhere
        return out
    d = np.abs(a.astype(np.int32) - b.astype(np.int32))
    t = np.where(d > 0, 0.25 + 0.75 * np.log2(d + 1) / 12.0, 0.0).clip(0, 1)
    rgb = np.zeros(d.shape + (3,), np.uint8)
    rgb[..., 0] = np.where(d > 0, 96 + 159 * np.minimum(1, t * 2), 0)
    rgb[..., 1] = np.where(d > 0, 255 * np.maximum(0, t * 2 - 1), 0)
    return rgb


# ---- running one case ------------------------------------------------------------------


# One Verilator thread per case: the runner already runs -j cases at once, and a
# multi-threaded model spin-waits badly when the cores are shared (measured: a 72-chip
# 20k-command case ran > 10 min with 2 threads on a loaded 2-core machine).
THREADS = 1


def _exe(chips: int, bug: bool) -> Path:
    return harness.build(chips, bug, threads=THREADS)


def _bug_model_cost(commands) -> int:
    return sum(min(c.dx, 4096) for c in commands if c.op == "EVAL")


def run_case(case: Case, exe: str, workdir: str) -> dict:
    """Worker: RTL frame vs reference. Returns a plain dict (crosses process pools); any
    exception becomes an ERROR result with its message."""
    t0 = time.monotonic()
    try:
        return _run_case(case, exe, workdir)
    except Exception as e:  # noqa: BLE001 - reported per case, the run goes on
        import traceback
        return {"name": case.name, "status": "error", "n_diff": 0, "first": None,
                "rtl": None, "ref": None, "harness": "", "n_commands": 0, "n_lines": 0,
                "message": f"{type(e).__name__}: {e}".splitlines()[0][:300],
                "reasons": [traceback.format_exc(limit=3)[-1500:]],
                "seconds": time.monotonic() - t0}


def _run_case(case: Case, exe: str, workdir: str) -> dict:
    t0 = time.monotonic()
    wd = Path(workdir)
    wd.mkdir(parents=True, exist_ok=True)
    res = {"name": case.name, "status": "error", "message": "", "n_diff": 0, "first": None,
           "rtl": None, "ref": None, "harness": "", "seconds": 0.0, "n_commands": 0,
           "n_lines": 0, "reasons": []}
    try:
        cmds = commands_for(case, wd)
    except Unavailable as e:
        res.update(status="unavailable", message=str(e), seconds=time.monotonic() - t0)
        return res
    res["n_commands"] = len(cmds)
    res["n_lines"] = sum(c.op == "REFRESH" for c in cmds)
    (wd / "stream.cmd").write_text(
        f"# {case.name}: {case.source}, {case.chips} chip(s) = {case.width} columns\n"
        + "\n".join(asm.format_command(c) for c in cmds) + "\n")
    src, dst = wd / "stream.de48", wd / "rtl.depx"
    src.write_bytes(binfmt.encode_de48(isa.serialise(cmds)))
    run = subprocess.run([exe, str(src), str(dst)], capture_output=True, text=True)
    res["harness"] = run.stdout.strip()
    if run.returncode:
        res.update(message=f"harness failed ({run.returncode}): {run.stderr.strip()}",
                   seconds=time.monotonic() - t0)
        return res
    rtl = harness.read_depx(dst)
    write_frame_text(wd / "rtl.txt", rtl)
    if case.reference:
        ref = read_frame_text(Path(case.reference))
        gold = functional.render(cmds, case.width)
        res["reasons"].append("reference: stored frame " + Path(case.reference).name +
                              (" (the golden model agrees with it)" if
                               gold.shape == ref.shape and (gold == ref).all() else
                               " (the golden model DISAGREES with it)"))
    else:
        ref = functional.render(cmds, case.width)
    res["rtl"], res["ref"] = rtl, ref
    if rtl.shape != ref.shape:
        res.update(status="fail", n_diff=-1,
                   message=f"frame {rtl.shape[0]}x{rtl.shape[1]} vs reference "
                           f"{ref.shape[0]}x{ref.shape[1]}")
    else:
        bad = np.argwhere(rtl != ref)
        if len(bad):
            y, x = (int(v) for v in bad[0])  # raster order: first line, then first column
            res.update(status="fail", n_diff=len(bad), first=(y, x),
                       message=f"{len(bad)} pixel(s) differ; first at line {y} column {x}: "
                               f"RTL {int(rtl[y, x])} reference {int(ref[y, x])}")
            res["touching"] = [(k, asm.format_command(c)) for k, c in touching(cmds, y, x)]
            lines_bad = sorted(set(bad[:, 0].tolist()))
            res["reasons"].append(f"{len(lines_bad)} of {rtl.shape[0]} lines differ")
            if case.bug:
                if _bug_model_cost(cmds) <= BUG_MODEL_BUDGET:
                    bm = functional.render(cmds, case.width, carry_bug=True)
                    same = bm.shape == rtl.shape and bool((bm == rtl).all())
                    res["reasons"].append(
                        "the golden model WITH the §7.7 carry fault reproduces the RTL frame "
                        "bit for bit: the difference is the fault" if same else
                        "the carry-fault golden model does NOT reproduce the RTL frame")
                    res["bug_model_matches"] = same
                d = rtl.astype(np.int64) - ref.astype(np.int64)
                vals = sorted(set(np.abs(d[d != 0]).tolist()))
                res["reasons"].append("pixel errors |RTL - golden| take the values "
                                      + ", ".join(str(v) for v in vals[:8])
                                      + (" ..." if len(vals) > 8 else ""))
        else:
            res.update(status="pass", message="bit-exact")
    res["seconds"] = time.monotonic() - t0
    return res


# ---- failure analysis: trace compare and a windowed FST (the trace build) ----------------


def _prefix(commands, line: int) -> list[isa.Command]:
    """The stream up to and including the Refresh of `line` (cycle numbers unchanged)."""
    return [c for ln in isa.split_lines(commands)[:line + 1] for c in ln]


def trace_compare(case: Case, commands, line: int, col: int) -> str:
    """Where the RTL and the structural model part on `line`, PEs col-1..col+1
    (`diffengine trace --compare --model-bug 0`: the model is always the correct one)."""
    from . import trace

    slots = isa.serialise(_prefix(commands, line))
    t = trace.Timing.of(slots, case.chips)
    lo, hi = t.line_window(line)
    pes = list(range(max(0, col - 1), min(case.width, col + 2)))
    r = trace.rtl_trace(slots, case.chips, case.bug, pes, lo, hi)
    m = trace.model_trace(slots, case.chips, False, pes, lo, hi)
    d = trace.first_difference(r.rows, m.rows)
    head = (f"diffengine trace stream.cmd --chips {case.chips} --bug {int(case.bug)} "
            f"--model-bug 0 --compare --line {line} --pes {pes[0]}-{pes[-1]}\n"
            f"RTL (bug {int(case.bug)}) vs structural model (bug 0), cycles {lo}..{hi}:\n")
    if d is None:
        return head + ("identical: the RTL does what the structural model does on this "
                       "line, so the difference lies in the reference")
    text = head + trace.describe(d)
    at = [row for row in r.rows if row.split(",")[:2] == [str(d["cycle"]), str(d["pe"])]]
    mt = [row for row in m.rows if row.split(",")[:2] == [str(d["cycle"]), str(d["pe"])]]
    if at and mt:
        text += "\n  RTL:   " + trace.text_row(at[0]) + "\n  model: " + trace.text_row(mt[0])
    return text


def write_waves(case: Case, commands, workdir: Path, line: int, col: int) -> list[str]:
    """A windowed FST of the bad line and its GTKWave save file (the trace build's
    `--fst FILE --line L --col Q`), next to the report."""
    exe = harness.build(case.chips, case.bug, threads=THREADS, trace=True)
    stem = f"line{line}_col{col}"
    src = workdir / "prefix.de48"
    src.write_bytes(binfmt.encode_de48(isa.serialise(_prefix(commands, line))))
    res = subprocess.run([str(exe), str(src), str(workdir / "waves.depx"), "--quiet",
                          "--fst", str(workdir / f"{stem}.fst"), "--line", str(line),
                          "--col", str(col)], capture_output=True, text=True, timeout=900)
    (workdir / "waves.log").write_text(res.stdout + res.stderr)
    src.unlink()
    (workdir / "waves.depx").unlink(missing_ok=True)
    return [p.name for p in sorted(workdir.glob(f"{stem}.*")) if p.suffix in (".fst", ".gtkw")]


# ---- reports ---------------------------------------------------------------------------


def verdict(case: Case, r: dict) -> str:
    """PASS, XFAIL (failed as expected), FAIL, XPASS (should have failed), ERROR, N/A."""
    s = r["status"]
    if s == "unavailable":
        return "N/A"
    if s == "error":
        return "ERROR"
    if case.bug:
        return "XFAIL" if s == "fail" and r.get("bug_model_matches", True) else (
            "XPASS" if s == "pass" else "FAIL")
    return "PASS" if s == "pass" else "FAIL"


GOOD = {"PASS", "XFAIL", "N/A"}


def summary_table(cases: list[Case], results: dict[str, dict]) -> str:
    rows = [("case", "chips", "build", "lines", "cmds", "result", "s", "detail")]
    for c in cases:
        r = results[c.name]
        rows.append((c.name, str(c.chips), "bug" if c.bug else "ok", str(r["n_lines"]),
                     str(r["n_commands"]), verdict(c, r), f"{r['seconds']:.1f}",
                     r["message"][:70]))
    w = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    out = ["  ".join(v.ljust(w[i]) for i, v in enumerate(row)) for row in rows]
    out.insert(1, "  ".join("-" * x for x in w))
    counts: dict[str, int] = {}
    for c in cases:
        v = verdict(c, results[c.name])
        counts[v] = counts.get(v, 0) + 1
    out.append(", ".join(f"{n} {k}" for k, n in sorted(counts.items())))
    return "\n".join(out)


def junit(cases: list[Case], results: dict[str, dict], tier: str, seconds: float,
          suite_name: str | None = None) -> bytes:
    suite = ET.Element("testsuite", name=suite_name or f"sim-regress-{tier}",
                       tests=str(len(cases)),
                       time=f"{seconds:.3f}")
    nfail = nerr = nskip = 0
    for c in cases:
        r = results[c.name]
        v = verdict(c, r)
        tc = ET.SubElement(suite, "testcase", classname=f"sim.{tier}.{c.kind}", name=c.name,
                           time=f"{r['seconds']:.3f}")
        detail = "\n".join([r["message"], *r["reasons"],
                            *(f"  cmd {k}: {t}" for k, t in r.get("touching", []))])
        if v == "FAIL" or v == "XPASS":
            nfail += 1
            msg = r["message"] if v == "FAIL" else "expected to fail on the carry-bug build but passed"
            ET.SubElement(tc, "failure", message=msg, type=v).text = detail
        elif v == "ERROR":
            nerr += 1
            ET.SubElement(tc, "error", message=r["message"]).text = detail
        elif v == "N/A":
            nskip += 1
            ET.SubElement(tc, "skipped", message=r["message"])
        else:
            ET.SubElement(tc, "system-out").text = f"{v}: {detail}"
    suite.set("failures", str(nfail))
    suite.set("errors", str(nerr))
    suite.set("skipped", str(nskip))
    return ET.tostring(suite, encoding="utf-8", xml_declaration=True)


_CSS = """
body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px;text-align:left}
.PASS,.XFAIL{background:#dfd}.FAIL,.XPASS,.ERROR{background:#fcc}.N\\/A{background:#eee}
.imgs{display:flex;gap:12px;flex-wrap:wrap}.imgs figure{margin:0}
.imgs img{image-rendering:pixelated;border:1px solid #888;min-width:240px}
figcaption{font-size:12px;color:#555}pre{background:#f6f6f6;padding:6px;overflow:auto}
section{border-top:2px solid #ddd;margin-top:1.2em;padding-top:.4em}
"""


def _img(frame, caption: str, scale_hint: int) -> str:
    if frame is None:
        return ""
    if frame.ndim == 2:
        g, top = grey(frame)
        caption += f" (white = {top})"
        data = png(g)
    else:
        data = png(frame)
    h, w = frame.shape[:2]
    k = max(1, min(8, scale_hint // max(1, w)))
    ky = min(64, max(k, -(-48 // max(1, h))))  # a one-line frame still gets 48 px
    return (f'<figure><img src="{data_uri(data)}" width="{w * k}" height="{h * ky}" '
            f'alt="{html.escape(caption)}"><figcaption>{html.escape(caption)}</figcaption></figure>')


def line_svg(rtl: np.ndarray, ref: np.ndarray, y: int, x: int) -> str:
    """The bad scanline, RTL (red) over the reference (blue), first bad column marked."""
    w, gw, gh, m = rtl.shape[1], 640, 160, 30
    top = max(1, int(max(rtl[y].max(), ref[y].max())))
    X = lambda c: m + (c + 0.5) * (gw - m - 6) / w  # noqa: E731
    Y = lambda v: gh - 16 - int(v) * (gh - 30) / top  # noqa: E731

    def poly(row, colour, width):
        pts = " ".join(f"{X(c - 0.5):.1f},{Y(v):.1f} {X(c + 0.5):.1f},{Y(v):.1f}"
                       for c, v in enumerate(row.tolist()))
        return (f'<polyline points="{pts}" fill="none" stroke="{colour}" '
                f'stroke-width="{width}"/>')

    return (f'<svg width="{gw}" height="{gh}" style="border:1px solid #ccc">'
            + poly(ref[y], "#1565c0", 3) + poly(rtl[y], "#e53935", 1.2)
            + f'<line x1="{X(x):.1f}" x2="{X(x):.1f}" y1="10" y2="{gh - 16}" stroke="#999" '
            f'stroke-dasharray="3,3"/><text x="{gw / 2}" y="11" font-size="11" '
            f'text-anchor="middle">scanline {y}: reference (blue), RTL (red), column {x} '
            f'dashed</text><text x="2" y="22" font-size="10">{top}</text>'
            f'<text x="2" y="{gh - 16}" font-size="10">0</text></svg>')


def html_report(cases: list[Case], results: dict[str, dict], tier: str, seconds: float,
                case_dirs: dict[str, Path] | None = None, out: Path | None = None,
                note: str = "") -> str:
    """The self-contained report. By default a case's files are linked as cases/<name>/
    next to the report; a merged report (shards) passes `case_dirs` (name -> the case's
    folder in its shard) and `out` (the report's folder) to link them where they are."""
    e = html.escape

    def href(name: str) -> str:
        if not case_dirs or name not in case_dirs:
            return f"cases/{name}"
        return Path(os.path.relpath(case_dirs[name], out or Path.cwd())).as_posix()

    def shown(name: str) -> str:  # the folder as a person types it, for the gtkwave hint
        if not case_dirs or name not in case_dirs:
            return f"sim/out/cases/{name}"
        d = Path(case_dirs[name]).resolve()
        return d.relative_to(REPO).as_posix() if d.is_relative_to(REPO) else str(d)

    rows = []
    for c in cases:
        r = results[c.name]
        v = verdict(c, r)
        rows.append(f'<tr class="{v}"><td><a href="#{e(c.name)}">{e(c.name)}</a></td>'
                    f"<td>{c.kind}</td><td>{c.chips}</td><td>{'carry bug' if c.bug else 'correct'}"
                    f"</td><td>{c.expect}</td><td>{v}</td><td>{r['n_lines']}</td>"
                    f"<td>{r['n_diff']}</td><td>{r['seconds']:.1f}</td></tr>")
    secs = []
    # unexpected results first, then the analysed expected failure, then the rest
    order = sorted(cases, key=lambda c: (verdict(c, results[c.name]) in GOOD,
                                         "trace" not in results[c.name]))
    for c in order:
        r = results[c.name]
        v = verdict(c, r)
        parts = [f'<section id="{e(c.name)}"><h3>{e(c.name)} <span class="{v}">{v}</span></h3>',
                 f"<p>{e(c.source)} &middot; {c.chips} chip(s) = {c.width} columns &middot; "
                 f"{'carry-bug build, expected to fail' if c.bug else 'correct build'} &middot; "
                 f"<a href=\"{e(href(c.name))}/stream.cmd\">stream.cmd</a> &middot; "
                 f"{e(r['message'])}</p>"]
        if r["reasons"]:
            parts.append("<ul>" + "".join(f"<li>{e(t)}</li>" for t in r["reasons"]) + "</ul>")
        if r["rtl"] is not None:
            imgs = [_img(r["rtl"], "RTL frame", 480), _img(r["ref"], "reference", 480),
                    _img(heatmap(r["rtl"], r["ref"]), "|RTL - reference| (log)", 480)]
            parts.append('<div class="imgs">' + "".join(imgs) + "</div>")
        if r.get("first") and r["rtl"] is not None:
            y, x = r["first"]
            parts.append(f"<h4>First differing pixel: line {y}, column {x} (PE {x}, chip "
                         f"{x // PE_PER_CHIP}): RTL {int(r['rtl'][y, x])}, reference "
                         f"{int(r['ref'][y, x])}</h4><p>Commands of line {y} acting on column "
                         f"{x} (stream index: command)</p><pre>"
                         + e("\n".join(f"{k:6d}: {t}" for k, t in r.get("touching", [])))
                         + "</pre>" + line_svg(r["rtl"], r["ref"], y, x))
            if r.get("trace"):
                parts.append("<p>Where the RTL and the structural model part "
                             "(<code>diffengine trace --compare</code>):</p><pre>"
                             + e(r["trace"]) + "</pre>")
            if r.get("waves"):
                parts.append("<p>Waves of the bad line: " + ", ".join(
                    f'<a href="{e(href(c.name))}/{e(w)}">{e(w)}</a>' for w in r["waves"])
                    + f" (open: <code>gtkwave {e(shown(c.name))}/"
                    f"{e(r['waves'][-1])}</code>)</p>")
        if r["harness"]:
            parts.append(f"<p><small>{e(r['harness'])}</small></p>")
        secs.append("".join(parts) + "</section>")
    counts = summary_table(cases, results).splitlines()[-1]
    return (f"<!doctype html><html><head><meta charset=\"utf-8\"><title>sim regression: {tier}"
            f"</title><style>{_CSS}</style></head><body><h1>RTL regression, tier {tier}</h1>"
            f"<p>{len(cases)} cases in {seconds:.1f} s: {e(counts)}."
            f"{' ' + e(note) if note else ''}"
            " Every frame comes from "
            "the Verilated array (sim/harness) and is compared bit for bit with the golden "
            "model (sw/diffengine/functional.py) or a stored reference frame. "
            "XFAIL = a carry-bug build that failed, as it must.</p><table><tr><th>case</th>"
            "<th>kind</th><th>chips</th><th>build</th><th>expect</th><th>result</th>"
            "<th>lines</th><th>pixels differing</th><th>s</th></tr>" + "".join(rows)
            + "</table>" + "".join(secs) + "</body></html>")


# ---- driver ------------------------------------------------------------------------------


def run(cases: list[Case], out: Path, jobs: int = 2, waves: bool = True, tier: str = "",
        log=print) -> tuple[dict[str, dict], float]:
    t0 = time.monotonic()
    out.mkdir(parents=True, exist_ok=True)
    cases_dir = out / "cases"
    exes: dict[tuple[int, bool], str] = {}
    for key in sorted({(c.chips, c.bug) for c in cases}):
        tb = time.monotonic()
        exes[key] = str(_exe(*key))
        log(f"sim: harness {key[0]} chip(s), carry bug {int(key[1])}: "
            f"{time.monotonic() - tb:.1f} s (build or cache)")
    results: dict[str, dict] = {}
    for c in cases:
        shutil.rmtree(cases_dir / c.name, ignore_errors=True)
    with ProcessPoolExecutor(max_workers=max(1, jobs)) as pool:
        futs = {c.name: pool.submit(run_case, c, exes[(c.chips, c.bug)],
                                    str(cases_dir / c.name)) for c in cases}
        for c in cases:
            results[c.name] = r = futs[c.name].result()
            log(f"  {verdict(c, r):5s} {c.name}  {r['message'][:90]}")
    # the expected failure analysed as an example: the smallest array (cheapest trace build)
    xf = [c for c in cases if verdict(c, results[c.name]) == "XFAIL"]
    example = min(xf, key=lambda c: (c.chips, c.name)).name if xf else None
    for c in cases:
        r = results[c.name]
        if r.get("first") is None or not (verdict(c, r) != "XFAIL" or c.name == example):
            continue  # analysed: every unexpected failure, and one expected one as an example
        y, x = r["first"]
        wd = cases_dir / c.name
        cmds = asm.parse_file(wd / "stream.cmd")
        tb = time.monotonic()
        try:
            r["trace"] = trace_compare(c, cmds, y, x)
            if waves:
                r["waves"] = write_waves(c, cmds, wd, y, x)
        except Exception as e:  # noqa: BLE001 - the analysis must not hide the verdict
            r["trace"] = (r.get("trace") or "") + f"\nanalysis failed: {type(e).__name__}: {e}"
        log(f"sim: analysed {c.name} (trace compare{', FST' if waves else ''}) in "
            f"{time.monotonic() - tb:.1f} s")
    return results, time.monotonic() - t0


# ---- shards: duration-balanced, deterministic (docs/regression.md §9) --------------------

# Per-case seconds recorded by earlier runs. Checked in next to the manifest (an input of
# the scheduling, like the manifest; sim/out/ is git-ignored and wiped by make clean).
DURATIONS = MANIFEST.parent / "durations.json"
# The fallback estimate of a case with no recorded duration (seconds): a cost model fitted
# to the figures of docs/regression.md §7 at 72 chips (the cube, 240 lines: 136 s; the
# teapot channels, 480 lines: 170-280 s) and the smoke tier (1500 random commands on one
# chip: 0.1 s); over the full tier it gives 1710 s, the measured cases added up to 1705 s.
# The 72-chip scene times follow their line counts, not their command counts: per line the
# cycles grow with the columns and each cycle's cost with the chips (chips^2 per line).
LINE_COST = 1e-4     # s per line per chip^2
CMD_COST = 1e-5      # s per command per chip
CASE_COST = 0.05     # s per case (process, files, golden model set-up)
SCENE_CMDS_PER_LINE = 100   # unknown before yproc runs: the teapot's ~50k / 480 lines
RECORDING_TIERS = ("full", "nightly")   # complete runs of these tiers update DURATIONS


def parse_shard(text: str) -> tuple[int, int]:
    """'k/N' -> (k, N), 1 <= k <= N; ValueError with the reason otherwise."""
    parts = str(text).strip().split("/")
    try:
        if len(parts) != 2:
            raise ValueError
        k, n = int(parts[0]), int(parts[1])
    except ValueError:
        raise ValueError(f"SHARD {text!r}: want k/N with whole numbers, e.g. 2/4") from None
    if n < 1:
        raise ValueError(f"SHARD {text!r}: N must be at least 1")
    if not 1 <= k <= n:
        raise ValueError(f"SHARD {text!r}: k must be in 1..{n} (shards count from 1)")
    return k, n


def shard_dir(out: Path, k: int, n: int) -> Path:
    return Path(out) / f"shard-{k}-of-{n}"


def load_durations(path: Path = DURATIONS) -> dict[str, float]:
    """{case name: seconds} from the durations file; {} if it does not exist."""
    path = Path(path)
    if not path.exists():
        return {}
    doc = json.loads(path.read_text())
    secs = doc.get("seconds", {}) if isinstance(doc, dict) else None
    if not isinstance(secs, dict):
        raise ValueError(f"{path}: want {{\"seconds\": {{case: seconds, ...}}}}")
    return {str(k): float(v) for k, v in secs.items()}


def case_size(case: Case) -> tuple[float, float]:
    """(lines, commands) of a case as far as the manifest tells, without making the
    stream: generated kinds from their parameters, files from their size, scenes from
    their `screen W H` line."""
    p = case.params
    if case.kind == "random":
        n = p.get("commands", 2000)
        return n / (sum(p.get("per_line", (1, 40))) / 2), n
    if case.kind == "carry":
        return p.get("lines", 8), 6 * p.get("lines", 8)     # 2-5 spans, Refresh, Acc_mode
    if case.kind == "chipcross":
        return p.get("lines", 8), 13 * p.get("lines", 8)    # 12 commands + Refresh
    if case.kind == "file":
        try:
            n = Path(p["path"]).stat().st_size / 16
        except OSError:
            n = 100
        return max(1.0, n / 4), n
    lines = 480
    try:
        for ln in Path(p["scene"]).read_text().splitlines():
            if ln.split()[:1] == ["screen"]:
                lines = int(ln.split()[2])
                break
    except (OSError, ValueError, IndexError):
        pass
    return lines, lines * SCENE_CMDS_PER_LINE


def model_seconds(case: Case) -> float:
    """The fallback cost model (LINE_COST, CMD_COST, CASE_COST)."""
    lines, cmds = case_size(case)
    return LINE_COST * lines * case.chips ** 2 + CMD_COST * cmds * case.chips + CASE_COST


def estimates(cases: list[Case], durations: dict[str, float]) -> dict[str, float]:
    """Seconds per case: the recorded duration, else model_seconds() times the median of
    recorded / modelled seconds over the recorded cases of the selection with the same
    kind and array size, else the same array size, else 1 (not across array sizes: a
    1-chip case's seconds are mostly fixed costs and say little about 72 chips).
    A pure function of its inputs."""
    def median(v: list[float]) -> float:
        v = sorted(v)
        return v[len(v) // 2] if len(v) % 2 else (v[len(v) // 2 - 1] + v[len(v) // 2]) / 2

    by_kind: dict[tuple[str, int], list[float]] = {}
    by_chips: dict[int, list[float]] = {}
    for c in cases:
        if c.name in durations:
            ratio = durations[c.name] / model_seconds(c)
            by_kind.setdefault((c.kind, c.chips), []).append(ratio)
            by_chips.setdefault(c.chips, []).append(ratio)

    def factor(c: Case) -> float:
        if (c.kind, c.chips) in by_kind:
            return median(by_kind[(c.kind, c.chips)])
        return median(by_chips[c.chips]) if c.chips in by_chips else 1.0

    return {c.name: durations[c.name] if c.name in durations else model_seconds(c) * factor(c)
            for c in cases}


def assign_shards(cases: list[Case], n: int, durations: dict[str, float]
                  ) -> list[list[Case]]:
    """Greedy longest-processing-time first: cases by decreasing estimate (ties by name)
    each go to the shard with the least estimated time so far (ties: the lowest index).
    Every case lands in exactly one shard; each shard's total stays within the longest
    case of the ideal (total / n). Shards keep the manifest order of their cases."""
    if n < 1:
        raise ValueError("n must be at least 1")
    est = estimates(cases, durations)
    load = [0.0] * n
    where: dict[str, int] = {}
    for c in sorted(cases, key=lambda c: (-est[c.name], c.name)):
        i = min(range(n), key=lambda j: (load[j], j))
        where[c.name] = i
        load[i] += est[c.name]
    return [[c for c in cases if where[c.name] == i] for i in range(n)]


def record_durations(path: Path, cases: list[Case], results: dict[str, dict],
                     keep: set[str] | None = None) -> int:
    """Write the measured seconds of `cases` into the durations file (other entries stay,
    except names not in `keep`, the manifest's cases, when given). Cases that did not
    really run (N/A, ERROR) are not recorded. Returns how many were recorded."""
    path = Path(path)
    old = load_durations(path) if path.exists() else {}
    n = 0
    for c in cases:
        r = results[c.name]
        if verdict(c, r) in ("N/A", "ERROR"):
            continue
        old[c.name] = max(0.01, round(float(r["seconds"]), 2))
        n += 1
    if keep is not None:
        old = {k: v for k, v in old.items() if k in keep}
    doc = {"about": "Seconds per case recorded by complete `make sim` runs of the full or "
                    "nightly tier (and their `make sim-merge`); `--shard k/N` balances on "
                    "them. docs/regression.md, section 'Shards and CI matrices'.",
           "seconds": dict(sorted(old.items()))}
    path.write_text(json.dumps(doc, indent=1) + "\n")
    return n


# ---- outputs of a run (also of a merge) -------------------------------------------------


def write_outputs(out: Path, cases: list[Case], results: dict[str, dict], tier: str,
                  secs: float, meta: dict, case_dirs: dict[str, Path] | None = None,
                  suite_name: str | None = None, note: str = "") -> bool:
    """summary.txt, junit.xml, report.html, results.json and run.json (what was run: tier,
    shard, selection, the cases; what --merge reads back) in `out`. True if all good."""
    out.mkdir(parents=True, exist_ok=True)
    table = summary_table(cases, results)
    print(table)
    (out / "summary.txt").write_text(table + "\n")
    (out / "junit.xml").write_bytes(junit(cases, results, tier, secs, suite_name))
    (out / "report.html").write_text(html_report(cases, results, tier, secs, case_dirs, out,
                                                 note))
    (out / "results.json").write_text(json.dumps(
        {c.name: {k: v for k, v in results[c.name].items() if k not in ("rtl", "ref")}
         | {"verdict": verdict(c, results[c.name])} for c in cases}, indent=1, default=str))
    ok = all(verdict(c, results[c.name]) in GOOD for c in cases)
    (out / "run.json").write_text(json.dumps(
        meta | {"tier": tier, "seconds": round(secs, 3), "ok": ok,
                "cases": [dataclasses.asdict(c) for c in cases]}, indent=1, default=str))
    return ok


def save_frames(out: Path, cases: list[Case], results: dict[str, dict]) -> None:
    """cases/<name>/frames.npz (RTL frame and reference): the merge's report shows them."""
    for c in cases:
        r = results[c.name]
        if r.get("rtl") is not None and r.get("ref") is not None:
            d = out / "cases" / c.name
            d.mkdir(parents=True, exist_ok=True)
            np.savez_compressed(d / "frames.npz", rtl=r["rtl"], ref=r["ref"])


class MergeError(Exception):
    """The shards do not add up to one run: a case missing, run twice, or unknown."""


def load_run_dir(d: Path) -> tuple[dict, list[Case], dict[str, dict]]:
    """run.json, results.json and the frames of one run (shard) folder."""
    d = Path(d)
    if not (d / "run.json").exists() or not (d / "results.json").exists():
        raise MergeError(f"{d}: not a shard folder (no run.json / results.json); "
                         "run `make sim SHARD=k/N` first, or name the folders")
    meta = json.loads((d / "run.json").read_text())
    stored = json.loads((d / "results.json").read_text())
    cases = [Case(**c) for c in meta["cases"]]
    results: dict[str, dict] = {}
    for c in cases:
        if c.name not in stored:
            raise MergeError(f"{d}: case {c.name} is in run.json but not in results.json")
        r = dict(stored[c.name])
        r.pop("verdict", None)
        if r.get("first") is not None:
            r["first"] = tuple(r["first"])
        r["rtl"] = r["ref"] = None
        f = d / "cases" / c.name / "frames.npz"
        if f.exists():
            with np.load(f) as z:
                r["rtl"], r["ref"] = z["rtl"], z["ref"]
        results[c.name] = r
    return meta, cases, results


def merge_runs(dirs: list[Path]) -> tuple[dict, list[Case], dict[str, dict], dict[str, Path]]:
    """Check that the shard folders are the N shards of one selection, with every case
    exactly once, and join them: (meta, cases in selection order, results, case dirs)."""
    if not dirs:
        raise MergeError("no shard folders given")
    runs = [(Path(d), *load_run_dir(d)) for d in dirs]
    meta0 = runs[0][1]
    for d, meta, _, _ in runs[1:]:
        for key in ("tier", "selected", "pattern", "no_bug_checks"):
            if meta.get(key) != meta0.get(key):
                raise MergeError(f"{d} and {runs[0][0]} come from different runs ({key} "
                                 f"differs): merge the shards of one run only")
        if meta["shard"][1] != meta0["shard"][1]:
            raise MergeError(f"{d} and {runs[0][0]} come from different runs (shard "
                             f"{meta['shard'][0]}/{meta['shard'][1]} vs "
                             f"{meta0['shard'][0]}/{meta0['shard'][1]}): merge the shards of "
                             "one run only")
    n = meta0["shard"][1]
    selected = list(meta0["selected"])
    problems = []
    seen_k: dict[int, list[str]] = {}
    for d, meta, _, _ in runs:
        seen_k.setdefault(meta["shard"][0], []).append(str(d))
    missing_k = [k for k in range(1, n + 1) if k not in seen_k]
    where: dict[str, list[Path]] = {}
    for d, _, cases, _ in runs:
        for c in cases:
            where.setdefault(c.name, []).append(d)
    missing = [name for name in selected if name not in where]
    if missing:
        problems.append(f"{len(missing)} case(s) missing (in no shard): "
                        + ", ".join(missing[:20]) + (" ..." if len(missing) > 20 else "")
                        + (f" [shard(s) not given: {', '.join(f'{k}/{n}' for k in missing_k)}]"
                           if missing_k else ""))
    twice = {name: ds for name, ds in where.items() if len(ds) > 1}
    if twice:
        problems.append(f"{len(twice)} case(s) ran more than once: " + "; ".join(
            f"{name} in {', '.join(map(str, ds))}" for name, ds in list(twice.items())[:20]))
    extra = [name for name in where if name not in set(selected)]
    if extra:
        problems.append(f"{len(extra)} case(s) not in the run's selection: "
                        + ", ".join(extra[:20]))
    if problems:
        raise MergeError("; ".join(problems))
    cases_by: dict[str, Case] = {}
    results: dict[str, dict] = {}
    dirs_by: dict[str, Path] = {}
    for d, _, cases, res in runs:
        for c in cases:
            cases_by[c.name], results[c.name] = c, res[c.name]
            dirs_by[c.name] = d / "cases" / c.name
    secs = [float(m["seconds"]) for _, m, _, _ in runs]
    meta = {k: meta0.get(k) for k in ("manifest", "pattern", "no_bug_checks", "selected")}
    meta |= {"shard": [1, 1], "merged_from": [str(d) for d, *_ in runs],
             "shard_seconds": secs, "tier": meta0["tier"]}
    return meta, [cases_by[name] for name in selected], results, dirs_by


def _complete(meta: dict) -> bool:
    return not meta.get("pattern") and not meta.get("no_bug_checks")


def _record(path: Path, manifest: Path, cases, results, log=print) -> None:
    try:
        keep = {c.name for c in load_manifest(manifest, "nightly")}
    except (OSError, ValueError):
        keep = None
    n = record_durations(path, cases, results, keep)
    log(f"sim: recorded {n} case durations in {path}")


def merge_main(dirs: list[Path], out: Path, durations: Path | None,
               record: bool | None) -> int:
    try:
        meta, cases, results, case_dirs = merge_runs(dirs)
    except MergeError as e:
        print(f"sim-merge: ERROR: {e}", file=sys.stderr)
        return 2
    secs = max(meta["shard_seconds"], default=0.0)
    n = len(meta["merged_from"])
    note = (f"Merged from {n} shard(s) (longest {secs:.1f} s, together "
            f"{sum(meta['shard_seconds']):.1f} s).")
    ok = write_outputs(out, cases, results, meta["tier"], secs, meta, case_dirs, note=note)
    manifest = REPO / meta.get("manifest", MANIFEST)   # repository-relative, or absolute
    if not manifest.exists():
        manifest = MANIFEST
    if record or (record is None and _complete(meta) and meta["tier"] in RECORDING_TIERS):
        _record(durations or manifest.parent / "durations.json", manifest, cases, results)
    print(f"sim-merge: {meta['tier']} tier, {len(cases)} cases from {n} shard(s): "
          f"{'OK' if ok else 'FAILED'}; report {out / 'report.html'}, junit {out / 'junit.xml'}")
    return 0 if ok else 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m diffengine.regress",
                                 description="RTL regression: every case of the manifest "
                                 "through the Verilated array, bit for bit against the "
                                 "golden model")
    ap.add_argument("--tier", choices=TIERS, default="full")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("-k", dest="pattern", help="only cases whose name matches this glob/text")
    ap.add_argument("--manifest", type=Path, default=MANIFEST)
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--no-waves", action="store_true", help="no FST on failures")
    ap.add_argument("--no-bug-checks", action="store_true",
                    help="skip the expected-failure runs on the carry-bug build")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--shard", metavar="K/N",
                    help="run only the K-th of N duration-balanced shards (K = 1..N); "
                    "outputs go to OUT/shard-K-of-N/")
    ap.add_argument("--merge", nargs="+", type=Path, metavar="DIR",
                    help="join the shard folders DIR... into one report in OUT (nothing "
                    "runs); exit 2 if a case is missing or ran twice")
    ap.add_argument("--durations", type=Path, default=None,
                    help="recorded case durations (default: durations.json next to the "
                    "manifest)")
    ap.add_argument("--record-durations", action=argparse.BooleanOptionalAction,
                    default=None, help="write the measured durations into the durations "
                    "file (default: only for complete full/nightly runs and their merge)")
    a = ap.parse_args(argv)
    durations = a.durations or Path(a.manifest).parent / "durations.json"
    if a.merge:
        return merge_main(a.merge, a.out, a.durations, a.record_durations)
    shard = None
    if a.shard is not None and a.shard.strip():
        try:
            shard = parse_shard(a.shard)
        except ValueError as e:
            ap.error(f"--shard: {e}")
    cases = load_manifest(a.manifest, a.tier)
    if a.pattern:
        cases = [c for c in cases if a.pattern in c.name or fnmatch.fnmatch(c.name, a.pattern)]
    if a.no_bug_checks:
        cases = [c for c in cases if not c.bug]
    selected = [c.name for c in cases]
    out = a.out
    if shard:
        k, n = shard
        recorded = load_durations(durations)
        cases = assign_shards(cases, n, recorded)[k - 1]
        out = shard_dir(a.out, k, n)
        est = estimates(cases, recorded)
        print(f"sim: shard {k}/{n}: {len(cases)} of {len(selected)} cases, estimated "
              f"{sum(est.values()):.1f} s ({sum(c.name in recorded for c in cases)} with a "
              f"recorded duration, {durations.name}); outputs in {out}", flush=True)
    if a.list:
        for c in cases:
            print(f"{c.name:32s} {c.chips:3d} chips  expect {c.expect}  {c.source}")
        return 0
    if not cases and not shard:
        print("sim: no cases selected", file=sys.stderr)
        return 1
    mpath = Path(a.manifest).resolve()
    meta = {"manifest": mpath.relative_to(REPO).as_posix() if mpath.is_relative_to(REPO)
            else str(mpath), "pattern": a.pattern,
            "no_bug_checks": a.no_bug_checks, "selected": selected,
            "shard": list(shard) if shard else [1, 1]}
    if cases:
        results, secs = run(cases, out, a.jobs, not a.no_waves, a.tier,
                            log=lambda m: print(m, flush=True))
    else:   # more shards than cases: an empty shard is a success with empty reports
        results, secs = {}, 0.0
    save_frames(out, cases, results)
    ok = write_outputs(out, cases, results, a.tier, secs, meta,
                       suite_name=f"sim-regress-{a.tier}-shard-{shard[0]}-of-{shard[1]}"
                       if shard else None)
    if a.record_durations or (a.record_durations is None and not shard and
                              _complete(meta) and a.tier in RECORDING_TIERS):
        _record(durations, a.manifest, cases, results)
    what = f"{a.tier} tier" + (f", shard {shard[0]}/{shard[1]}" if shard else "")
    print(f"sim: {what}, {len(cases)} cases in {secs:.1f} s: "
          f"{'OK' if ok else 'FAILED'}; report {out / 'report.html'}, junit {out / 'junit.xml'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
