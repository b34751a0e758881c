"""A clock-level timing model of de_span_array's front end, issue, pipeline and drain
(rtl/varray/de_span_array.sv), for weighing levers before building them in RTL.

It models only *when* things happen (which slot is taken, which column token is issued,
when a pass retires, when the drain puts out a line's last pixel), not the column state:
the pixels come from the Verilated RTL in `diffengine bench span`, and this model is
checked against that RTL's clocks per line there (same streams, same run). Options:

  gap       idle clocks the driver leaves after each slot it hands over (a FIFO with a
            backlog leaves 0; the cocotb driver used to leave 1);
  prefetch  the RTL's Prefetch: no load clock between passes;
  fwd       the RTL's Forward ("rtl"), or none, or an ideal bypass (never a wait);
  engines   more engines per colour over disjoint column ranges (an estimate);
  rate      paced like the display's bus: one slot per `rate` core clocks on average,
            a Fraction (the board's 25/8) or an integer; slot k is due at clock
            floor(k * rate) (slot_due), the pacer tb/de_span_array's driver uses too.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from .. import isa

K_DEFAULT = 4
NPASS = 16


@dataclass
class Pass:
    rfr: bool
    cols: list          # the columns the pass walks, in order
    nslot: int


def parse_ratio(text) -> Fraction:
    """A clock ratio (core clocks per pixel clock) from "3", "3.125" or "25/8" (or an int
    or Fraction), exactly; ValueError with a message naming the text if it is not a
    number of at least 1 (the array takes at most one slot per core clock)."""
    try:
        r = Fraction(text.strip()) if isinstance(text, str) else Fraction(text)
    except (ValueError, TypeError, ZeroDivisionError):
        raise ValueError(f"clock ratio {text!r}: not a number (give e.g. 3, 3.125 or 25/8)") \
            from None
    if r < 1:
        raise ValueError(f"clock ratio {text!r}: below 1 (the array takes one slot per "
                         f"core clock at most)")
    return r


def slot_due(k: int, rate) -> int:
    """The core clock (from the first slot's) at which slot k of the paced bus is due:
    floor(k * rate), exact for a fractional rate (25/8: 0, 3, 6, 9, 12, 15, 18, 21, 25)."""
    r = Fraction(rate)
    return k * r.numerator // r.denominator


def last_due(t: int, rate) -> int:
    """The last slot due by clock t: the largest j with slot_due(j) <= t, i.e.
    ceil((t + 1) / rate) - 1 (t // rate for an integer rate). The backlog while slot k
    waits at clock t is last_due(t) - k."""
    r = Fraction(rate)
    return -(-(t + 1) * r.denominator // r.numerator) - 1


def passes_of(slots, ncols: int = 648, max_slots: int = K_DEFAULT) -> list[list[Pass]]:
    """The stream's passes, line by line, as the front end cuts them (one list per
    Refresh; the Refresh itself is the last pass of each list)."""
    lines: list[list[Pass]] = [[]]
    for p, _, _ in _front_end(slots, ncols, max_slots, 0):
        lines[-1].append(p)
        if p.rfr:
            lines.append([])
    return lines[:-1]


def _paced(slots, htotal: int):
    """Each line padded with Nops to `htotal` slots before its Refresh (the display's bus)."""
    line = []
    for sl in slots:
        if sl[0] == isa.REFRESH:
            yield from line
            yield from [(isa.NOP, 0)] * (htotal - 1 - len(line))
            yield sl
            line = []
        else:
            line.append(sl)


def _front_end(slots, ncols: int, k: int, gap: int, room=None, rate=0,
               htotal: int = 800, stats: dict | None = None):
    """The passes in stream order with the clock each is written into the pass table
    (commit; a Refresh is written when it is taken) and the index of its line. The front
    end takes a slot a clock (plus `gap` idle clocks of the driver after each) and
    spends a clock on each commit of a pending group (the slot that closes it waits).
    room(i): the first clock pass i finds a free table entry. rate: slot j of the padded
    stream is due at clock slot_due(j, rate) (paced like the bus; a slot not taken when
    due waits, and waiting slots go in back to back); stats gets the largest backlog in
    slots and the clock each Refresh was due."""
    t, line, n = 0, 0, 0
    open_, pend_cols, nslot, eff = False, None, 0, 0
    stats = stats if stats is not None else {}
    stats.update(backlog=0, due=[])

    def at_room(c):
        return max(c, room(n)) if room else c

    src = _paced(slots, htotal) if rate else slots
    for j, (ident, data) in enumerate(src):
        due = slot_due(j, rate) if rate else 0
        t = max(t, due)
        addr = bool(ident & isa.ID_ADDR)
        ref = bool(ident & isa.ID_REFRESH) and not addr
        is_dat = not addr and not ref and bool(ident & (isa.ID_DATA | isa.ID_ACC))
        pending = open_ and (nslot or eff)
        if pending and (not is_dat or nslot == k):
            t = at_room(t)
            yield Pass(False, pend_cols, nslot), t, line
            n += 1
            t += 1
            nslot, eff = 0, 0
        if is_dat:
            nslot += int(open_)
        else:
            open_ = False
            if addr:
                sub = ident & isa.SUB_MASK
                b0, b1 = data & 0xFFF, (data >> 12) & 0xFFF
                if sub == isa.SUB_PERIODIC:
                    pend_cols = list(range(b1, ncols, b0 or 4096))
                else:
                    pend_cols = list(range(b0, min(b0 + b1, ncols)))
                open_, nslot, eff = True, 0, int(sub in (isa.SUB_EVAL0, isa.SUB_DIS))
            elif ref:
                t = at_room(t)
                stats["due"].append(due)
                yield Pass(True, [], 0), t, line
                n += 1
                line += 1
        if rate:
            stats["backlog"] = max(stats["backlog"], last_due(t, rate) - j)
        t += 1 + gap


def simulate(slots, ncols: int = 648, k: int = K_DEFAULT, *, gap: int = 0,
             prefetch: bool = False, fwd: str = "none", engines: int = 1,
             table: int = NPASS, rate=0, htotal: int = 800,
             stats: dict | None = None) -> list[int]:
    """Clocks per line (from one Refresh token's issue to the next) of de_span_array fed
    `slots` back to back (gap 0) or with `gap` idle clocks after each slot.

    fwd: "none" - a token waits while an earlier token of its column is anywhere between
    issue and write back (K+4 clocks apart at least: the RTL with Forward = 0); "rtl" -
    only while it is in the first K stages (K+1 apart: Forward = 1); "ideal" - never.
    prefetch: the next pass goes into the issue registers in the clock its predecessor's
    last token issues (Prefetch = 1), else a clock later. engines: E engines, each over
    NumCols/E consecutive columns, walking the parts of each pass at the same time (an
    estimate; the value chain handed across a boundary without a wait). table: pass
    table entries (the RTL's 2**PassAw). The defaults are the RTL before the levers.
    """
    dist = {"none": k + 4, "rtl": k + 1, "ideal": 1}[fwd]
    bounds = [ncols * e // engines for e in range(engines + 1)]
    retire = []                               # clock each pass leaves the table

    def room(i):
        # The table has room for pass i once pass i - (table - 1) has retired.
        return retire[i - (table - 1)] + 1 if i >= table - 1 else 0

    stats = stats if stats is not None else {}
    fe = _front_end(slots, ncols, k, gap, room, rate, htotal, stats)
    last = [dict() for _ in range(engines)]   # column -> clock of its last token
    tok_free = [0] * engines                  # next clock each engine may issue a token
    fin = -1                                  # clock of the previous pass's last token
    xfer_prev = -1
    drain_free = 0
    refresh_at = []
    for p, c_commit, _ in fe:
        load = max(c_commit + 1, xfer_prev)              # decoded into nxt
        xfer = max(load + 1, fin if prefetch else fin + 1)
        xfer_prev = xfer
        start = xfer + 1
        if p.rfr:
            t = max(start, drain_free, max(tok_free))
            drain_free = t + k + 6 + ncols
            fin = t
            refresh_at.append(t)
        else:
            parts = [[] for _ in range(engines)]
            for col in p.cols:
                e = 0
                while col >= bounds[e + 1]:
                    e += 1
                parts[e].append(col)
            if not p.cols:
                fin = max(start, tok_free[0])
                tok_free[0] = fin + 1
            else:
                ends = []
                for e in range(engines):
                    if not parts[e]:
                        continue
                    t = max(start, tok_free[e])
                    lc = last[e]
                    for col in parts[e]:
                        t = max(t, lc.get(col, -dist) + dist)
                        lc[col] = t
                        t += 1
                    tok_free[e] = t
                    ends.append(t - 1)
                fin = max(ends)
        retire.append(fin + k + 3)
    # A line's last pixel leaves the drain ~NumCols + K + 6 clocks after its Refresh
    # token; paced, the lag is counted from the clock the Refresh was due.
    stats["lag"] = [r + ncols + k + 6 - d for r, d in zip(refresh_at, stats["due"])]
    return [b - a for a, b in zip([0] + refresh_at, refresh_at)]
