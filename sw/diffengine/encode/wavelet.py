"""2-D spline-wavelet coding decoded by the array (§7.7.2, Fig. 7.28; after Marais 94).

Transform. The CDF (2,2) biorthogonal spline wavelet ("5/3", LeGall): its synthesis
scaling function is the linear B-spline (a hat) and its synthesis wavelet a sum of
hats, so a synthesised scanline is piecewise linear on the pixel grid with knots only
where some kept basis function has one - exactly what one `Eval2 (0, W, I, dI)` plus a
`SetdI (k, g)` per knot draws (spline.py). Lifting with symmetric extension, in floating
point, any length. Separable, in the *standard* (tensor) form: the full J_x-level 1-D
transform along every row, then the full J_y-level transform along every column. So
undoing the column transform gives, for every scanline, the 1-D horizontal wavelet
coefficients of that line: vertical synthesis with the hat is linear interpolation
between coarser rows plus details - the y-processor's part, done on coefficients - and
the horizontal synthesis of each line is what the array does (Difference Engine
commands, one Refresh per line).

Quantisation. A dead-zone uniform quantiser per band, step = delta / ||synthesis basis
function of the band|| (so that every band's quantisation error costs the same in the
image), q = sign(c) floor(|c| / step + 1/2 - DEADZONE), reconstruction (|q| + RECON) step.
Colour: JPEG's (JFIF) RGB -> YCbCr before the transform, the steps weighted by the
norms of the inverse's columns; the decoder turns the dequantised YCbCr coefficients
back into R, G, B coefficients (the transform is linear) and emits three streams.

Entropy coding: entropy.py (adaptive binary range coding, constriction). The file:
header (magic, sizes, levels, delta) + range-coded words; its length is the rate.

Emission per scanline: the synthesised line r (float) is piecewise linear; its knot set
is where the second difference of r is nonzero (numerically: |Δ²r| > KNOT_TOL);
spline.quantise turns it into an exact 12.24 Eval2 + SetdI program whose pixels are
round(r) (the +0.5 of the truncation), Eval0 patches where round(r) leaves 0..4095 (the
array wraps, no saturation) or, rarely, where r is within 2^-24 of a half, so that the
array's pixels equal the floating-point decoder's clip(round(r)) exactly. A knot costs
2 slots, an Eval2 4 and an Eval0 run 1, so where fine detail makes knots dense the same
pixels are cheaper as Eval0 runs: each line is cut into Eval2 segments (with their own
knots) and Eval0 runs by an exact dynamic programme over the segment ends
(`segment_plan`, O(W)) - same pixels, fewest instructions of the two forms mixed.

`decode_file` is the receiver: file -> commands (three lists for colour); the pixels
are the golden model's (functional.render) output of those commands.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from .. import isa
from ..isa import Command
from . import entropy as EC
from . import raster as ER
from . import spline as ES

MAGIC = b"DEW1"
HEADER = "<4sHHBBBd"          # magic, width, height, channels, Jx, Jy, delta
DEADZONE = 0.2
RECON = 0.1
KNOT_TOL = 1e-6
PIXEL_MAX = 4095
# JFIF RGB -> YCbCr (offsets dropped: the transform's low band absorbs them)
RGB2YCC = np.array([[0.299, 0.587, 0.114],
                    [-0.168736, -0.331264, 0.5],
                    [0.5, -0.418688, -0.081312]])
YCC2RGB = np.linalg.inv(RGB2YCC)


class WaveletError(ValueError):
    """Bad input or a file that is not a wavelet stream."""


# ---- 1-D lifting ----------------------------------------------------------------------


def _split_neighbours(e, d, ne, no):
    e_next = np.concatenate([e[1:], e[-1:]])[:no]
    d_prev = np.concatenate([d[:1], d])[:ne]
    d_cur = np.concatenate([d, d[-1:]])[:ne]
    return e_next, d_prev, d_cur


def fwd1(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One 5/3 lifting step along axis 0: (s, d) = (low, high)."""
    n = x.shape[0]
    e, o = x[0::2], x[1::2]
    ne, no = e.shape[0], o.shape[0]
    if no == 0:
        return e.copy(), o.copy()
    e_next = np.concatenate([e[1:], e[-1:]])[:no]
    d = o - (e[:no] + e_next) / 2
    _, d_prev, d_cur = _split_neighbours(e, d, ne, no)
    s = e + (d_prev + d_cur) / 4
    assert s.shape[0] + d.shape[0] == n
    return s, d


