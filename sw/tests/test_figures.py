"""Figs. 7.21 and 7.25 of the source: the command lists as printed, and the properties
their captions describe, checked on the functional model.

Units, as in the shipped sw/scenes/fig7_*.cmd: Fig. 7.21 uses `.unit dac 0` (1.0 = full
scale of a DAC on pixel bits [5:0] = 64 pixel LSBs, raw = round(v * 2^30)), the window
the caption names; Fig. 7.25 uses `.unit dac 2` (1.0 = 256 LSBs), the scene files'
reading that fits every curve in the middle window of Fig. 7.22. The seed prints Fig.
7.21(c)'s last operand as "0.9375.0"; it is read as 0.9375 (60 LSBs).
"""
from math import comb
from pathlib import Path

import numpy as np
import pytest

from diffengine.formats import asm
from diffengine import isa
from diffengine.model import functional as F

W = 130
FIG = {
    "7.21a": "Eval2 (1, 17, 0.0625, 0.015625);\nEval2 (21, 17, 0.0625, 0.0078125);",
    "7.21c": "Eval2 (1, 17, 0.5, 0.0078125);\nEval3 (21, 33, 0.0, 0.0, 0.001953125);\n"
             "Eval1 (55, 16, 0.9375);",
    "7.21e": "Eval2 (1, 17, 0.5, -0.0078125);\nEval3 (21, 33, 0.984375, 0.0, -0.001953125);\n"
             "Eval1 (55, 16, 0.046875);",
    "7.25a": "Eval4 (1, 52, 0.0, 0.18,-0.0127, 0.000427);",
    "7.25b": "Setddi (10, 1,-0.003906);\nSetddi (40, 1, 0.0078125);\n"
             "Eval3 (1, 48, 0.25,-0.005859, 0.0078125);",
    "7.25c": "Eval2 (2, 40, 0.0, 0.01);\nEval3 (42, 41, 0.4, 0.01,-0.0005);\n"
             "Eval2 (83, 40, 0.4, -0.01);",
    "7.25d": "Setpi (8, 7, 0.0);\nEval2 (1, 100, 0.0, 0.0703);\nEval2 (1, 100, 0.59375,-0.00586);",
    "7.25e": "Setddi (9, 1,-0.0078125);\nSetddi (38, 1, 0.008789);\n"
             "Eval3 (1, 55, 0.0957, 0, 0.008789);",
}
FIG["7.25f"] = "Acc_mode ();\n" + FIG["7.25e"]


def cmds(name):
    unit = 0 if name.startswith("7.21") else 2
    return asm.parse_text(f".unit dac {unit}\n" + FIG[name], f"fig{name}")


def run(commands, bug=False):
    pixels, state = F.run_line(commands, W, carry_bug=bug)
    return pixels.astype(np.int64), state


def signed(words):
    return np.array([isa.to_signed(int(w)) for w in words], dtype=object)


def compensated(commands, comp=isa.compensate):
    return [isa.Command(c.op, c.x, c.dx, tuple(comp(v) for v in c.values))
            if c.op.startswith(("EVAL", "SET")) and c.op != "EVAL0" else c for c in commands]


def halve_fraction(v):
    """Carry-bug compensation without §7's sign rule: fraction at half scale, any sign."""
    w = isa.to_word(v)
    return isa.to_signed((w & ~0xFFFFFF & isa.WORD_MASK) | ((w & 0xFFFFFF) >> 1))


def floor_div(num, den):
    return num // den  # Python ints: exact floor for negatives too


# ---- Fig. 7.21: ramps and a parabola, 6-bit DAC on the pixel LSBs -------------------

