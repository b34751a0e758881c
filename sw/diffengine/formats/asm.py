"""Command-file text format (docs/isa.md §9): parser and printer.

The syntax is the source's own (Figs. 7.21, 7.25), so its command lists can be pasted
verbatim. Decimal operands are converted exactly (fractions.Fraction) and rounded to
the nearest 12.24 value, ties to even; `0xIII.FFFFFF` literals are raw 36-bit patterns.
Nothing is ever truncated: an operand that does not fit is an error naming file:line,
and all errors of a file are reported together.
"""
from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path

from .. import isa
from ..isa import Command

__all__ = ["AsmError", "parse_text", "parse_file", "format_command", "format_value",
           "mnemonic", "unit_shift"]


class AsmError(ValueError):
    """One or more errors, each rendered `file:where: message` on its own line.

    `where` is a line number for text, or e.g. "byte 14" / "slot 3" for binaries.
    """

    def __init__(self, filename: str, errors):
        self.filename = filename
        self.errors = [(where, msg) for where, msg in errors]
        super().__init__("\n".join(f"{filename}:{w}: {m}" for w, m in self.errors))


# mnemonic (lower case, '_' removed) -> (op, order or None)
_EVAL_N = {f"eval{n}": ("EVAL", n - 1) for n in range(1, isa.MAX_EVAL_ORDER + 2)}
_MNEMONICS = {
    "eval0": ("EVAL0", None), **_EVAL_N,
    "seti": ("SETI", None), "setdi": ("SETDI", None), "setddi": ("SETDDI", None),
    "setpi": ("SETPI", None), "setpdi": ("SETPDI", None), "setpddi": ("SETPDDI", None),
    "dis": ("DIS", None), "accmode": ("ACCMODE", None),
    "refresh": ("REFRESH", None), "nop": ("NOP", None),
}
_PRINT_NAME = {"EVAL0": "Eval0", "SETI": "SetI", "SETDI": "SetdI", "SETDDI": "SetddI",
               "SETPI": "SetPI", "SETPDI": "SetPdI", "SETPDDI": "SetPddI", "DIS": "Dis",
               "ACCMODE": "Acc_mode", "REFRESH": "Refresh", "NOP": "Nop"}

_STMT = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*(?:\((.*)\))?$", re.S)
_INT = re.compile(r"^[+-]?[0-9]+$")
_DEC = re.compile(r"^[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?$")
_HEX = re.compile(r"^0[xX]([0-9a-fA-F]{3})\.([0-9a-fA-F]{6})$")
_LIMIT = 1 << (isa.WORD_BITS - 1)


def unit_shift(unit: int | None) -> int:
    """log2 of the pixel LSBs that 1.0 stands for: 0 for `.unit pixel`, W+6 for dac W."""
    if unit is None:
        return 0
    if not 0 <= unit <= 6:
        raise ValueError(f"DAC window {unit} outside 0..6")
    return unit + 6


def _strip_comment(line: str) -> str:
    cut = [i for i in (line.find("#"), line.find("//")) if i >= 0]
    return line[:min(cut)] if cut else line


def _parse_int(tok: str, name: str) -> int:
    if not _INT.match(tok):
        raise ValueError(f"{name} must be an integer, got {tok!r}")
    v = int(tok)
    if not 0 <= v <= isa.ADDR_MAX:
        raise ValueError(f"{name} = {v} outside 0..{isa.ADDR_MAX}")
    return v


def _parse_number(tok: str, name: str, shift: int) -> tuple[Fraction, bool]:
    """Operand as an exact value in pixel LSBs (Fraction) and whether it was a hex pattern."""
    m = _HEX.match(tok)
    if m:
        word = (int(m.group(1), 16) << isa.FRAC_BITS) | int(m.group(2), 16)
        return Fraction(isa.to_signed(word), 1 << isa.FRAC_BITS), True
    if tok.lstrip("+-").lower().startswith("0x"):
        raise ValueError(f"{name}: bad hex literal {tok!r} (want 0xIII.FFFFFF, 3 and 6 hex "
                         "digits, no sign: it is the raw two's complement pattern)")
    if not _DEC.match(tok):
        raise ValueError(f"{name}: not a number: {tok!r}")
    exp = tok.lower().partition("e")[2]
    if exp and abs(int(exp)) > 99:  # keep Fraction from building 10**huge
        raise ValueError(f"{name}: exponent of {tok!r} outside -99..99")
    return Fraction(tok) * (1 << shift), False


