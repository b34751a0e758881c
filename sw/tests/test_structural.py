"""Structural (cycle-level) model vs functional model: identical pixels.

Random well-formed command streams; the seed is printed and SEED=<n> replays it
(`SEED=123 pytest -q sw/tests/test_structural.py`).
"""
from __future__ import annotations

import os
import random

import numpy as np
import pytest

from diffengine.model import functional
from diffengine import isa
from diffengine.model import structural as st


def _seed(salt: int) -> int:
    base = int(os.environ["SEED"]) if "SEED" in os.environ else random.randrange(1 << 32)
    return base ^ salt


@pytest.mark.parametrize("carry_bug", [False, True])
def test_random_streams_match_functional(carry_bug):
    seed = _seed(0x57 + carry_bug)
    print(f"test_random_streams_match_functional carry_bug={carry_bug} seed {seed}")
    rng = np.random.default_rng(seed)
    for case in range(60):
        n = int(rng.integers(1, 24))
        cmds = st.random_commands(rng, n, int(rng.integers(5, 80)))
        got = st.render(cmds, n, carry_bug)
        ref = functional.render(cmds, n, carry_bug)
        assert np.array_equal(got, ref), (
            f"seed {seed} case {case} n_pe {n} carry_bug {carry_bug}:\n"
            f"structural {got.tolist()}\nfunctional {ref.tolist()}")


@pytest.mark.parametrize("carry_bug", [False, True])
def test_wide_array(carry_bug):
    seed = _seed(0x640 + carry_bug)
    print(f"test_wide_array seed {seed}")
    rng = np.random.default_rng(seed)
    cmds = st.random_commands(rng, 640, 300, refresh_every=40)
    assert np.array_equal(st.render(cmds, 640, carry_bug),
                          functional.render(cmds, 640, carry_bug)), f"seed {seed}"



def _set_carry_fault(monkeypatch, carry_from, carry_to):
    from diffengine.isa import _tables
    for mod in (isa, _tables):
        monkeypatch.setattr(mod, "ADD_CARRY_FROM", carry_from)
        monkeypatch.setattr(mod, "ADD_CARRY_TO", carry_to)


@pytest.mark.parametrize("carry_from,carry_to", [(24, 26), (24, 27)])
def test_carry_fault_follows_the_spec(monkeypatch, carry_from, carry_to):
    """The structural model takes the carry fault from spec/isa.toml [adder] (the generated
    isa.ADD_CARRY_FROM/TO), as de_pe takes it from de_pkg::blk_carry_in: with another fault
    (the carry landing two or three bits up) it still equals the functional model, whose
    adder is the generated isa.add_word. A private copy of the fault fails here."""
    _set_carry_fault(monkeypatch, carry_from, carry_to)
    seed = _seed(0xCA + carry_from)
    print(f"test_carry_fault_follows_the_spec seed {seed}")
    rng = np.random.default_rng(seed)
    differs = 0
    for case in range(20):
        n = int(rng.integers(1, 16))
        cmds = st.random_commands(rng, n, int(rng.integers(5, 60)))
        ref = functional.render(cmds, n, True)
        assert np.array_equal(st.render(cmds, n, True), ref), f"seed {seed} case {case}"
        differs += not np.array_equal(ref, functional.render(cmds, n, False))
    assert differs, f"seed {seed}: no stream exercised the fault"


def test_carry_fault_below_the_top_block_is_refused(monkeypatch):
    """A fault into block 1 could carry 2 out of it: no one-bit block carry holds that,
    so the model refuses it as de_pe does (g_bad_carry_blk)."""
    _set_carry_fault(monkeypatch, 12, 13)
    with pytest.raises(ValueError, match="top block"):
        st.Array(4, carry_bug=True)

TABLE_7_5 = {
    False: ([0x0, 0x800000, 0x1000000, 0x1800000, 0x2000000, 0x2800000, 0x3000000,
             0x3800000, 0x4000000],
            [0x0, 0x0, 0x800000, 0x1800000, 0x3000000, 0x5000000, 0x7800000, 0xA800000,
             0xE000000]),
    True: ([0x0, 0x800000, 0x2000000, 0x2800000, 0x4000000, 0x4800000, 0x6000000,
            0x6800000, 0x8000000],
           [0x0, 0x0, 0x800000, 0x2800000, 0x6000000, 0xA000000, 0xE800000, 0x14800000,
            0x1C000000]),
}


