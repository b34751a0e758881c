"""Running cases: one case through the Verilated array against the golden model, the
failure analysis of a bad line (trace compare, windowed FST), and the parallel driver."""
from __future__ import annotations

import shutil
import subprocess
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from .. import isa
from ..formats import asm, binfmt
from ..formats.frame import read_frame_text, write_frame_text
from ..model import functional
from ..model.lines import touching
from ..rtl import harness
from .cases import Case, Unavailable, commands_for
from .report import verdict


# The carry-bug golden model is a per-column Python path: only used to explain an
# expected failure when the frame is small enough (sum of Eval span lengths).
BUG_MODEL_BUDGET = 400_000


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
    from ..rtl import trace

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
