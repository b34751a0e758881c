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
"""
from __future__ import annotations

import platform
import sys
import time

import numpy as np

from .. import isa
from ..model import functional, structural
from . import record, render as doc

ONE = 1 << isa.FRAC_BITS
SECTION = "## Golden model (functional)"


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


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--write", action="store_true",
                    help="keep the record in docs/bench and render docs/performance.md")
    ap.set_defaults(func=command)


def command(args) -> int:
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
