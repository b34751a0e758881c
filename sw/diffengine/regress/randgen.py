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
