"""The functional model in C (sw/fmodel, `fmodel.h`) through ctypes: the same pixels as
`functional` (the numpy golden model, which stays the readable reference) in
milliseconds, for the pipeline, the animation and the viewer.

The library is built on first use (`make -C sw/fmodel build/libfmodel.so`, under a file
lock like yproc's, so parallel pytest workers and make do not build it together) and
loaded once per process. It reads .de48 instruction words directly, so a stream never
becomes Python `Command` objects on the fast path.

    render_frame(streams, width, height)    three colour streams -> (H, W, 3) uint16
    render_lines(img, changes)              only the changed lines of an incremental frame,
                                            in place, all three colours
    render(commands, width, carry_bug)      drop-in for functional.render (tests)
    Line(width, carry_bug)                  one line's PE state, a command at a time (tests)

sw/tests/test_fmodel.py proves it equal to the numpy model: every opcode compared
register by register and flag by flag after each command, protect flags, Dis, Eval0,
Acc_mode, the carry bug, decode refusals slot for slot, random frames (seeds printed)
and the shipped scenes. Errors are FastModelError naming the stream and the slot.
"""
from __future__ import annotations

import ctypes as C
import warnings
from pathlib import Path

import numpy as np

from .. import REPO, isa
from ..host.yproc import make_locked

FMODEL_DIR = REPO / "sw" / "fmodel"
LIB = FMODEL_DIR / "build" / "libfmodel.so"
HEADER = 8                      # .de48: b"DE48", u16 version 1, u16 0
MAX_WIDTH = 4104

OPS = {"NOP": 0, "REFRESH": 1, "EVAL0": 2, "EVAL": 3, "SETI": 4, "SETDI": 5, "SETDDI": 6,
       "SETPI": 7, "SETPDI": 8, "SETPDDI": 9, "DIS": 10, "ACCMODE": 11}
STATUS = ["ok", "invalid argument", "out of memory", "malformed instruction stream",
          "more lines than rows"]


class FastModelError(RuntimeError):
    """The library could not be built, or refused a stream (the message names it and the
    slot) or an argument."""


class _Cmd(C.Structure):
    _fields_ = [("op", C.c_int32), ("x", C.c_int32), ("dx", C.c_int32),
                ("nvals", C.c_int32), ("v", C.c_int64 * 8)]


class _Err(C.Structure):
    _fields_ = [("slot", C.c_int64), ("msg", C.c_char * 160)]


class _Stream(C.Structure):
    _fields_ = [("words", C.c_char_p), ("nwords", C.c_size_t),
                ("rows", C.POINTER(C.c_int32)), ("nrows", C.c_size_t)]


_lib = None


def build() -> Path:
    """Build sw/fmodel/build/libfmodel.so if it is out of date; returns its path."""
    r = make_locked(FMODEL_DIR, "build/libfmodel.so", "fmodel_build.lock")
    if r.returncode or not LIB.exists():
        raise FastModelError("cannot build sw/fmodel/build/libfmodel.so:\n" + r.stdout + r.stderr)
    return LIB


def lib():
    """The loaded library (built on first use)."""
    global _lib
    if _lib is None:
        L = C.CDLL(str(build()))
        P16, P32 = C.POINTER(C.c_uint16), C.POINTER(C.c_int32)
        L.fm_line_new.argtypes = [C.c_int, C.c_int, C.POINTER(C.c_void_p)]
        L.fm_line_free.argtypes = [C.c_void_p]
        L.fm_line_reset.argtypes = [C.c_void_p]
        L.fm_line_exec.argtypes = [C.c_void_p, C.POINTER(_Cmd)]
        L.fm_line_state.argtypes = [C.c_void_p, C.POINTER(C.c_uint64), C.POINTER(C.c_uint8),
                                    C.POINTER(C.c_int)]
        L.fm_line_state.restype = None
        L.fm_line_pixels.argtypes = [C.c_void_p, P16]
        L.fm_line_pixels.restype = None
        L.fm_render.argtypes = [C.c_char_p, C.c_size_t, C.c_int, C.c_int, P16, C.c_ssize_t,
                                C.c_ssize_t, P32, C.c_size_t, C.POINTER(C.c_size_t),
                                C.POINTER(C.c_size_t), C.POINTER(_Err)]
        L.fm_render_rgb.argtypes = [C.POINTER(_Stream), C.c_int, C.c_int, C.c_int, P16,
                                    C.POINTER(_Err)]
        _lib = L
    return _lib


