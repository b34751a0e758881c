"""Multiresolution spline coding of scanlines for the Difference Engine (§7.7.2).

What the array evaluates cheaply
--------------------------------
One `Eval2 (0, W, I, dI)` plus a `SetdI (k, g)` per knot draws a piecewise-linear
scanline: the Set overrides, in PE k, the first difference that forward differencing
brings, so the slope changes at k and the value stays continuous. Likewise
`Eval3 (0, W, I, dI, ddI)` plus `SetddI (k, g)` knots draws a discrete quadratic spline
(C1: value and slope continuous, curvature changes at k). In both cases the d-th
difference of the line, Δ^d s(n), is piecewise constant and a knot k sets its value
for n >= k; a knot costs 2 instructions (ADDR + SET), an Eval d+3, Refresh 1. So the
cost of a line is set by its number of knots, not by the span lengths - the source's
point in §7.7.2.

Multiresolution analysis
------------------------
Per scanline a B-spline pyramid: at scale h = 2^j (j = J..1) the discrete B-splines
of degree d, box_h^(d+1) (a box of h ones convolved d+1 times), on a lattice of
spacing h; least squares of the residual onto each scale in turn, coarse to fine, and
at j = 0 the residual itself (h = 1: unit impulses). The coefficients are the
wavelet-like detail coefficients of the line; every atom is a sum of d+2 knots at
spacing h, so summing kept atoms over scales - which the array does with its signed
accumulation - gives again a spline whose knots are the union of the atoms' knots.

Selection and refit
-------------------
With a Lagrange multiplier lam (squared error, in 12-bit pixel units, per
instruction), an atom is kept iff c^2 >= lam * (its knot cost in instructions) (greedy
by magnitude per unit cost). The kept atoms fix the knot set K; the line is then
refitted by least squares over *all* splines with knots K (a local divided-difference
B-spline basis), which is at least as good as the kept coefficients and costs the same
number of instructions. Then every operand is quantised to 12.24 with exact integer
error feedback (the knot values are hit to within 2^-24 pixel, so no drift along the
line), 0.5 is added so that the array's truncation to D[35:24] rounds, and any pixel
whose squared error still exceeds lam (or that would wrap, §1: no saturation) is
patched by an Eval0 after the Eval: one instruction per run of equal pixels, which
overrides and locks D in those PEs. lam = 0 means lossless: the knots are then exactly
the positions where Δ^(d+1) of the line is nonzero (a piecewise-linear line costs only
its kinks).

Emission: `merged` (one Eval per line, all knots as Sets) or `layered` (one accumulated
Eval per scale, each with its own Sets; the knot jumps of a scale are summed into D by
the array, §7.7.2). Both give identical pixels; `auto` takes the cheaper per line.

Per-coefficient emission (decided at encoding time, `SplineCoder(basis=...)`):
`coefficient` sends every kept pyramid atom as its own accumulated Eval over its support
(the wavelet synthesis sum of §7.7.2, done by D += A): the atom's coefficient is
quantised to one integer multiplier q of its integer kernel (q * box_h^(d+1), exact in
12.24, zero outside the span), evaluated at the lowest order that represents it (a
unit impulse is one `Eval1`, 3 instructions), with Sets at its interior knots. One base
Eval carries the least-squares polynomial of the residual and the +0.5 rounding offset.
`choice` decides per kept atom: its own Eval if that costs fewer instructions than the
knots it alone adds to the merged form (2 per knot not shared with another merged atom),
otherwise its knots join the merged Eval, which is refitted (least squares) to what the
own-Eval atoms leave. Patches as above in both.
"""
from __future__ import annotations

import contextlib
import ctypes
import glob
import os
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from .. import isa
from ..isa import Command

ONE = 1 << isa.FRAC_BITS
HALF = ONE >> 1
PIXEL_MAX = 4095
SET_OP = {1: "SETDI", 2: "SETDDI"}


