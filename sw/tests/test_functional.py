"""Directed tests of the functional golden model against docs/isa.md §5-§7.

Expected values are worked out by hand (comments show the forward differencing). At
the end, a hypothesis test checks the vectorised model against `SlotOracle`, a
deliberately naive slot-by-slot interpretation of §6 driven by `isa.slots()`, on random
command lists with every command type, the carry bug on and off.
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from diffengine.model import functional as F
from diffengine import isa
from diffengine.isa import Command as C

ONE = 1 << 24
W = 16


def px(*cmds, width=W, bug=False):
    return F.run_line(list(cmds), width, carry_bug=bug)[0].tolist()


def ev(x, dx, *vals):
    return C("EVAL", x, dx, tuple(int(v * ONE) for v in vals))


def s(op, x, dx, v):
    return C(op, x, dx, (int(v * ONE),))


# ---- spans (§5) -----------------------------------------------------------------

def test_span_is_half_open():
    assert px(ev(3, 4, 5)) == [0, 0, 0, 5, 5, 5, 5] + [0] * 9


def test_dx_zero_and_one():
    assert px(ev(3, 0, 5)) == [0] * W
    assert px(ev(3, 1, 5)) == [0, 0, 0, 5] + [0] * 12


def test_x_beyond_width_and_clipping():
    assert px(ev(W, 5, 5)) == [0] * W
    assert px(ev(4000, 95, 5)) == [0] * W
    assert px(ev(W - 2, 100, 5)) == [0] * (W - 2) + [5, 5]


def test_render_batch_clips_like_run_line():
    cmds = [ev(W - 2, 100, 1, 1, 1), ev(W, 3, 9), ev(4095, 4095, 7), ev(0, 0, 3), C("REFRESH")]
    assert F.render(cmds, W).tolist() == [[0] * (W - 2) + [1, 2]]


# ---- Eval orders ------------------------------------------------------------------

def test_eval2_ramp_and_pixel_truncation():
    # I = 1.5 + 0.25 n -> floor: 1 1 2 2 2 2 3 3
    assert px(ev(0, 8, 1.5, 0.25), width=8) == [1, 1, 2, 2, 2, 2, 3, 3]


def test_eval3_second_order():
    # I(n) = 1 + 2n + C(n,2)*1: 1 3 6 10 15 21
    assert px(ev(2, 6, 1, 2, 1), width=8) == [0, 0, 1, 3, 6, 10, 15, 21]


def test_eval3_registers_are_forward_differences():
    _, stt = F.run_line([ev(0, 4, 1, 2, 1)], 4)
    assert (stt.A >> 24).tolist() == [1, 3, 6, 10]
    assert (stt.B >> 24).tolist() == [2, 3, 4, 5]
    assert (stt.C >> 24).tolist() == [1, 1, 1, 1]


def test_evals_accumulate():
    assert px(ev(0, 4, 1), ev(2, 4, 0, 1), width=6) == [1, 1, 1, 2, 2, 3]


def test_eval4_cubic_and_eval8():
    # Eval4 (0, 6, 0, 0, 0, 1): I(n) = C(n, 3)
    assert px(ev(0, 6, 0, 0, 0, 1), width=6) == [0, 0, 0, 1, 4, 10]
    # Eval8 with d^7 = 1: I(n) = C(n, 7)
    assert px(ev(0, 10, 0, 0, 0, 0, 0, 0, 0, 1), width=10) == [0] * 7 + [1, 8, 36]


def test_wraparound_mod_2_36_and_raw_pixel():
    big = C("EVAL", 0, 1, (0x7FF << 24,))
    assert px(big, big, width=1) == [0xFFE]
    assert px(big, big, big, width=1) == [(3 * 0x7FF) % 4096]
    assert px(ev(0, 1, -0.5), width=1) == [0xFFF]   # negative D shows raw
    # a difference that carries the intensity through 2^35 wraps, never saturates
    assert px(C("EVAL", 0, 3, (0x7FF << 24, 1 << 24)), width=3) == [0x7FF, 0x800, 0x801]


# ---- Set, protect flags -----------------------------------------------------------

def test_seti_before_eval1():
    assert px(s("SETI", 5, 1, 7), ev(0, 10, 3), width=10) == [3] * 5 + [7] * 5


def test_setdi_before_eval2():
    # 0 1 2 3 4 | B := 3 at column 4 -> 4 7 10 13 16 ... (A at 4 still 4)
    assert px(s("SETDI", 4, 1, 3), ev(0, 10, 0, 1), width=10) == [0, 1, 2, 3, 4, 7, 10, 13, 16, 19]


def test_setddi_before_eval3():
    # C := 2 at 3: col3 (A,B,C)=(0,0,2) -> col4 (0,2,2) -> col5 (2,4) -> col6 (6,6) -> 12
    assert px(s("SETDDI", 3, 1, 2), ev(0, 8, 0, 0, 0), width=8) == [0, 0, 0, 0, 0, 2, 6, 12]


def test_seti_before_eval3_breaks_continuity():
    # ramp 0,1,2.. with A := 10 at 3 keeps dI: 0 1 2 10 11 12
    assert px(s("SETI", 3, 1, 10), ev(0, 6, 0, 1, 0), width=6) == [0, 1, 2, 10, 11, 12]


def test_set_range_form_covers_dx_columns():
    assert px(s("SETI", 2, 3, 9), ev(0, 6, 1), width=6) == [1, 1, 9, 9, 9, 9]


def test_set_after_eval_does_not_change_it_and_waits_for_next():
    out, stt = F.run_line([ev(0, 6, 1), s("SETI", 3, 1, 5), ev(5, 1, 1)], 6)
    assert out.tolist() == [1, 1, 1, 1, 1, 2]
    assert stt.pA.tolist() == [False] * 3 + [True, False, False]  # Eval elsewhere: flag kept
    assert px(ev(0, 6, 1), s("SETI", 3, 1, 5), ev(5, 1, 1), ev(0, 6, 1), width=6) == [2, 2, 2, 6, 6, 7]


def test_protect_cleared_by_covering_eval():
    # the second Eval is not overridden any more
    assert px(s("SETI", 5, 1, 7), ev(0, 10, 3), ev(0, 10, 1), width=10) == [4] * 5 + [8] * 5


def test_protect_cleared_by_refresh():
    cmds = [s("SETI", 2, 1, 9), C("REFRESH"), ev(0, 4, 1), C("REFRESH")]
    assert F.render(cmds, 4).tolist() == [[0] * 4, [1] * 4]


def test_setpi_periodic_and_dx_zero():
    _, stt = F.run_line([s("SETPI", 8, 7, 1)], 40)
    assert np.flatnonzero(stt.pA).tolist() == [8, 15, 22, 29, 36]
    _, stt = F.run_line([s("SETPDDI", 3, 0, 1)], 40)
    assert np.flatnonzero(stt.pC).tolist() == [3]
    _, stt = F.run_line([s("SETPDI", 50, 2, 1)], 40)
    assert not stt.pB.any()


def test_setpi_sawtooth():
    # A := 0 every 3rd column from 1 under a unit ramp: 0 0 1 2 0 1 2 0
    assert px(s("SETPI", 1, 3, 0), ev(0, 8, 0, 1), width=8) == [0, 0, 1, 2, 0, 1, 2, 0]


def test_order3_plus_register_reuse():
    base = ev(0, 10, 0, 0, 0, 0)
    # SetddI sets d^3 (register C): I(n) = C(n-2, 3)
    assert px(s("SETDDI", 2, 1, 1), base, width=10) == [0] * 5 + [1, 4, 10, 20, 35]
    # SetdI sets d^2 (register B): I(n) = C(n-2, 2)
    assert px(s("SETDI", 2, 1, 1), base, width=10) == [0] * 4 + [1, 3, 6, 10, 15, 21]
    # SetI is ineffective for order >= 3, and its flag is cleared by the ACC slot
    out, stt = F.run_line([s("SETI", 2, 1, 5), base], 10)
    assert out.tolist() == [0] * 10 and not stt.pA.any()


# ---- Dis ----------------------------------------------------------------------------

def test_dis_suppresses_next_eval_only():
    d = C("DIS", 2, 3)
    assert px(d, ev(0, 8, 1), width=8) == [1, 1, 0, 0, 0, 1, 1, 1]
    assert px(d, ev(0, 8, 1), ev(0, 8, 1), width=8) == [2, 2, 1, 1, 1, 2, 2, 2]


def test_dis_waits_for_eval_active_in_that_pe():
    assert px(C("DIS", 2, 3), ev(5, 3, 1), ev(0, 8, 1), width=8) == [1, 1, 0, 0, 0, 2, 2, 2]


def test_dis_keeps_forward_differencing():
    assert px(C("DIS", 2, 3), ev(0, 8, 0, 1), width=8) == [0, 1, 0, 0, 0, 5, 6, 7]


def test_dis_suppresses_eval0_without_locking():
    assert px(C("DIS", 2, 1), C("EVAL0", 0, 4, (9,)), ev(0, 4, 1), width=4) == [9, 9, 1, 9]


# ---- Eval0 ----------------------------------------------------------------------------

def test_eval0_overwrites_and_locks_first_wins():
    e0 = C("EVAL0", 2, 3, (100,))
    assert px(ev(0, 6, 3), e0, width=6) == [3, 3, 100, 100, 100, 3]
    assert px(ev(0, 6, 3), e0, ev(0, 6, 1), width=6) == [4, 4, 100, 100, 100, 4]
    assert px(e0, C("EVAL0", 0, 6, (50,)), width=6) == [50, 50, 100, 100, 100, 50]


def test_eval0_lock_keeps_forward_differencing():
    assert px(C("EVAL0", 2, 2, (100,)), ev(0, 6, 0, 1), width=6) == [0, 1, 100, 100, 4, 5]


def test_eval0_clears_protect_and_leaves_registers():
    _, stt = F.run_line([s("SETI", 1, 1, 7), C("EVAL0", 0, 3, (4,))], 3)
    assert not stt.pA.any() and (stt.A >> 24).tolist() == [0, 7, 0]
    assert stt.lock.tolist() == [True] * 3 and (stt.D >> 24).tolist() == [4] * 3


# ---- Acc_mode and Refresh -------------------------------------------------------------

def test_acc_mode_suppresses_negative_a_only_after_it():
    base = [ev(0, 4, 10)]
    assert px(*base, ev(0, 4, -3), width=4) == [7] * 4
    assert px(*base, C("ACCMODE", values=(1,)), ev(0, 4, -3), width=4) == [10] * 4
    assert px(*base, C("ACCMODE", values=(1,)), ev(0, 4, -2, 1), width=4) == [10, 10, 10, 11]
    assert px(*base, ev(0, 4, -3), C("ACCMODE", values=(1,)), width=4) == [7] * 4
    assert px(*base, C("ACCMODE", values=(1,)), C("ACCMODE", values=(0,)), ev(0, 4, -3),
              width=4) == [7] * 4


def test_refresh_clears_everything():
    line1 = [C("ACCMODE", values=(1,)), C("EVAL0", 0, 1, (5,)), C("DIS", 1, 1), ev(0, 3, 2),
             s("SETDI", 2, 1, 1), C("REFRESH")]
    line2 = [ev(0, 3, 3), ev(0, 3, -1), C("REFRESH")]
    assert F.render(line1 + line2, 3).tolist() == [[5, 0, 2], [2, 2, 2]]


def test_render_warns_about_unterminated_line():
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        out = F.render([ev(0, 2, 1), C("REFRESH"), ev(0, 2, 1), C("NOP")], 2)
    assert out.shape == (1, 2) and out.dtype == np.uint16
    assert len(w) == 1 and "2 command" in str(w[0].message)


def test_run_line_rejects_inner_refresh():
    with pytest.raises(ValueError):
        F.run_line([C("REFRESH"), ev(0, 1, 1)], 2)


# ---- carry bug (§7) -------------------------------------------------------------------

def test_carry_bug_in_acc_and_differencing():
    half = ev(0, 1, 0.5)
    assert px(half, half, width=1) == [1]
    assert px(half, half, width=1, bug=True) == [2]
    assert px(ev(0, 3, 0, 0.5), width=3, bug=True) == [0, 0, 2]   # 0.5 + 0.5 -> 2.0


def test_bug_add():
    assert F.bug_add(0x000800000, 0x000800000) == 0x002000000
    assert F.bug_add(0xFFF000000, 0x001000000) == 0          # block 2 carry dropped
    assert F.bug_add(0x000000FFF, 0x000000001) == 0x000001000  # block 0 carry fine


# ---- cross-check against a naive slot-level reading of §6 -------------------------------

class SlotOracle:
    """Every slot of isa.slots() through every PE in turn: §5/§6 read literally."""

    def __init__(self, width, bug):
        self.w, self.bug = width, bug
        self.clear()

    def clear(self):
        n = self.w
        self.r = [[0] * n for _ in range(4)]   # index 1..3 = A, B, C
        self.p = [[False] * n for _ in range(4)]
        self.D = [0] * n
        self.dis, self.lock, self.act = [False] * n, [False] * n, [False] * n
        self.acc_mode = False

    def add(self, a, b):
        return F.bug_add(a, b) if self.bug else (a + b) & isa.WORD_MASK

    def slot(self, ident, data):
        if ident == isa.REFRESH:
            out = [(d >> 24) & 0xFFF for d in self.D]
            self.clear()
            return out
        if ident in (isa.ACCMODE_ON, isa.ACCMODE_OFF):
            self.acc_mode = ident == isa.ACCMODE_ON
        for pe in range(self.w):
            data = self.pe(pe, ident, data)
        return None

    def pe(self, i, ident, data):
        if ident & isa.ID_ADDR:
            sub = ident & 3
            lo, mid, hi = data & 0xFFF, (data >> 12) & 0xFFF, data >> 24
            if sub == isa.SUB_PERIODIC:
                self.act[i] = mid == 0
                mid = (lo - 1) % 4096 if mid == 0 else mid - 1
            else:
                self.act[i] = lo == 0 and mid != 0
                lo, mid = (lo - 1, mid) if lo else (0, max(mid - 1, 0))
            if self.act[i] and sub == isa.SUB_DIS:
                self.dis[i] = True
            if self.act[i] and sub == isa.SUB_EVAL0:
                if not (self.lock[i] or self.dis[i]):
                    self.D[i], self.lock[i] = hi << 24, True
                self.end_eval(i)
            return lo | (mid << 12) | (hi << 24)
        if ident & isa.ID_DATA:
            if not self.act[i]:
                return data
            dst, src = (ident >> 6) & 3, (ident >> 4) & 3
            if ident & isa.ID_SET:
                self.r[dst][i], self.p[dst][i] = data, True
                return data
            v = self.r[dst][i] if (ident & isa.ID_PROT and self.p[dst][i]) else data
            out = self.add(v, self.r[src][i] if src else 0)
            self.r[dst][i] = v
            return out
        if ident & isa.ID_ACC:
            if self.act[i]:
                a = self.r[1][i]
                if not (self.lock[i] or self.dis[i] or (self.acc_mode and a >> 35)):
                    self.D[i] = self.add(self.D[i], a)
                self.end_eval(i)
            return data
        self.act[i] = False
        return data

    def end_eval(self, i):
        self.p[1][i] = self.p[2][i] = self.p[3][i] = False
        self.dis[i] = False


def _oracle_render(cmds, width, bug):
    o, rows = SlotOracle(width, bug), []
    for c in cmds:
        for ident, data in isa.slots(c):
            out = o.slot(ident, data)
            if out is not None:
                rows.append(out)
    return rows, o


OW = 24
val = st.integers(-(1 << 35), (1 << 35) - 1)
small = st.integers(-8 * ONE, 8 * ONE)
xs = st.integers(0, OW + 3)
dxs = st.integers(0, OW + 3)
command = st.one_of(
    st.builds(lambda x, dx, v: C("EVAL", x, dx, tuple(v)), xs, dxs,
              st.lists(st.one_of(small, val), min_size=1, max_size=8)),
    st.builds(lambda x, dx, v: C("EVAL0", x, dx, (v,)), xs, dxs, st.integers(0, 4095)),
    st.builds(lambda op, x, dx, v: C(op, x, dx, (v,)),
              st.sampled_from(["SETI", "SETDI", "SETDDI", "SETPI", "SETPDI", "SETPDDI"]),
              xs, st.integers(0, 9), st.one_of(small, val)),
    st.builds(lambda x, dx: C("DIS", x, dx), xs, dxs),
    st.builds(lambda on: C("ACCMODE", values=(on,)), st.integers(0, 1)),
    st.just(C("NOP")),
)
lines = st.lists(st.lists(command, max_size=12), min_size=1, max_size=3)


@settings(max_examples=150, deadline=None)
@given(lines, st.booleans())
def test_matches_slot_oracle(lns, bug):
    cmds = [c for ln in lns for c in ln + [C("REFRESH")]]
    want, _ = _oracle_render(cmds, OW, bug)
    assert F.render(cmds, OW, carry_bug=bug).tolist() == want
    # registers and flags too, on the last line, just before its Refresh
    _, o = _oracle_render(lns[-1], OW, bug)
    _, stt = F.run_line(lns[-1], OW, carry_bug=bug)
    for r, name in ((1, "A"), (2, "B"), (3, "C")):
        assert getattr(stt, name).tolist() == o.r[r]
        assert getattr(stt, "p" + name).tolist() == o.p[r]
    assert stt.D.tolist() == o.D and stt.dis.tolist() == o.dis and stt.lock.tolist() == o.lock


evals = st.builds(lambda x, dx, v: C("EVAL", x, dx, tuple(v)), xs, dxs,
                  st.lists(st.one_of(small, val), min_size=1, max_size=3))


@settings(max_examples=100, deadline=None)
@given(st.lists(st.lists(st.one_of(evals, st.just(C("NOP"))), max_size=15), min_size=1, max_size=4))
def test_batched_frame_path_matches_per_line_path(lns):
    cmds = [c for ln in lns for c in ln + [C("REFRESH")]]
    fast = F.render(cmds, OW)
    assert fast.tolist() == [F.run_line(ln, OW)[0].tolist() for ln in lns]
    assert fast.tolist() == _oracle_render(cmds, OW, False)[0]