def _fail(status: int, err: _Err, name: str):
    msg = err.msg.decode(errors="replace") or STATUS[status]
    raise FastModelError(f"{name}: {msg}")


def words_of(data: bytes, name: str = "<de48>") -> bytes:
    """The instruction words of .de48 file bytes (header checked, as binfmt does)."""
    if len(data) < HEADER or data[:4] != b"DE48":
        raise FastModelError(f"{name}: byte 0: not a .de48 stream (bad magic or too short)")
    if data[4:6] != b"\0\1":
        raise FastModelError(f"{name}: byte 4: unsupported version {int.from_bytes(data[4:6], 'big')}")
    if data[6:8] != b"\0\0":
        raise FastModelError(f"{name}: byte 6: reserved header field is not zero")
    if (len(data) - HEADER) % 6:
        raise FastModelError(f"{name}: byte {len(data) - (len(data) - HEADER) % 6}: "
                             f"truncated instruction ({(len(data) - HEADER) % 6} of 6 bytes)")
    return bytes(data[HEADER:])


def _p16(a: np.ndarray):
    return a.ctypes.data_as(C.POINTER(C.c_uint16))


def render_words(words: bytes, width: int, out: np.ndarray, rows=None,
                 carry_bug: bool = False, name: str = "<de48>") -> tuple[int, int]:
    """Render raw instruction words (lines closed by Refresh) into `out`, a 2-D uint16
    array or a 2-D view of one (e.g. img[..., c]): line k into row rows[k] (row k without
    rows). Returns (lines, commands after the last Refresh). The stream is checked whole
    before a pixel is written."""
    if out.dtype != np.uint16 or out.ndim != 2 or out.shape[1] < width:
        raise FastModelError(f"{name}: out must be a 2-D uint16 array at least {width} wide")
    if not 1 <= width <= MAX_WIDTH:
        raise FastModelError(f"{name}: width {width} outside 1..{MAX_WIDTH}")
    if len(words) % 6:
        raise FastModelError(f"{name}: {len(words)} bytes is not a whole number of 6-byte words")
    rs, cs = (s // 2 for s in out.strides)
    if rows is None:
        rp, nrows = None, out.shape[0]
    else:
        r = np.ascontiguousarray(rows, dtype=np.int32)
        if len(r) and (r.min() < 0 or r.max() >= out.shape[0]):
            raise FastModelError(f"{name}: a row outside 0..{out.shape[0] - 1}")
        rp, nrows = r.ctypes.data_as(C.POINTER(C.c_int32)), len(r)
    nl, tr, err = C.c_size_t(), C.c_size_t(), _Err()
    st = lib().fm_render(bytes(words), len(words) // 6, width, int(carry_bug), _p16(out), rs,
                         cs, rp, nrows, C.byref(nl), C.byref(tr), C.byref(err))
    if st:
        _fail(st, err, name)
    return nl.value, tr.value


def render_frame(streams, width: int, height: int, carry_bug: bool = False,
                 out: np.ndarray | None = None) -> np.ndarray:
    """Three colour streams (r, g, b: .de48 file bytes or paths) -> (H, W, 3) uint16, rows
    without a line left 0. Every stream is checked before a pixel is written."""
    if len(streams) != 3:
        raise FastModelError(f"render_frame needs 3 streams (r, g, b), got {len(streams)}")
    names, words = [], []
    for s in streams:
        name = str(s) if isinstance(s, (str, Path)) else "<de48>"
        data = Path(s).read_bytes() if isinstance(s, (str, Path)) else s
        names.append(name)
        words.append(words_of(data, name))
    if out is None:
        out = np.zeros((height, width, 3), dtype=np.uint16)
    elif out.shape != (height, width, 3) or out.dtype != np.uint16 or not out.flags.c_contiguous:
        raise FastModelError(f"out must be a C-contiguous ({height}, {width}, 3) uint16 array")
    _rgb(words, [None] * 3, width, height, carry_bug, out, names)
    return out


def render_lines(img: np.ndarray, changes, carry_bug: bool = False) -> int:
    """An incremental frame: changes[c] = {row: that line's instruction words (6-byte .de48
    words, its Refresh last)} for c = r, g, b; only those rows of img (H, W, 3) uint16,
    C-contiguous, are rendered, in place. Returns how many lines were rendered."""
    if len(changes) != 3:
        raise FastModelError(f"render_lines needs 3 colours of changes, got {len(changes)}")
    if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint16 or not img.flags.c_contiguous:
        raise FastModelError("img must be a C-contiguous (H, W, 3) uint16 array")
    words, rows = [], []
    for ch in changes:
        ys = sorted(ch)
        words.append(b"".join(ch[y] for y in ys))
        rows.append(np.array(ys, dtype=np.int32))
    _rgb(words, rows, img.shape[1], img.shape[0], carry_bug, img,
         [f"changed lines of colour {c}" for c in "rgb"])
    return sum(len(r) for r in rows)


def _rgb(words, rows, width, height, carry_bug, out, names) -> None:
    if not 1 <= width <= MAX_WIDTH:
        raise FastModelError(f"width {width} outside 1..{MAX_WIDTH}")
    s = (_Stream * 3)()
    for c in range(3):
        if len(words[c]) % 6:
            raise FastModelError(f"{names[c]}: not a whole number of 6-byte words")
        s[c].words, s[c].nwords = words[c], len(words[c]) // 6
        if rows[c] is not None:
            s[c].rows, s[c].nrows = rows[c].ctypes.data_as(C.POINTER(C.c_int32)), len(rows[c])
    err = _Err()
    st = lib().fm_render_rgb(s, width, height, int(carry_bug), _p16(out), C.byref(err))
    if st:
        msg = err.msg.decode(errors="replace") or STATUS[st]
        colour = "rgb".find(msg[7:8]) if msg.startswith("colour ") else -1
        raise FastModelError(f"{names[colour]}: {msg[10:]}" if colour >= 0 else msg)


def render(commands, width: int = 640, carry_bug: bool = False) -> np.ndarray:
    """What functional.render computes, through the C library: one row per Refresh."""
    words = b"".join(((i << isa.WORD_BITS) | d).to_bytes(6, "big")
                     for i, d in isa.serialise(commands))
    lines = sum(1 for c in commands if c.op == "REFRESH")
    out = np.zeros((lines, width), dtype=np.uint16)
    _, trailing = render_words(words, width, out, carry_bug=carry_bug, name="<commands>")
    if trailing:
        warnings.warn(f"{trailing} command(s) after the last Refresh ignored", stacklevel=2)
    return out


class Line:
    """The PE state of one line in the C model, a command at a time (`functional._Line`'s
    twin for the command-by-command comparison)."""

    def __init__(self, width: int, carry_bug: bool = False):
        self.width = width
        self._p = C.c_void_p()
        if lib().fm_line_new(width, int(carry_bug), C.byref(self._p)):
            raise FastModelError(f"fm_line_new({width}) refused")

    def __del__(self):
        if getattr(self, "_p", None) and _lib is not None:
            _lib.fm_line_free(self._p)
            self._p = None

    def run(self, c: isa.Command) -> None:
        cmd = _Cmd(OPS[c.op], c.x, c.dx, len(c.values))
        for k, v in enumerate(c.values):
            cmd.v[k] = v
        st = lib().fm_line_exec(self._p, C.byref(cmd))
        if st:
            raise FastModelError(f"{c}: {STATUS[st]}")

    def reset(self) -> None:
        lib().fm_line_reset(self._p)

    def state(self) -> dict:
        """A, B, C, D (uint64), pA, pB, pC, dis, lock (bool) arrays and acc_mode."""
        w = self.width
        regs = np.zeros(4 * w, dtype=np.uint64)
        flags = np.zeros(5 * w, dtype=np.uint8)
        am = C.c_int()
        lib().fm_line_state(self._p, regs.ctypes.data_as(C.POINTER(C.c_uint64)),
                            flags.ctypes.data_as(C.POINTER(C.c_uint8)), C.byref(am))
        out = {k: regs[i * w:(i + 1) * w] for i, k in enumerate("ABCD")}
        out.update({k: flags[i * w:(i + 1) * w].astype(bool)
                    for i, k in enumerate(("pA", "pB", "pC", "dis", "lock"))})
        out["acc_mode"] = bool(am.value)
        return out

    def pixels(self) -> np.ndarray:
        px = np.zeros(self.width, dtype=np.uint16)
        lib().fm_line_pixels(self._p, _p16(px))
        return px
