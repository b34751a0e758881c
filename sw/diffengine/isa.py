"""The x-processor instruction set: identifiers, commands and their serialisation.

docs/isa.md is the normative text; this module is its executable form. Everything else
(assembler, golden models, testbenches) builds on the names defined here.
"""
from __future__ import annotations

from dataclasses import dataclass, field

WORD_BITS = 36
WORD_MASK = (1 << WORD_BITS) - 1
FRAC_BITS = 24
BLOCK_BITS = 12
BLOCK_MASK = (1 << BLOCK_BITS) - 1
ADDR_MAX = 4095
MAX_EVAL_ORDER = 7  # Eval8 = order 7 is the largest EvalN accepted

# ---- identifier bit fields (docs/isa.md §3) -------------------------------------
ID_ADDR = 1 << 11
ID_DATA = 1 << 10
ID_ACC = 1 << 9
ID_REFRESH = 1 << 8
DST_SHIFT = 6
SRC_SHIFT = 4
ID_SET = 1 << 3
ID_PROT = 1 << 2
SUB_MASK = 0x3

REG_NONE, REG_A, REG_B, REG_C = 0, 1, 2, 3
REG_NAMES = {REG_NONE: "-", REG_A: "A", REG_B: "B", REG_C: "C"}

SUB_RANGE, SUB_PERIODIC, SUB_EVAL0, SUB_DIS = 0, 1, 2, 3
SUB_ACCMODE_ON, SUB_ACCMODE_OFF = 1, 2


def data_id(dst: int, src: int, prot: bool) -> int:
    """Identifier of an Eval data slot: dst := v, pass v + src on."""
    return ID_DATA | (dst << DST_SHIFT) | (src << SRC_SHIFT) | (ID_PROT if prot else 0)


def set_id(dst: int) -> int:
    return ID_DATA | (dst << DST_SHIFT) | ID_SET


NOP = 0x000
REFRESH = ID_REFRESH
ACCMODE_ON = SUB_ACCMODE_ON
ACCMODE_OFF = SUB_ACCMODE_OFF
ADDR_RANGE = ID_ADDR | SUB_RANGE
ADDR_PERIODIC = ID_ADDR | SUB_PERIODIC
ADDR_EVAL0 = ID_ADDR | SUB_EVAL0
ADDR_DIS = ID_ADDR | SUB_DIS
ACC = ID_ACC
D_A = data_id(REG_A, REG_NONE, True)
D_B = data_id(REG_B, REG_NONE, True)
D_C = data_id(REG_C, REG_NONE, True)
D_B_C = data_id(REG_B, REG_C, True)
D_A_B = data_id(REG_A, REG_B, True)
D_A_B_NP = data_id(REG_A, REG_B, False)
D_A_A_NP = data_id(REG_A, REG_A, False)
SET_A = set_id(REG_A)
SET_B = set_id(REG_B)
SET_C = set_id(REG_C)

TYPE_NONE, TYPE_ADDR, TYPE_INT = "none", "address", "intensity"

# The instruction look-up table of the prototype (§7.6.2): 5-bit index -> identifier.
LUT: list[tuple[str, int, str]] = [
    ("NOP", NOP, TYPE_NONE),
    ("REFRESH", REFRESH, TYPE_NONE),
    ("ACCMODE_ON", ACCMODE_ON, TYPE_NONE),
    ("ACCMODE_OFF", ACCMODE_OFF, TYPE_NONE),
    ("ADDR_RANGE", ADDR_RANGE, TYPE_ADDR),
    ("ADDR_PERIODIC", ADDR_PERIODIC, TYPE_ADDR),
    ("ADDR_EVAL0", ADDR_EVAL0, TYPE_ADDR),
    ("ADDR_DIS", ADDR_DIS, TYPE_ADDR),
    ("ACC", ACC, TYPE_NONE),
    ("D_A", D_A, TYPE_INT),
    ("D_B", D_B, TYPE_INT),
    ("D_C", D_C, TYPE_INT),
    ("D_B_C", D_B_C, TYPE_INT),
    ("D_A_B", D_A_B, TYPE_INT),
    ("D_A_B_NP", D_A_B_NP, TYPE_INT),
    ("D_A_A_NP", D_A_A_NP, TYPE_INT),
    ("SET_A", SET_A, TYPE_INT),
    ("SET_B", SET_B, TYPE_INT),
    ("SET_C", SET_C, TYPE_INT),
]
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


def compensate(value: int, literal: bool = False) -> int:
    """§7.7 carry-bug compensation of a signed 36-bit value (returns a signed value).

    The 24 fraction bits are shifted down one place, so that a fraction overflow (now
    worth 0.5) that the faulty adder lands at bit 25 (+2) is worth exactly 1.0 again.
    literal=True also sets bit 23 of negative values, as the source's text says; under
    the modelled fault that makes a negative operand represent v + 1, so it is kept only
    to reproduce and document that discrepancy (docs/isa.md §7).
    """
    word = to_word(value)
    frac = word & 0xFFFFFF
    out = (word & ~0xFFFFFF & WORD_MASK) | (frac >> 1)
    if literal and value < 0:
        out |= 0x800000
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