def test_fig_7_21a_two_ramps():
    p, _ = run(cmds("7.21a"))
    cols = np.arange(W)
    want = np.where((cols >= 1) & (cols < 18), 4 + cols - 1, 0)
    want = np.where((cols >= 21) & (cols < 38), 4 + (cols - 21) // 2, want)
    assert p.tolist() == want.tolist()
    assert set(np.diff(p[1:18])) == {1}               # slope 1 LSB/pixel
    assert np.diff(p[21:38]).tolist() == [0, 1] * 8   # slope 1/2: a staircase


def test_fig_7_21c_ramp_parabola_constant():
    p, _ = run(cmds("7.21c"))
    n1, n2 = np.arange(17), np.arange(33)
    assert p[1:18].tolist() == (32 + n1 // 2).tolist()
    assert p[21:54].tolist() == (n2 * (n2 - 1) // 16).tolist()   # floor(C(n,2)/8)
    assert p[55:71].tolist() == [60] * 16
    assert p[[0, 18, 19, 20, 54, 71]].tolist() == [0] * 6


def test_fig_7_21e_falling_ramp_and_parabola():
    p, _ = run(cmds("7.21e"))
    n1, n2 = np.arange(17), np.arange(33)
    assert p[1:18].tolist() == [floor_div(64 - int(n), 2) for n in n1]      # 32 - n/2
    assert p[21:54].tolist() == [floor_div(504 - int(n) * (int(n) - 1) // 2, 8) for n in n2]
    assert p[55:71].tolist() == [3] * 16


@pytest.mark.parametrize("name", ["7.21a", "7.21c", "7.21e"])
def test_fig_7_21_uncompensated_bug_shows(name):
    """(a), (c), (e): the same data through the faulty adder is visibly wrong."""
    good, _ = run(cmds(name))
    bad, _ = run(cmds(name), bug=True)
    assert (bad != good).sum() >= 8
    assert np.abs(bad - good).max() >= 7
    if name == "7.21a":   # integer slope: no fraction carries, first ramp untouched
        assert bad[1:18].tolist() == good[1:18].tolist()
        assert np.diff(bad[21:38]).tolist() == [0, 2] * 8   # slope 1/2 came out as 1


@pytest.mark.parametrize("name", ["7.21a", "7.21c"])
def test_fig_7_21_bd_compensation_costs_only_the_lsb(name):
    """(b), (d): compensated operands through the faulty adder: right but for the LSB."""
    good, _ = run(cmds(name))
    comp, _ = run(compensated(cmds(name)), bug=True)
    err = comp - good
    assert set(err.tolist()) == {0, -1}               # some error, never more than 1 LSB


def test_fig_7_21f_compensation_of_negative_operands():
    """(f) has negative dI and ddI. Fraction-halving alone keeps the error within one LSB
    (the sum of half-scale fractions is exact under the fault, whatever the sign)."""
    good, _ = run(cmds("7.21e"))
    comp, _ = run(compensated(cmds("7.21e"), halve_fraction), bug=True)
    assert set((comp - good).tolist()) == {0, -1}


def test_fig_7_21f_compensate_negative_within_one_lsb():
    """isa.md §7: plain fraction halving keeps negative slopes within one LSB."""
    good, _ = run(cmds("7.21e"))
    comp, _ = run(compensated(cmds("7.21e")), bug=True)
    assert set((comp - good).tolist()) <= {0, -1}


def test_fig_7_21f_literal_sign_fill_is_wrong():
    """The source's literal sign-fill rule breaks negative slopes under the fault."""
    good, _ = run(cmds("7.21e"))
    bad, _ = run(compensated(cmds("7.21e"), comp=lambda v: isa.compensate(v, literal=True)),
                 bug=True)
    assert np.abs(bad.astype(int) - good.astype(int)).max() > 100


# ---- Fig. 7.25 -------------------------------------------------------------------------

def test_fig_7_25a_cubic_from_one_command():
    (c,) = cmds("7.25a")
    v = c.values
    p, st = run([c])
    a = signed(st.A[1:53])
    d3 = [(a[i + 3] - 3 * a[i + 2] + 3 * a[i + 1] - a[i]) % (1 << 36) for i in range(len(a) - 3)]
    assert set(d3) == {v[3] % (1 << 36)}               # third difference = dddI exactly
    exact = [sum(comb(n, k) * v[k] for k in range(4)) for n in range(52)]
    assert p[1:53].tolist() == [(e >> 24) & 0xFFF for e in exact]  # floor of the polynomial
    assert p[0] == 0 and p[53] == 0
    d = np.diff(p[1:53])
    assert d[0] > 0 and (d < 0).any() and d[-1] > 0    # rise, dip, rise: a genuine cubic


def test_fig_7_25b_quadratic_spline_knots_at_10_and_40():
    cs = cmds("7.25b")
    p, st = run(cs)
    ddi = {c.x: c.values[0] for c in cs if c.op == "SETDDI"}
    ev = cs[-1]
    c_reg = signed(st.C[1:49]).tolist()
    assert c_reg == [ev.values[2]] * 9 + [ddi[10]] * 30 + [ddi[40]] * 9
    a = signed(st.A[1:49])
    b = signed(st.B[1:49])
    assert (a[1:] - a[:-1]).tolist() == b[:-1].tolist()      # continuous: no jump in I
    assert (b[1:] - b[:-1]).tolist() == c_reg[:-1]           # dI bends only at the knots
    assert np.abs(np.diff(p[1:49])).max() <= 17               # |dI| <= 16.5 LSB
    assert int(np.argmax(p)) == 27 and p.max() == 267         # the bump between the knots


def test_fig_7_25c_linear_quadratic_linear_tiles_without_spikes():
    p, _ = run(cmds("7.25c"))
    assert p[:3].tolist() == [0, 0, 0] and p[123:].max() == 0    # spans tile [2, 123)
    assert np.abs(np.diff(p[:125])).max() <= 3       # slope 2.56 LSB: continuous at 42, 83
    assert p[41] <= p[42] <= p[41] + 3 and p[82] >= p[83] >= p[82] - 3
    assert all(abs(int(p[c]) - int(p[125 - c])) <= 1 for c in range(2, 63))  # symmetric
    assert p.max() == 129 and p[42] < 110 and p[83] < 110    # no double-counted pixel


def test_fig_7_25d_periodic_sawtooth_plus_ramp():
    cs = cmds("7.25d")
    _, st = run(cs[:2])          # SetPI + the first Eval2: the sawtooth alone
    dI = cs[1].values[1]
    assert np.flatnonzero(F.run_line(cs[:1], W)[1].pA).tolist() == list(range(8, 130, 7))
    assert signed(st.A[1:101]).tolist() == [((col - 1) % 7) * dI for col in range(1, 101)]
    p, _ = run(cs)
    drops = [c for c in range(2, 101) if p[c] < p[c - 1]]
    assert drops == list(range(8, 101, 7))                    # every 7th column from 8
    saw = run(cs[:2])[0]
    assert saw[1:8].tolist() * 13 + saw[1:2].tolist() == saw[8:100].tolist()


def test_fig_7_25ef_acc_mode_drops_exactly_the_negative_columns():
    """The printed numbers do drive A negative: from column 32 to the end of the span
    (55), the curve falls through zero after its peak. (e) shows those columns raw
    (wrapped to values near 4095); (f) with Acc_mode drops their contribution (D = 0)."""
    e_px, e_st = run(cmds("7.25e"))
    f_px, f_st = run(cmds("7.25f"))
    neg = np.flatnonzero(e_st.A >> np.uint64(35)).tolist()
    assert neg == list(range(32, 56))
    assert np.flatnonzero(e_px != f_px).tolist() == neg
    assert f_px[neg].max() == 0 and e_px[neg].min() >= 2048   # (e): wrapped, top bit set
    assert (e_st.A == f_st.A).all()        # Acc_mode does not touch forward differencing


# ---- the shipped scene files say the same -------------------------------------------------

SCENES = Path(__file__).resolve().parents[1] / "scenes"


@pytest.mark.parametrize("name,text", [(f"7.21{b}", "7.21" + a) for a, b in zip("ace", "bdf")]
                         + [(n, n) for n in FIG])
def test_scene_files_match_the_source_lists(name, text):
    path = SCENES / f"fig{name.replace('.', '_')}.cmd"
    if not path.exists():
        pytest.skip(f"{path.name} not shipped")
    shipped = [c for c in asm.parse_file(path) if c.op != "REFRESH"]
    assert shipped == cmds(text)
