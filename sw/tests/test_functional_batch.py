"""The frame batch of `functional.render` (`_Plan`) against the per-command path.

`functional._render_reference` runs every line through `run_line` (one numpy pass per
command, the model's reference for *what* is computed). The batch must give the same
pixels on streams rich in what it treats specially: protect flags (Set, periodic SetP
with dX 0/1/n), Dis, Eval0 locks, Acc_mode, spans past the end, X beyond the array,
dX 0/1, values that wrap modulo 2^36, and Eval4+ (whose pieces the batch expands
column by column, with only SetdI/SetddI honoured).

Seeded; the seed is printed and SEED=<n> replays it
(`SEED=123 pytest -q sw/tests/test_functional_batch.py`).
"""
from __future__ import annotations

import os
import random

import numpy as np
import pytest

from diffengine.model import functional as F
from diffengine import isa
from diffengine.regress import randgen

C = isa.Command
EXTREMES = [-(1 << 35), (1 << 35) - 1, -1, 1, (1 << 24) - 1, -(1 << 24), 0x7FFFFF]


def _seed(salt: int) -> int:
    base = int(os.environ["SEED"]) if "SEED" in os.environ else random.randrange(1 << 32)
    return base ^ salt


def _value(rng: random.Random, order: int) -> int:
    return rng.choice(EXTREMES) if rng.random() < 0.1 else randgen._value(rng, order)


def _command(rng: random.Random, width: int, max_order: int) -> isa.Command:
    """randgen's mix, with Evals capped at `max_order` and more of the special commands."""
    r = rng.random()
    x, dx = randgen._x(rng, width), randgen._dx(rng, width)
    if r < 0.40:
        p = rng.randrange(min(max_order, 2) + 1)
        if max_order > 2 and rng.random() < 0.1:
            p = rng.randrange(3, max_order + 1)
        return C("EVAL", x, dx, tuple(_value(rng, k) for k in range(p + 1)))
    if r < 0.55:
        return C(rng.choice(["SETI", "SETDI", "SETDDI"]), x, rng.choice([1, 1, 2, dx]),
                 (_value(rng, rng.randrange(3)),))
    if r < 0.65:
        return C(rng.choice(["SETPI", "SETPDI", "SETPDDI"]), x,
                 rng.choice([0, 1, rng.randrange(2, 12), dx]), (_value(rng, rng.randrange(3)),))
    if r < 0.75:
        return C("DIS", x, rng.choice([1, 2, dx]))
    if r < 0.85:
        return C("EVAL0", x, rng.choice([1, 3, dx]), (rng.randrange(4096),))
    if r < 0.93:
        return C("ACCMODE", values=(rng.randrange(2),))
    return C("NOP")


def _stream(rng: random.Random, width: int, n_lines: int, max_order: int) -> list[isa.Command]:
    out: list[isa.Command] = []
    for _ in range(n_lines):
        out += [_command(rng, width, max_order) for _ in range(rng.randint(0, 40))]
        out.append(C("REFRESH"))
    return out


def _check(cmds, width, where):
    got = F.render(cmds, width)
    want = F._render_reference(cmds, width)
    if not np.array_equal(got, want):
        row = int(np.flatnonzero((got != want).any(axis=1))[0])
        line = isa.split_lines(cmds)[row]
        pytest.fail(f"{where} width {width}: line {row} differs\n"
                    f"commands {line}\nbatch     {got[row].tolist()}\n"
                    f"reference {want[row].tolist()}")


@pytest.mark.parametrize("max_order", [2, 7])
def test_batch_matches_per_command_path(max_order):
    seed = _seed(0xBA7C + max_order)
    print(f"test_batch_matches_per_command_path max_order={max_order} seed {seed}")
    rng = random.Random(seed)
    for case in range(150):
        width = rng.choice([1, 2, 3, 9, 17, 40, 64, 100])
        _check(_stream(rng, width, rng.randint(1, 6), max_order), width,
               f"seed {seed} case {case}")


def test_batch_matches_on_wide_frames():
    seed = _seed(0xF7A)
    print(f"test_batch_matches_on_wide_frames seed {seed}")
    rng = random.Random(seed)
    for case in range(3):
        _check(_stream(rng, 640, 40, 2), 640, f"seed {seed} case {case}")


def test_batch_matches_on_randgen_streams():
    seed = _seed(0x4A6)
    print(f"test_batch_matches_on_randgen_streams seed {seed}")
    rng = random.Random(seed)
    for case in range(40):
        width = rng.choice([5, 9, 33, 128])
        _check(randgen.stream(rng.randrange(1 << 30), 300, width), width,
               f"seed {seed} case {case}")


def test_bench_mixed_frame_rows():
    """A few lines of the benchmark's mixed frame (diffengine bench model), as they are."""
    seed = _seed(0xB3)
    print(f"test_bench_mixed_frame_rows seed {seed}")
    rng = np.random.default_rng(seed)
    one = 1 << isa.FRAC_BITS
    cmds = []
    for _ in range(8):
        line = [C("EVAL", int(rng.integers(0, 640)), int(rng.integers(5, 61)),
                  (int(rng.integers(0, 200 * one)), int(rng.integers(-one, one)),
                   int(rng.integers(-one // 32, one // 32)))[: int(rng.integers(0, 3)) + 1])
                for _ in range(100)]
        for _ in range(6):
            x = int(rng.integers(0, 640))
            kind = ["SETDDI", "SETI", "SETPDI", "DIS", "EVAL0", "SETDI"][int(rng.integers(6))]
            if kind in ("DIS", "EVAL0"):
                cmd = C(kind, x, int(rng.integers(1, 20)),
                        (int(rng.integers(0, 4096)),) if kind == "EVAL0" else ())
            else:
                cmd = C(kind, x, int(rng.integers(1, 40)), (int(rng.integers(-one, one)),))
            line.insert(int(rng.integers(0, len(line) + 1)), cmd)
        cmds += line + [C("REFRESH")]
    _check(cmds, 640, f"seed {seed}")


def test_acc_mode_and_eval0_examples():
    one = 1 << isa.FRAC_BITS
    cmds = [C("ACCMODE", values=(1,)), C("EVAL", 0, 8, (2 * one, -one)),  # 2 1 0 -1 ..
            C("DIS", 1, 1), C("EVAL", 0, 8, (one,)),
            C("EVAL0", 5, 2, (7,)), C("EVAL0", 4, 3, (9,)), C("EVAL", 4, 4, (one,)),
            C("ACCMODE", values=(0,)), C("EVAL", 6, 2, (-one,)), C("REFRESH")]
    assert F.render(cmds, 8).tolist() == [[3, 1, 1, 1, 9, 7, 7, 1]]
    _check(cmds, 8, "fixed example")
