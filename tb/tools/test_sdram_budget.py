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
    from diffengine.formats import binfmt
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
    path.write_bytes(binfmt.encode_de48(slots))
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


def small(monkeypatch, seed: int, light: int):
    """The script with a small display (100 clocks a line, 40 of 44 lines active: the
    search is quick) and three colours of a band of heavy lines (80-99 words) in light
    ones (light-35 words)."""
    b = budget()
    monkeypatch.setattr(b, "H_TOTAL", 100)
    monkeypatch.setattr(b, "V_ACTIVE", 40)
    monkeypatch.setattr(b, "V_TOTAL", 44)
    rng = random.Random(seed)
    return b, [[rng.randrange(80, 100) if 15 <= v < 22 else rng.randrange(light, 36)
                for v in range(40)] for _ in range(3)]


@pytest.mark.parametrize("rate", [2.46, 2.0])
def test_min_depth_is_the_smallest(rate, monkeypatch):
    b, lines = small(monkeypatch, 11, 5)
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


def test_fetch_pattern():
    """--fetch: the fetchers' bursts on a frame stored as a table of lines."""
    b = budget()
    lines = [5, 1, 8, 3, 1]
    bursts = b.fetch_bursts(lines, 4, True)
    # a table burst before lines 0 and 4; 5 -> 4 + 1 (3 words dropped), the lone marker a
    # pad, 8 -> 4 + 4, 3 -> 3 (1 dropped)
    assert bursts == [(0, 4), (4, 4), (1, 4), (1, 0), (4, 4), (4, 4), (3, 4), (0, 4), (1, 0)]
    assert sum(fw for fw, _ in bursts) == sum(lines)
    assert b.fetch_bursts(lines, 4, False) == [(4, 4)]


def test_fetch_pattern_needs_more(monkeypatch):
    b, lines = small(monkeypatch, 3, 1)        # light lines down to a lone marker (pads)
    plain, fetch = b.min_depth(lines, 2.46, 4), b.min_depth(lines, 2.46, 4, fetch=True)
    assert b.late_lines(lines, 2.46, 4, fetch, fetch=True) == 0
    assert b.late_lines(lines, 2.46, 4, fetch - 4, fetch=True) > 0
    assert fetch > plain, (plain, fetch)
