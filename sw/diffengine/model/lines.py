"""Where commands land: the first command of every scanline in a stream, and whether a
command acts on a given column (docs/isa.md §5). Used by the regression's failure
analysis and the frame inspector."""
from __future__ import annotations

from .. import isa


def line_starts(commands) -> list[int]:
    """Stream index of the first command of every line (lines end with their Refresh)."""
    starts, k = [], 0
    for ln in isa.split_lines(commands):
        starts.append(k)
        k += len(ln)
    return starts


def covers(c: isa.Command, col: int) -> bool:
    """Does command c act on column `col`? (docs/isa.md §5: range, periodic.)"""
    if c.op in ("EVAL", "EVAL0", "DIS", "SETI", "SETDI", "SETDDI"):
        return c.x <= col < c.x + c.dx
    if c.op in ("SETPI", "SETPDI", "SETPDDI"):
        step = c.dx if c.dx else 4096
        return col >= c.x and (col - c.x) % step == 0
    return c.op in ("ACCMODE", "REFRESH")  # every column


def touching(commands, line: int, col: int) -> list[tuple[int, isa.Command]]:
    """(stream index, command) of every command of scanline `line` acting on `col`."""
    lines = isa.split_lines(commands)
    start = line_starts(commands)[line]
    return [(start + i, c) for i, c in enumerate(lines[line]) if covers(c, col)]
