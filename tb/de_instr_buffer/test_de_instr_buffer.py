"""cocotb tests for rtl/ctrl/de_instr_buffer.sv (the Instruction Buffer).

Random stalls on both sides; every cycle the DUT is compared with a Python model of the
FIFO and of its commit gating (order, no loss, no duplicates, full/empty/level/committed
exact). The seed is printed; SEED=<n> replays a run.
"""

from __future__ import annotations

import os
import random
import sys
from collections import deque
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT / "sw"))
from diffengine import isa  # noqa: E402

W = isa.WORD_BITS
ID_MARKER = isa.REFRESH


def is_start(word: int) -> bool:
    # A command starts with a slot of no DATA / ACC class bit.
    return (word >> W) & (isa.ID_DATA | isa.ID_ACC) == 0


def is_marker(word: int) -> bool:
    return (word >> W) == ID_MARKER


def random_stream(rng: random.Random, n_lines: int, max_cmds: int,
                  max_len: int = 5) -> list[int]:
    """A legal y-processor stream: commands of 1..5 slots, lines ended by markers."""
    words = []
    seq = 0
    for _ in range(n_lines):
        for _ in range(rng.randint(0, max_cmds)):
            n = min(max_len, rng.choice([1, 1, 2, 3, 4, 5]))
            ids = [rng.choice([isa.ADDR_RANGE, isa.ADDR_PERIODIC, isa.ADDR_EVAL0,
                               isa.ADDR_DIS, isa.ACCMODE_ON, isa.ACCMODE_OFF, isa.NOP])]
            if n > 1:
                ids[0] = isa.ADDR_RANGE
                ids += [rng.choice([isa.D_A, isa.D_B, isa.D_C, isa.D_B_C, isa.D_A_B, isa.SET_A])
                        for _ in range(n - 2)]
                ids.append(rng.choice([isa.ACC, isa.SET_A, isa.SET_B]))
            for ident in ids:
                words.append((ident << W) | (seq & 0xFFFF) | (rng.getrandbits(20) << 16))
                seq += 1
        words.append((ID_MARKER << W) | (seq & 0xFFFF))
        seq += 1
    return words


def get_seed() -> int:
    return int(os.environ.get("SEED", random.randrange(1 << 31)))


async def reset(dut):
    from common.run import hold_reset
    await hold_reset(dut, 3, falling=False, clock_ns=10, wr_valid_i=0, wr_data_i=0,
                     rd_ready_i=0, drain_i=0)


async def run_random(dut, seed: int, wr_p: float, rd_p: float, n_lines: int, max_cmds: int,
                     drain_p: float = 0.0):
    rng = random.Random(seed)
    depth = int(dut.Depth.value)
    stream = random_stream(rng, n_lines, max_cmds, int(dut.MaxCmdLen.value))
    await reset(dut)
    model: deque[int] = deque()
    committed = 0  # entries of the model that the read side may see
    src = 0
    got: list[int] = []
    seen_full = seen_empty = False
    cycles = 0
    while len(got) < len(stream):
        cycles += 1
        assert cycles < 200 * len(stream) + 1000, "no progress"
        # Drive inputs for this cycle.
        wv = src < len(stream) and rng.random() < wr_p
        dut.wr_valid_i.value = int(wv)
        dut.wr_data_i.value = stream[src] if src < len(stream) else rng.getrandbits(48)
        rr = rng.random() < rd_p
        dut.rd_ready_i.value = int(rr)
        dr = rng.random() < drain_p
        dut.drain_i.value = int(dr)
        await ReadOnly()
        level = len(model)
        assert int(dut.level_o.value) == level, f"level {int(dut.level_o.value)} != {level}"
        assert int(dut.committed_o.value) == committed
        assert int(dut.full_o.value) == int(level == depth)
        assert int(dut.empty_o.value) == int(level == 0)
        assert int(dut.wr_ready_o.value) == int(level < depth)
        avail = level > 0 if dr else committed > 0
        assert int(dut.rd_valid_o.value) == int(avail)
        seen_full |= level == depth
        seen_empty |= level == 0 and len(got) > 0
        wr_fire = wv and level < depth
        rd_fire = rr and avail
        if avail:
            assert dut.rd_data_o.value.to_unsigned() == model[0], "head mismatch"
        # Update the model as the DUT will on this clock edge.
        if rd_fire:
            got.append(model.popleft())
            committed = max(0, committed - 1)
        if wr_fire:
            w = stream[src]
            src += 1
            if is_marker(w):
                committed = len(model) + 1
            elif is_start(w):
                committed = len(model)
            model.append(w)
        await RisingEdge(dut.clk_i)
    dut.wr_valid_i.value = 0
    dut.rd_ready_i.value = 0
    dut.drain_i.value = 0
    assert got == stream, "order/loss/duplication mismatch"
    return cycles, seen_full, seen_empty


