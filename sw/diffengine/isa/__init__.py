"""The x-processor instruction set: identifiers, commands and their serialisation.

docs/isa.md is the normative text; this module is its executable form. Everything else
(assembler, golden models, testbenches) builds on the names defined here. The tables
(identifier fields, encodings, look-up table, adder, video modes, debug-vector layout)
are generated from spec/isa.toml and spec/video.toml into _tables.py by
`python -m diffengine.isa.gen`, which also writes rtl/xproc/de_pkg.sv and
sw/include/de_isa.h from the same text.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ._tables import *  # noqa: F401,F403 (generated from spec/isa.toml)
from ._tables import (
    ACC, ACCMODE_OFF, ACCMODE_ON, ADDR_DIS, ADDR_EVAL0, ADDR_MAX, ADDR_PERIODIC,
    ADDR_RANGE, BLOCK_BITS, BLOCK_MASK, BLOCKS, D_A, D_A_A_NP, D_A_B, D_A_B_NP, D_B, D_B_C,
    D_C, DST_SHIFT, FRAC_BITS, FRAC_MASK, ID_DATA, ID_PROT, ID_SET, LUT, MAX_EVAL_ORDER,
    NOP, REFRESH, REG_A, REG_B, REG_C, REG_NONE, SET_A, SET_B, SET_C, SRC_SHIFT,
    TYPE_ADDR, TYPE_INT, TYPE_NONE, WORD_BITS, WORD_MASK, add_word,
)

REG_NAMES = {REG_NONE: "-", REG_A: "A", REG_B: "B", REG_C: "C"}


def data_id(dst: int, src: int, prot: bool) -> int:
    """Identifier of an Eval data slot: dst := v, pass v + src on."""
    return ID_DATA | (dst << DST_SHIFT) | (src << SRC_SHIFT) | (ID_PROT if prot else 0)


def set_id(dst: int) -> int:
    return ID_DATA | (dst << DST_SHIFT) | ID_SET


LUT_INDEX = {ident: i for i, (_, ident, _) in enumerate(LUT)}
ID_NAME = {ident: name for name, ident, _ in LUT}
ID_TYPE = {ident: typ for _, ident, typ in LUT}

# ---- fixed point -----------------------------------------------------------------


def to_word(value: int) -> int:
    """Signed integer (12.24 units) -> 36-bit two's complement pattern."""
    return value & WORD_MASK


def to_signed(word: int) -> int:
    """36-bit pattern -> signed integer in [-2^35, 2^35)."""
    word &= WORD_MASK
    return word - (1 << WORD_BITS) if word >> (WORD_BITS - 1) else word


def fits_signed36(value: int) -> bool:
    return -(1 << (WORD_BITS - 1)) <= value < (1 << (WORD_BITS - 1))


def format_fixed(word: int) -> str:
    """36-bit pattern as the exact hex literal 0xIII.FFFFFF (the source's Table 7.5 style)."""
    word &= WORD_MASK
    return f"0x{word >> FRAC_BITS:03x}.{word & ((1 << FRAC_BITS) - 1):06x}"


def pixel_of(word: int) -> int:
    """The 12-bit pixel a D register shows: its integer part, raw (wraps)."""
    return (word >> FRAC_BITS) & BLOCK_MASK


def word_blocks(word: int) -> tuple[int, ...]:
    """A 36-bit word as its BLOCKS blocks of BLOCK_BITS, block 0 (the least significant)
    first: the split the PE's adder and the skewed bus make (de_pkg::word_blk)."""
    return tuple((word >> (BLOCK_BITS * j)) & BLOCK_MASK for j in range(BLOCKS))


def blocks_word(blocks) -> int:
    """The inverse of word_blocks: blocks, block 0 first, back into one word."""
    return sum((int(b) & BLOCK_MASK) << (BLOCK_BITS * j) for j, b in enumerate(blocks))


def block_bits(j: int) -> tuple[int, int]:
    """(msb, lsb) of block j in the word, for messages."""
    return BLOCK_BITS * j + BLOCK_BITS - 1, BLOCK_BITS * j


def compensate(value: int, literal: bool = False) -> int:
    """§7.7 carry-bug compensation of a signed 36-bit value (returns a signed value).

    The 24 fraction bits are shifted down one place, so that a fraction overflow (now
    worth 0.5) that the faulty adder lands at bit 25 (+2) is worth exactly 1.0 again.
    literal=True also sets bit 23 of negative values, as the source's text says; under
    the modelled fault that makes a negative operand represent v + 1, so it is kept only
    to reproduce and document that discrepancy (docs/isa.md §7).
    """
    word = to_word(value)
    frac = word & FRAC_MASK
    out = (word & ~FRAC_MASK & WORD_MASK) | (frac >> 1)
    if literal and value < 0:
        out |= 1 << (FRAC_BITS - 1)
    return to_signed(out)


# ---- commands --------------------------------------------------------------------

OPS = (
    "EVAL0", "EVAL", "SETI", "SETDI", "SETDDI", "SETPI", "SETPDI", "SETPDDI",
    "DIS", "ACCMODE", "REFRESH", "NOP",
)
SET_REG = {"SETI": REG_A, "SETDI": REG_B, "SETDDI": REG_C,
           "SETPI": REG_A, "SETPDI": REG_B, "SETPDDI": REG_C}


