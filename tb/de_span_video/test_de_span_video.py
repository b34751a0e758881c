"""cocotb bench of rtl/varray/de_span_video.sv: the span-serial array behind de_array's
pixel-bus contract (docs/fpga.md 3.5).

The plain de_array and de_span_video share one instruction bus on the pixel clock
(tb_de_span_video.sv); the span array runs on its own core clock (a little over 3x the
pixel clock, at a random phase, so the FIFO really crosses clock domains). Checked, clock
by clock: the wrapper's (pixel_valid, pixel) is the plain array's delayed by exactly
Latency - (NumChips + 3) clocks, the frame equals the golden model, and late / overflow
stay low. With a Latency too small for the stream, late_o must rise. Seed printed,
SEED=<n> replays.
"""
from __future__ import annotations

import os
import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, Timer

from diffengine.model import functional
from diffengine import isa
from diffengine.regress import randgen

PIX_PS = 40000


def lines_of(cmds, htotal: int):
    """Serialise and pad each line with Nops to htotal slots, like the display's bus."""
    out, line = [], []
    for ident, data in isa.serialise(cmds):
        line.append((ident, data))
        if ident == isa.REFRESH:
            assert len(line) <= htotal, f"line of {len(line)} slots > HTotal {htotal}"
            out += line[:-1] + [(isa.NOP, 0)] * (htotal - len(line)) + [line[-1]]
            line = []
    return out + [(isa.NOP, 0)] * (4 * htotal)


async def run(dut, slots, seed: int):
    rng = random.Random(seed)
    core_ps = 2 * ((PIX_PS // 3 - rng.randrange(1, 400)) // 2)   # a little over 3x
    cocotb.start_soon(Clock(dut.clk_i, PIX_PS, unit="ps").start())
    await Timer(rng.randrange(1, core_ps), unit="ps")       # random phase
    cocotb.start_soon(Clock(dut.clk_core_i, core_ps, unit="ps").start())
    dut.id_i.value = 0
    dut.data_i.value = 0
    dut.rst_i.value = 1
    for _ in range(8):
        await RisingEdge(dut.clk_i)
    await FallingEdge(dut.clk_i)
    dut.rst_i.value = 0
    # The span array clears its state RAM after reset (NumCols core clocks).
    n = 9 * int(dut.NumChips.value)
    for _ in range(n // 3 + 8):
        await RisingEdge(dut.clk_i)
    a, s = [], []
    for ident, data in slots:
        await FallingEdge(dut.clk_i)
        dut.id_i.value = ident
        dut.data_i.value = data
        await RisingEdge(dut.clk_i)
        await ReadOnly()
        for arr, out in ((dut.u_array, a), (dut.u_span, s)):
            valid = int(arr.pix_valid_o.value)
            out.append((valid, int(arr.pix_o.value) if valid else 0))
    return a, s


def bug() -> bool:
    return bool(int(os.environ.get("DE_CARRY_BUG", "0")))


@cocotb.test()
async def same_pixels_fixed_latency(dut):
    """Random streams: the wrapper's pixel bus is de_array's, Latency - (NumChips+3)
    clocks later, clock for clock."""
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    dut._log.info(f"SEED={seed} (replay with SEED={seed})")
    chips, lat = int(dut.NumChips.value), int(dut.Latency.value)
    n, htotal = 9 * chips, int(os.environ.get("DE_HTOTAL", 120))
    cmds = randgen.stream(seed, int(os.environ.get("N_CMDS", 150)), n, (1, 6))
    a, s = await run(dut, lines_of(cmds, htotal), seed)
    assert not int(dut.u_span.overflow_o.value), "a slot found the FIFO full"
    assert not int(dut.u_span.late_o.value), "a line was not ready at its read-out"
    d = lat - (chips + 3)
    assert d >= 0
    assert s[d:] == a[:len(a) - d], "span array's pixel bus differs from de_array's"
    assert sum(v for v, _ in s) > 0
    pix = np.array([p for v, p in a if v], dtype=np.uint16).reshape(-1, n)
    want = functional.render(cmds, n, carry_bug=bug())
    np.testing.assert_array_equal(pix, want)
    dut._log.info(f"{pix.shape[0]} lines: equal to de_array {d} clocks later, and the model")


@cocotb.test()
async def late_is_flagged(dut):
    """Lines of full-width Evals with a Latency too small for them: late_o must rise."""
    n = 9 * int(dut.NumChips.value)
    one = 1 << isa.FRAC_BITS
    cmds = [isa.Command("EVAL", 0, n, (one, one // 9, one // 81))] * 12 + \
        [isa.Command("REFRESH")]
    await run(dut, lines_of(cmds, 80), 1)
    lat = int(dut.Latency.value)
    assert int(dut.u_span.late_o.value), f"Latency {lat} is too small, yet late_o stayed low"


# (chips, latency, carry bug). 18 columns; Latency 60 is ample for these lines (HTotal
# 120 slots, 360 core clocks), 6 is not.
RUNS = [(2, 60, 0), (2, 60, 1), (2, 6, 0)]


@pytest.mark.parametrize("chips,lat,bug", RUNS,
                         ids=[f"chips{c}_lat{la}_bug{b}" for c, la, b in RUNS])
def test_de_span_video(chips, lat, bug):
    from common.run import build_and_test, rtl_files
    here = Path(__file__).resolve().parent
    srcs = rtl_files("diffengine:tb:de_span_video")   # tb/de_span_video/de_span_video_tb.core
    build_and_test(here, "tb_de_span_video", srcs, "test_de_span_video",
                   parameters={"NumChips": chips, "Latency": lat, "CarryBug": bug},
                   extra_env={"DE_CARRY_BUG": str(bug)},
                   testcase="same_pixels_fixed_latency" if lat >= 20 else "late_is_flagged")
