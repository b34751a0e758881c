"""Constrained-random command streams for scoreboards (models and RTL alike).

The mix is weighted towards what breaks hardware: spans that touch column 0 and the
last column, cross chip boundaries (every 9 columns), have dX of 0 or 1, run past the
array's end, carry across the 12-bit block boundaries, and interleave Set / Dis / Eval0 /
Acc_mode with the Evals they affect. Every stream is a pure function of its seed.
"""
from __future__ import annotations

import random

from .. import isa


ONE = 1 << isa.FRAC_BITS


def _x(rng: random.Random, width: int) -> int:
    """A column, biased to the edges and to chip boundaries."""
    r = rng.random()
    if r < 0.15:
        return 0
    if r < 0.25:
        return max(0, width - 1 - rng.randrange(2))
    if r < 0.40:
        return min(isa.ADDR_MAX, 9 * rng.randrange(1, width // 9 + 2) - rng.randrange(2))
    if r < 0.45:
        return min(isa.ADDR_MAX, width + rng.randrange(4))  # beyond the array
    return rng.randrange(width)


def _dx(rng: random.Random, width: int) -> int:
    r = rng.random()
    if r < 0.08:
        return 0
    if r < 0.18:
        return 1
    if r < 0.25:
        return width + rng.randrange(10)  # runs past the end
    return rng.randrange(1, max(2, width))


def _value(rng: random.Random, order: int) -> int:
    """An intensity or difference; magnitudes shrink with the difference order, and some
    fractions sit just below a block boundary so that carries ripple between blocks."""
    r = rng.random()
    if r < 0.2:  # near the block-1 / block-2 carry: fraction all ones or half
        frac = rng.choice([0xFFFFFF, 0x800000, 0xFFF000, 0x000FFF, 0x7FFFFF])
        v = (rng.randrange(-4, 5) << isa.FRAC_BITS) | frac
    else:
        scale = [2048, 64, 2, 1 / 16, 1 / 256, 1 / 4096, 1 / 65536, 1 / 2**20][min(order, 7)]
        v = int(rng.uniform(-scale, scale) * ONE)
    return max(-(1 << 35), min((1 << 35) - 1, v))


def command(rng: random.Random, width: int) -> isa.Command:
    r = rng.random()
    x, dx = _x(rng, width), _dx(rng, width)
    if r < 0.55:
        p = rng.choices(range(8), weights=[4, 5, 5, 2, 1, 1, 1, 1])[0]
        return isa.Command("EVAL", x, dx, tuple(_value(rng, k) for k in range(p + 1)))
    if r < 0.63:
        return isa.Command(rng.choice(["SETI", "SETDI", "SETDDI"]), x, rng.choice([1, 1, dx]),
                           (_value(rng, rng.randrange(3)),))
    if r < 0.69:
        return isa.Command(rng.choice(["SETPI", "SETPDI", "SETPDDI"]), x,
                           rng.choice([0, 1, rng.randrange(2, 12), dx]),
                           (_value(rng, rng.randrange(3)),))
    if r < 0.76:
        return isa.Command("DIS", x, dx)
    if r < 0.83:
        return isa.Command("EVAL0", x, dx, (rng.randrange(4096),))
    if r < 0.86:
        return isa.Command("ACCMODE", values=(rng.randrange(2),))
    if r < 0.88:
        return isa.Command("NOP")
    return isa.Command("EVAL", x, dx, (_value(rng, 0),))


def stream(seed: int, n_commands: int, width: int, per_line: tuple[int, int] = (1, 40)
           ) -> list[isa.Command]:
    """`n_commands` random commands (Refreshes included) in lines of random length."""
    return [c for chunk in chunks(seed, n_commands, width, per_line, n_commands)
            for c in chunk]


def chunks(seed: int, n_commands: int, width: int, per_line: tuple[int, int] = (1, 40),
           chunk: int = 200_000):
    """stream(seed, n_commands, ...) in pieces of whole lines, about `chunk` commands each
    (each piece ends with a Refresh): the same commands, without holding them all, for
    streams too long to keep as Python objects (make test-long: 10^7 commands)."""
    rng = random.Random(seed)
    out: list[isa.Command] = []
    done = 0
    while done + len(out) < n_commands:
        for _ in range(rng.randint(*per_line)):
            out.append(command(rng, width))
        out.append(isa.Command("REFRESH"))
        if len(out) >= chunk:
            done += len(out)
            yield out
            out = []
    if out:
        yield out


# ---- raw slot streams ---------------------------------------------------------------------

SOUP_IDS = (isa.NOP, isa.REFRESH, isa.ACCMODE_ON, isa.ACCMODE_OFF, isa.ADDR_RANGE,
            isa.ADDR_PERIODIC, isa.ADDR_EVAL0, isa.ADDR_DIS, isa.ACC, isa.D_A, isa.D_B,
            isa.D_C, isa.D_B_C, isa.D_A_B, isa.D_A_B_NP, isa.D_A_A_NP, isa.SET_A, isa.SET_B,
            isa.SET_C)
SOUP_WEIGHTS = (2, 2, 1, 1, 6, 3, 3, 3, 6) + (4,) * 7 + (2, 2, 2)


def undefined_pair(prev: int, ident: int) -> bool:
    """A data slot right behind an ACC or an Eval0 address slot: no command makes either
    sequence, and docs/isa.md section 6 ("Undefined") leaves both undefined (the PE reads
    the protect flags in the data slot's first stage, a clock before the ACC / Eval0
    clears them in its second)."""
    return prev in (isa.ACC, isa.ADDR_EVAL0) and bool(ident & isa.ID_DATA)


def slot_soup(seed: int, count: int, width: int) -> list[tuple[int, int]]:
    """Raw slots of the 19 atomic instructions in any order, for a `width`-column array:
    orphan data and ACC slots, address slots with no data, Refreshes back to back, X and
    dX at and past the end. Draws `count` slots, drops the undefined pairs
    (undefined_pair) and ends with a Refresh."""
    rng = random.Random(seed)
    slots: list[tuple[int, int]] = []
    for _ in range(count):
        ident = rng.choices(SOUP_IDS, SOUP_WEIGHTS)[0]
        if ident & isa.ID_ADDR:
            x = rng.choice([0, rng.randrange(width), width - 1, width + rng.randrange(3)])
            blk = 1 << isa.BLOCK_BITS
            dx = rng.choice([0, 1, rng.randrange(1, width + 4), rng.randrange(blk)])
            data = isa.blocks_word((x, dx, rng.randrange(blk)))   # X, dX, Eval0 intensity
        elif ident & isa.ID_DATA:
            data = rng.randrange(1 << isa.WORD_BITS) if rng.random() < 0.3 else \
                isa.to_word(rng.randrange(-8 * ONE, 8 * ONE))
        else:
            data = 0
        if slots and undefined_pair(slots[-1][0], ident):
            continue
        slots.append((ident, data))
    slots.append((isa.REFRESH, 0))
    return slots
