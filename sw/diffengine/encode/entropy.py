"""Adaptive binary arithmetic (range) coding of quantised wavelet coefficients.

The range coder is `constriction` (queue.RangeEncoder / RangeDecoder, MIT OR Apache-2.0,
pinned in scripts/requirements.txt); this module is the modelling around it: every bit
is coded with a probability that adapts to the bits already coded in its context
(Krichevsky-Trofimov estimate p1 = (n1 + 1/2) / (n + 1), kept as an integer number of
1/65536 so that encoder and decoder compute the same value exactly).

Stream of one set of coefficient bands (a list of integer 2-D arrays, each with a band
class that selects its contexts), in three passes - the coder is FIFO, so they follow
each other in one stream:

A. significance (q != 0) of every coefficient, band after band, raster order inside a
   band; context = band class x (significant among left + up: 0..2) x (significant
   among up-left, up-right, left-left, up-up, capped at 2).
B. for each significant coefficient, k = bit length of |q| - 1, in unary (k ones, then
   a zero); context = band class x min(position in the unary code, 15).
C. signs, then the k - 1 bits of |q| - 1 below its leading one, as raw bits (p = 1/2).

The encoder computes every context and probability with numpy (it knows all bits); the
decoder runs the passes bit by bit. `encode_bands` / `decode_bands` are inverses
(tests: sw/tests/test_wavelet.py, random bands with printed seeds).
"""
from __future__ import annotations

import numpy as np

PBITS = 16
PONE = 1 << PBITS
UNARY_CTX = 16
SIG_CTX = 9


class EntropyError(ValueError):
    """The compressed stream does not decode (truncated or not this format)."""


def _rc():
    import constriction  # noqa: PLC0415  (a compiled extension; imported when used)

    return constriction.stream


def _p1(n1: np.ndarray, n: np.ndarray) -> np.ndarray:
    """KT estimate as an integer count of 1/65536, in [1, 65535]."""
    v = ((2 * n1 + 1) * PONE) // (2 * n + 2)
    return np.clip(v, 1, PONE - 1)


def adaptive_probabilities(bits: np.ndarray, ctx: np.ndarray) -> np.ndarray:
    """p1 (in 1/65536) of every bit from the bits before it in the same context."""
    bits = np.asarray(bits, dtype=np.int64)
    ctx = np.asarray(ctx, dtype=np.int64)
    if bits.size == 0:
        return np.zeros(0, dtype=np.int64)
    order = np.argsort(ctx, kind="stable")
    cs, bs = ctx[order], bits[order]
    start = np.r_[0, np.flatnonzero(cs[1:] != cs[:-1]) + 1]
    grp = np.repeat(start, np.diff(np.r_[start, len(cs)]))
    n = np.arange(len(cs)) - grp
    c1 = np.cumsum(bs) - bs
    n1 = c1 - c1[grp]
    p = np.empty_like(bits)
    p[order] = _p1(n1, n)
    return p


