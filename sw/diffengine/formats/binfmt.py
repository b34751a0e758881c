"""Binary formats: the 48-bit instruction stream (.de48) and the prototype's 32-bit
frame-store words (.de32), plus the frame-store data mapper of §7.6.2.

.de48  b"DE48", u16 version = 1, u16 reserved = 0, then one 6-byte big-endian word per
       instruction: identifier in bits 47..36, data in bits 35..0. This is exactly what
       enters PE 0, so testbenches can stream it without knowing about commands.
.de32  b"DE32", u16 version = 1, u8 window w (0..4), u8 flags (bit 0: carry-bug
       compensation), then one 4-byte big-endian word per instruction: [31:27] LUT
       index, [26:0] operand (docs/isa.md §8).

`map_word` is the reference model of the data mapper (LUT, sign extension, zero padding,
compensation); the RTL mapper is tested against it, so it is a plain pure function.
`framestore_encode` is its inverse and refuses anything the 27-bit operand cannot hold.
All errors are AsmError: `file:where: message` with a byte offset, slot or line.
"""
from __future__ import annotations

import struct

from .. import isa
from ..isa import Command
from .asm import AsmError, mnemonic, parse_text

DE48_MAGIC = b"DE48"
DE32_MAGIC = b"DE32"
VERSION = 1
HEADER_LEN = 8
FLAG_COMPENSATE = 0x01
FS_WINDOWS = range(0, 5)
OPERAND_BITS = 27
OPERAND_MASK = (1 << OPERAND_BITS) - 1
# The frame store's address-type operand: X, dX of FS_ADDR_BITS each, then a 7-bit Eval0
# intensity (de_data_mapper's layout, docs/formats.md).
FS_ADDR_BITS = 10
FS_ADDR_MAX = (1 << FS_ADDR_BITS) - 1


def _sext(value: int, bits: int) -> int:
    value &= (1 << bits) - 1
    return value - (1 << bits) if value >> (bits - 1) else value


# ---- .de48 --------------------------------------------------------------------------


def encode_de48(slots) -> bytes:
    """Instruction stream [(ident12, data36), ...] -> .de48 bytes."""
    out = bytearray(DE48_MAGIC + struct.pack(">HH", VERSION, 0))
    for i, (ident, data) in enumerate(slots):
        if not (0 <= ident <= isa.BLOCK_MASK and 0 <= data <= isa.WORD_MASK):
            raise ValueError(f"slot {i}: identifier {ident:#x} or data {data:#x} out of range")
        out += ((ident << isa.WORD_BITS) | data).to_bytes(6, "big")
    return bytes(out)


def decode_de48(data: bytes, filename: str = "<de48>") -> list[tuple[int, int]]:
    """.de48 bytes -> instruction stream; AsmError on a bad header or a truncated word."""
    _check_header(data, DE48_MAGIC, filename)
    if data[6:8] != b"\0\0":
        raise AsmError(filename, [("byte 6", "reserved header field is not zero")])
    body = data[HEADER_LEN:]
    if len(body) % 6:
        raise AsmError(filename, [(f"byte {HEADER_LEN + len(body) // 6 * 6}",
                                   f"truncated instruction ({len(body) % 6} of 6 bytes)")])
    out = []
    for k in range(0, len(body), 6):
        w = int.from_bytes(body[k:k + 6], "big")
        out.append((w >> isa.WORD_BITS, w & isa.WORD_MASK))
    return out


def _check_header(data: bytes, magic: bytes, filename: str) -> None:
    if len(data) < HEADER_LEN:
        raise AsmError(filename, [("byte 0", f"too short for a {magic.decode()} header "
                                             f"({len(data)} bytes)")])
    if data[:4] != magic:
        raise AsmError(filename, [("byte 0", f"bad magic {data[:4]!r}, want {magic!r}")])
    version = struct.unpack(">H", data[4:6])[0]
    if version != VERSION:
        raise AsmError(filename, [("byte 4", f"unsupported version {version}, want {VERSION}")])


# ---- instruction stream -> commands -------------------------------------------------

_SIMPLE = {isa.NOP: "NOP", isa.REFRESH: "REFRESH"}
_SET_OPS = {(isa.ADDR_RANGE, isa.SET_A): "SETI", (isa.ADDR_RANGE, isa.SET_B): "SETDI",
            (isa.ADDR_RANGE, isa.SET_C): "SETDDI", (isa.ADDR_PERIODIC, isa.SET_A): "SETPI",
            (isa.ADDR_PERIODIC, isa.SET_B): "SETPDI", (isa.ADDR_PERIODIC, isa.SET_C): "SETPDDI"}
_EVAL_SEQS = {tuple(isa.eval_data_ids(p)): p for p in range(isa.MAX_EVAL_ORDER + 1)}


