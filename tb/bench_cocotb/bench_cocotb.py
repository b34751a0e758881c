"""cocotb overhead benchmark (not a test: the file name keeps it out of `make test`;
diffengine bench array runs it explicitly). Drives a random stream into de_array, one
instruction per clock, with no checking, and prints the simulated cycles per second."""
from __future__ import annotations

import os
import time
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import RisingEdge

from diffengine import isa
from diffengine.regress import randgen


@cocotb.test()
async def drive_stream(dut):
    n_pe = int(dut.n_pe_o.value)
    cmds = randgen.stream(int(os.environ["BENCH_SEED"]), int(os.environ["BENCH_N"]),
                          n_pe, (1, 40))
    slots, since = [], n_pe
    for ident, data in isa.serialise(cmds):
        if ident == isa.REFRESH:
            slots += [(0, 0)] * max(0, n_pe - since)
            since = 0
        slots.append((ident, data))
        since += 1
    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    for sig in (dut.cfg_mode_i, dut.cfg_bit_i, dut.obs_load_i, dut.obs_shift_i):
        sig.value = 0
    dut.rst_i.value = 1
    await RisingEdge(dut.clk_i)
    dut.rst_i.value = 0
    t = time.perf_counter()
    for ident, data in slots:
        dut.id_i.value = ident
        dut.data_i.value = data
        await RisingEdge(dut.clk_i)
    secs = time.perf_counter() - t
    print(f"BENCH cycles={len(slots)} seconds={secs:.3f}", flush=True)


def test_bench_cocotb():
    from common.run import build_and_test, rtl_files
    here = Path(__file__).resolve().parent
    srcs = rtl_files("array", "sim")
    build_and_test(here, "de_array", srcs, "bench_cocotb",
                   parameters={"NumChips": int(os.environ.get("BENCH_CHIPS", 1)),
                               "CarryBug": 0},
                   extra_env={k: os.environ[k] for k in ("BENCH_N", "BENCH_SEED")})
