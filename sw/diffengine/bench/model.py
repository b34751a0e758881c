"""Benchmark the functional golden model on random but realistic 640x480 frames.

Two frames, ~100 commands per line, spans of 5-60 px at random X:
  * "eval-only": Eval1/2/3 (20/40/40 %);
  * "mixed": the same plus, per line, about 3 Set/SetP/Dis/Eval0 commands.
Both take the batched frame path of `functional.render`. For comparison, the mixed frame
also goes once through the per-command path (`functional._render_reference`, what every
line with a Set/Dis/Eval0 took before the batch covered them), and the first lines of it
through the cycle-level structural model (the baseline).
Prints commands/s and seconds/frame (best of --repeat); records them (bench.record) and,
with --write, renders the "Golden model (functional)" section of docs/performance.md.

`--fast`: the C functional model (sw/fmodel through diffengine.model.fast), against the
numpy model in the same run as its baseline, into its own record and section
("model-fast", "Functional model in C"):
the two random frames (one colour, from instruction words), the teapot and CAD scenes
(yproc scan, 640x480, three colours, from the .de48 files: decoding included), and the
changed lines of the incremental frames of `yproc anim` on sw/scenes/anim/cad_drag.anim.
Every C frame is checked equal to the numpy frame before it is timed.
"""
from __future__ import annotations

import json
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .. import REPO, isa
from ..model import fast, functional, structural
from . import record, render as doc

ONE = 1 << isa.FRAC_BITS
SECTION = "## Golden model (functional)"
SECTION_FAST = "## Functional model in C (sw/fmodel): pixels in milliseconds"
SCENES = (("teapot", "sw/scenes/teapot/teapot.scene"), ("CAD", "sw/scenes/cad/cad.scene"))
ANIM = "sw/scenes/anim/cad_drag.anim"


