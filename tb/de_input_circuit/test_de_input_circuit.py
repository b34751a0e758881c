"""The prototype input circuit against the golden model (diffengine.formats.binfmt.map_word).

driver: random frame-store words (every LUT code, random operands, windows 0..4,
compensation on/off) one per clock -> monitor: mapper output one clock later, the
skewed blocks, the deskewed bus -> model: map_word -> in-order checker.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge

from diffengine import isa
from diffengine.formats.binfmt import map_word

N_WORDS = 4000


@cocotb.test()
async def mapper_matches_model(dut):
    from common.run import seed_from_env
    rng = random.Random(seed_from_env())
    from common.run import drive, hold_reset
    await hold_reset(dut, 3, falling=False, clock_ns=10, valid_i=0, word_i=0, window_i=0,
                     compensate_i=0)

    mapper, skew, deskew = dut.u_mapper, dut.u_skew, dut.u_deskew
    history: list[tuple[int, int]] = []  # (ident, data) seen at the mapper output
    checked = 0
    window, comp = 0, 0
    for i in range(N_WORDS):
        await FallingEdge(dut.clk_i)
        if i % 64 == 0:
            window, comp = rng.randrange(5), rng.randrange(2)
        word = (rng.randrange(32) << 27) | rng.getrandbits(27)
        valid = rng.random() < 0.9
        drive(dut, valid_i=int(valid), word_i=word, window_i=window, compensate_i=comp)
        ident, data = map_word(word, window, bool(comp)) if valid else (0, 0)
        await RisingEdge(dut.clk_i)      # the mapper registers this word
        await ReadOnly()
        got = (int(mapper.valid_o.value), int(mapper.id_o.value), int(mapper.data_o.value))
        assert got == (int(valid), ident, data), (
            f"word 0x{word:08x} window {window} comp {comp}: got valid/ident/data "
            f"{got[0]}/0x{got[1]:03x}/0x{got[2]:09x}, want {int(valid)}/0x{ident:03x}/0x{data:09x}")
        history.append((got[1], got[2]))
        checked += 1
        # skew: block j comes from the word that left the mapper j clocks ago.
        if len(history) >= 3:
            blk = isa.word_blocks(int(skew.blk_o.value))
            for j in range(isa.BLOCKS):
                assert blk[j] == isa.word_blocks(history[-1 - j][1])[j], f"block {j}"
            assert int(skew.id_o.value) == history[-1][0]
            # deskew restores whole words two clocks later.
            assert int(deskew.data_o.value) == history[-3][1]
            assert int(deskew.id_o.value) == history[-3][0]
    assert checked == N_WORDS
    dut._log.info(f"checked {checked} mapped words and their skew/deskew")


def test_de_input_circuit():
    from common.run import build_and_test, rtl_files
    here = Path(__file__).resolve().parent
    build_and_test(here, "de_input_circuit_tb", rtl_files("diffengine:tb:de_input_circuit"),
                   "test_de_input_circuit")
