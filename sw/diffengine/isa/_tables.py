# GENERATED FILE, DO NOT EDIT. Source: spec/isa.toml, spec/video.toml, spec/regs.toml.
# Regenerate with `python -m diffengine.isa.gen` (or `make gen`); `make gen-check` diffs.
"""The ISA tables of spec/isa.toml and spec/video.toml (imported by diffengine.isa)."""
from __future__ import annotations

ID_BITS = 12
BLOCK_BITS = 12
BLOCKS = 3
WORD_BITS = BLOCK_BITS * BLOCKS
FRAC_BITS = 24
ADDR_MAX = 4095
MAX_EVAL_ORDER = 7
RECORD_BITS = 48
ID_MASK = (1 << ID_BITS) - 1
BLOCK_MASK = (1 << BLOCK_BITS) - 1
WORD_MASK = (1 << WORD_BITS) - 1
FRAC_MASK = (1 << FRAC_BITS) - 1

# Identifier fields: name -> (lsb, width).
ID_FIELDS = {
    "addr": (11, 1),  # address slot (X / dX in the data)
    "data": (10, 1),  # data slot (Eval value or Set)
    "acc": (9, 1),  # accumulate slot, D += A
    "refresh": (8, 1),  # output the pixel, clear the PE
    "dst": (6, 2),  # destination register code
    "src": (4, 2),  # source register code
    "set": (3, 1),  # data slot is a Set
    "prot": (2, 1),  # Eval data slot honours DST's protect flag
    "sub": (0, 2),  # addressing sub-mode / Acc_mode
}
ID_ADDR = 1 << 11
ID_DATA = 1 << 10
ID_ACC = 1 << 9
ID_REFRESH = 1 << 8
DST_SHIFT = 6
DST_MASK = 0x3
SRC_SHIFT = 4
SRC_MASK = 0x3
ID_SET = 1 << 3
ID_PROT = 1 << 2
SUB_SHIFT = 0
SUB_MASK = 0x3

REG_NONE = 0
REG_A = 1
REG_B = 2
REG_C = 3
SUB_RANGE = 0
SUB_PERIODIC = 1
SUB_EVAL0 = 2
SUB_DIS = 3
SUB_ACCMODE_ON = 1
SUB_ACCMODE_OFF = 2

TYPE_NONE, TYPE_ADDR, TYPE_INT = "none", "address", "intensity"
OPERAND_TYPE_CODE = {"none": 0, "address": 1, "intensity": 2}

NOP = 0x000
REFRESH = 0x100
ACCMODE_ON = 0x001
ACCMODE_OFF = 0x002
ADDR_RANGE = 0x800
ADDR_PERIODIC = 0x801
ADDR_EVAL0 = 0x802
ADDR_DIS = 0x803
ACC = 0x200
D_A = 0x444
D_B = 0x484
D_C = 0x4c4
D_B_C = 0x4b4
D_A_B = 0x464
D_A_B_NP = 0x460
D_A_A_NP = 0x450
SET_A = 0x448
SET_B = 0x488
SET_C = 0x4c8

LUT_CODE_BITS = 5
# The instruction look-up table of the prototype (7.6.2): 5-bit code -> identifier.
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

# The host register map (spec/regs.toml).
REG_CHAN_LSB = 0x00c  # address bits above it: the channel
REG_INFO_CHAN = 0x003  # channel of the controller's registers
LM_ID_MAGIC = 0x0de  # Load Monitor ID[31:24]
CTRL_ID_MAGIC = 0x0dc  # controller ID[31:24]
LM_REG_ID = 0x000  # Load Monitor register
LM_REG_FRAMES = 0x001  # Load Monitor register
LM_REG_ISSUED = 0x002  # Load Monitor register
LM_REG_FREE = 0x003  # Load Monitor register
LM_REG_LATE = 0x004  # Load Monitor register
LM_REG_DROP = 0x005  # Load Monitor register
LM_REG_MAX_ISSUED = 0x006  # Load Monitor register
LM_REG_LAST_LINE = 0x007  # Load Monitor register
LM_REG_LAST_REC = 0x008  # Load Monitor register
LM_REG_TOTAL_DROP = 0x009  # Load Monitor register
LM_REG_TOTAL_LATE = 0x00a  # Load Monitor register
LM_HIST_BASE = 0x040  # HIST[b] at LM_HIST_BASE + b
LM_LINE_BASE = 0x400  # LINE[l] at LM_LINE_BASE + l
CTRL_REG_ID = 0x000  # controller register
CTRL_REG_ALIGN_ERR = 0x001  # controller register

ADD_CARRY_FROM = 24
ADD_CARRY_TO = 25


def add_word(x: int, y: int, carry_bug: bool = False) -> int:
    """The adder (isa.md section 7); with carry_bug the carry out of the fraction
    enters the integer part at ADD_CARRY_TO instead of ADD_CARRY_FROM."""
    if not carry_bug:
        return (x + y) & WORD_MASK
    lm = (1 << ADD_CARRY_FROM) - 1
    lo = (x & lm) + (y & lm)
    hi = (x >> ADD_CARRY_FROM) + (y >> ADD_CARRY_FROM) + ((lo >> ADD_CARRY_FROM) << (ADD_CARRY_TO - ADD_CARRY_FROM))
    return ((hi << ADD_CARRY_FROM) | (lo & lm)) & WORD_MASK


# Video modes (spec/video.toml): index -> (name, (hact, hfp, hsync, hbp),
# (vact, vfp, vsync, vbp), hpol, vpol); index VIDEO_MODE_TEST is given by the caller.
VIDEO_MODE_TEST = 3
VIDEO_MODES = {
    0: ("640x480", (640, 16, 96, 48), (480, 10, 2, 33), False, False),
    1: ("640x485", (640, 8, 24, 11), (485, 11, 2, 27), False, False),
    2: ("1280x1024", (1280, 48, 112, 248), (1024, 1, 3, 38), True, True),
}

# de_pe's debug vector dbg_o, MSB first: (name, width).
DBG_FIELDS: list[tuple[str, int]] = [
    ("A", 36),
    ("B", 36),
    ("C", 36),
    ("D", 36),
    ("pA", 1),
    ("pB", 1),
    ("pC", 1),
    ("dis", 1),
    ("lock", 1),
    ("acc_mode", 1),
    ("act", 1),
    ("id1", 12),
    ("id2", 12),
    ("out", 36),
    ("xz1", 1),
    ("act1", 1),
    ("prot1", 1),
    ("c1", 1),
    ("act2", 1),
    ("prot2", 1),
    ("c2", 1),
    ("e0wr2", 1),
    ("accen2", 1),
    ("accc2", 1),
    ("accen3", 1),
    ("accc3", 1),
    ("pix_valid", 1),
    ("pix", 12),
]
