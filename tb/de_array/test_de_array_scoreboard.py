"""Constrained-random scoreboard: the Verilated array against the functional golden
model, per array configuration (1, 2, 8, 72 chips x carry bug off/on).

The stream is played by the plain C++ harness (sim/harness) because 10^5 commands
through cocotb's per-cycle Python loop would take minutes per configuration; the
cocotb bench (test_de_array.py) covers the cycle-level checks on small arrays.
Each run prints its seed; SEED=<n> replays it, N_COMMANDS=<n> sets the volume.
"""
from __future__ import annotations

import os
import random
import sys
from pathlib import Path

import numpy as np
import pytest

from diffengine import coverage, functional, harness, randgen

N_COMMANDS = int(os.environ.get("N_COMMANDS", 100_000))

CONFIGS = [(1, 0), (1, 1), (2, 0), (2, 1), (8, 0), (8, 1), (72, 0), (72, 1)]


@pytest.mark.parametrize("chips,bug", CONFIGS, ids=[f"chips{c}_bug{b}" for c, b in CONFIGS])
def test_random_stream_matches_golden_model(chips, bug):
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    print(f"SEED={seed} chips={chips} carry_bug={bug} (replay: SEED={seed})", file=sys.stderr)
    width = 9 * chips
    # Lines long enough that Refresh padding does not dominate on wide arrays.
    per_line = (1, 40) if width < 100 else (60, 200)
    cmds = randgen.stream(seed, N_COMMANDS, width, per_line)
    cov = coverage.Coverage(width).add_stream(cmds)
    (Path(__file__).parent / f"coverage_chips{chips}_bug{bug}.txt").write_text(cov.report() + "\n")
    print(cov.report(), file=sys.stderr)
    got, report = harness.run(cmds, chips, bool(bug))
    want = functional.render(cmds, width, carry_bug=bool(bug))
    print(report, file=sys.stderr)
    assert got.shape == want.shape, f"seed {seed}: frame {got.shape} vs model {want.shape}"
    bad = np.argwhere(got != want)
    assert bad.size == 0, (
        f"seed {seed}: {len(bad)} pixels differ; first at line {bad[0][0]} column "
        f"{bad[0][1]}: RTL {got[tuple(bad[0])]} model {want[tuple(bad[0])]}")
    assert not cov.missing(), f"coverage bins not hit: {cov.missing()}"