def deserialise(slots, filename: str = "<slots>") -> list[Command]:
    """Instruction stream back to commands; the inverse of isa.serialise.

    Raises AsmError("file:slot N: ...") at the first slot that no command produces:
    an orphan data/ACC slot, an Eval whose data slots are not a Table 7.2 sequence,
    an unknown identifier, or data bits that the slot's command leaves zero.
    """
    slots = list(slots)
    out: list[Command] = []
    i = 0

    def fail(k, msg):
        raise AsmError(filename, [(f"slot {k}", msg)])

    def name(ident):
        return isa.ID_NAME.get(ident, f"{ident:#05x}")

    while i < len(slots):
        ident, data = slots[i]
        if ident not in isa.ID_NAME:
            fail(i, f"unknown identifier {ident:#05x}")
        b0, b1, b2 = isa.word_blocks(data)
        if ident in _SIMPLE or ident in (isa.ACCMODE_ON, isa.ACCMODE_OFF):
            if data:
                fail(i, f"{name(ident)} carries nonzero data {isa.format_fixed(data)}")
            if ident in _SIMPLE:
                out.append(Command(_SIMPLE[ident]))
            else:
                out.append(Command("ACCMODE", values=(1 if ident == isa.ACCMODE_ON else 0,)))
            i += 1
        elif ident == isa.ADDR_EVAL0:
            out.append(Command("EVAL0", b0, b1, (b2,)))
            i += 1
        elif ident == isa.ADDR_DIS:
            if b2:
                fail(i, "ADDR_DIS carries a nonzero block 2")
            out.append(Command("DIS", b0, b1))
            i += 1
        elif ident in (isa.ADDR_RANGE, isa.ADDR_PERIODIC):
            if b2:
                fail(i, f"{name(ident)} carries a nonzero block 2")
            x, dx = (b0, b1) if ident == isa.ADDR_RANGE else (b1, b0)
            if i + 1 >= len(slots):
                fail(i, f"{name(ident)} at the end of the stream: its data slots are missing")
            nxt = slots[i + 1][0]
            if (ident, nxt) in _SET_OPS:
                out.append(Command(_SET_OPS[ident, nxt], x, dx, (isa.to_signed(slots[i + 1][1]),)))
                i += 2
                continue
            if ident == isa.ADDR_PERIODIC:
                fail(i + 1, f"{name(nxt)} after ADDR_PERIODIC: only SET_A/B/C may follow")
            j = i + 1
            while j < len(slots) and slots[j][0] != isa.ACC and isa.ID_TYPE.get(
                    slots[j][0]) == isa.TYPE_INT and j - i <= isa.MAX_EVAL_ORDER + 1:
                j += 1
            if j >= len(slots) or slots[j][0] != isa.ACC:
                where = min(j, len(slots) - 1)
                fail(where, "Eval data slots not closed by ACC "
                            f"(found {name(slots[j][0]) if j < len(slots) else 'end of stream'})")
            if slots[j][1]:
                fail(j, "ACC carries nonzero data")
            seq = tuple(s[0] for s in slots[i + 1:j])
            if seq not in _EVAL_SEQS:
                fail(i + 1, "Eval data slots " + " ".join(name(s) for s in seq)
                     + " are not a Table 7.2 sequence")
            values = tuple(isa.to_signed(s[1]) for s in reversed(slots[i + 1:j]))
            out.append(Command("EVAL", x, dx, values))
            i = j + 1
        else:
            fail(i, f"{name(ident)} without a preceding address slot")
    return out


def compensate_slots(slots) -> list[tuple[int, int]]:
    """Apply the §7.7 compensation to every intensity-type slot (what the mapper does)."""
    return [(ident, isa.to_word(isa.compensate(isa.to_signed(data))))
            if isa.ID_TYPE.get(ident) == isa.TYPE_INT else (ident, data)
            for ident, data in slots]


# ---- frame store ----------------------------------------------------------------------


def map_word(word: int, window: int, compensate: bool = False) -> tuple[int, int]:
    """The data mapper (§7.6.2, docs/isa.md §8): 32-bit frame-store word -> (ident12, data36).

    Address type: [9:0] -> bits 9..0, [19:10] -> bits 21..12, [26:20] (7-bit Eval0
    intensity) -> pixel bits [w+6:w], sign-extended above, zero-padded below.
    Intensity type: 27-bit two's complement -> bits [30+w:4+w], sign-extended above,
    zero-padded below, then comp() if compensate. None type, and LUT indices 19..31
    (which become Nop): data 0.
    """
    if not 0 <= word <= 0xFFFFFFFF:
        raise ValueError(f"frame-store word {word:#x} is not 32 bits")
    if window not in FS_WINDOWS:
        raise ValueError(f"frame-store window {window} outside 0..4")
    index, operand = word >> OPERAND_BITS, word & OPERAND_MASK
    if index >= len(isa.LUT):
        return isa.NOP, 0
    _, ident, typ = isa.LUT[index]
    if typ == isa.TYPE_NONE:
        return ident, 0
    if typ == isa.TYPE_ADDR:
        pixel = (_sext(operand >> 2 * FS_ADDR_BITS, 7) << window) & isa.BLOCK_MASK
        return ident, isa.blocks_word((operand & FS_ADDR_MAX,
                                       (operand >> FS_ADDR_BITS) & FS_ADDR_MAX, pixel))
    value = _sext(operand, OPERAND_BITS) << (4 + window)
    if compensate:
        value = isa.compensate(value)
    return ident, isa.to_word(value)