@contextlib.contextmanager
def single_thread_blas():
    """Run OpenBLAS single-threaded: the per-line solves are small (<= 260 unknowns) and
    thread start-up makes them ~10x slower on a busy machine. No-op if not found."""
    fn_set = fn_get = None
    try:
        libdir = os.path.join(os.path.dirname(np.__file__), "..", "numpy.libs")
        for path in glob.glob(os.path.join(libdir, "*openblas*")):
            lib = ctypes.CDLL(path)
            for suffix in ("64_", "_64_", ""):
                if hasattr(lib, f"scipy_openblas_set_num_threads{suffix}"):
                    fn_set = getattr(lib, f"scipy_openblas_set_num_threads{suffix}")
                    fn_get = getattr(lib, f"scipy_openblas_get_num_threads{suffix}")
                    break
    except OSError:
        fn_set = None
    old = None
    if fn_set is not None:
        old = fn_get()
        fn_set(1)
    try:
        yield
    finally:
        if fn_set is not None and old:
            fn_set(old)


def psnr(a: np.ndarray, b: np.ndarray, peak: float = PIXEL_MAX) -> float:
    mse = float(np.mean((np.asarray(a, float) - np.asarray(b, float)) ** 2))
    return float("inf") if mse == 0 else 10.0 * np.log10(peak * peak / mse)


# ---- the pyramid -------------------------------------------------------------------


@dataclass
class Level:
    h: int
    atoms: np.ndarray      # (n, M) unit-norm columns
    pinv: np.ndarray       # (M, n)
    knots: np.ndarray      # (M, n) bool: knot incidence of each atom
    cost: np.ndarray       # (M,) instructions of the atom's knots (2 per knot)
    ints: np.ndarray = None    # (n, M) int64: the integer kernels (atoms = ints / norms)
    norms: np.ndarray = None   # (M,)


def _knot_mask(col: np.ndarray, d: int) -> np.ndarray:
    """Knots k (1 <= k <= n-1-d) where Δ^d of the sequence changes: Δ^(d+1) s(k-1) != 0."""
    n = len(col)
    m = np.zeros(n, dtype=bool)
    if n >= d + 2:
        dd = np.diff(col, d + 1)            # dd[k-1] = Δ^(d+1) s(k-1), k = 1..n-1-d
        m[1:n - d] = dd != 0
    return m


