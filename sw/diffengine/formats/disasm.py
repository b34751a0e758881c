"""Disassembler: commands or raw instruction streams back to readable text.

`disassemble` writes a command file that parses back to the same commands (intensities as
exact hex literals, their decimal values in a trailing comment). `list_slots` is the
instruction-level view (one slot per line), for debugging streams that do not
deserialise or for comparing against an RTL trace.
"""
from __future__ import annotations

from .. import isa
from .asm import format_command


def disassemble(commands, unit: int | None = None, comment: bool = True,
                header: list[str] | None = None) -> str:
    """Command-file text; a blank line after each Refresh separates scanlines."""
    out = [f"# {h}" for h in header or []]
    if unit is not None:
        out.append(f".unit dac {unit}")
    for cmd in commands:
        out.append(format_command(cmd, unit, comment))
        if cmd.op == "REFRESH":
            out.append("")
    return "\n".join(out).rstrip("\n") + "\n"


def list_slots(slots) -> str:
    """`index identifier name data` per instruction; data as the exact 12.24 pattern
    (address slots also as their three 12-bit blocks)."""
    rows = []
    for i, (ident, data) in enumerate(slots):
        name = isa.ID_NAME.get(ident, "?")
        text = f"{i:6d}  {ident:#05x}  {name:<13} {isa.format_fixed(data)}"
        if isa.ID_TYPE.get(ident) == isa.TYPE_ADDR:
            b0, b1, b2 = isa.word_blocks(data)
            text += f"  [b2={b2} b1={b1} b0={b0}]"
        rows.append(text)
    return "\n".join(rows) + ("\n" if rows else "")
