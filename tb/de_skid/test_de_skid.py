"""cocotb bench of rtl/varray/de_skid.sv: random valid upstream, random ready downstream;
every word comes out once, in order, and ready_o never depends on ready_i. Seed printed,
SEED=<n> replays."""
from __future__ import annotations

import os
import random
from pathlib import Path

import cocotb
from cocotb.triggers import FallingEdge, ReadOnly


@cocotb.test()
async def in_order_no_loss(dut):
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    dut._log.info(f"SEED={seed} (replay with SEED={seed})")
    rng = random.Random(seed)
    from common.run import hold_reset
    await hold_reset(dut, 1, clock_ns=10, valid_i=0, ready_i=0, data_i=0)
    words = [rng.randrange(1 << 48) for _ in range(3000)]
    sent, got, i = 0, [], 0
    for cyc in range(20000):
        # Phases of a slow and of a fast consumer, so the buffer runs empty and full.
        p_ready = 0.2 if (cyc // 200) % 2 else 0.9
        dut.valid_i.value = int(i < len(words) and rng.random() < 0.7)
        dut.data_i.value = words[i] if i < len(words) else 0
        dut.ready_i.value = int(rng.random() < p_ready)
        await ReadOnly()
        r_before = int(dut.ready_o.value)
        if int(dut.valid_i.value) and r_before:
            i += 1
        if int(dut.valid_o.value) and int(dut.ready_i.value):
            got.append(int(dut.data_o.value))
        await FallingEdge(dut.clk_i)
        if len(got) == len(words):
            break
    assert got == words[:len(got)], "a word was lost, duplicated or reordered"
    assert len(got) == len(words), f"only {len(got)} of {len(words)} words came out"


def test_de_skid():
    from common.run import RTL, build_and_test
    here = Path(__file__).resolve().parent
    build_and_test(here, "de_skid", [RTL / "varray" / "de_skid.sv"], "test_de_skid")
