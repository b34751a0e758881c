"""scripts/sdram_budget.py, the bandwidth budget that sizes the prefetch FIFOs
(docs/sdram.md §3), on small inputs: its word count per line from a .de48 stream (the
script's own reader, which broke when make bench-span's code moved into diffengine.bench),
and its FIFO search (the depth it returns has no late line, one burst less has some; a
lower rate needs a deeper FIFO).
"""
from __future__ import annotations

import importlib.util
import random
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "sw"))


def budget():
    spec = importlib.util.spec_from_file_location("sdram_budget", REPO / "scripts" / "sdram_budget.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_words_per_line_of_a_stream(tmp_path):
    from diffengine import isa
    rng = random.Random(5)
    want, cmds = [], []
    for _ in range(7):
        n = rng.randrange(0, 5)
        for _ in range(n):
            cmds.append(isa.Command("EVAL", rng.randrange(600), rng.randrange(1, 40),
                                    (rng.randrange(1 << 20), rng.randrange(1 << 20))))
        cmds.append(isa.Command("REFRESH"))
        want.append(n)
    slots = isa.serialise(cmds)
    path = tmp_path / "r.de48"
    path.write_bytes(b"DE48\0\1\0\0" + b"".join((i << 36 | d).to_bytes(6, "big")
                                                 for i, d in slots))
    got = budget().words_per_line(path)
    # One word per slot, the marker included: an EVAL is several slots, so count them.
    per_line, k = [], 0
    for ident, _ in slots:
        k += 1
        if ident == isa.REFRESH:
            per_line.append(k)
            k = 0
    assert got == per_line and len(got) == 7
    assert all(g >= 1 + 2 * n for g, n in zip(got, want))   # each EVAL at least 2 slots


@pytest.mark.parametrize("rate", [2.46, 2.0])
def test_min_depth_is_the_smallest(rate, monkeypatch):
    b = budget()
    # A small display (100 clocks a line, 40 of 44 lines active) keeps the search quick.
    monkeypatch.setattr(b, "H_TOTAL", 100)
    monkeypatch.setattr(b, "V_ACTIVE", 40)
    monkeypatch.setattr(b, "V_TOTAL", 44)
    rng = random.Random(11)
    # Three colours: a band of heavy lines (80-99 words) in light ones (5-35).
    lines = [[rng.randrange(80, 100) if 15 <= v < 22 else rng.randrange(5, 36)
              for v in range(40)] for _ in range(3)]
    d = b.min_depth(lines, rate, 4)
    assert d > 0 and d % 4 == 0
    assert b.late_lines(lines, rate, 4, d) == 0
    assert b.late_lines(lines, rate, 4, d - 4) > 0
    # A lower rate needs more; under the mean demand the FIFO must carry the two
    # frames' whole deficit (the model starts from full FIFOs).
    if rate == 2.0:
        assert d > b.min_depth(lines, 2.46, 4)
    mean = sum(map(sum, lines)) / (44 * 100)
    assert b.min_depth(lines, mean * 0.9, 4) > 2 * 0.1 * mean * 44 * 100 / 3