def _intensity(tok: str, name: str, shift: int, round_bits: int) -> int:
    val, exact = _parse_number(tok, name, shift)
    raw = val * (1 << isa.FRAC_BITS)
    if not exact:
        q = 1 << round_bits
        raw = Fraction(round(raw / q) * q)  # round() on a Fraction: nearest, ties to even
    raw = int(raw)
    if not -_LIMIT <= raw < _LIMIT:
        raise ValueError(f"{name} = {tok} is {float(val):g} pixel units, outside [-2048, 2048)")
    return raw


def _eval0_intensity(tok: str, shift: int) -> int:
    val, exact = _parse_number(tok, "Eval0 intensity", shift)
    if exact:  # a raw pattern: D = pattern, so its integer part is the 12-bit pixel
        word = isa.to_word(int(val * (1 << isa.FRAC_BITS)))
        if word & ((1 << isa.FRAC_BITS) - 1):
            raise ValueError(f"Eval0 intensity {tok} has a fraction; it must be an integer")
        return word >> isa.FRAC_BITS
    if val.denominator != 1 or not 0 <= val <= isa.BLOCK_MASK:
        raise ValueError(f"Eval0 intensity {tok} is {float(val):g} pixel units; it must be "
                         "an integer in 0..4095")
    return int(val)


def _parse_statement(stmt: str, shift: int, round_bits: int, lineno: int) -> Command:
    m = _STMT.match(stmt)
    if not m:
        raise ValueError(f"cannot parse statement {stmt!r}")
    name, argtext = m.group(1), m.group(2)
    key = name.lower().replace("_", "")
    if key not in _MNEMONICS:
        raise ValueError(f"unknown mnemonic {name!r}")
    op, order = _MNEMONICS[key]
    args = [] if argtext is None or not argtext.strip() else [a.strip() for a in argtext.split(",")]
    if any(not a for a in args):
        raise ValueError(f"{name}: empty operand in ({argtext})")

    def need(*counts):
        if len(args) not in counts:
            want = " or ".join(str(c) for c in counts)
            raise ValueError(f"{name} takes {want} operand(s), got {len(args)}")

    def inten(tok, what):
        return _intensity(tok, f"{name} {what}", shift, round_bits)

    if op in ("REFRESH", "NOP"):
        need(0)
        return Command(op, line=lineno)
    if op == "ACCMODE":
        need(0, 1)
        on = 1
        if args:
            if args[0] not in ("0", "1"):
                raise ValueError(f"Acc_mode operand must be 0 or 1, got {args[0]!r}")
            on = int(args[0])
        return Command(op, values=(on,), line=lineno)
    if op == "DIS":
        need(2)
        return Command(op, _parse_int(args[0], "X"), _parse_int(args[1], "dX"), line=lineno)
    if op == "EVAL0":
        need(3)
        return Command(op, _parse_int(args[0], "X"), _parse_int(args[1], "dX"),
                       (_eval0_intensity(args[2], shift),), line=lineno)
    if op == "EVAL":
        need(order + 3)
        names = ["I", "dI", "ddI"] + [f"d^{k}I" for k in range(3, order + 1)]
        vals = tuple(inten(t, names[k]) for k, t in enumerate(args[2:]))
        return Command(op, _parse_int(args[0], "X"), _parse_int(args[1], "dX"), vals,
                       line=lineno)
    if op in ("SETI", "SETDI", "SETDDI"):
        need(2, 3)
        x = _parse_int(args[0], "X")
        dx = _parse_int(args[1], "dX") if len(args) == 3 else 1
        return Command(op, x, dx, (inten(args[-1], "value"),), line=lineno)
    need(3)  # periodic Sets
    return Command(op, _parse_int(args[0], "X"), _parse_int(args[1], "dX"),
                   (inten(args[2], "value"),), line=lineno)


