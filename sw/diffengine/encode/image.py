"""`diffengine encode`: images -> command files that the array decodes (§7.7.2).

    diffengine encode IMAGE -o OUT.cmd [--codec spline2|spline1|rle|raster]
                      [--psnr DB | --slots-per-line N | --bytes B | --lossless]
                      [--baselines] [--preview DECODED.png] [--de48]

The subcommand is `configure(parser)` + `command(args) -> int` (0 ok, 2 on any error,
which is printed as `diffengine encode: error: FILE: reason`).

Pixels. The image is read with OpenImageIO (8- or 16-bit integer, or half; grey or
colour) and mapped to the array's 12-bit pixel (D[35:24], 0..4095, docs/isa.md §1):
v12 = round(v * 4095 / max). PSNR is measured on that 12-bit scale (peak 4095), always
from the golden model's output (`functional.render`) of the emitted commands.

Colour is three independent streams R, G, B, each its own command file
(`OUT.r.cmd`, `OUT.g.cmd`, `OUT.b.cmd`): the array has one 12-bit pixel per PE, so a
colour display runs three arrays (or three passes) - the source's colour handling is
per-channel intensity too.

Vertical handling: every scanline is coded on its own (per-row coding). It is exact,
needs no state between lines, and matches the machine: the x-array keeps nothing from
one Refresh to the next, so every line's commands must be sent every frame anyway; a
y-processor interpolating between coded rows would cut the *stored* bytes but not the
instructions per line, which is the real-time limit (capacity). The price is that
vertical redundancy is not exploited, which is where JPEG gains on bytes.

Codecs: `spline1` / `spline2` (encode_spline: multiresolution B-spline pyramid,
piecewise-linear Eval2 + SetdI knots or quadratic Eval3 + SetddI knots), `rle` (Eval0
runs, lossy with a tolerance) and `raster` (Eval0 per pixel). Targets: `--psnr` (the
achieved PSNR is >= the target; lam is searched), `--slots-per-line` (every line fits,
e.g. 800 for 640x480@60), `--bytes` (48-bit stream, 6 bytes per instruction), or
`--lossless` (exact). Spline emission (`--emission`): knots - `merged`, `layered`, `auto`
(default: the cheaper of the two per line) - or per basis function - `coefficient` (one
accumulated Eval per kept pyramid atom) and `choice` (per atom, own Eval or knots,
whichever costs fewer instructions); docs/reconstruction.md compares them. Baselines (`--baselines`): the Eval0 raster, the lossless RLE
raster and a JPEG at the spline stream's byte size, written next to the output.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import fail, isa
from ..isa import Command
from ..model import functional
from . import raster as ER
from . import spline as ES

PIXEL_MAX = 4095
BYTES_PER_SLOT = 6
CHANNEL_SUFFIX = ("r", "g", "b")
CODECS = ("spline2", "spline1", "rle", "raster")
# knot forms (one Eval per line / per scale / cheaper per line) and per-coefficient forms
# (one accumulated Eval per kept basis function / per function the cheaper of that and
# its knots): encode_spline's module docstring
EMISSIONS = ("auto", "merged", "layered", "coefficient", "choice")
LAM_LO, LAM_HI = -1.0, 7.5   # log10 of the search range of lam


class EncodeError(Exception):
    """A user-facing error; the message names the file."""


# ---- image input ------------------------------------------------------------------------


def load_image(path) -> np.ndarray:
    """Read an image as 12-bit pixels: (rows, cols) grey or (rows, cols, 3) colour."""
    import OpenImageIO as oiio

    name = str(path)
    if not Path(name).is_file():
        raise EncodeError(f"{name}: cannot read image: no such file")
    buf = oiio.ImageBuf(name)
    spec = buf.spec() if not buf.has_error else None
    if spec is None or buf.has_error or spec.width < 0:
        raise EncodeError(f"{name}: cannot read image: {buf.geterror() or 'unknown format'}")
    if spec.width == 0 or spec.height == 0 or spec.nchannels == 0:
        raise EncodeError(f"{name}: zero-size image ({spec.width}x{spec.height}, "
                          f"{spec.nchannels} channels)")
    base = spec.format.basetype
    bits = int(spec.get_int_attribute("oiio:BitsPerSample", 0)) or 8 * spec.format.size()
    if bits > 16 or spec.format.size() > 2:
        raise EncodeError(f"{name}: bit depth {max(bits, 8 * spec.format.size())} is above 16 "
                          f"({spec.format}); the array's pixels are 12 bits - convert to "
                          "8- or 16-bit integers first")
    if base in (oiio.HALF,):
        px = buf.get_pixels(oiio.FLOAT)
        if px is None:
            raise EncodeError(f"{name}: cannot read pixels: {buf.geterror()}")
        v = np.rint(np.clip(np.nan_to_num(px), 0.0, 1.0) * PIXEL_MAX).astype(np.int64)
    else:
        px = buf.get_pixels(oiio.UINT16)
        if px is None:
            raise EncodeError(f"{name}: cannot read pixels: {buf.geterror()}")
        v = (px.astype(np.int64) * PIXEL_MAX + 32767) // 65535
    v = v.reshape(spec.height, spec.width, spec.nchannels)
    check_array(v, name)
    return v[:, :, 0] if spec.nchannels < 3 else v[:, :, :3]


def check_array(x: np.ndarray, name: str = "<array>") -> None:
    if x.ndim < 2 or x.shape[0] == 0 or x.shape[1] == 0:
        raise EncodeError(f"{name}: zero-size image {tuple(x.shape)}")
    if x.shape[1] > isa.ADDR_MAX + 1:
        raise EncodeError(f"{name}: {x.shape[1]} columns; X and dX are 12 bits, at most 4096")


def save_png16(path, x12: np.ndarray) -> None:
    import OpenImageIO as oiio

    x = np.asarray(x12, dtype=np.int64)
    if x.ndim == 2:
        x = x[:, :, None]
    data = ((np.clip(x, 0, PIXEL_MAX) * 65535 + PIXEL_MAX // 2) // PIXEL_MAX).astype(np.uint16)
    h, w, c = (int(v) for v in data.shape)
    buf = oiio.ImageBuf(oiio.ImageSpec(w, h, c, oiio.UINT16))
    buf.set_pixels(oiio.ROI(), np.ascontiguousarray(data))
    if not buf.write(str(path)):
        raise EncodeError(f"{path}: cannot write: {buf.geterror()}")


# ---- one channel --------------------------------------------------------------------------


@dataclass
class Result:
    codec: str
    commands: list[Command]
    pixels: np.ndarray           # decoded by the golden model
    psnr: float
    slots: int
    max_slots_per_line: int
    param: float = 0.0           # lam (spline) or tolerance (rle)
    notes: dict = field(default_factory=dict)

    @property
    def bytes(self) -> int:
        return BYTES_PER_SLOT * self.slots


def line_slots(commands) -> list[int]:
    return [ES.slot_count(line) for line in isa.split_lines(commands)]


def decode(commands, width: int) -> np.ndarray:
    """The golden model's pixels of a command list (rows, width)."""
    return functional.render(commands, width).astype(np.int64)


