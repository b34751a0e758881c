"""cocotb test of the SDRAM model's back-door preload (docs/sdram-frames-spec.md §5):
`+sdram_image=<file>`, lines "<addr> <word>" in hex, addr the controller's 23-bit word
address {bank, row, column[8:1]}, the word's [15:0] at the even column.

Run by test_sdram_model.py's runner on the tck8000 build (after its own tests), with an
image written there: random words in all four banks, first and last rows and columns,
64 consecutive words, comment and blank lines, upper- and lower-case hex. The test reads
every word back through legal ACT / READ / PRECHARGE sequences (BL 8 bursts: 4 words
each, and BL 1), checks that unwritten columns read 0, that a WRITE over a preloaded word
changes only that word, and that a power-on (rst_i) restores the image; 0 violations.
SDRAM_IMAGE / SDRAM_IMAGE_JSON name the image and its expected contents.
"""
from __future__ import annotations

import json
import os
import random
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import cocotb  # noqa: E402

from test_sdram_model import start  # noqa: E402

COL_BITS, ROW_BITS = 9, 13


def split(a: int) -> tuple[int, int, int]:
    """Word address -> (bank, row, even column)."""
    return a >> (ROW_BITS + COL_BITS - 1), (a >> (COL_BITS - 1)) & ((1 << ROW_BITS) - 1), \
        (a & ((1 << (COL_BITS - 1)) - 1)) << 1


def write_image(path: Path, rng: random.Random) -> dict[int, int]:
    """A preload file and the words it defines."""
    words: dict[int, int] = {}
    for _ in range(200):
        words[rng.randrange(1 << 23)] = rng.getrandbits(32)
    for a in (0, (1 << 23) - 1, 255, 256, 3 << 21):
        words[a] = rng.getrandbits(32)
    base = rng.randrange(1 << 23) & ~0xFF                 # 64 words in one row
    for k in range(64):
        words[base + k] = rng.getrandbits(32)
    lines = ["# a preload image for test_sdram_preload", ""]
    for k, (a, w) in enumerate(sorted(words.items())):
        text = f"{a:06x} {w:08x}" if k % 3 else f"  {a:X}\t{w:08X}  # upper case"
        lines.append(text)
        if k % 50 == 7:
            lines.append("   # a comment line")
    path.write_text("\n".join(lines) + "\n")
    return words


async def read_words(s, addrs: list[int], bl: int) -> dict[int, int]:
    """The 32-bit words at `addrs` (all in one row for bl 8: 4 per burst)."""
    got = {}
    for a in addrs:
        b, r, c = split(a)
        n = 2 if bl == 1 else bl
        if bl == 1:
            lo, _ = await s.read(b, r, c, n=1)
            hi, _ = await s.read(b, r, c + 1, n=1)
            halves = lo + hi
        else:
            halves, cols = await s.read(b, r, c & ~(bl - 1), n=n)
            assert cols[0] == c & ~(bl - 1)
        for k in range(0, len(halves), 2):
            assert halves[k] >= 0 and halves[k + 1] >= 0, f"{a:#x}: DQ not driven"
            got[(a & ~(bl // 2 - 1) if bl > 1 else a) + k // 2] = halves[k] | halves[k + 1] << 16
    return got


@cocotb.test()
async def preload(dut):
    words = {int(a): w for a, w in json.loads(Path(os.environ["SDRAM_IMAGE_JSON"]).read_text()).items()}
    s = await start(dut, 8000)
    for rnd in range(2):                                  # the second after a power-on
        if rnd:
            await s.power_on()
        await s.init(cl=3, bl=8)
        # BL 8: every preloaded word's aligned group of 4 words.
        groups = sorted({a & ~3 for a in words})
        got = await read_words(s, groups, 8)
        for a, w in got.items():
            assert w == words.get(a, 0), f"word {a:#08x}: read {w:#010x}, preloaded " \
                                         f"{words.get(a, 0):#010x}"
        assert set(words) <= set(got)
        # BL 1: a sample word by word, and words never preloaded read 0.
        await s.lmr(3, 1)
        rng = random.Random(5)
        sample = rng.sample(sorted(words), 20)
        unset = [a for a in (rng.randrange(1 << 23) for _ in range(20)) if a not in words]
        got = await read_words(s, sample + unset, 1)
        for a in sample + unset:
            assert got[a] == words.get(a, 0), f"BL1 word {a:#08x}: read {got[a]:#010x}"
        if not rnd:
            # A write over a preloaded word changes that column only.
            a = sample[0]
            b, r, c = split(a)
            await s.write(b, r, c, [0x5A5A])
            got = await read_words(s, [a], 1)
            assert got[a] == (words[a] & 0xFFFF0000) | 0x5A5A
        assert s.errors() == 0, "\n".join(s.log_lines())
    dut._log.info("preload: %d words read back through READ bursts twice (power-on restores "
                  "the image), 0 violations", len(words))