class _AdaptiveDecoder:
    def __init__(self, words: np.ndarray, nctx: int):
        st = _rc()
        self.dec = st.queue.RangeDecoder(np.asarray(words, dtype=np.uint32))
        self.model = st.model
        self.n = [0] * nctx
        self.n1 = [0] * nctx

    def bit(self, c: int) -> int:
        n, n1 = self.n[c], self.n1[c]
        p = min(max(((2 * n1 + 1) * PONE) // (2 * n + 2), 1), PONE - 1)
        b = int(self.dec.decode(self.model.Bernoulli(p / PONE, perfect=False)))
        self.n[c] = n + 1
        self.n1[c] = n1 + b
        return b

    def raw(self, count: int) -> np.ndarray:
        if count == 0:
            return np.zeros(0, dtype=np.int64)
        half = self.model.Bernoulli(0.5, perfect=False)
        return np.asarray(self.dec.decode(half, count), dtype=np.int64)


def bit_length(m: np.ndarray) -> np.ndarray:
    """Elementwise int.bit_length of non-negative int64 values."""
    m = np.asarray(m, dtype=np.int64)
    k = np.zeros(m.shape, dtype=np.int64)
    for i in range(63):
        k += (m >> i) > 0
    return k


def _sig_context(sig: np.ndarray) -> np.ndarray:
    """Neighbourhood class 0..8 of every coefficient from the causal neighbours' significance."""
    h, w = sig.shape
    p = np.zeros((h + 2, w + 4), dtype=np.int64)
    p[2:, 2:w + 2] = sig
    left, up = p[2:, 1:w + 1], p[1:h + 1, 2:w + 2]
    ul, ur = p[1:h + 1, 1:w + 1], p[1:h + 1, 3:w + 3]
    ll, uu = p[2:, 0:w], p[0:h, 2:w + 2]
    return (left + up) * 3 + np.minimum(ul + ur + ll + uu, 2)


def encode_bands(bands: list[np.ndarray], classes: list[int]) -> np.ndarray:
    """Integer coefficient bands -> range-coded words (uint32). classes[i] < 256."""
    st = _rc()
    if len(bands) != len(classes):
        raise ValueError("one class per band")
    sig_b, sig_c, nz = [], [], []
    for q, cl in zip(bands, classes):
        q = np.asarray(q, dtype=np.int64)
        s = (q != 0).astype(np.int64)
        sig_b.append(s.ravel())
        sig_c.append((cl * SIG_CTX + _sig_context(s)).ravel())
        nz.append((q[q != 0], np.full(int(s.sum()), cl, dtype=np.int64)))
    bits_a = np.concatenate(sig_b) if sig_b else np.zeros(0, np.int64)
    ctx_a = np.concatenate(sig_c) if sig_c else np.zeros(0, np.int64)
    vals = np.concatenate([v for v, _ in nz]) if nz else np.zeros(0, np.int64)
    cls = np.concatenate([c for _, c in nz]) if nz else np.zeros(0, np.int64)
    m = np.abs(vals) - 1
    k = bit_length(m)
    # pass B: unary k
    lens = k + 1
    starts = np.cumsum(lens) - lens
    idx = np.arange(int(lens.sum())) - np.repeat(starts, lens)
    bits_b = (idx < np.repeat(k, lens)).astype(np.int64)
    ctx_b = 256 * SIG_CTX + np.repeat(cls, lens) * UNARY_CTX + np.minimum(idx, UNARY_CTX - 1)
    # pass C: signs, then mantissas (k - 1 bits below the leading one, MSB first)
    mk = np.maximum(k - 1, 0)
    mstart = np.cumsum(mk) - mk
    midx = np.arange(int(mk.sum())) - np.repeat(mstart, mk)
    shift = np.repeat(mk, mk) - 1 - midx
    mant = (np.repeat(m, mk) >> shift) & 1
    raw = np.concatenate([(vals < 0).astype(np.int64), mant])
    enc = st.queue.RangeEncoder()
    for bits, ctx in ((bits_a, ctx_a), (bits_b, ctx_b)):
        if bits.size:
            p = adaptive_probabilities(bits, ctx).astype(np.float64) / PONE
            enc.encode(bits.astype(np.int32), st.model.Bernoulli(perfect=False), p)
    if raw.size:
        enc.encode(raw.astype(np.int32), st.model.Bernoulli(0.5, perfect=False))
    return np.asarray(enc.get_compressed(), dtype=np.uint32)


def decode_bands(words: np.ndarray, shapes: list[tuple[int, int]],
                 classes: list[int]) -> list[np.ndarray]:
    """Inverse of encode_bands, given the band shapes and classes."""
    d = _AdaptiveDecoder(words, 256 * SIG_CTX + 256 * UNARY_CTX)
    sigs = []
    try:
        for (h, w), cl in zip(shapes, classes):
            p = [[0] * (w + 4) for _ in range(h + 2)]
            base = cl * SIG_CTX
            for r in range(h):
                pu, pc, pp = p[r + 1], p[r + 2], p[r]
                for c in range(w):
                    ctx = (pc[c + 1] + pu[c + 2]) * 3 + min(pu[c + 1] + pu[c + 3] + pc[c]
                                                            + pp[c + 2], 2)
                    pc[c + 2] = d.bit(base + ctx)
            sigs.append(np.array([row[2:w + 2] for row in p[2:]], dtype=np.int64).reshape(h, w))
        ks = []
        for s, cl in zip(sigs, classes):
            base = 256 * SIG_CTX + cl * UNARY_CTX
            for _ in range(int(s.sum())):
                k = 0
                while d.bit(base + min(k, UNARY_CTX - 1)):
                    k += 1
                    if k > 62:
                        raise EntropyError("magnitude code longer than 62 bits: corrupt stream")
                ks.append(k)
        k = np.array(ks, dtype=np.int64)
        nnz = len(k)
        signs = d.raw(nnz)
        mk = np.maximum(k - 1, 0)
        mant = d.raw(int(mk.sum()))
    except (ValueError, RuntimeError) as e:
        raise EntropyError(f"coefficient stream does not decode: {e}") from e
    m = (k > 0).astype(np.int64)          # the leading one, then the bits below it
    pos = 0
    for i in np.flatnonzero(mk):
        v = 1
        for b in mant[pos:pos + mk[i]]:
            v = (v << 1) | int(b)
        m[i] = v
        pos += mk[i]
    vals = (m + 1) * np.where(signs > 0, -1, 1)
    out, pos = [], 0
    for s in sigs:
        q = np.zeros(s.shape, dtype=np.int64)
        n = int(s.sum())
        q[s != 0] = vals[pos:pos + n]
        pos += n
        out.append(q)
    return out