def _result(codec, cmds, x, param, sim=None, **notes) -> Result:
    pix = decode(cmds, x.shape[1])
    if sim is not None and not np.array_equal(pix, sim):
        raise RuntimeError(f"{codec}: encoder's integer simulation disagrees with the golden "
                           "model (a bug in encode_spline or functional)")
    ls = line_slots(cmds)
    return Result(codec, cmds, pix, ES.psnr(pix, x), sum(ls), max(ls), param, dict(notes))


class ChannelEncoder:
    """All codecs for one channel of 12-bit pixels (rows, cols)."""

    def __init__(self, x: np.ndarray, emission: str = "auto"):
        check_array(x)
        if emission not in EMISSIONS:
            raise EncodeError(f"unknown emission {emission!r} (one of {', '.join(EMISSIONS)})")
        self.x = np.asarray(x, dtype=np.int64)
        self.emission = emission
        self._coders: dict[int, ES.SplineCoder] = {}

    @property
    def basis(self) -> str:
        """Encoding-time part of the emission: knots, or per-coefficient pieces."""
        return self.emission if self.emission in ES.BASES else "knots"

    @property
    def line_mode(self) -> str:
        """Emission of the per-line base Eval (per-coefficient modes: merged)."""
        return "merged" if self.emission in ES.BASES else self.emission

    def coder(self, d: int) -> ES.SplineCoder:
        if d not in self._coders:
            self._coders[d] = ES.SplineCoder(self.x, d, basis=self.basis)
        return self._coders[d]

    # spline ------------------------------------------------------------------------------
    def spline_lam(self, d: int, lam: float) -> Result:
        progs = self.coder(d).encode(lam)
        cmds = ES.frame_commands(progs, self.line_mode)
        return _result(f"spline{d}", cmds, self.x, lam, ES.frame_pixels(progs))

    def _spline_quick(self, d: int, lam: float) -> tuple[float, int, list]:
        progs = self.coder(d).encode(lam)
        pix = ES.frame_pixels(progs)
        return ES.psnr(pix, self.x), sum(ES.line_cost(p) for p in progs), progs

    def spline_lossless(self, d: int) -> Result:
        # lam = 0: knots where the (d+1)-th difference is nonzero; lam = 0.5: every
        # integer error is patched. Both exact; keep the cheaper.
        a, b = self.spline_lam(d, 0.0), self.spline_lam(d, 0.5)
        return a if a.slots <= b.slots else b

    def spline_psnr(self, d: int, target: float) -> Result:
        """Largest lam (fewest instructions) whose decoded PSNR is >= target."""
        lo, hi = LAM_LO, LAM_HI
        ok = None
        if self._spline_quick(d, 10 ** hi)[0] >= target:
            ok = hi
        else:
            for _ in range(13):
                mid = (lo + hi) / 2
                if self._spline_quick(d, 10 ** mid)[0] >= target:
                    lo, ok = mid, mid
                else:
                    hi = mid
        if ok is None:
            return self.spline_lossless(d)
        res = self.spline_lam(d, 10 ** ok)
        while res.psnr < target:  # non-monotone corner: step down (lam -> 0 is exact)
            ok -= 0.25
            res = self.spline_lam(d, 10 ** ok) if ok > LAM_LO - 2 else self.spline_lossless(d)
        # instructions are not monotone in lam either (patches, refit): on step-edge
        # images the exact code can be the cheaper one
        exact = self.spline_lossless(d)
        return exact if exact.slots <= res.slots else res

    def spline_bytes(self, d: int, max_bytes: int) -> Result:
        """Smallest lam (best quality) whose stream has at most max_bytes."""
        max_slots = max_bytes // BYTES_PER_SLOT
        exact = self.spline_lossless(d)
        if exact.slots <= max_slots:
            return exact
        lo, hi = LAM_LO, LAM_HI + 3
        best = hi
        for _ in range(13):
            mid = (lo + hi) / 2
            if self._spline_quick(d, 10 ** mid)[1] <= max_slots:
                hi, best = mid, mid
            else:
                lo = mid
        res = self.spline_lam(d, 10 ** best)
        res.notes["fits"] = res.slots <= max_slots
        return res

    def spline_budget(self, d: int, per_line: int) -> Result:
        """Every line within `per_line` instructions (Refresh included), best quality each."""
        co = self.coder(d)
        with ES.single_thread_blas():
            progs = [co.encode_line_budget(r, per_line) for r in range(self.x.shape[0])]
        cmds = ES.frame_commands(progs, self.line_mode)
        res = _result(f"spline{d}", cmds, self.x, float("nan"), ES.frame_pixels(progs))
        res.notes["fits"] = res.max_slots_per_line <= per_line
        return res

    # rasters -----------------------------------------------------------------------------
    def raster(self) -> Result:
        return _result("raster", ER.raster_frame(self.x), self.x, 0)

    def rle_tol(self, tol: int) -> Result:
        cmds, pix = ER.rle_frame(self.x, tol)
        return _result("rle", cmds, self.x, tol, pix)

    def rle_psnr(self, target: float) -> Result:
        lo, hi = 0, PIXEL_MAX
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if ES.psnr(ER.rle_frame(self.x, mid)[1], self.x) >= target:
                lo = mid
            else:
                hi = mid
        t = hi if ES.psnr(ER.rle_frame(self.x, hi)[1], self.x) >= target else lo
        return self.rle_tol(t)

    def rle_slots(self, max_slots: int, per_line: bool) -> Result:
        def cost(t):
            ls = line_slots(ER.rle_frame(self.x, t)[0])
            return max(ls) if per_line else sum(ls)
        lo, hi = -1, PIXEL_MAX
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if cost(mid) <= max_slots:
                hi = mid
            else:
                lo = mid
        res = self.rle_tol(hi)
        res.notes["fits"] = cost(hi) <= max_slots
        return res

    def encode(self, codec: str, psnr=None, slots_per_line=None, max_bytes=None,
               lossless=False) -> Result:
        if codec == "raster":
            return self.raster()
        if codec == "rle":
            if psnr is not None:
                return self.rle_psnr(psnr)
            if slots_per_line is not None:
                return self.rle_slots(slots_per_line, True)
            if max_bytes is not None:
                return self.rle_slots(max_bytes // BYTES_PER_SLOT, False)
            return self.rle_tol(0)
        if codec not in ("spline1", "spline2"):
            raise EncodeError(f"unknown codec {codec!r} (one of {', '.join(CODECS)})")
        d = int(codec[-1])
        if psnr is not None:
            return self.spline_psnr(d, psnr)
        if slots_per_line is not None:
            return self.spline_budget(d, slots_per_line)
        if max_bytes is not None:
            return self.spline_bytes(d, max_bytes)
        return self.spline_lossless(d)


def channels(x: np.ndarray) -> list[np.ndarray]:
    return [x] if x.ndim == 2 else [x[:, :, c] for c in range(x.shape[2])]


def image_psnr(results: list[Result], x: np.ndarray) -> float:
    dec = np.stack([r.pixels for r in results], axis=-1) if x.ndim == 3 else results[0].pixels
    return ES.psnr(dec, x)


# ---- RTL hook -------------------------------------------------------------------------------


def rtl_bit_identity(commands, width: int, rtl: bool = False) -> tuple[bool, str]:
    """Decode `commands` with a hardware path and compare with the golden model.

    rtl=True plays them through the Verilated array (sim/harness, ceil(width/9) chips;
    columns past `width` are ignored: relative addressing makes a PE's result depend only
    on its own column). Otherwise the cycle-level structural model stands in, which keeps
    the Python unit tests free of Verilator builds. Returns (identical, which path ran).
    """
    gold = functional.render(commands, width)
    if rtl:
        from ..rtl import harness

        chips = -(-width // 9)
        hw, _ = harness.run(commands, chips)
        return bool(np.array_equal(hw[:, :width], gold)), f"Verilated array, {chips} chips"
    from ..model import structural

    hw = structural.render(commands, width)
    return bool(np.array_equal(hw, gold)), "structural model"


# ---- files ------------------------------------------------------------------------------------


def write_commands(path, commands, header: list[str]) -> None:
    from ..formats.asm import format_command

    lines = [f"# {h}" for h in header]
    lines += [format_command(c) for c in commands]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


def write_de48(path, commands) -> None:
    from ..formats import binfmt

    Path(path).write_bytes(binfmt.encode_de48(isa.serialise(commands)))


def channel_paths(out: Path, nch: int, tag: str = "") -> list[Path]:
    stem, suf = out.stem, out.suffix or ".cmd"
    tag = f".{tag}" if tag else ""
    if nch == 1:
        return [out.with_name(f"{stem}{tag}{suf}")]
    return [out.with_name(f"{stem}{tag}.{c}{suf}") for c in CHANNEL_SUFFIX[:nch]]


def _header(src, res: Result, x: np.ndarray, target: str) -> list[str]:
    return [f"diffengine encode {src} --codec {res.codec} ({target})",
            f"{x.shape[0]} lines x {x.shape[1]} columns, 12-bit pixels, one Refresh per line",
            f"PSNR {res.psnr:.2f} dB (golden model), {res.slots} instructions, "
            f"{res.bytes} bytes of 48-bit stream, max {res.max_slots_per_line} per line",
            ]


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("image")
    ap.add_argument("-o", "--output", required=True, help="command file (.cmd); colour "
                    "images give OUT.r.cmd, OUT.g.cmd, OUT.b.cmd")
    ap.add_argument("--codec", default="spline2", choices=CODECS)
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--psnr", type=float, help="quality target in dB (12-bit peak)")
    g.add_argument("--slots-per-line", type=int, help="instruction budget per line, "
                   "Refresh included (800 = 640x480@60)")
    g.add_argument("--bytes", type=int, help="size target: bytes of the 48-bit stream")
    g.add_argument("--lossless", action="store_true", help="exact (the default target)")
    ap.add_argument("--emission", default="auto", choices=EMISSIONS,
                    help="spline emission: one Eval per line (merged), one per scale "
                    "(layered), the cheaper of the two per line (auto), one accumulated "
                    "Eval per kept basis function (coefficient), or per basis function "
                    "whichever of own Eval / knots is cheaper (choice)")
    ap.add_argument("--baselines", action="store_true",
                    help="also write OUT.raster.cmd, OUT.rle.cmd and OUT.jpg (matched bytes)")
    ap.add_argument("--preview", help="write the golden model's decoded image (16-bit PNG)")
    ap.add_argument("--de48", action="store_true", help="also write the .de48 stream(s)")
    ap.set_defaults(func=command)


def command(args) -> int:
    try:
        x = load_image(args.image)
        chans = channels(x)
        out = Path(args.output)
        if args.bytes is not None:
            per_ch_bytes = args.bytes // len(chans)
        else:
            per_ch_bytes = None
        target = ("psnr >= %g dB" % args.psnr if args.psnr is not None else
                  "<= %d instructions per line" % args.slots_per_line
                  if args.slots_per_line is not None else
                  "<= %d bytes" % args.bytes if args.bytes is not None else "lossless")
        encs = [ChannelEncoder(c, args.emission) for c in chans]
        results = [e.encode(args.codec, args.psnr, args.slots_per_line, per_ch_bytes)
                   for e in encs]
        for p, r in zip(channel_paths(out, len(chans)), results):
            write_commands(p, r.commands, _header(args.image, r, chans[0], target))
            if args.de48:
                write_de48(p.with_suffix(".de48"), r.commands)
            print(f"wrote {p}: PSNR {r.psnr:.2f} dB, {r.slots} instructions "
                  f"({r.bytes} bytes), max {r.max_slots_per_line}/line")
        total = sum(r.bytes for r in results)
        print(f"{args.codec}: PSNR {image_psnr(results, x):.2f} dB, {total} bytes")
        if args.preview:
            dec = np.stack([r.pixels for r in results], -1) if x.ndim == 3 else results[0].pixels
            save_png16(args.preview, dec)
        if args.baselines:
            for codec in ("raster", "rle"):
                base = [e.encode(codec) for e in encs]
                for p, r in zip(channel_paths(out, len(chans), codec), base):
                    write_commands(p, r.commands, _header(args.image, r, chans[0], "lossless"))
                print(f"{codec}: PSNR {image_psnr(base, x):.2f} dB, "
                      f"{sum(r.bytes for r in base)} bytes -> {channel_paths(out, len(chans), codec)[0]}")
            jpath = out.with_suffix(".jpg")
            q, size, dec = ER.jpeg_matched(x, total, str(jpath))
            print(f"jpeg: quality {q}, PSNR {ES.psnr(dec, x):.2f} dB, {size} bytes -> {jpath}"
                  + ("" if size <= total else " (larger than the spline stream even at q=1)"))
    except EncodeError as e:
        return fail("diffengine encode", e, 2)
    except OSError as e:
        return fail("diffengine encode", f"{e.filename or ''}: {e.strerror or e}", 2)
    return 0