def _directive(words: list[str]) -> int | None:
    """Return the new unit (None = pixel, W = dac W) of a `.unit` directive."""
    if words and words[-1] == ";":
        words = words[:-1]
    if words and words[-1].endswith(";"):
        words = words[:-1] + [words[-1][:-1]]
    if not words or words[0].lower() != ".unit":
        raise ValueError(f"unknown directive {words[0] if words else '.'!r} (only .unit)")
    args = [w.lower() for w in words[1:]]
    if args == ["pixel"]:
        return None
    if len(args) == 2 and args[0] == "dac" and re.fullmatch(r"[0-6]", args[1]):
        return int(args[1])
    raise ValueError(f"bad directive {' '.join(words)!r}: want '.unit pixel' or '.unit dac W' "
                     "with W in 0..6")


def parse_text(text: str, filename: str = "<string>", round_bits: int = 0) -> list[Command]:
    """Parse a command file (docs/isa.md §9) into commands; raise AsmError listing all errors.

    round_bits > 0 rounds decimal operands to a multiple of 2^round_bits raw units instead
    of to the 12.24 grid (the frame store keeps only bits 35..4+w); hex literals stay exact.
    """
    commands: list[Command] = []
    errors: list[tuple[int, str]] = []
    unit: int | None = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        body = _strip_comment(raw).strip()
        if not body:
            continue
        if body.startswith("."):
            try:
                unit = _directive(body.split())
            except ValueError as e:
                errors.append((lineno, str(e)))
            continue
        for stmt in body.split(";"):
            stmt = stmt.strip()
            if not stmt:
                continue
            try:
                cmd = _parse_statement(stmt, unit_shift(unit), round_bits, lineno)
                cmd.validate()
            except ValueError as e:
                errors.append((lineno, str(e)))
                continue
            commands.append(cmd)
    if errors:
        raise AsmError(filename, errors)
    return commands


def parse_file(path, round_bits: int = 0) -> list[Command]:
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as e:
        raise AsmError(str(path), [(1, f"not UTF-8 text ({e.reason} at byte {e.start})")])
    return parse_text(text, str(path), round_bits)


# ---- printing ----------------------------------------------------------------------


def mnemonic(cmd: Command) -> str:
    return f"Eval{cmd.order + 1}" if cmd.op == "EVAL" else _PRINT_NAME[cmd.op]


def _exact_decimal(f: Fraction) -> str:
    """Exact decimal of a dyadic rational (always finite)."""
    sign = "-" if f < 0 else ""
    f = abs(f)
    digits = 0
    while f.denominator != 1:
        f *= 10
        digits += 1
    s = str(f.numerator).rjust(digits + 1, "0")
    return sign + (s[:-digits] + "." + s[-digits:] if digits else s + ".0")


def format_value(raw: int, unit: int | None = None) -> str:
    """A signed 12.24 value as an exact decimal in `unit` (for comments and messages)."""
    return _exact_decimal(Fraction(raw, 1 << (isa.FRAC_BITS + unit_shift(unit))))


def format_command(cmd: Command, unit: int | None = None, comment: bool = False) -> str:
    """One statement in §9 syntax; parse_text(format_command(c)) == [c] in the same unit.

    Intensities are exact hex literals (unit-independent). The Eval0 intensity is an
    integer (pixel) or an exact decimal (dac W). comment=True appends the decimal values
    in `unit`, for people.
    """
    name = mnemonic(cmd)
    op = cmd.op
    if op in ("REFRESH", "NOP"):
        return f"{name};"
    if op == "ACCMODE":
        return f"{name} ({cmd.values[0]});"
    if op == "DIS":
        args = [cmd.x, cmd.dx]
    elif op == "EVAL0":
        args = [cmd.x, cmd.dx, str(cmd.values[0]) if unit is None
                else _exact_decimal(Fraction(cmd.values[0], 1 << unit_shift(unit)))]
    else:
        xs = [cmd.x] if op in ("SETI", "SETDI", "SETDDI") and cmd.dx == 1 else [cmd.x, cmd.dx]
        args = xs + [isa.format_fixed(v) for v in cmd.values]
    text = f"{name} ({', '.join(str(a) for a in args)});"
    if comment and op not in ("EVAL0", "DIS"):
        text += "  # " + ", ".join(_short(v, unit) for v in cmd.values)
    return text


def _short(raw: int, unit: int | None) -> str:
    return f"{raw / (1 << (isa.FRAC_BITS + unit_shift(unit))):.9g}"