@cocotb.test()
async def test_random_stalls(dut):
    """Random stalls on both sides in several regimes; order, no loss, no duplicates."""
    seed = get_seed()
    dut._log.info("SEED=%d (set SEED=%d to replay)", seed, seed)
    saw_full = saw_empty = False
    # The last regime drains always and reads every cycle behind a slow writer, so the
    # buffer runs empty after almost every word: without it, whether a run ever saw the
    # empty edge depended on the seed (SEED=391665407 did not: commit gating keeps the
    # next line's first words in the buffer while the reader waits for its marker).
    regimes = [(0.9, 0.3, 0.0), (0.3, 0.9, 0.0), (0.5, 0.5, 0.0), (1.0, 1.0, 0.0),
               (0.95, 0.05, 0.0), (0.7, 0.5, 0.2), (0.3, 1.0, 1.0)]
    for i, (wp, rp, dp) in enumerate(regimes):
        cycles, f, e = await run_random(dut, seed + i, wp, rp, n_lines=12, max_cmds=6,
                                        drain_p=dp)
        dut._log.info("regime wr_p=%.2f rd_p=%.2f: %d cycles, full=%s empty=%s",
                      wp, rp, cycles, f, e)
        saw_full |= f
        saw_empty |= e
    assert saw_full and saw_empty, "edges (full and empty) not exercised"


@cocotb.test()
async def test_commit_gating(dut):
    """An unfinished command is held back until the next command start or a marker."""
    if int(dut.Depth.value) < 8:
        return  # needs room for five words without reading
    await reset(dut)
    dut.rd_ready_i.value = 0

    async def write(word):
        dut.wr_valid_i.value = 1
        dut.wr_data_i.value = word
        await RisingEdge(dut.clk_i)
        dut.wr_valid_i.value = 0
        await ReadOnly()
        v = int(dut.rd_valid_o.value), int(dut.committed_o.value)
        await RisingEdge(dut.clk_i)
        return v

    assert await write(isa.ADDR_RANGE << W) == (0, 0)   # ADDR: command may go on
    assert await write(isa.D_A << W) == (0, 0)          # DATA
    assert await write(isa.ACC << W) == (0, 0)          # ACC: end not yet known
    assert await write(isa.ADDR_EVAL0 << W) == (1, 3)   # next start commits the Eval1
    assert await write(ID_MARKER << W) == (1, 5)       # marker commits Eval0 + itself


def _build_and_run(depth: int, max_cmd_len: int):
    from common.run import build_and_test, rtl_files

    seed = get_seed()
    print(f"de_instr_buffer Depth={depth} MaxCmdLen={max_cmd_len} SEED={seed}")
    # rtl/ctrl/de_display_core.core
    build_and_test(HERE, "de_instr_buffer", rtl_files("display_core", "instr_buffer"),
                   "test_de_instr_buffer", {"Depth": depth, "MaxCmdLen": max_cmd_len},
                   {"SEED": str(seed)}, lint=True)


@pytest.mark.parametrize("depth,max_cmd_len", [(4, 3), (16, 10)])
def test_de_instr_buffer(depth, max_cmd_len):
    _build_and_run(depth, max_cmd_len)
