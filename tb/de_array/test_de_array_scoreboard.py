"""Constrained-random scoreboard: the Verilated array against the functional golden
model, per array configuration (1, 2, 8, 72 chips x carry bug off/on).

The stream is played by the plain C++ harness (sim/harness) because 10^5 commands
through cocotb's per-cycle Python loop would take minutes per configuration; the
cocotb bench (test_de_array.py) covers the cycle-level checks on small arrays.
Each run prints its seed and writes it to seed_chips<C>_bug<B>.txt beside this file
before anything else runs (a run killed half-way still leaves it); SEED=<n> replays it,
N_COMMANDS=<n> sets the volume.

The stream is made, written and modelled in chunks of whole lines (randgen.chunks): lines
are independent (a Refresh clears every PE), so the golden model of a chunk is that
chunk's rows of the whole frame, and make test-long's 10^7 commands never exist as
Python objects at once (they ran a 24 GB machine out of memory that way).
"""
from __future__ import annotations

import os
import random
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from diffengine.formats import binfmt
from diffengine.regress import coverage, randgen
from diffengine.model import functional
from diffengine.rtl import harness
from diffengine import isa

N_COMMANDS = int(os.environ.get("N_COMMANDS", 100_000))
CHUNK = 200_000
HERE = Path(__file__).parent

CONFIGS = [(1, 0), (1, 1), (2, 0), (2, 1), (8, 0), (8, 1), (72, 0), (72, 1)]


@pytest.mark.parametrize("chips,bug", CONFIGS, ids=[f"chips{c}_bug{b}" for c, b in CONFIGS])
def test_random_stream_matches_golden_model(chips, bug):
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    name = f"chips{chips}_bug{bug}"
    msg = f"SEED={seed} chips={chips} carry_bug={bug} commands={N_COMMANDS} (replay: SEED={seed})"
    (HERE / f"seed_{name}.txt").write_text(msg + "\n")
    print(msg, file=sys.stderr, flush=True)
    width = 9 * chips
    # Lines long enough that Refresh padding does not dominate on wide arrays.
    per_line = (1, 40) if width < 100 else (60, 200)
    cov = coverage.Coverage(width)
    want = []
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "stream.de48"
        with src.open("wb") as f:
            f.write(binfmt.encode_de48([]))  # the header
            for cmds in randgen.chunks(seed, N_COMMANDS, width, per_line, CHUNK):
                cov.add_stream(cmds)
                f.write(binfmt.encode_de48(isa.serialise(cmds))[binfmt.HEADER_LEN:])
                want.append(functional.render(cmds, width, carry_bug=bool(bug)))
        (HERE / f"coverage_{name}.txt").write_text(cov.report() + "\n")
        print(cov.report(), file=sys.stderr)
        got, report = harness.run_file(src, chips, bool(bug))
    print(report, file=sys.stderr)
    rows = sum(w.shape[0] for w in want)
    assert got.shape == (rows, width), f"seed {seed}: frame {got.shape} vs model {(rows, width)}"
    r0 = 0
    for w in want:
        bad = np.argwhere(got[r0:r0 + w.shape[0]] != w)
        assert bad.size == 0, (
            f"seed {seed}: {len(bad)} pixels differ in rows {r0}..{r0 + w.shape[0] - 1}; "
            f"first at line {r0 + bad[0][0]} column {bad[0][1]}: "
            f"RTL {got[r0 + bad[0][0], bad[0][1]]} model {w[tuple(bad[0])]}")
        r0 += w.shape[0]
    assert not cov.missing(), f"coverage bins not hit: {cov.missing()}"
