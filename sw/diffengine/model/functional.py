"""Functional-level golden model of the x-processor array (docs/isa.md §5-§7).

The array is systolic and commands never overtake each other, so the architectural
state after a line equals executing each *command* across all columns before the next
one. This model does exactly that, vectorised over columns with numpy. It is bit-exact
on pixels with the slot-by-slot structural model (`structural.py`), which is the
reference for *how* the hardware gets there; this one is the reference for *what* it
computes, and is fast enough to render whole frames.

Why the arithmetic is exact: every register is a 36-bit word and 2^36 divides 2^64, so
uint64 sums, products and cumulative sums taken modulo 2^64 and masked to 36 bits at
the end are exact modulo 2^36 (which is what the hardware computes). Forward
differencing from a start vector (v_0 .. v_p) gives, n columns later,
val_j(n) = sum_k C(n, k) v_{j+k}; the binomials are tabulated mod 2^64 once.
A span is split only where a protect flag relevant to the Eval's order is raised.

With the §7.7 carry bug the adder is not linear, so those Evals take a per-column
Python path through `bug_add` (correct, slower; only tests and demos use it).

`render` batches every line of a frame (`_Plan`), Set/SetP/Dis/Eval0/Acc_mode
included: a scalar walk of each line turns its Evals into polynomial pieces (cut where a
protect flag substitutes a register, split around disabled columns); a piece of degree
<= 2 (Eval1..Eval3, by far the common case) becomes six impulses in three difference
arrays, and three cumulative sums per row give every D for the whole frame at once.
Only the carry bug goes through the per-command path (`run_line`), which is also the
reference the batch is tested against (`_render_reference`).
"""
from __future__ import annotations

import warnings
from bisect import bisect_left
from dataclasses import dataclass
from math import comb

import numpy as np

from .. import isa

MASK = np.uint64(isa.WORD_MASK)
SIGN = np.uint64(1 << (isa.WORD_BITS - 1))
MAX_COLS = 4096 + 8
_U64 = (1 << 64) - 1


def _binomials(kmax: int, n: int) -> list[np.ndarray]:
    """BINOM[k][n] = C(n, k) mod 2^64, via C(n, k) = sum_{m<n} C(m, k-1)."""
    rows = [np.ones(n, dtype=np.uint64)]
    for _ in range(kmax):
        prev = rows[-1]
        row = np.zeros(n, dtype=np.uint64)
        row[1:] = np.cumsum(prev[:-1], dtype=np.uint64)
        rows.append(row)
    return rows


BINOM = _binomials(isa.MAX_EVAL_ORDER, MAX_COLS)


def bug_add(a: int, b: int) -> int:
    """The faulty adder of §7.7: the carry out of bit 23 lands in bit 25."""
    return isa.add_word(a, b, carry_bug=True)  # generated from spec/isa.toml [adder]


def _add(a: int, b: int) -> int:
    return isa.add_word(a, b)


def _prot_levels(order: int) -> dict[int, int]:
    """Difference level -> register whose protect flag an order-p Eval honours (§6)."""
    if order <= 2:
        return {j: isa.REG_A + j for j in range(order + 1)}  # A=I, B=dI, C=ddI
    return {order - 1: isa.REG_B, order: isa.REG_C}  # A is scratch for p >= 3


def _reg_levels(order: int) -> dict[int, int]:
    """Register -> difference level it holds after an order-p Eval in an active PE."""
    if order <= 2:
        return {isa.REG_A + j: j for j in range(order + 1)}
    return {isa.REG_A: 0, isa.REG_B: order - 1, isa.REG_C: order}