@lru_cache(maxsize=32)
def pyramid(n: int, d: int, levels: int) -> tuple[Level, ...]:
    """Levels coarse to fine: h = 2^levels .. 2, then h = 1 (impulses)."""
    out = []
    for j in range(levels, 0, -1):
        h = 1 << j
        ker = np.ones(h, dtype=np.int64)
        for _ in range(d):
            ker = np.convolve(ker, np.ones(h, dtype=np.int64))
        L = len(ker)
        off = (L - 1) // 2
        starts = [s for s in range(-off - h * ((L + h) // h), n + h, h) if s + L > 0 and s < n]
        ext = np.zeros((n + 2 * L, len(starts)), dtype=np.int64)
        for i, s in enumerate(starts):
            ext[s + L:s + 2 * L, i] = ker
        atoms_i = ext[L:L + n]
        keep = atoms_i.any(axis=0)
        atoms_i = atoms_i[:, keep]
        knots = np.array([_knot_mask(atoms_i[:, i], d) for i in range(atoms_i.shape[1])])
        norms = np.linalg.norm(atoms_i, axis=0)
        atoms = atoms_i / norms
        out.append(Level(h, atoms, np.linalg.pinv(atoms), knots, 2 * knots.sum(axis=1),
                         atoms_i, norms))
    eye = np.eye(n)
    knots = np.array([_knot_mask(eye[:, i], d) for i in range(n)])
    out.append(Level(1, eye, eye, knots, np.maximum(2 * knots.sum(axis=1), 1),
                     np.eye(n, dtype=np.int64), np.ones(n)))
    return tuple(out)


def default_levels(n: int) -> int:
    """Coarsest scale about n/8 (h = 32 for 256 columns), at least 1, at most 6."""
    return int(max(1, min(6, np.floor(np.log2(max(n, 2) / 8)))))


def analyse(x: np.ndarray, d: int, levels: int | None = None) -> list[np.ndarray]:
    """Pyramid coefficients of every row of x (rows, n): one (rows, M_j) array per level."""
    x = np.asarray(x, dtype=float)
    n = x.shape[1]
    pyr = pyramid(n, d, default_levels(n) if levels is None else levels)
    r = x.copy()
    coefs = []
    for lev in pyr:
        c = r @ lev.pinv.T
        r = r - c @ lev.atoms.T
        coefs.append(c)
    return coefs


# ---- least squares over all splines with a given knot set -----------------------------


def _tpow(n: int, k: np.ndarray, d: int) -> np.ndarray:
    """T_k(m) = C(m - k, d) for m >= k else 0 (a unit jump of Δ^d at k), shape (n, len(k))."""
    m = np.arange(n, dtype=float)[:, None] - np.asarray(k, dtype=float)[None, :]
    t = m if d == 1 else m * (m - 1) / 2
    return np.where(m >= 0, t, 0.0)


def spline_basis(n: int, knots: np.ndarray, d: int) -> np.ndarray:
    """Local basis of {s : Δ^d s constant between knots} on [0, n): divided differences of
    truncated powers over the knot sequence extended by d+1 virtual knots at each end."""
    e = np.concatenate([np.arange(-d, 1), np.asarray(knots, dtype=np.int64),
                        np.arange(n - d, n + 1)]).astype(float)
    T = _tpow(n, e, d)
    nb = len(e) - d - 1
    P = np.stack([e[m:m + nb] for m in range(d + 2)], axis=1)      # (nb, d+2)
    B = np.zeros((n, nb))
    for m in range(d + 2):
        den = np.ones(nb)
        for l in range(d + 2):
            if l != m:
                den *= P[:, m] - P[:, l]
        B += T[:, m:m + nb] / den[None, :]
    scale = np.abs(B).max(axis=0)
    B /= np.where(scale > 0, scale, 1.0)
    B[np.abs(B) < 1e-9] = 0.0
    return B


def fit(x: np.ndarray, knots: np.ndarray, d: int) -> np.ndarray:
    """Least-squares spline with knot set `knots` (Δ^d changes only there) to the line x."""
    B = spline_basis(len(x), knots, d)
    # the local basis is well conditioned (cond ~ 2-10): normal equations are safe
    G = B.T @ B
    G[np.diag_indices_from(G)] += 1e-12
    coef = np.linalg.solve(G, B.T @ x)
    return B @ coef


# ---- quantisation to an exact 12.24 program ---------------------------------------------


@dataclass
class LineProgram:
    """One scanline: initial differences, knot values of Δ^d, scale labels, patches."""
    n: int
    d: int
    init: list[int]                      # I, dI[, ddI] in 12.24 units
    knots: list[tuple[int, int]]         # (k, Δ^d value from k on), 12.24 units
    labels: dict[int, int] = field(default_factory=dict)  # knot -> pyramid level index
    patches: list[tuple[int, int, int]] = field(default_factory=list)  # (x, dx, pixel)
    # accumulated Evals of single basis functions (per-coefficient emission): (x, program)
    pieces: list[tuple[int, "LineProgram"]] = field(default_factory=list)

    def cost(self) -> int:
        """Instructions of this program as one Eval with its Sets (no patches, pieces)."""
        return self.d + 3 + 2 * len(self.knots)

    def spline_raw(self) -> np.ndarray:
        """Exact D values of the base Eval plus every piece (int64, not reduced)."""
        s = self.raw()
        for x0, sp in self.pieces:
            s[x0:x0 + sp.n] += sp.raw()
        return s

    def raw(self) -> np.ndarray:
        """Exact D values (int64, not yet reduced mod 2^36) of the base Eval alone."""
        top = np.zeros(self.n, dtype=np.int64)     # Δ^d s(m)
        top[:] = self.init[self.d]
        for k, g in self.knots:
            top[k:] = g
        s = top
        for j in range(self.d - 1, -1, -1):       # integrate: Δ^j s(0) = init[j]
            s = np.concatenate([[self.init[j]], self.init[j] + np.cumsum(s[:-1])])
        return s

    def pixels(self) -> np.ndarray:
        p = ((self.spline_raw() & isa.WORD_MASK) >> isa.FRAC_BITS).astype(np.int64) & isa.BLOCK_MASK
        for x, dx, v in self.patches:
            p[x:x + dx] = v
        return p


def quantise(s: np.ndarray, knots, d: int) -> LineProgram:
    """Spline s (pixel units) with knot set `knots` -> exact integer program.

    Operands are rounded to 12.24 with feedback from the exact integer state, aiming
    each knot's Δ^d at the target value at the next knot (or two columns on), so the
    line never drifts. 0.5 pixel is added so that truncation to D[35:24] rounds.
    """
    n = len(s)
    R = (np.asarray(s, dtype=float) + 0.5) * ONE
    Ri = lambda i: float(R[min(i, n - 1)])  # noqa: E731
    S = int(round(Ri(0)))
    init = [S]
    DS = 0
    if d == 2:
        DS = int(round(Ri(1) - Ri(0))) if n > 1 else 0
        init.append(DS)
    ks = [0] + [int(k) for k in knots if 1 <= k <= n - 1 - d]
    out_knots: list[tuple[int, int]] = []
    prev_g = None
    for i, k in enumerate(ks):
        nxt = ks[i + 1] if i + 1 < len(ks) else n - 1
        if d == 1:
            # deadbeat on the value: hit the target at the next knot (stable, no drift)
            m = max(nxt, k + 1) - k
            g = int(round((Ri(k + m) - S) / m)) if k + m <= n - 1 else (prev_g or 0)
        else:
            # track the slope at the next knot (a second-order deadbeat on the value
            # alone is unstable); the value error stays below ~n^2/4 units = 0.002 px
            t = min(max(nxt, k + 1), n - 2)
            m = t - k
            if m <= 0:
                g = prev_g if prev_g is not None else 0
            else:
                g = int(round((Ri(t + 1) - Ri(t) - DS) / m))
        if i == 0:
            init.append(g)
        elif g != prev_g:
            out_knots.append((k, _sig(g)))
        prev_g = g
        # advance the exact state to the next knot
        step = nxt - k
        if d == 1:
            S += step * g
        else:
            S += step * DS + step * (step - 1) // 2 * g
            DS += step * g
    # Values wrap modulo 2^36 in the array (docs/isa.md §1), so e.g. a second difference
    # of +2946 pixels is sent as -1150: same pattern, same pixels.
    return LineProgram(n, d, [_sig(v) for v in init], out_knots)


def exact_program(v: np.ndarray, dmax: int) -> LineProgram:
    """The cheapest exact Eval (order 0..dmax, with Sets of its top difference) for the
    integer 12.24 sequence v; its raw() equals v."""
    v = np.asarray(v, dtype=np.int64)
    n = len(v)
    best = None
    for p in range(0, dmax + 1):
        if p > 0 and n < p + 1:
            break
        top = np.diff(v, p)
        if p == 0 and np.any(top != top[0]):
            continue
        init = [int(np.diff(v, j)[0]) for j in range(p + 1)]
        ch = np.flatnonzero(top[1:] != top[:-1]) + 1
        knots = [(int(k), int(top[k])) for k in ch]
        prog = LineProgram(n, p, init, knots)
        if best is None or prog.cost() < best.cost():
            best = prog
    return best


# ---- emission ---------------------------------------------------------------------------


def _sig(v: int) -> int:
    """A 12.24 value as the signed operand the ISA accepts (same 36-bit pattern)."""
    return isa.to_signed(isa.to_word(v))


def _merged(p: LineProgram) -> list[Command]:
    op = SET_OP[p.d]
    cmds = [Command(op, k, 1, (_sig(g),)) for k, g in p.knots]
    cmds.append(Command("EVAL", 0, p.n, tuple(_sig(v) for v in p.init)))
    return cmds


def _layered(p: LineProgram) -> list[Command]:
    """One accumulated Eval per scale: the knot *jumps* of a scale form its own spline."""
    op = SET_OP[p.d]
    prev = p.init[p.d]
    jumps = []
    for k, g in p.knots:
        jumps.append((k, g - prev))
        prev = g
    layers: dict[int, list[tuple[int, int]]] = {}
    for k, j in jumps:
        layers.setdefault(p.labels.get(k, -1), []).append((k, j))
    cmds = [Command("EVAL", 0, p.n, tuple(_sig(v) for v in p.init))]
    for lab in sorted(layers):
        ks = layers[lab]
        k0, j0 = ks[0]
        acc = j0
        for k, j in ks[1:]:
            acc += j
            cmds.append(Command(op, k, 1, (_sig(acc),)))
        cmds.append(Command("EVAL", k0, p.n - k0, (0,) * p.d + (_sig(j0),)))
    return cmds


def _pieces(p: LineProgram) -> list[Command]:
    """One accumulated Eval per piece, each right after its own Sets (a Set waits for the
    next Eval active in its PE, so it must not precede an earlier piece's Eval there)."""
    cmds = []
    for x0, sp in p.pieces:
        if sp.d:
            cmds += [Command(SET_OP[sp.d], x0 + k, 1, (_sig(g),)) for k, g in sp.knots]
        cmds.append(Command("EVAL", x0, sp.n, tuple(_sig(v) for v in sp.init)))
    return cmds


def slot_count(cmds) -> int:
    return sum(len(isa.slots(c)) for c in cmds)


def emit(p: LineProgram, mode: str = "auto") -> list[Command]:
    """Commands of one line, ending with Refresh. mode: merged | layered | auto."""
    if mode == "merged":
        body = _merged(p)
    elif mode == "layered":
        body = _layered(p)
    elif mode == "auto":
        a, b = _merged(p), _layered(p)
        body = a if slot_count(a) <= slot_count(b) else b
    else:
        raise ValueError(f"unknown emission mode {mode!r}")
    body += _pieces(p)
    body += [Command("EVAL0", x, dx, (v,)) for x, dx, v in p.patches]
    return body + [Command("REFRESH")]


def line_cost(p: LineProgram) -> int:
    """Instructions of the merged form (what `auto` never exceeds), pieces included."""
    return (p.cost() + sum(sp.cost() for _, sp in p.pieces) + len(p.patches) + 1)


# ---- encoding ----------------------------------------------------------------------------


def _patch(p: LineProgram, target: np.ndarray, lam: float) -> None:
    """Eval0 runs for pixels whose squared error is >= lam (always for wrapped pixels)."""
    pix = p.pixels()
    err = pix - target
    bad = (err != 0) & ((err.astype(float) ** 2 >= lam) | (np.abs(err) > 2047))
    p.patches = patch_runs(bad, target)


def patch_runs(bad: np.ndarray, target: np.ndarray) -> list[tuple[int, int, int]]:
    """Eval0 patches (x, dx, pixel): one per run of flagged pixels with equal targets."""
    out = []
    i, n = 0, len(target)
    while i < n:
        if bad[i]:
            j = i + 1
            while j < n and bad[j] and target[j] == target[i]:
                j += 1
            out.append((i, j - i, int(target[i])))
            i = j
        else:
            i += 1
    return out


BASES = ("knots", "coefficient", "choice")


class SplineCoder:
    """Encoder for one channel (rows, n) of 12-bit targets at degree d (1 or 2).

    basis: `knots` (every kept atom contributes knots to one refitted Eval per line),
    `coefficient` (every kept atom its own accumulated Eval) or `choice` (per atom, the
    cheaper of the two); see the module docstring."""

    def __init__(self, target: np.ndarray, d: int = 2, levels: int | None = None,
                 basis: str = "knots"):
        if d not in (1, 2):
            raise ValueError("spline degree must be 1 (Eval2 + SetdI) or 2 (Eval3 + SetddI)")
        if basis not in BASES:
            raise ValueError(f"unknown basis {basis!r} (one of {', '.join(BASES)})")
        self.basis = basis
        self.x = np.asarray(target, dtype=np.int64)
        self.d = d
        n = self.x.shape[1]
        self.levels = default_levels(n) if levels is None else levels
        self.pyr = pyramid(n, d, self.levels)
        self.coefs = analyse(self.x, d, self.levels)

    def kept_knots(self, row: int, lam: float) -> tuple[np.ndarray, dict[int, int]]:
        n = self.x.shape[1]
        mask = np.zeros(n, dtype=bool)
        labels: dict[int, int] = {}
        for li, (lev, c) in enumerate(zip(self.pyr, self.coefs)):
            keep = c[row] ** 2 >= lam * lev.cost
            if keep.any():
                km = lev.knots[keep].any(axis=0)
                for k in np.flatnonzero(km & ~mask):
                    labels[int(k)] = li
                mask |= km
        return np.flatnonzero(mask), labels

    def encode_line_pieces(self, row: int, lam: float) -> LineProgram:
        """Per-coefficient emission: kept atoms as accumulated Evals (basis `coefficient`),
        or per atom whichever is cheaper, own Eval or knots in the merged Eval (`choice`)."""
        x = self.x[row]
        n, d = len(x), self.d
        atoms = []   # (knot mask, start, piece program)
        for lev, c in zip(self.pyr, self.coefs):
            for i in np.flatnonzero(c[row] ** 2 >= lam * lev.cost):
                q = int(round(float(c[row, i]) / lev.norms[i] * ONE))
                if q == 0:
                    continue
                ker = lev.ints[:, i]
                nz = np.flatnonzero(ker)
                a, b = int(nz[0]), int(nz[-1]) + 1
                atoms.append((lev.knots[i], a, exact_program(q * ker[a:b], d)))
        own = [True] * len(atoms)
        cnt = np.zeros(n, dtype=np.int64)
        if self.basis == "choice":
            own = [False] * len(atoms)
            for km, _, _ in atoms:
                cnt += km
            changed = True
            while changed:
                changed = False
                for j, (km, _, sp) in enumerate(atoms):
                    if not own[j] and sp.cost() < 2 * int(np.count_nonzero(km & (cnt == 1))):
                        own[j] = True
                        cnt -= km
                        changed = True
        pieces = [(a, sp) for (km, a, sp), o in zip(atoms, own) if o]
        resid = x.astype(float)
        for a, sp in pieces:
            resid[a:a + sp.n] -= sp.raw() / ONE
        knots = np.flatnonzero(cnt > 0)
        s = fit(resid, knots, d) if len(knots) < n - d - 1 else resid
        p = quantise(s, knots, d)
        p.labels = {int(k): 0 for k in knots}
        p.pieces = pieces
        _patch(p, x, lam)
        return p

    def encode_line(self, row: int, lam: float) -> LineProgram:
        x = self.x[row]
        if self.basis != "knots":
            return self.encode_line_pieces(row, lam)
        if lam <= 0:
            knots = np.flatnonzero(_knot_mask(x, self.d))
            p = quantise(x.astype(float), knots, self.d)
            p.labels = {int(k): len(self.pyr) - 1 for k in knots}
        else:
            knots, labels = self.kept_knots(row, lam)
            s = fit(x.astype(float), knots, self.d) if len(knots) < len(x) - self.d - 1 \
                else x.astype(float)
            p = quantise(s, knots, self.d)
            p.labels = labels
        _patch(p, x, lam)
        return p

    def encode(self, lam: float) -> list[LineProgram]:
        with single_thread_blas():
            return [self.encode_line(r, lam) for r in range(self.x.shape[0])]

    def encode_line_budget(self, row: int, budget: int) -> LineProgram:
        """Best line (smallest lam) whose merged form costs at most `budget` instructions."""
        p = self.encode_line(row, 0.0)
        if line_cost(p) <= budget:
            return p
        lo, hi = -3.0, 9.0   # log10 lam
        best = self.encode_line(row, 10.0 ** hi)
        if line_cost(best) > budget:  # even the coarsest does not fit: keep the coarsest
            return best
        for _ in range(14):
            mid = (lo + hi) / 2
            q = self.encode_line(row, 10.0 ** mid)
            if line_cost(q) <= budget:
                best, hi = q, mid
            else:
                lo = mid
        return best


def frame_commands(progs: list[LineProgram], mode: str = "auto") -> list[Command]:
    out: list[Command] = []
    for p in progs:
        out.extend(emit(p, mode))
    return out


def frame_pixels(progs: list[LineProgram]) -> np.ndarray:
    return np.array([p.pixels() for p in progs], dtype=np.int64)
