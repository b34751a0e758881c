"""`diffengine bench span` (sw/diffengine/bench/span.py, span_timing.py): the fractional
pacer (slot k at floor(k x ratio) core clocks; integer ratios as before), the ratio's
parsing, the board's ratio read from its PLL, and a verdict that fails when it should.
The RTL driver's use of the same pacer is tested in tb/de_span_array (paced_driver)."""
from __future__ import annotations

import re
import subprocess
import sys
from fractions import Fraction

import pytest

from diffengine import REPO, isa
from diffengine.bench import span, span_timing
from diffengine.bench.span_timing import last_due, parse_ratio, slot_due


def test_pacer_fractional_ratio():
    """25/8: 0, 3, 6, 9, 12, 15, 18, 21, 25, ...: every 8 slots exactly 25 clocks, the
    spacing 3 or 4 (never drifting), and floor(k x 3.125) for every k."""
    r = Fraction(25, 8)
    due = [slot_due(k, r) for k in range(20000)]
    assert due[:10] == [0, 3, 6, 9, 12, 15, 18, 21, 25, 28]
    assert all(d == int(k * 3.125) for k, d in enumerate(due))      # 3.125 is exact in binary
    gaps = [b - a for a, b in zip(due, due[1:])]
    assert set(gaps) == {3, 4} and gaps[:8] == [3, 3, 3, 3, 3, 3, 3, 4]
    assert all(due[k + 8] - due[k] == 25 for k in range(len(due) - 8))
    assert slot_due(800, r) == 2500                                    # one line: 2,500 clocks
    # Same from a float or a string of the same value.
    assert [slot_due(k, 3.125) for k in range(100)] == due[:100]
    assert [slot_due(k, parse_ratio("3.125")) for k in range(100)] == due[:100]