def random_frame(rng, width=640, height=480, per_line=100, mixed=False):
    cmds = []
    for _ in range(height):
        for _ in range(per_line):
            x = int(rng.integers(0, width))
            dx = int(rng.integers(5, 61))
            order = int(rng.choice([0, 1, 2], p=[0.2, 0.4, 0.4]))
            vals = [int(rng.integers(0, 200 * ONE)), int(rng.integers(-ONE, ONE)),
                    int(rng.integers(-ONE // 32, ONE // 32))][: order + 1]
            cmds.append(isa.Command("EVAL", x, dx, tuple(vals)))
        if mixed:
            for _ in range(3):
                x = int(rng.integers(0, width))
                kind = rng.choice(["SETDDI", "SETI", "SETPDI", "DIS", "EVAL0"])
                if kind == "DIS":
                    cmd = isa.Command("DIS", x, int(rng.integers(1, 20)))
                elif kind == "EVAL0":
                    cmd = isa.Command("EVAL0", x, int(rng.integers(1, 20)), (int(rng.integers(0, 4096)),))
                elif kind == "SETPDI":
                    cmd = isa.Command("SETPDI", x, int(rng.integers(5, 40)), (int(rng.integers(-ONE, ONE)),))
                else:
                    cmd = isa.Command(str(kind), x, 1, (int(rng.integers(-ONE, ONE)),))
                cmds.insert(len(cmds) - int(rng.integers(0, per_line)), cmd)
        cmds.append(isa.Command("REFRESH"))
    return cmds


def bench(cmds, repeat, fn=functional.render):
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        fn(cmds)
        best = min(best, time.perf_counter() - t)
    return best


def timed(fn, repeat: int) -> tuple[float, float]:
    """(best wall seconds, best CPU seconds of this process) of fn() over repeat runs: on a
    shared machine the CPU figure is the one that compares."""
    wall = cpu = float("inf")
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        fn()
        cpu = min(cpu, time.process_time() - c)
        wall = min(wall, time.perf_counter() - w)
    return wall, cpu


def _words(cmds) -> bytes:
    return b"".join(((i << isa.WORD_BITS) | d).to_bytes(6, "big") for i, d in isa.serialise(cmds))


def _fast_rows(run, frames, repeat: int) -> list[dict]:
    """The C model on the random frames (one colour, from instruction words) against
    functional.render (numpy, from commands) in the same run."""
    rows = []
    for name, cmds in frames:
        want = functional.render(cmds)
        words = _words(cmds)
        out = np.zeros_like(want)
        fast.render_words(words, 640, out)
        if not np.array_equal(out, want):
            sys.exit(f"{name} frame: the C model and the numpy model disagree")
        nw, nc = timed(lambda: functional.render(cmds), max(1, repeat // 2))
        fw, fc = timed(lambda: fast.render_words(words, 640, out), 10 * repeat)
        rows.append({"what": f"random {name}, 1 colour", "commands": len(cmds),
                     "numpy_ms": [nw * 1e3, nc * 1e3], "c_ms": [fw * 1e3, fc * 1e3]})
        run.log(f"{name}: numpy {nc * 1e3:.1f} CPU ms, C {fc * 1e3:.2f} CPU ms")
    return rows


def _scene_rows(run, tmp: Path, repeat: int) -> list[dict]:
    """Teapot and CAD, yproc scan at 640x480, all three colours from the .de48 files."""
    from ..pipeline import demo

    rows = []
    for name, scene in SCENES:
        demo.yproc_scan(REPO / scene, tmp / name)
        paths = [tmp / name / f"{c}.de48" for c in "rgb"]
        want = demo.golden(paths, 640, 480, model="numpy")
        got = fast.render_frame(paths, 640, 480)
        if not np.array_equal(got, want):
            sys.exit(f"{name}: the C model and the numpy model disagree")
        n = sum((p.stat().st_size - 8) // 6 for p in paths)
        nw, nc = timed(lambda: demo.golden(paths, 640, 480, model="numpy"), max(1, repeat // 2))
        fw, fc = timed(lambda: fast.render_frame(paths, 640, 480), 10 * repeat)
        rows.append({"what": f"{name} (yproc scan), 3 colours, from .de48 files",
                     "instructions": n, "numpy_ms": [nw * 1e3, nc * 1e3],
                     "c_ms": [fw * 1e3, fc * 1e3]})
        run.log(f"{name}: numpy {nc * 1e3:.0f} CPU ms, C {fc * 1e3:.1f} CPU ms for 3 colours")
    return rows


def _anim_rows(run, tmp: Path) -> dict:
    """The incremental frames of cad_drag.anim: only the changed lines, C and numpy."""
    from ..host import yproc
    from ..pipeline import anim

    r = subprocess.run([str(yproc.build()), "anim", str(REPO / ANIM), "-o", str(tmp / "anim")],
                       capture_output=True, text=True)
    if r.returncode:
        sys.exit(f"yproc anim {ANIM} failed:\n{r.stderr}")
    seq = anim.frames(tmp / "anim")
    st = json.loads((tmp / "anim" / "anim_stats.json").read_text())
    W, H = st["width"], st["height"]
    img_c = fast.render_frame([anim.to_de48(ch) for ch in seq[0]], W, H)
    img_n = img_c.copy()
    per = []
    for f in range(1, len(seq)):
        ch = [{y: seq[f][c][y] for y in range(H) if seq[f][c][y] != seq[f - 1][c][y]}
              for c in range(3)]
        w, c = time.perf_counter(), time.process_time()
        fast.render_lines(img_c, ch)
        fc, fw = time.process_time() - c, time.perf_counter() - w
        w, c = time.perf_counter(), time.process_time()
        for k in range(3):
            if ch[k]:
                ys = sorted(ch[k])
                img_n[ys, :, k] = anim.render_lines([ch[k][y] for y in ys], W)
        nc, nw = time.process_time() - c, time.perf_counter() - w
        if not np.array_equal(img_c, img_n):
            sys.exit(f"{ANIM} frame {f}: the C model and the numpy model disagree")
        per.append((sum(len(x) for x in ch), fw * 1e3, fc * 1e3, nw * 1e3, nc * 1e3))
    a = np.array(per)
    run.log(f"anim: {len(per)} incremental frames, {a[:, 0].mean():.0f} changed lines (of 3 x "
            f"{H}) per frame, C {a[:, 2].mean():.2f} CPU ms, numpy {a[:, 4].mean():.0f} CPU ms")
    return {"frames": len(per), "lines": 3 * H, "changed_mean": a[:, 0].mean(),
            "changed_max": a[:, 0].max(), "c_ms_mean": [a[:, 1].mean(), a[:, 2].mean()],
            "c_ms_max": [a[:, 1].max(), a[:, 2].max()],
            "numpy_ms_mean": [a[:, 3].mean(), a[:, 4].mean()],
            "numpy_ms_max": [a[:, 3].max(), a[:, 4].max()]}


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    record.add_write(ap)
    ap.add_argument("--fast", action="store_true",
                    help="the C functional model (sw/fmodel) against the numpy one, on the "
                         "random frames, the teapot and CAD scenes and the animation's "
                         "changed lines: record \"model-fast\"")
    ap.set_defaults(func=command)


def command_fast(args) -> int:
    """`diffengine bench model --fast`: record "model-fast" (the C model and its baseline)."""
    run = record.Run("model-fast")
    run.log("the C functional model against the numpy one (sw/fmodel)")
    frames = [(name, random_frame(np.random.default_rng(args.seed), mixed=mixed))
              for name, mixed in (("eval-only", False), ("mixed", True))]
    with tempfile.TemporaryDirectory() as tmp:
        data = {"frames": _fast_rows(run, frames, args.repeat),
                "scenes": _scene_rows(run, Path(tmp), args.repeat),
                "anim": _anim_rows(run, Path(tmp)), "repeat": args.repeat, "seed": args.seed,
                "cc": subprocess.run(["cc", "--version"], capture_output=True,
                                     text=True).stdout.split("\n")[0]}
    rec = run.save(data, args.write)
    print(render_fast(rec))
    return doc.write(["model-fast"]) if args.write else 0


def command(args) -> int:
    if args.fast:
        return command_fast(args)
    run = record.Run("model")
    rows = []
    for name, mixed in (("eval-only", False), ("mixed", True)):
        cmds = random_frame(np.random.default_rng(args.seed), mixed=mixed)
        sec = bench(cmds, args.repeat)
        rows.append((name, len(cmds), sec, len(cmds) / sec))
        print(f"{name:10s} {len(cmds):7d} commands  {sec:7.3f} s/frame  {len(cmds) / sec:12,.0f} commands/s")
    sec = bench(cmds, 1, functional._render_reference)  # slow: once is enough
    if not np.array_equal(functional.render(cmds), functional._render_reference(cmds)):
        sys.exit("mixed frame: the batched path and the per-command path disagree")
    rows.append(("mixed, per-command path (`_render_reference`, once)", len(cmds), sec,
                 len(cmds) / sec))
    print(f"per-cmd    {len(cmds):7d} commands  {sec:7.3f} s/frame  {len(cmds) / sec:12,.0f} commands/s")
    # Baseline in the same run (these machines are noisy): the cycle-level structural
    # model on the first lines of the mixed frame, extrapolated to a whole frame.
    lines = isa.split_lines(random_frame(np.random.default_rng(args.seed), mixed=True))[:4]
    sub = [c for line in lines for c in line]
    t = time.perf_counter()
    structural.render(sub, 640)
    sec_line = (time.perf_counter() - t) / len(lines)
    n_frame = rows[-1][1]
    rows.append(("baseline: structural, cycle level (4 lines, x120)", n_frame, sec_line * 480,
                 n_frame / (sec_line * 480)))
    print(f"baseline   structural model {sec_line * 480:7.1f} s/frame (extrapolated from 4 lines)")
    run.save({"rows": rows, "repeat": args.repeat, "seed": args.seed,
              "python": f"{platform.python_implementation()} {platform.python_version()}",
              "numpy": np.__version__, "machine": platform.machine()}, args.write)
    return doc.write(["model"]) if args.write else 0


def render(rec: dict) -> str:
    """The "Golden model (functional)" section of docs/performance.md."""
    d = rec["data"]
    rows, repeat = d["rows"], d["repeat"]
    base = rows[-1][2]
    table = "\n".join(f"| {n} | {c} | {s:.3f} | {r:,.0f} | {base / s:,.0f}x |" for n, c, s, r in rows)
    body = f"""{SECTION}

`functional.render()` on a random 640x480 frame, ~100 commands per line (Eval1/2/3 spans
of 5-60 px; "mixed" adds ~3 Set/SetP/Dis/Eval0 per line). Both frames take the batched
frame path (`functional._Plan`: a scalar walk of each line turns its Evals into polynomial
pieces, cut at protect flags and split around disabled columns, and difference arrays sum
them for the whole frame); only the carry-bug option goes command by command.
For comparison, the mixed frame also goes through the per-command path (`run_line` on
every line, `functional._render_reference`), which lines with a Set/Dis/Eval0 took before
the batch covered them; the batch is tested against it (`sw/tests/test_functional_batch.py`)
and checked equal to it here. The baseline, measured in the same run,
is the cycle-level structural model on the mixed frame. Best of {repeat} (per-command path:
once), one core, {d['python']}, numpy {d['numpy']}, {d['machine']}.

| frame | commands | s/frame | commands/s | speed vs baseline |
|---|---|---|---|---|
{table}

Reproduce: `make bench` (`diffengine bench model --write`)
"""
    return body


def render_fast(rec: dict) -> str:
    """The "Functional model in C" section of docs/performance.md."""
    f = d = rec["data"]

    def ms(x):
        return f"{x:.1f}" if x >= 10 else f"{x:.2f}"

    def row(r, n):
        return (f"| {r['what']} | {r[n]:,} | {ms(r['numpy_ms'][1])} ({ms(r['numpy_ms'][0])}) | "
                f"{ms(r['c_ms'][1])} ({ms(r['c_ms'][0])}) | {r['numpy_ms'][1] / r['c_ms'][1]:,.0f}x |")
    table = "\n".join([row(r, "commands") for r in f["frames"]]
                      + [row(r, "instructions") for r in f["scenes"]])
    a = f["anim"]
    worst = max(r["c_ms"][1] for r in f["scenes"])
    # Above one job per core the wall clock also counts other jobs' time slices.
    busy = max(float(rec["load_before"]), float(rec["load_after"])) > 2.5
    load_note = (", so the wall figures there are inflated and the CPU figures are the ones "
                 "that compare." if busy else ", about one job per core: wall and CPU agree.")
    return f"""{SECTION_FAST}

Issue 19 item 4: a 640x480 colour frame in at most 50 ms, and only the changed lines of an
incremental frame. `diffengine.model.fast` renders .de48 instruction words with the C
library sw/fmodel (`fmodel.h`, loaded with ctypes, built on first use): every PE of a line
a command at a time, column by column, a port of the numpy model's per-command path, which
stays the readable reference; sw/tests/test_fmodel.py compares the two command by command
(every register and flag of every PE after each command, with and without the carry bug)
and on whole frames. The baseline, measured in the same run, is the numpy model
(`functional.render`, the batched `_Plan` path; for the scenes `pipeline.demo.golden(...,
model="numpy")`, which also decodes the .de48 files into commands). Every C frame is
checked equal to the numpy frame before it is timed. Figures: CPU ms of this process (one
thread), best of {10 * d['repeat']} (numpy: best of {max(1, d['repeat'] // 2)}); wall ms in
brackets. The machine is shared: 1-minute load {rec['load_before']} before the run and
{rec['load_after']} after it (2 cores){load_note} {f['cc']}, -O2.

| frame | commands / instructions | numpy CPU ms (wall) | C CPU ms (wall) | C vs numpy |
|---|---|---|---|---|
{table}

The worst full colour frame takes **{ms(worst)} CPU ms** in C (target: at most 50 ms).

Incremental frames: `yproc anim {ANIM}`, its {a['frames']} frames after the first, each
frame's changed lines only (`fast.render_lines`, all three colours; numpy:
`pipeline.anim.render_lines` on the same lines); the image is checked equal after every
frame. Changed lines per frame: {a['changed_mean']:.0f} on average, at most
{a['changed_max']:.0f}, of {a['lines']}.

| changed lines of a frame | numpy CPU ms (wall) | C CPU ms (wall) |
|---|---|---|
| mean over the frames | {ms(a['numpy_ms_mean'][1])} ({ms(a['numpy_ms_mean'][0])}) | {ms(a['c_ms_mean'][1])} ({ms(a['c_ms_mean'][0])}) |
| worst frame | {ms(a['numpy_ms_max'][1])} ({ms(a['numpy_ms_max'][0])}) | {ms(a['c_ms_max'][1])} ({ms(a['c_ms_max'][0])}) |

Reproduce: `make bench` (`diffengine bench model --fast --write`)
"""
