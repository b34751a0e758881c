"""Table 7.5 of the source (§7.7), digit for digit.

Eval3 (X=0, dX=9, I=0, dI=0, ddI=0x000.800000) on a 9-column array: row k of the table
is (B, A) = (dI, I) of column k. Correct = no fault; erroneous = carry out of bit 23
into bit 25; compensated = the same fault with every operand passed through
isa.compensate (ddI becomes 0x000.400000).
"""
import pytest

from diffengine.model import functional
from diffengine import isa

# (dI, I) rows, copied from the source as printed: correct | erroneous | compensated
TABLE_7_5 = """
000.000000 000.000000 000.000000 000.000000 000.000000 000.000000
000.800000 000.000000 000.800000 000.000000 000.400000 000.000000
001.000000 000.800000 002.000000 000.800000 000.800000 000.400000
001.800000 001.800000 002.800000 002.800000 000.c00000 000.c00000
002.000000 003.000000 004.000000 006.000000 002.000000 002.800000
002.800000 005.000000 004.800000 00a.000000 002.400000 004.800000
003.000000 007.800000 006.000000 00e.800000 002.800000 006.c00000
003.800000 00a.800000 006.800000 014.800000 002.c00000 00a.400000
004.000000 00e.000000 008.000000 01c.000000 004.000000 00e.000000
"""
ROWS = [line.split() for line in TABLE_7_5.strip().splitlines()]
DDI = 0x000800000


def _registers(bug: bool, comp: bool) -> list[tuple[str, str]]:
    vals = (0, 0, DDI)
    if comp:
        vals = tuple(isa.compensate(v) for v in vals)
    cmd = isa.Command("EVAL", 0, 9, vals)
    _, state = functional.run_line([cmd], width=9, carry_bug=bug)
    return [(isa.format_fixed(int(b))[2:], isa.format_fixed(int(a))[2:])
            for b, a in zip(state.B, state.A)]


@pytest.mark.parametrize("pair,bug,comp", [(0, False, False), (1, True, False), (2, True, True)],
                         ids=["correct", "erroneous", "compensated"])
def test_table_7_5(pair, bug, comp):
    want = [(r[2 * pair], r[2 * pair + 1]) for r in ROWS]
    assert len(want) == 9
    assert _registers(bug, comp) == want


def test_compensated_pixels_differ_only_in_lsb():
    """The text's claim about the right-hand pair: the 12-bit intensity is right but for the LSB."""
    right = [int(r[1].split(".")[0], 16) for r in ROWS]
    comp = [int(r[5].split(".")[0], 16) for r in ROWS]
    assert all(abs(a - b) <= 1 for a, b in zip(right, comp)) and right != comp


@pytest.mark.parametrize("pair,bug,comp", [(0, False, False), (1, True, False), (2, True, True)],
                         ids=["correct", "erroneous", "compensated"])
def test_table_7_5_structural(pair, bug, comp):
    """The cycle-level model gives the same three column pairs. The compensation is the
    data mapper's (binfmt.compensate_slots, what the prototype's mapper does to the
    serialised slots in front of the array), so the fault and its repair meet exactly
    where they do in hardware."""
    from diffengine.formats import binfmt
    from diffengine.model import structural

    slots = isa.serialise([isa.Command("EVAL", 0, 9, (0, 0, DDI))])
    if comp:
        slots = binfmt.compensate_slots(slots)
    arr = structural.Array(9, carry_bug=bug)
    arr.run(slots)
    arr.flush()
    s = arr.state()
    got = [(isa.format_fixed(int(b))[2:], isa.format_fixed(int(a))[2:])
           for b, a in zip(s["B"], s["A"])]
    assert got == [(r[2 * pair], r[2 * pair + 1]) for r in ROWS]