def _fs_operand(ident: int, data: int, window: int) -> int:
    """Operand that map_word (uncompensated) turns back into `data`; ValueError if none."""
    typ = isa.ID_TYPE[ident]
    if typ == isa.TYPE_NONE:
        return 0
    if typ == isa.TYPE_ADDR:
        b0, b1, b2 = isa.word_blocks(data)
        names = ("dX", "X") if ident == isa.ADDR_PERIODIC else ("X", "dX")
        for n, v in zip(names, (b0, b1)):
            if v > FS_ADDR_MAX:
                raise ValueError(f"{n} = {v}: the frame store addresses columns "
                                 f"0..{FS_ADDR_MAX} only")
        op7 = (b2 >> window) & 0x7F
        if (_sext(op7, 7) << window) & isa.BLOCK_MASK != b2:
            raise ValueError(f"Eval0 intensity {b2} does not fit the 7-bit frame-store field at "
                             f"window {window} (multiples of {1 << window} up to {63 << window})")
        return b0 | b1 << FS_ADDR_BITS | op7 << 2 * FS_ADDR_BITS
    v = isa.to_signed(data)
    low = 4 + window
    if v & ((1 << low) - 1):
        raise ValueError(f"intensity {isa.format_fixed(data)} needs precision below bit {low} "
                         f"(window {window} keeps bits 35..{low}; try asm --round)")
    q = v >> low
    if not -(1 << 26) <= q < (1 << 26):
        raise ValueError(f"intensity {isa.format_fixed(data)} exceeds the 27-bit frame-store "
                         f"range at window {window}: |value| < {1 << (window + 6)} pixel units")
    return q & OPERAND_MASK


def framestore_encode(commands, window: int, filename: str = "<commands>") -> list[int]:
    """Commands -> 32-bit frame-store words at DAC window w (one word per instruction).

    Every operand must survive map_word exactly; all violations are reported together
    (never truncated). Compensation is not applied here: it is the mapper's job
    (.de32 flag / --compensate).
    """
    if window not in FS_WINDOWS:
        raise AsmError(filename, [(0, f"frame-store window {window} outside 0..4")])
    words: list[int] = []
    errors = []
    for k, cmd in enumerate(commands):
        for ident, data in isa.slots(cmd):
            try:
                words.append(isa.LUT_INDEX[ident] << OPERAND_BITS | _fs_operand(ident, data, window))
            except ValueError as e:
                errors.append((cmd.line or f"command {k}", f"{mnemonic(cmd)}: {e}"))
                break
    if errors:
        raise AsmError(filename, errors)
    return words


def framestore_slots(words, window: int, compensate: bool = False) -> list[tuple[int, int]]:
    return [map_word(w, window, compensate) for w in words]


def encode_de32(words, window: int, compensate: bool = False) -> bytes:
    if window not in FS_WINDOWS:
        raise ValueError(f"frame-store window {window} outside 0..4")
    out = bytearray(DE32_MAGIC + struct.pack(">HBB", VERSION, window,
                                             FLAG_COMPENSATE if compensate else 0))
    for w in words:
        out += struct.pack(">I", w)
    return bytes(out)


def decode_de32(data: bytes, filename: str = "<de32>") -> tuple[list[int], int, bool]:
    """.de32 bytes -> (words, window, compensate)."""
    _check_header(data, DE32_MAGIC, filename)
    window, flags = data[6], data[7]
    if window not in FS_WINDOWS:
        raise AsmError(filename, [("byte 6", f"window {window} outside 0..4")])
    if flags & ~FLAG_COMPENSATE:
        raise AsmError(filename, [("byte 7", f"unknown flag bits {flags:#04x}")])
    body = data[HEADER_LEN:]
    if len(body) % 4:
        raise AsmError(filename, [(f"byte {HEADER_LEN + len(body) // 4 * 4}",
                                   f"truncated word ({len(body) % 4} of 4 bytes)")])
    words = list(struct.unpack(f">{len(body) // 4}I", body))
    return words, window, bool(flags & FLAG_COMPENSATE)


# ---- any file -> commands -----------------------------------------------------------


def detect(data: bytes) -> str:
    """'de48', 'de32' or 'text', by magic."""
    return {DE48_MAGIC: "de48", DE32_MAGIC: "de32"}.get(data[:4], "text")


def load_commands(data: bytes, filename: str, mapped: bool = True):
    """Commands from .de48/.de32/text bytes, and (kind, window or None, compensate).

    For .de32, mapped=True returns what the array receives (compensation applied if the
    file's flag says so); mapped=False returns the stored commands.
    """
    kind = detect(data)
    if kind == "de48":
        return deserialise(decode_de48(data, filename), filename), (kind, None, False)
    if kind == "de32":
        words, window, comp = decode_de32(data, filename)
        return (deserialise(framestore_slots(words, window, comp and mapped), filename),
                (kind, window, comp))
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise AsmError(filename, [(1, f"not a .de48/.de32 file nor UTF-8 text "
                                      f"({e.reason} at byte {e.start})")])
    return parse_text(text, filename), (kind, None, False)