def test_pacer_integer_ratio_unchanged():
    """At an integer ratio the pacer is the old one: slot k at k x ratio, and the slots
    due by clock t are t // ratio + 1 (the old backlog formula)."""
    for r in (1, 3, 4):
        assert [slot_due(k, r) for k in range(5000)] == [k * r for k in range(5000)]
        assert [last_due(t, r) for t in range(5000)] == [t // r for t in range(5000)]


@pytest.mark.parametrize("r", [Fraction(25, 8), Fraction(10, 3), Fraction(3), Fraction(1),
                               Fraction(7, 5)])
def test_last_due_is_the_inverse(r):
    """last_due(t) = the last slot whose due clock is <= t (brute force)."""
    due = [slot_due(k, r) for k in range(3000)]
    k = 0
    for t in range(0, due[-1]):
        while due[k + 1] <= t:
            k += 1
        assert last_due(t, r) == k, (r, t)


def _stream(lines: int, n: int = 40) -> list:
    """A light slot stream: a short Eval and a Set per line, then the Refresh."""
    one = 1 << isa.FRAC_BITS
    cmds = []
    for y in range(lines):
        cmds += [isa.Command("EVAL", y % n, 3, (one // 2, one // 64)),
                 isa.Command("SETI", n - 4, 2, (one // 3,)), isa.Command("REFRESH")]
    return isa.serialise(cmds)


def test_model_paces_refreshes_at_floor():
    """span_timing.simulate paced at 25/8: line i's Refresh (slot 800 i + 799 of the padded
    bus) is due at floor((800 i + 799) x 25/8); at 3 at (800 i + 799) x 3, as before.
    A light stream never holds a slot back: backlog 0, and the lag is the drain alone."""
    slots = _stream(12)
    for r in (Fraction(25, 8), 3):
        st: dict = {}
        span_timing.simulate(slots, 40, prefetch=True, fwd="rtl", table=32, rate=r, stats=st)
        assert st["due"] == [int((800 * i + 799) * Fraction(r)) for i in range(12)]
        assert st["backlog"] == 0
        assert max(st["lag"]) <= 40 + span_timing.K_DEFAULT + 6 + 4


def test_model_backlog_at_fraction():
    """A line of 3-slot Eval2s each on 200 columns (~200 clocks a pass) against a bus of
    one slot per 25/8 clocks: the backlog the model reports is last_due(t) - j, so it
    must grow by about one slot per 25/8 clocks of waiting, more than at ratio 4."""
    one = 1 << isa.FRAC_BITS
    cmds = [isa.Command("EVAL", 0, 200, (one, one // 8, one // 64))] * 60 + [
        isa.Command("REFRESH")]
    slots = isa.serialise(cmds)
    got = {}
    for r in (Fraction(25, 8), Fraction(4)):
        st: dict = {}
        span_timing.simulate(slots, 648, prefetch=True, fwd="rtl", table=32, rate=r, stats=st)
        got[r] = st["backlog"]
    assert got[Fraction(25, 8)] > got[Fraction(4)] > 0


@pytest.mark.parametrize("text,want", [("3", Fraction(3)), ("3.125", Fraction(25, 8)),
                                       ("25/8", Fraction(25, 8)), (" 25/8 ", Fraction(25, 8)),
                                       ("1", Fraction(1)), (4, Fraction(4))])
def test_parse_ratio(text, want):
    assert parse_ratio(text) == want


@pytest.mark.parametrize("text", ["abc", "", "3,125", "1/0", "25/", "0.5", "0", "-3", "nan"])
def test_parse_ratio_rejects(text):
    with pytest.raises(ValueError, match=re.escape(repr(text))):
        parse_ratio(text)


def test_cli_ratio_abc_is_a_clear_error():
    """`diffengine bench span --ratio abc`: argparse's usage error naming the option and
    the text, exit 2, before anything runs."""
    res = subprocess.run([sys.executable, "-m", "diffengine", "bench", "span", "--ratio", "abc"],
                         capture_output=True, text=True, cwd=REPO, timeout=120)
    assert res.returncode == 2
    assert "--ratio" in res.stderr and "'abc': not a number" in res.stderr, res.stderr


def test_board_ratio_from_the_pll():
    """The default ratio comes from the shell's PLL dividers: 25/8, and agrees with the
    frequencies the same file declares to nextpnr (FREQUENCY_PIN_CLKOS2 / _CLKOS)."""
    b = span.board()
    assert b["ratio"] == Fraction(25, 8)
    assert (b["pixel_mhz"], b["core_mhz"]) == (25.0, 78.125)
    text = (REPO / span.BOARD_SHELL).read_text()
    core = Fraction(re.search(r'FREQUENCY_PIN_CLKOS2 = "([\d.]+)"', text).group(1))
    pix = Fraction(re.search(r'FREQUENCY_PIN_CLKOS = "([\d.]+)"', text).group(1))
    assert b["ratio"] == core / pix
    assert b["latency_px"] == 300 and b["fifo_slots"] == 2048


def _record(lags: dict, worst: int = 2000, latency: int = 300) -> dict:
    """A synthetic record: two scenes x r, g, b at ratios 25/8 and 3; every line 1,000
    clocks unpaced but one of `worst`; paced lags 661 but those given in `lags`
    ({(scene, ch, ratio): [lag, ...]})."""
    rows = []
    for sc in ("teapot", "cad"):
        for ch in "rgb":
            free = [1000] * 480
            free[17] = worst
            paced = {}
            for r in ("25/8", "3"):
                lag = lags.get((sc, ch, r), [661] * 480)
                paced[r] = {"lag_clocks": lag, "backlog_slots": 0}
            rows.append({"scene": sc, "ch": ch, "slots": [300] * 480,
                         "free": {"clocks_per_line": free}, "paced": paced})
    return {"rows": rows, "ratio": "25/8", "ratios": ["25/8", "3"], "latency_px": latency}


def test_verdict_passes():
    ok, text = span.verdict(_record({}))
    assert ok and "Verdict: PASS" in text
    assert "cad 2,000 (80.0 %)" in text              # of 2,500 clocks
    assert "cad lag 661 (70.5 %), 0 late lines" in text   # of 300 x 25/8 = 937.5


def test_verdict_fails_on_one_late_line():
    """One line of one colour 1 clock past SpanLatency (938 > 937.5) fails (b) alone."""
    lag = [661] * 480
    lag[250] = 938
    ok, text = span.verdict(_record({("cad", "g", "25/8"): lag}))
    assert not ok
    assert "Verdict: FAIL, (b) failed." in text
    assert "cad lag 938 (100.1 %), 1 late line" in text
    # 937 is on time; the same lag at ratio 3 (900 clocks) is late there only.
    lag[250] = 937
    assert span.verdict(_record({("cad", "g", "25/8"): lag}))[0]
    ok3, text3 = span.verdict(_record({("cad", "g", "3"): lag}), Fraction(3))
    assert not ok3 and "(b) failed" in text3


def test_verdict_fails_on_the_worst_line():
    """A worst line over 90 % of the line period fails (a): 2,251 of 2,500 clocks."""
    ok, text = span.verdict(_record({}, worst=2251))
    assert not ok and "Verdict: FAIL, (a) failed." in text and "NOT within 90 %" in text
    assert span.verdict(_record({}, worst=2250))[0]
    lag = [661] * 480
    lag[3] = 5000
    ok, text = span.verdict(_record({("teapot", "r", "25/8"): lag}, worst=2400))
    assert not ok and "(a) and (b) failed" in text


def test_verdict_without_the_paced_run_fails():
    """A ratio with no paced runs in the record cannot pass (b)."""
    ok, text = span.verdict(_record({}), Fraction(4))
    assert not ok and "not measured at ratio 4" in text