@pytest.mark.parametrize("carry_bug", [False, True])
def test_table_7_5(carry_bug):
    arr = st.Array(9, carry_bug)
    arr.run(isa.serialise([isa.Command("EVAL", 0, 9, (0, 0, 0x800000))]))
    arr.flush()
    s = arr.state()
    di, i = TABLE_7_5[carry_bug]
    assert s["B"].tolist() == di
    assert s["A"].tolist() == i
    assert s["D"].tolist() == i


def test_pixel_timing():
    """A Refresh fed at cycle R: PE p loads its pixel register in cycle R + p + 2 (the
    event's cycle) and shows it on its output in cycle R + p + 3 (docs/xproc.md)."""
    arr = st.Array(5)
    arr.run(isa.serialise([isa.Command("EVAL", 0, 5, (0, 1 << 24))]))
    r = arr.cycle
    arr.step(isa.REFRESH, 0)
    arr.flush()
    assert [(c - r, p, v) for c, p, v in arr.events] == [(p + 2, p, p) for p in range(5)]


def test_packed_state_width():
    arr = st.Array(3)
    assert all(v < (1 << st.DBG_WIDTH) for v in arr.packed_state())
    assert st.DBG_WIDTH == 236


# ---- raw slot streams: the structural model against §5/§6 read slot by slot ----------------

def _soup_rows(slots, n, carry_bug):
    arr = st.Array(n, carry_bug)
    arr.run(slots)
    arr.flush()
    rows = np.zeros((sum(1 for s in slots if s[0] == isa.REFRESH), n), dtype=np.int64)
    seen = np.zeros(n, dtype=np.int64)
    for _, p, v in arr.events:
        rows[seen[p], p] = v
        seen[p] += 1
    return rows


@pytest.mark.parametrize("carry_bug", [False, True])
def test_slot_soup_matches_slot_oracle(carry_bug):
    """tb/de_span_array slot_soup's raw slot streams (randgen.slot_soup: any order, the
    pairs isa.md leaves undefined left out): the structural model (= de_pe) gives the
    pixels of the literal slot-level reading of isa.md §5/§6, which the span-serial array
    implements. 2065067757 is issue 18's seed (it failed while a data slot right behind
    an Eval0 was still generated)."""
    from diffengine.regress import randgen
    from test_functional import SlotOracle
    for seed in (2065067757, _seed(0x50 + carry_bug)):
        print(f"test_slot_soup_matches_slot_oracle carry_bug={carry_bug} seed {seed}")
        n = 37
        slots = randgen.slot_soup(seed, 1500, n)
        oracle = SlotOracle(n, carry_bug)
        want = [r for r in (oracle.slot(i, d) for i, d in slots) if r is not None]
        got = _soup_rows(slots, n, carry_bug)
        assert got.tolist() == want, f"seed {seed}: structural model differs from the oracle"


def test_data_slot_behind_eval0_is_undefined():
    """Why randgen.slot_soup leaves the pair out (isa.md §6, "Undefined"): a protected data
    slot right behind an Eval0 address slot still sees the protect flag that the Eval0
    clears a clock later, so the PE keeps the Set's value where the slot-level reading
    takes the incoming one. Should de_pe ever forward the clear, this fails: then isa.md
    can define the pair and slot_soup generate it."""
    from test_functional import SlotOracle
    rng0, ev0 = isa.ADDR_RANGE, isa.ADDR_EVAL0
    slots = [(rng0, 1 << 12), (isa.SET_B, 5 << 24), (ev0, 1 << 12), (isa.D_B, 7 << 24)]
    arr = st.Array(1)
    arr.run(slots)
    arr.flush()
    oracle = SlotOracle(1, False)
    for i, d in slots:
        oracle.slot(i, d)
    assert int(arr.state()["B"][0]) == 5 << 24      # the stale flag: B kept
    assert oracle.r[2][0] == 7 << 24                 # flags already clear: B taken
    # One slot apart (a range address slot between), both readings agree.
    arr = st.Array(1)
    arr.run(slots[:3] + [(rng0, 1 << 12)] + slots[3:])
    arr.flush()
    assert int(arr.state()["B"][0]) == 7 << 24