@dataclass
class LineState:
    """Architectural state of every PE of the array (docs/isa.md §6).

    A, B, C, D are 36-bit words in uint64 arrays; pA/pB/pC/dis/lock are bool arrays;
    acc_mode is common to all PEs (Acc_mode reaches every PE in stream order).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    pA: np.ndarray
    pB: np.ndarray
    pC: np.ndarray
    dis: np.ndarray
    lock: np.ndarray
    acc_mode: bool = False

    @classmethod
    def reset(cls, width: int) -> "LineState":
        z = lambda dt: np.zeros(width, dtype=dt)  # noqa: E731
        return cls(z(np.uint64), z(np.uint64), z(np.uint64), z(np.uint64),
                   z(bool), z(bool), z(bool), z(bool), z(bool))

    @property
    def width(self) -> int:
        return len(self.D)

    def reg(self, r: int) -> np.ndarray:
        return (None, self.A, self.B, self.C)[r]

    def prot(self, r: int) -> np.ndarray:
        return (None, self.pA, self.pB, self.pC)[r]

    def pixels(self) -> np.ndarray:
        return ((self.D >> np.uint64(isa.FRAC_BITS)) & np.uint64(isa.BLOCK_MASK)).astype(np.uint16)


class _Line:
    """Executes the commands of one scanline on a LineState."""

    def __init__(self, width: int, carry_bug: bool):
        self.s = LineState.reset(width)
        self.bug = carry_bug
        self.any_prot = False   # a Set has run in this line: spans may need splitting
        self.any_gate = False   # a Dis/Eval0 has run: D writes may be suppressed

    def span(self, x: int, dx: int) -> tuple[int, int]:
        """Active columns [x, x+dx) clipped to the array (§5)."""
        w = self.s.width
        return min(x, w), min(x + dx, w)

    def run(self, c: isa.Command) -> None:
        op = c.op
        if op == "EVAL":
            self.eval(c)
        elif op == "EVAL0":
            self.eval0(c)
        elif op in ("SETI", "SETDI", "SETDDI"):
            a, e = self.span(c.x, c.dx)
            self.set(isa.SET_REG[op], slice(a, e), c.values[0])
        elif op in ("SETPI", "SETPDI", "SETPDDI"):
            step = c.dx if c.dx else 4096  # countdown reloads with dX-1 mod 4096
            self.set(isa.SET_REG[op], slice(min(c.x, self.s.width), None, step), c.values[0])
        elif op == "DIS":
            a, e = self.span(c.x, c.dx)
            self.s.dis[a:e] = True
            self.any_gate |= e > a
        elif op == "ACCMODE":
            self.s.acc_mode = bool(c.values[0])
        elif op == "NOP":
            pass
        elif op == "REFRESH":
            raise ValueError("Refresh inside a line")
        else:
            raise ValueError(f"unknown command {op!r}")

    def set(self, r: int, cols: slice, value: int) -> None:
        self.s.reg(r)[cols] = np.uint64(isa.to_word(value))
        self.s.prot(r)[cols] = True
        self.any_prot = True

    def _end_of_eval(self, a: int, e: int) -> None:
        """What every Eval does last in each active PE: clear protect and dis flags."""
        s = self.s
        if self.any_prot:
            s.pA[a:e] = s.pB[a:e] = s.pC[a:e] = False
        if self.any_gate:
            s.dis[a:e] = False

    def eval0(self, c: isa.Command) -> None:
        a, e = self.span(c.x, c.dx)
        if e <= a:
            return
        s = self.s
        ok = ~(s.lock[a:e] | s.dis[a:e])
        s.D[a:e][ok] = np.uint64(c.values[0] << isa.FRAC_BITS)
        s.lock[a:e] |= ok
        self.any_gate = True
        self._end_of_eval(a, e)

    def eval(self, c: isa.Command) -> None:
        a, e = self.span(c.x, c.dx)
        if e <= a:
            return
        p = c.order
        s = self.s
        vin = [isa.to_word(v) for v in c.values]
        levels = _prot_levels(p)
        if self.bug:
            self._eval_columns(a, e, p, vin, levels)
        else:
            cuts = [a]
            if self.any_prot:
                hit = np.zeros(e - a, dtype=bool)
                for r in set(levels.values()):
                    hit |= s.prot(r)[a:e]
                cuts += [a + i for i in np.flatnonzero(hit).tolist() if i]
            cuts.append(e)
            for k in range(len(cuts) - 1):
                vin = self._segment(cuts[k], cuts[k + 1], p, vin, levels)
        self._end_of_eval(a, e)

    def _substitute(self, col: int, vin: list[int], levels: dict[int, int]) -> list[int]:
        """Incoming differences at a PE, with protected registers overriding them."""
        s = self.s
        val = list(vin)
        if self.any_prot:
            for j, r in levels.items():
                if s.prot(r)[col]:
                    val[j] = int(s.reg(r)[col])
        return val

    def _segment(self, a: int, e: int, p: int, vin: list[int], levels) -> list[int]:
        """Columns [a, e) with no protect flag after column a: closed-form differencing."""
        s = self.s
        v = self._substitute(a, vin, levels)
        n = e - a

        def level(j: int) -> np.ndarray:
            acc = np.full(n, v[j], dtype=np.uint64)
            for k in range(1, p - j + 1):
                if v[j + k]:
                    acc += BINOM[k][:n] * np.uint64(v[j + k])
            return acc & MASK

        val0 = level(0)
        for r, j in _reg_levels(p).items():
            s.reg(r)[a:e] = val0 if j == 0 else level(j)
        self._accumulate(a, e, val0)
        # differences entering column e: sum_k C(n, k) v_{j+k}
        return [sum(comb(n, k) * v[j + k] for k in range(p - j + 1)) & isa.WORD_MASK
                for j in range(p + 1)]

    def _accumulate(self, a: int, e: int, val0: np.ndarray) -> None:
        """ACC slot: D += A unless locked, disabled, or (Acc_mode and A < 0)."""
        s = self.s
        if not self.any_gate and not s.acc_mode:
            s.D[a:e] = (s.D[a:e] + val0) & MASK
            return
        ok = ~(s.lock[a:e] | s.dis[a:e])
        if s.acc_mode:
            ok &= (val0 & SIGN) == 0
        d = s.D[a:e]
        d[ok] = (d[ok] + val0[ok]) & MASK

    def _eval_columns(self, a: int, e: int, p: int, vin: list[int], levels) -> None:
        """Column-by-column Eval through the faulty adder (§7: nonlinear, no shortcut)."""
        s = self.s
        regs = _reg_levels(p)
        for col in range(a, e):
            val = self._substitute(col, vin, levels)
            for r, j in regs.items():
                s.reg(r)[col] = val[j]
            a_neg = bool(val[0] >> (isa.WORD_BITS - 1))
            if not (s.lock[col] or s.dis[col] or (s.acc_mode and a_neg)):
                s.D[col] = bug_add(int(s.D[col]), val[0])
            vin = [bug_add(val[j], val[j + 1]) for j in range(p)] + [val[p]]


def run_line(commands, width: int = 640, carry_bug: bool = False) -> tuple[np.ndarray, LineState]:
    """Execute one scanline. A Refresh, if present, must be the last command.

    Returns the pixels the (final) Refresh outputs and the state just before it clears
    the array, so tests can look at every register.
    """
    cmds = list(commands)
    if cmds and cmds[-1].op == "REFRESH":
        cmds = cmds[:-1]
    line = _Line(width, carry_bug)
    for c in cmds:
        line.run(c)
    return line.s.pixels(), line.s


_W = isa.WORD_MASK


def _advance(v0: int, v1: int, v2: int, n: int) -> tuple[int, int, int]:
    """Differences (order <= 2) n columns further on: sum_k C(n, k) v_{j+k} mod 2^36."""
    return ((v0 + n * v1 + (n * (n - 1) >> 1) * v2) & _W, (v1 + n * v2) & _W, v2)


def _advance_n(v: list[int], n: int) -> list[int]:
    """The same for any order p = len(v) - 1."""
    p = len(v) - 1
    return [sum(comb(n, k) * v[j + k] for k in range(p - j + 1)) & _W for j in range(p + 1)]


def _expl(start: int, n: int, acc: bool, v) -> tuple[int, ...]:
    """A piece expanded column by column: start, n, Acc_mode, v_0 .. v_7 (zero-padded)."""
    return (start, n, acc, *v) + (0,) * (isa.MAX_EVAL_ORDER + 1 - len(v))


class _Plan:
    """Frame-wide batch of lines (any Eval order, no carry bug).

    Each line is walked command by command with Python scalars only: the protect, dis and
    lock flags that are raised are few, so they live in dicts keyed by column (a protect
    dict holds the register value its Set wrote, which is what the flag substitutes), with
    sorted key lists for range queries. An Eval becomes pieces [s, t) that each add one
    polynomial val0(m) = v0 + m v1 + C(m, 2) v2 to D: the Eval is cut where a relevant
    protect flag substitutes a register (exactly the cuts of `_Line.eval`), and a cut
    piece is split again around columns whose dis flag suppresses the ACC. Pieces with
    Acc_mode off go into difference arrays (`finish`); with Acc_mode on, the sign of
    every value matters, so they are expanded column by column (vectorised at the end),
    as are the pieces of Eval4+ (degree > 2, rare), from the tabulated binomials.
    Eval0 locks D, and nothing changes a locked D, so the first Eval0 that gets through
    simply overrides the column's final D.
    """

    def __init__(self, width: int):
        self.width = width
        self.stride = width + 3
        # pieces by order k = 0..2, flat: row offset, X, dX (clipped later), v_0 .. v_k
        self.poly: list[list[int]] = [[], [], []]
        self.expl: list[tuple[int, ...]] = []  # Acc_mode or Eval4+: see `_expl`
        self.over: list[tuple[int, int]] = []  # flat column, Eval0 intensity
        self.rows = 0

    def line(self, cmds) -> None:
        """Plan one line (its commands, a final Refresh allowed) as the next row."""
        w = self.width
        base = self.rows * self.stride
        poly, expl = self.poly, self.expl
        poly2 = poly[2]
        pv: list[dict[int, int]] = [{}, {}, {}]  # A, B, C: column -> Set value
        pk: list[list[int]] = [[], [], []]  # sorted keys of pv
        dis: set[int] = set()
        dk: list[int] = []
        lock: dict[int, int] = {}
        acc = False
        quiet = True  # no flag raised, Acc_mode off: an Eval is one piece, as written
        for c in cmds:
            op = c.op
            if op == "EVAL":
                vals = c.values
                p = len(vals) - 1
                if p > 2:
                    self._eval_high(c, base, pv, pk, dis, dk, acc)
                    quiet = not (pk[0] or pk[1] or pk[2] or dk or acc)
                    continue
                if quiet:  # the common case
                    poly[p].extend((base, c.x, c.dx) + vals)
                    continue
                a = c.x if c.x < w else w
                e = c.x + c.dx
                if e > w:
                    e = w
                if e <= a:
                    continue
                v0 = vals[0] & _W
                v1 = vals[1] & _W if p >= 1 else 0
                v2 = vals[2] & _W if p >= 2 else 0
                cuts = {a}
                for r in range(p + 1):
                    ks = pk[r]
                    if ks:
                        i, j = bisect_left(ks, a), bisect_left(ks, e)
                        if i < j:
                            cuts.update(ks[i:j])
                cuts = sorted(cuts)
                cuts.append(e)
                for k in range(len(cuts) - 1):
                    s, t = cuts[k], cuts[k + 1]
                    if s in pv[0]:  # protect flags substitute the incoming differences
                        v0 = pv[0][s]
                    if p >= 1 and s in pv[1]:
                        v1 = pv[1][s]
                    if p >= 2 and s in pv[2]:
                        v2 = pv[2][s]
                    q = s
                    if dk:  # columns whose ACC a Dis suppresses: skip them
                        i, j = bisect_left(dk, s), bisect_left(dk, t)
                        for col in dk[i:j]:
                            if col > q:
                                if acc:
                                    expl.append(_expl(base + q, col - q, True,
                                                      _advance(v0, v1, v2, q - s)))
                                else:
                                    poly2.extend((base, q, col - q, *_advance(v0, v1, v2, q - s)))
                            q = col + 1
                    if t > q:
                        if acc:
                            expl.append(_expl(base + q, t - q, True, _advance(v0, v1, v2, q - s)))
                        else:
                            poly2.extend((base, q, t - q, *_advance(v0, v1, v2, q - s)))
                    v0, v1, v2 = _advance(v0, v1, v2, t - s)
                self._clear(a, e, pv, pk, dis, dk)
                quiet = not (pk[0] or pk[1] or pk[2] or dk or acc)
            elif op in ("SETI", "SETDI", "SETDDI", "SETPI", "SETPDI", "SETPDDI"):
                r = isa.SET_REG[op] - isa.REG_A
                if op.startswith("SETP"):
                    cols = range(min(c.x, w), w, c.dx if c.dx else 4096)
                else:
                    cols = range(min(c.x, w), min(c.x + c.dx, w))
                if cols:
                    pv[r].update(dict.fromkeys(cols, c.values[0] & _W))
                    pk[r] = sorted(pv[r])
                    quiet = False
            elif op == "DIS":
                cols = range(min(c.x, w), min(c.x + c.dx, w))
                if cols:
                    dis.update(cols)
                    dk = sorted(dis)
                    quiet = False
            elif op == "EVAL0":
                a, e = min(c.x, w), min(c.x + c.dx, w)
                if e <= a:
                    continue
                for col in range(a, e):
                    if col not in lock and col not in dis:
                        lock[col] = c.values[0]
                dk = self._clear(a, e, pv, pk, dis, dk)
                quiet = not (pk[0] or pk[1] or pk[2] or dk or acc)
            elif op == "ACCMODE":
                acc = bool(c.values[0])
                quiet = not (pk[0] or pk[1] or pk[2] or dk or acc)
            elif op == "NOP" or op == "REFRESH":
                pass
            else:
                raise ValueError(f"unknown command {op!r}")
        self.over.extend((base + col, i) for col, i in lock.items())
        self.rows += 1

    def _eval_high(self, c: isa.Command, base: int, pv, pk, dis, dk, acc: bool) -> None:
        """An Eval of order p >= 3: only SetdI (B, d^(p-1)) and SetddI (C, d^p) count."""
        w = self.width
        a, e = min(c.x, w), min(c.x + c.dx, w)
        if e <= a:
            return
        p = c.order
        v = [x & _W for x in c.values]
        cuts = {a}
        for r in (1, 2):
            ks = pk[r]
            if ks:
                i, j = bisect_left(ks, a), bisect_left(ks, e)
                cuts.update(ks[i:j])
        cuts = sorted(cuts)
        cuts.append(e)
        for k in range(len(cuts) - 1):
            s, t = cuts[k], cuts[k + 1]
            if s in pv[1]:
                v[p - 1] = pv[1][s]
            if s in pv[2]:
                v[p] = pv[2][s]
            q = s
            for col in dk[bisect_left(dk, s):bisect_left(dk, t)] if dk else ():
                if col > q:
                    self.expl.append(_expl(base + q, col - q, acc, _advance_n(v, q - s)))
                q = col + 1
            if t > q:
                self.expl.append(_expl(base + q, t - q, acc, _advance_n(v, q - s)))
            v = _advance_n(v, t - s)
        self._clear(a, e, pv, pk, dis, dk)

    @staticmethod
    def _clear(a, e, pv, pk, dis, dk):
        """End of an Eval active in [a, e): its protect and dis flags drop."""
        for r in range(3):
            ks = pk[r]
            if ks:
                i, j = bisect_left(ks, a), bisect_left(ks, e)
                if i < j:
                    for col in ks[i:j]:
                        del pv[r][col]
                    del ks[i:j]
        if dk:
            i, j = bisect_left(dk, a), bisect_left(dk, e)
            if i < j:
                dis.difference_update(dk[i:j])
                del dk[i:j]
        return dk

    def finish(self) -> np.ndarray:
        """Pixels of every planned line.

        A piece at s of length L adding f(m) = a + b*m + c*C(m,2) (m = column - s) is the
        impulses G1[s] += a, G2[s+1] += b, G3[s+2] += c, and, so that f stops at e = s+L,
        the continuation a + bL + cC(L,2) + (b + cL)m' + cC(m',2) (m' = column - e,
        Vandermonde) subtracted at e, e+1, e+2. D = cumsum(G1 + cumsum(G2 + cumsum(G3))).
        """
        stride, width, n_lines = self.stride, self.width, self.rows
        g = np.zeros((3, n_lines * stride), dtype=np.uint64)
        t = np.zeros((sum(len(q) // (k + 4) for k, q in enumerate(self.poly)), 6), np.int64)
        i = 0
        for k, q in enumerate(self.poly):
            rec = np.array(q, dtype=np.int64).reshape(-1, k + 4)
            t[i:i + len(rec), :k + 4] = rec
            i += len(rec)
        # clip [X, X+dX) to the array (pieces of the flag path already are)
        x = np.minimum(t[:, 1], width)
        n = np.minimum(t[:, 1] + t[:, 2], width) - x
        t = t[n > 0]
        if len(t):
            base = t[:, 0] + x[n > 0]
            n = n[n > 0]
            # signed or 36-bit values -> uint64 (mod 2^64 is a multiple of mod 2^36)
            ua, ub, uc = (t[:, k].view(np.uint64) for k in (3, 4, 5))
            nu = n.view(np.uint64)
            tri = (nu * (nu - np.uint64(1))) >> np.uint64(1)  # C(L,2), exact: n < 2^32
            end = base + n
            np.add.at(g[0], base, ua)
            np.add.at(g[1], base + 1, ub)
            np.add.at(g[2], base + 2, uc)
            np.add.at(g[0], end, (ua + ub * nu + uc * tri) * np.uint64(_U64))  # times -1
            np.add.at(g[1], end + 1, (ub + uc * nu) * np.uint64(_U64))
            np.add.at(g[2], end + 2, uc * np.uint64(_U64))
        g = g.reshape(3, n_lines, stride)
        d = np.cumsum(g[0] + np.cumsum(g[1] + np.cumsum(g[2], axis=1, dtype=np.uint64),
                                       axis=1, dtype=np.uint64), axis=1, dtype=np.uint64)
        flat = d.reshape(-1)
        if self.expl:  # val0(m) = sum_k C(m, k) v_k; with Acc_mode only where A >= 0
            t = np.array(self.expl, dtype=np.int64)
            n = t[:, 1]
            first = np.cumsum(n) - n
            piece = np.repeat(np.arange(len(t)), n)
            m = np.arange(int(n.sum()), dtype=np.int64) - first[piece]
            u = t[:, 3:].view(np.uint64)
            val = u[piece, 0].copy()
            for k in range(1, u.shape[1]):
                if u[:, k].any():
                    val += BINOM[k][m] * u[piece, k]
            val &= MASK
            ok = (t[piece, 2] == 0) | ((val & SIGN) == 0)
            np.add.at(flat, (t[piece, 0] + m)[ok], val[ok])
        if self.over:  # Eval0: a locked D is the Eval0 intensity, whatever else ran
            t = np.array(self.over, dtype=np.int64)
            flat[t[:, 0]] = t[:, 1].view(np.uint64) << np.uint64(isa.FRAC_BITS)
        d = d[:, :width] & MASK
        return ((d >> np.uint64(isa.FRAC_BITS)) & np.uint64(isa.BLOCK_MASK)).astype(np.uint16)


def _render_reference(commands, width: int = 640, carry_bug: bool = False) -> np.ndarray:
    """`render` through the per-command path only (`run_line` on every line).

    The reference the frame batch (`_Plan`) is tested against; slow.
    """
    lines = isa.split_lines(commands)
    if lines and lines[-1][-1].op != "REFRESH":
        lines.pop()
    out = np.zeros((len(lines), width), dtype=np.uint16)
    for i, ln in enumerate(lines):
        out[i] = run_line(ln, width, carry_bug)[0]
    return out


def render(commands, width: int = 640, carry_bug: bool = False) -> np.ndarray:
    """Render a command stream: one row of `width` pixels per Refresh.

    Commands after the last Refresh form an unterminated line; it is not shown and a
    warning says how many commands it held.
    """
    lines = isa.split_lines(commands)
    if lines and lines[-1][-1].op != "REFRESH":
        warnings.warn(f"{len(lines[-1])} command(s) after the last Refresh ignored",
                      stacklevel=2)
        lines.pop()
    out = np.zeros((len(lines), width), dtype=np.uint16)
    if carry_bug:  # the faulty adder is not linear: command by command, column by column
        for i, ln in enumerate(lines):
            out[i] = run_line(ln, width, carry_bug)[0]
    elif lines:
        plan = _Plan(width)
        for ln in lines:
            plan.line(ln)
        out[:] = plan.finish()
    return out