@dataclass(frozen=True)
class Command:
    """One command of Table 7.1.

    op:      one of OPS.
    x, dx:   12-bit unsigned operands (0 where the command has none).
    values:  intensities as signed 12.24 integers. For EVAL: (I, dI, ..., d^pI), lowest
             order first (order p = len(values) - 1). For Set*: (v,). For EVAL0: (I12,)
             where I12 is the 12-bit integer intensity. For ACCMODE: (1,) on, (0,) off.
    line:    source line, for messages (not part of equality).
    """

    op: str
    x: int = 0
    dx: int = 0
    values: tuple[int, ...] = ()
    line: int = field(default=0, compare=False)

    @property
    def order(self) -> int:
        return len(self.values) - 1 if self.op == "EVAL" else -1

    def validate(self) -> None:
        """Raise ValueError if any operand is out of range (never truncate)."""
        if self.op not in OPS:
            raise ValueError(f"unknown command {self.op!r}")
        for name, v in (("X", self.x), ("dX", self.dx)):
            if not 0 <= v <= ADDR_MAX:
                raise ValueError(f"{name} = {v} outside 0..{ADDR_MAX}")
        if self.op == "EVAL":
            if not 1 <= len(self.values) <= MAX_EVAL_ORDER + 1:
                raise ValueError(f"Eval needs 1..{MAX_EVAL_ORDER + 1} values")
        if self.op == "EVAL0":
            if len(self.values) != 1 or not 0 <= self.values[0] <= 4095:
                raise ValueError("Eval0 intensity must be an integer in 0..4095")
            return
        if self.op == "ACCMODE":
            if self.values not in ((0,), (1,)):
                raise ValueError("Acc_mode takes 0 or 1")
            return
        for v in self.values:
            if not fits_signed36(v):
                raise ValueError(f"intensity {v / (1 << FRAC_BITS):g} outside [-2048, 2048)")


def slots(cmd: Command) -> list[tuple[int, int]]:
    """Serialise a command into (identifier, 36-bit data) instructions (Table 7.2)."""
    op = cmd.op
    rng = (cmd.x & BLOCK_MASK) | ((cmd.dx & BLOCK_MASK) << BLOCK_BITS)
    if op == "NOP":
        return [(NOP, 0)]
    if op == "REFRESH":
        return [(REFRESH, 0)]
    if op == "ACCMODE":
        return [(ACCMODE_ON if cmd.values[0] else ACCMODE_OFF, 0)]
    if op == "DIS":
        return [(ADDR_DIS, rng)]
    if op == "EVAL0":
        return [(ADDR_EVAL0, rng | ((cmd.values[0] & BLOCK_MASK) << 2 * BLOCK_BITS))]
    if op in ("SETI", "SETDI", "SETDDI"):
        return [(ADDR_RANGE, rng), (set_id(SET_REG[op]), to_word(cmd.values[0]))]
    if op in ("SETPI", "SETPDI", "SETPDDI"):
        per = (cmd.dx & BLOCK_MASK) | ((cmd.x & BLOCK_MASK) << BLOCK_BITS)
        return [(ADDR_PERIODIC, per), (set_id(SET_REG[op]), to_word(cmd.values[0]))]
    if op == "EVAL":
        return [(ADDR_RANGE, rng)] + [
            (ident, to_word(v)) for ident, v in zip(eval_data_ids(cmd.order), reversed(cmd.values))
        ] + [(ACC, 0)]
    raise ValueError(f"unknown command {op!r}")


def eval_data_ids(order: int) -> list[int]:
    """Identifiers of the data slots of an order-p Eval, highest difference first."""
    if order == 0:
        return [D_A]
    if order == 1:
        return [D_B, D_A_B]
    if order == 2:
        return [D_C, D_B_C, D_A_B]
    return [D_C, D_B_C, D_A_B_NP] + [D_A_A_NP] * (order - 2)


def serialise(commands) -> list[tuple[int, int]]:
    out: list[tuple[int, int]] = []
    for c in commands:
        out.extend(slots(c))
    return out


def split_lines(commands) -> list[list[Command]]:
    """Group commands into scanlines; each line ends with (and includes) its Refresh."""
    lines: list[list[Command]] = []
    cur: list[Command] = []
    for c in commands:
        cur.append(c)
        if c.op == "REFRESH":
            lines.append(cur)
            cur = []
    if cur:
        lines.append(cur)
    return lines


# ---- video modes -----------------------------------------------------------------
# de_pkg::video_mode_t (generated from spec/video.toml), MSB first: h_act, h_fp, h_sync,
# h_bp, v_act, v_fp, v_sync, v_bp of 12 bits each, then h_pol, v_pol.
VIDEO_FIELD_BITS = 12
VIDEO_MODE_BITS = 8 * VIDEO_FIELD_BITS + 2


def video_mode_param(h, v, hpol: bool = False, vpol: bool = False) -> str:
    """A de_pkg::video_mode_t as a Verilog literal, for a top's TestMode parameter (-G):
    h and v are (active, front porch, sync, back porch)."""
    if len(h) != 4 or len(v) != 4 or not all(0 <= n < 1 << VIDEO_FIELD_BITS
                                             for n in (*h, *v)):
        raise ValueError(f"video mode {h} {v}: 4 + 4 values of 0..4095")
    word = 0
    for n in (*h, *v):
        word = word << VIDEO_FIELD_BITS | n
    return f"{VIDEO_MODE_BITS}'h{word << 2 | int(hpol) << 1 | int(vpol):x}"


def video_mode_fields(word: int) -> dict:
    """A de_pkg::video_mode_t read back (a top's TestMode): the tops' old parameter names
    TestHActive ... TestVBp, HTotal and VTotal."""
    names = ("TestHActive", "TestHFp", "TestHSync", "TestHBp",
             "TestVActive", "TestVFp", "TestVSync", "TestVBp")
    mask = (1 << VIDEO_FIELD_BITS) - 1
    g = {k: word >> (2 + VIDEO_FIELD_BITS * (7 - i)) & mask for i, k in enumerate(names)}
    g["HTotal"] = sum(g[k] for k in names[:4])
    g["VTotal"] = sum(g[k] for k in names[4:])
    return g