def inv1(s: np.ndarray, d: np.ndarray) -> np.ndarray:
    ne, no = s.shape[0], d.shape[0]
    if no == 0:
        return s.copy()
    _, d_prev, d_cur = _split_neighbours(s, d, ne, no)
    e = s - (d_prev + d_cur) / 4
    e_next = np.concatenate([e[1:], e[-1:]])[:no]
    o = d + (e[:no] + e_next) / 2
    x = np.empty((ne + no,) + s.shape[1:], dtype=float)
    x[0::2], x[1::2] = e, o
    return x


def levels_for(n: int) -> int:
    """Levels of a length-n axis: coarsest band about 8-16 samples, at most 6."""
    return int(max(0, min(6, np.floor(np.log2(max(n, 1))) - 3)))


def band_edges(n: int, J: int) -> list[int]:
    """Boundaries of [s_J, d_J, d_(J-1), ..., d_1] in the transformed axis."""
    sizes = []
    m = n
    for _ in range(J):
        sizes.append(m // 2)
        m = m - m // 2
    edges = [0, m]
    for sz in reversed(sizes):
        edges.append(edges[-1] + sz)
    return edges


def fwd(x: np.ndarray, J: int) -> np.ndarray:
    """Full J-level transform along axis 0."""
    x = np.asarray(x, dtype=float)
    ds = []
    s = x
    for _ in range(J):
        s, d = fwd1(s)
        ds.append(d)
    return np.concatenate([s] + ds[::-1], axis=0)


def inv(c: np.ndarray, J: int) -> np.ndarray:
    e = band_edges(c.shape[0], J)
    s = c[e[0]:e[1]]
    for i in range(J):
        s = inv1(s, c[e[i + 1]:e[i + 2]])
    return s


def fwd2(x: np.ndarray, Jx: int, Jy: int) -> np.ndarray:
    return fwd(fwd(x.T, Jx).T, Jy)


def inv2(c: np.ndarray, Jx: int, Jy: int) -> np.ndarray:
    return inv(inv(c, Jy).T, Jx).T


def band_norms(n: int, J: int) -> np.ndarray:
    """L2 norm of the synthesis basis function of each band (middle element)."""
    e = band_edges(n, J)
    out = []
    for b in range(len(e) - 1):
        c = np.zeros(n)
        c[(e[b] + e[b + 1]) // 2] = 1.0
        out.append(np.linalg.norm(inv(c[:, None], J)))
    return np.array(out)


# ---- quantisation and the file ----------------------------------------------------------


@dataclass
class Layout:
    width: int
    height: int
    Jx: int
    Jy: int

    @property
    def xe(self):
        return band_edges(self.width, self.Jx)

    @property
    def ye(self):
        return band_edges(self.height, self.Jy)

    def bands(self):
        """(class, rows slice, cols slice, weight) coarse to fine."""
        nx, ny = band_norms(self.width, self.Jx), band_norms(self.height, self.Jy)
        xe, ye = self.xe, self.ye
        out = []
        order = sorted(((by, bx) for by in range(len(ye) - 1) for bx in range(len(xe) - 1)),
                       key=lambda t: (max(t), t))
        for by, bx in order:
            out.append((by * 8 + bx, slice(ye[by], ye[by + 1]), slice(xe[bx], xe[bx + 1]),
                        float(nx[bx] * ny[by])))
        return out


def _chan_weights(nch: int) -> np.ndarray:
    if nch == 1:
        return np.ones(1)
    w = np.linalg.norm(YCC2RGB, axis=0)
    return w / np.sqrt(3.0)


def quantise_coefs(C: np.ndarray, lay: Layout, delta: float, cw: float) -> list[np.ndarray]:
    out = []
    for _, rs, cs, wt in lay.bands():
        step = delta / (wt * cw)
        c = C[rs, cs]
        out.append((np.sign(c) * np.floor(np.abs(c) / step + 0.5 - DEADZONE)).astype(np.int64))
    return out


def dequantise(qs: list[np.ndarray], lay: Layout, delta: float, cw: float) -> np.ndarray:
    C = np.zeros((lay.height, lay.width))
    for q, (_, rs, cs, wt) in zip(qs, lay.bands()):
        step = delta / (wt * cw)
        C[rs, cs] = np.sign(q) * (np.abs(q) + RECON) * step * (q != 0)
    return C


def _classes(lay: Layout, ch: int) -> list[int]:
    # luma and chroma (or grey) bands learn separate statistics: 64 band ids x 2
    return [cl + (64 if ch > 0 else 0) for cl, _, _, _ in lay.bands()]


def encode_file(x12: np.ndarray, delta: float) -> bytes:
    """12-bit image (rows, cols) or (rows, cols, 3) -> wavelet file bytes."""
    x = np.asarray(x12, dtype=float)
    if x.ndim == 2:
        x = x[:, :, None]
    h, w, nch = x.shape
    if nch not in (1, 3) or h < 1 or w < 1 or w > isa.ADDR_MAX + 1 or h > 65535:
        raise WaveletError(f"image shape {x12.shape}: need (rows, cols[, 3]), cols <= 4096")
    if not delta > 0:
        raise WaveletError(f"quantiser step {delta} must be > 0")
    if nch == 3:
        x = x @ RGB2YCC.T
    lay = Layout(w, h, levels_for(w), levels_for(h))
    cws = _chan_weights(nch)
    bands, classes = [], []
    for c in range(nch):
        C = fwd2(x[:, :, c] - (2048.0 if c == 0 else 0.0), lay.Jx, lay.Jy)
        bands += quantise_coefs(C, lay, delta, cws[c])
        classes += _classes(lay, c)
    words = EC.encode_bands(bands, classes)
    return struct.pack(HEADER, MAGIC, w, h, nch, lay.Jx, lay.Jy, delta) + words.tobytes()


def read_coefficients(data: bytes) -> tuple[Layout, np.ndarray]:
    """File -> (layout, dequantised coefficients (channels, rows, cols), RGB for colour)."""
    hs = struct.calcsize(HEADER)
    if len(data) < hs or data[:4] != MAGIC:
        raise WaveletError("not a DEW1 wavelet stream")
    _, w, h, nch, Jx, Jy, delta = struct.unpack(HEADER, data[:hs])
    if (len(data) - hs) % 4:
        raise WaveletError("truncated wavelet stream (not whole 32-bit words)")
    lay = Layout(w, h, Jx, Jy)
    words = np.frombuffer(data[hs:], dtype="<u4")
    shapes = [(rs.stop - rs.start, cs.stop - cs.start) for _, rs, cs, _ in lay.bands()]
    classes = sum((_classes(lay, c) for c in range(nch)), [])
    qs = EC.decode_bands(words, shapes * nch, classes)
    nb = len(shapes)
    cws = _chan_weights(nch)
    C = np.stack([dequantise(qs[c * nb:(c + 1) * nb], lay, delta, cws[c]) for c in range(nch)])
    if nch == 3:
        C = np.einsum("ij,jrc->irc", YCC2RGB, C)
        # the luma offset 2048 sits in every channel (YCC2RGB's first column is all ones)
    return lay, C


# ---- the array's part: one scanline -> commands -------------------------------------------


def line_rows(C: np.ndarray, lay: Layout) -> np.ndarray:
    """The y-processor's part: vertical synthesis -> every line's horizontal coefficients."""
    return inv(C, lay.Jy)


def synth_line(hc: np.ndarray, lay: Layout) -> np.ndarray:
    """Horizontal synthesis of one line (float pixels, the 2048 offset restored)."""
    return inv(hc[:, None], lay.Jx)[:, 0] + 2048.0


@dataclass
class LineCode:
    commands: list[Command]
    pixels: np.ndarray
    kind: str            # "spline" (all knots), "rle" (all Eval0 runs) or "mixed"
    knots: int
    spline_px: int       # pixels drawn by Eval2 segments


EVAL2_SLOTS, SET_SLOTS, EVAL0_SLOTS = 4, 2, 1


def segment_plan(knot: np.ndarray, target: np.ndarray) -> list[tuple[int, int, bool]]:
    """Cheapest cover of the line by segments [a, b): True = one Eval2 + a SetdI per knot
    inside (knots k with a + 1 <= k <= b - 2), False = Eval0 runs of the target pixels.
    knot[k] marks a change of slope at k. Dynamic programming over segment ends; both
    costs split into a part of the start and a part of the end, so a running minimum
    over the starts makes it O(n)."""
    n = len(target)
    K = [0] + np.cumsum(knot.astype(np.int64)).tolist()                 # K[i] = knots < i
    st = [1] + (target[1:] != target[:-1]).astype(np.int64).tolist()    # run starts
    R = [0] + np.cumsum(st).tolist()                                     # R[i] = starts < i
    best = [0] * (n + 1)
    back = [(0, False)] * (n + 1)
    INF = 1 << 62
    rmin, rarg = INF, 0          # min over j < i of best[j] - E0 (R[j] + st[j])  (Eval0)
    smin, sarg = INF, 0          # min over j <= i - 2 of best[j] - 2 K[j + 1]  (Eval2)
    for i in range(1, n + 1):
        j = i - 1
        v = best[j] - EVAL0_SLOTS * (R[j] + st[j])
        if v < rmin:
            rmin, rarg = v, j
        rle = rmin + EVAL0_SLOTS * (R[i] + 1)
        spl, sj = best[j] + EVAL2_SLOTS, j                   # a one-pixel Eval2
        if i >= 2:
            v = best[i - 2] - SET_SLOTS * K[i - 1]
            if v < smin:
                smin, sarg = v, i - 2
            c = smin + EVAL2_SLOTS + SET_SLOTS * K[i - 1]
            if c < spl:
                spl, sj = c, sarg
        if spl < rle:
            best[i], back[i] = spl, (sj, True)
        else:
            best[i], back[i] = rle, (rarg, False)
    segs = []
    i = n
    while i > 0:
        j, spline = back[i]
        segs.append((j, i, spline))
        i = j
    return segs[::-1]


def line_commands(r: np.ndarray) -> LineCode:
    """A piecewise-linear line (float) -> commands: the cheapest mix of Eval2 + SetdI
    segments and Eval0 runs (segment_plan) whose pixels are clip(round(r))."""
    n = len(r)
    target = np.clip(np.floor(r + 0.5), 0, PIXEL_MAX).astype(np.int64)
    knot = np.zeros(n, dtype=bool)
    if n >= 3:
        knot[1:n - 1] = np.abs(np.diff(r, 2)) > KNOT_TOL
    cmds: list[Command] = []
    pix = np.empty(n, dtype=np.int64)
    nk = spx = 0
    kinds = set()
    for a, b, spline in segment_plan(knot, target):
        kinds.add(spline)
        if not spline:
            run_cmds, pix[a:b] = ER.rle_line(target[a:b], 0)
            cmds += [Command("EVAL0", a + c.x, c.dx, c.values) for c in run_cmds[:-1]]
            continue
        ks = np.flatnonzero(knot[a + 1:b - 1]) + 1
        p = ES.quantise(r[a:b], ks, 1)
        # operands wrap mod 2^36 (a line above 4095 comes out mod 4096) and the 12.24
        # feedback can land a value within 2^-24 of a half on the other side: patch both
        p.patches = ES.patch_runs(p.pixels() != target[a:b], target[a:b])
        seg = ES.emit(p, "merged")[:-1]
        cmds += [Command(c.op, a + c.x, c.dx, c.values) for c in seg]
        pix[a:b] = p.pixels()
        nk += len(p.knots)
        spx += b - a
    kind = "mixed" if len(kinds) > 1 else ("spline" if True in kinds else "rle")
    return LineCode(cmds + [Command("REFRESH")], pix, kind, nk, spx)


STATS = ("spline_lines", "rle_lines", "mixed_lines", "knots", "spline_px")


def channel_commands(C: np.ndarray, lay: Layout) -> tuple[list[Command], np.ndarray, dict]:
    """One channel's dequantised coefficients -> (commands, pixels by the encoder's integer
    simulation, stats)."""
    H = line_rows(C, lay)
    cmds, pix = [], []
    st = dict.fromkeys(STATS, 0)
    for y in range(lay.height):
        lc = line_commands(synth_line(H[y], lay))
        cmds += lc.commands
        pix.append(lc.pixels)
        st[lc.kind + "_lines"] += 1
        st["knots"] += lc.knots
        st["spline_px"] += lc.spline_px
    return cmds, np.array(pix, dtype=np.int64), st


def decode_file(data: bytes) -> tuple[list[list[Command]], np.ndarray, dict]:
    """Wavelet file -> per-channel command lists, the pixels those commands give (rows,
    cols[, 3]) by the encoder's integer simulation, and emission statistics."""
    lay, C = read_coefficients(data)
    streams, pix = [], []
    st = dict.fromkeys(STATS, 0)
    for c in range(C.shape[0]):
        cm, px, s = channel_commands(C[c], lay)
        streams.append(cm)
        pix.append(px)
        for k in st:
            st[k] += s[k]
    out = pix[0] if len(pix) == 1 else np.stack(pix, axis=-1)
    return streams, out, st


def float_decode(data: bytes) -> np.ndarray:
    """Reference decoder without the array: inverse transform, rounded and clipped."""
    lay, C = read_coefficients(data)
    img = [np.clip(np.floor(inv2(C[c], lay.Jx, lay.Jy) + 2048.0 + 0.5), 0, PIXEL_MAX)
           for c in range(C.shape[0])]
    return (img[0] if len(img) == 1 else np.stack(img, -1)).astype(np.int64)
