"""The fast array (sim/fast, docs/simulation.md) against the whole de_array Verilated flat:
random inputs into both, every output compared every cycle (sim/fast/equiv.cpp), per
array size and carry bug. The stream mixes reset in mid-stream, the bypass configuration
chain, the observation chain, collisions and raw identifiers.

Each run prints its seed; SEED=<n> replays it, EQUIV_CYCLES=<n> sets the length.
"""
from __future__ import annotations

import fcntl
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CYCLES = int(os.environ.get("EQUIV_CYCLES", 200_000))
# 1 chip (head + tail only), 2 chips with the carry bug (one unit), 8 chips (units feeding
# units); each is a flat Verilator build of its own, so make test keeps to three.
CONFIGS = [(1, 0), (2, 1), (8, 0)]


def build(chips: int, bug: int) -> Path:
    (REPO / "sim" / "build").mkdir(parents=True, exist_ok=True)
    with open(REPO / "sim" / "build" / f".equiv_c{chips}_b{bug}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        subprocess.run(["make", "-s", "-C", str(REPO / "sim"), "equiv", f"CHIPS={chips}",
                        f"CARRY_BUG={bug}"], check=True)
    return REPO / "sim" / "build" / f"equiv_c{chips}_b{bug}" / "Vflat"


@pytest.mark.parametrize("chips,bug", CONFIGS, ids=[f"chips{c}_bug{b}" for c, b in CONFIGS])
def test_fast_array_equals_flat_every_cycle(chips, bug):
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    print(f"SEED={seed} chips={chips} carry_bug={bug} (replay: SEED={seed})", file=sys.stderr)
    exe = build(chips, bug)
    res = subprocess.run([str(exe), "--cycles", str(CYCLES), "--seed", str(seed)],
                         capture_output=True, text=True)
    print(res.stdout, file=sys.stderr)
    assert res.returncode == 0, f"seed {seed}: fast array differs from flat:\n{res.stdout}"
    assert f"EQUAL for {CYCLES} cycles" in res.stdout
    # The stream really exercised the chains and the pixel bus.
    stats = res.stdout.rsplit("(", 1)[1]
    pixels, cfg, obs = (int(stats.split(" pixels")[0]),
                        int(stats.split(", ")[1].split()[0]), int(stats.split(", ")[2].split()[0]))
    assert pixels > 0 and cfg > 0 and obs > 0, res.stdout
