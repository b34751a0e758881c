"""cocotb bench of the virtual array rtl/varray/de_varray.sv (docs/fpga.md).

The virtual array (Fold columns per physical PE, state in RAM, core clock Fold x the
slot rate) and the plain de_array run side by side on one stream (tb_de_varray.sv):
every step the virtual array's pixel and bus outputs must equal the plain array's (bus
outputs as a sequence, pixels as raster-order lines with no gap), and the frames must
equal the golden model (functional.render) bit for bit. Streams: random
(sw/diffengine/regress/randgen.py, seed printed, SEED=<n> replays), directed fold-boundary
spans, and the seed's Fig. 7.21 / 7.25 command lists. With and without the carry bug.
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

from diffengine.formats import asm
from diffengine.model import functional
from diffengine import isa
from diffengine.regress import randgen

SCENES = Path(__file__).resolve().parents[2] / "sw" / "scenes"


from de_array.test_de_array import spaced  # noqa: E402  Refreshes n slots apart


class Bench:
    def __init__(self, dut):
        self.dut = dut
        self.n = int(dut.n_pe_o.value)
        self.fold = int(os.environ["DE_FOLD"])
        self.v_pix: list[int] = []
        self.a_pix: list[int] = []
        self.v_steps: list[int] = []   # step index of every virtual-array pixel
        self.v_bus: list[tuple[int, int]] = []
        self.a_bus: list[tuple[int, int]] = []
        self.collision_step = 0

    async def reset(self):
        d = self.dut
        d.ident_i.value = 0
        d.data_i.value = 0
        d.clk_a_i.value = 0
        d.rst_i.value = 1
        for _ in range(2):
            await RisingEdge(d.clk_i)
            d.clk_a_i.value = 1
            await FallingEdge(d.clk_i)
            d.clk_a_i.value = 0
        d.rst_i.value = 0

    async def play(self, slots):
        d = self.dut
        step = 0
        for ident, data in slots:
            # Wait for the cycle in which the virtual array samples its slot (step_o
            # depends on registers only: settled at the falling edge).
            while True:
                await FallingEdge(d.clk_i)
                d.clk_a_i.value = 0
                if int(d.step_o.value):
                    break
            d.ident_i.value = ident
            d.data_i.value = data
            await RisingEdge(d.clk_i)
            d.clk_a_i.value = 1          # the plain array takes the same slot
            await ReadOnly()
            # Both arrays' outputs of this step (the virtual array's hold for the step).
            if int(d.a_pixel_valid_o.value):
                self.a_pix.append(int(d.a_pixel_o.value))
            if int(d.v_pixel_valid_o.value):
                self.v_pix.append(int(d.v_pixel_o.value))
                self.v_steps.append(step)
            if int(d.v_collision_o.value) and not self.collision_step:
                self.collision_step = step
            self.v_bus.append((int(d.v_ident_o.value), int(d.v_data_o.value)))
            self.a_bus.append((int(d.a_ident_o.value), int(d.a_data_o.value)))
            step += 1
        await FallingEdge(d.clk_i)
        d.clk_a_i.value = 0
        await ReadOnly()
        assert not int(d.v_collision_o.value), \
            f"pixel collision in the virtual array from step {self.collision_step}"
        assert not int(d.a_collision_o.value), "pixel collision in the plain array"

    def check(self, cmds, carry_bug: bool):
        n = self.n
        assert len(self.v_pix) == len(self.a_pix), \
            f"virtual array {len(self.v_pix)} pixels, plain array {len(self.a_pix)}"
        assert self.v_pix == self.a_pix, "virtual array pixels differ from de_array"
        for line in range(len(self.v_steps) // n):
            s = self.v_steps[line * n:(line + 1) * n]
            assert s == list(range(s[0], s[0] + n)), f"line {line}: gap in {s}"
        # Bus outputs: same sequence, the virtual array's shifted by a fixed latency.
        nz = [i for i, b in enumerate(self.a_bus) if b != (0, 0)]
        if nz:
            vz = [i for i, b in enumerate(self.v_bus) if b != (0, 0)]
            assert vz, "virtual array bus output stays zero"
            lag = vz[0] - nz[0]   # the latencies differ (de_array: one per chip)
            v, a = (self.v_bus[lag:], self.a_bus) if lag >= 0 else \
                (self.v_bus, self.a_bus[-lag:])
            m = min(len(v), len(a))
            assert m > len(nz) // 2, f"bus outputs too short to compare ({m})"
            assert v[:m] == a[:m], f"bus output differs from de_array (lag {lag})"
        frame = np.array(self.v_pix, dtype=np.uint16).reshape(-1, n)
        want = functional.render(cmds, n, carry_bug=carry_bug)
        np.testing.assert_array_equal(frame, want)
        return frame


async def start(dut) -> Bench:
    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    b = Bench(dut)
    await Timer(1, unit="ns")
    await b.reset()
    return b


def bug() -> bool:
    return bool(int(os.environ.get("DE_CARRY_BUG", "0")))


@cocotb.test()
async def random_streams(dut):
    """Random streams (randgen) equal de_array and the golden model."""
    b = await start(dut)
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    dut._log.info(f"SEED={seed} (replay with SEED={seed})")
    cmds = randgen.stream(seed, int(os.environ.get("N_CMDS", 150)), b.n, (1, 10))
    await b.play(spaced(isa.serialise(cmds), b.n))
    frame = b.check(cmds, bug())
    dut._log.info(f"{frame.shape[0]} lines x {b.n} columns, fold {b.fold}: equal")


@cocotb.test()
async def fold_boundaries(dut):
    """Spans starting, ending and crossing every physical-PE row boundary (k*P)."""
    b = await start(dut)
    n, one = b.n, 1 << 24
    p = n // b.fold
    cmds = []
    for k in range(1, b.fold):
        c = k * p
        x0 = max(c - 2, 0)
        cmds += [isa.Command("EVAL", x0, min(4, n - x0), (10 * one, 3 * one, one // 2)),
                 isa.Command("EVAL", c - 1, 1, (one,)),
                 isa.Command("SETI", c, 1, (100 * one,)), isa.Command("REFRESH")]
    cmds += [isa.Command("EVAL", 0, n, (0, one // 3, one // 1000)), isa.Command("REFRESH"),
             isa.Command("EVAL0", 0, n, (4095,)), isa.Command("REFRESH")]
    await b.play(spaced(isa.serialise(cmds), n))
    b.check(cmds, bug())


@cocotb.test()
async def reset_mid_stream(dut):
    """rst_i for one cycle in the middle of a line clears every column's state."""
    b = await start(dut)
    n, one = b.n, 1 << 24
    dirty = [isa.Command("EVAL", 0, n, (5 * one, one // 7)),
             isa.Command("SETI", 0, n, (3 * one,)), isa.Command("ACCMODE", 0, 0, (1,))]
    await b.play(isa.serialise(dirty) + [(0, 0)] * 4)
    d = dut
    await FallingEdge(d.clk_i)
    d.rst_i.value = 1
    await RisingEdge(d.clk_i)
    d.clk_a_i.value = 1
    await FallingEdge(d.clk_i)
    d.clk_a_i.value = 0
    d.rst_i.value = 0
    b2 = Bench(dut)
    cmds = [isa.Command("EVAL", 1, n - 2, (one,)), isa.Command("REFRESH")]
    await b2.play(spaced(isa.serialise(cmds), n))
    b2.check(cmds, bug())


@cocotb.test()
async def figure_lists(dut):
    """The seed's Fig. 7.21 / 7.25 command lists (only when the array is wide enough)."""
    b = await start(dut)
    cmds = []
    for path in sorted(SCENES.glob("fig7_*.cmd")):
        cmds += asm.parse_file(path)
    need = max((c.x + c.dx for c in cmds if c.op != "REFRESH"), default=0)
    if need > b.n:
        dut._log.info(f"lists need {need} columns; array has {b.n}: run with more chips")
        cmds = [c for c in cmds if c.op == "REFRESH" or c.x + c.dx <= b.n]
    await b.play(spaced(isa.serialise(cmds), b.n))
    b.check(cmds, bug())


# ---- pytest runners -------------------------------------------------------------------
# Default run (make test): two small builds. DE_VARRAY_LONG=1 adds the full-width figure
# lists (16 chips = 144 columns at fold 8, both carry settings) and folds 9 and 1.
RUNS = [  # (chips, fold, carry_bug, tests)
    (2, 3, 0, None), (2, 2, 1, None),
]
if int(os.environ.get("DE_VARRAY_LONG", "0")):
    RUNS += [(1, 9, 0, None), (2, 1, 0, "fold_boundaries"),
             (16, 8, 0, "figure_lists"), (16, 8, 1, "figure_lists")]


@pytest.mark.parametrize("chips,fold,bug,tests", RUNS,
                         ids=[f"chips{c}_fold{f}_bug{b}" for c, f, b, _ in RUNS])
def test_de_varray(chips, fold, bug, tests):
    import sys
    from common.run import RTL, build_and_test
    here = Path(__file__).resolve().parent
    sys.path.insert(0, str(RTL / "varray"))
    from gen_vpe import ensure  # de_vpe.sv is generated from de_pe.sv
    vpe = ensure(here / "sim_build_gen" / "de_vpe.sv")
    srcs = [RTL / "xproc" / "de_pkg.sv", RTL / "xproc" / "de_pe.sv",
            RTL / "proto" / "de_skew.sv", RTL / "proto" / "de_deskew.sv",
            RTL / "array" / "de_chip.sv", RTL / "array" / "de_array.sv",
            vpe, RTL / "varray" / "de_varray.sv",
            here / "tb_de_varray.sv"]
    build_and_test(here, "tb_de_varray", srcs, "test_de_varray",
                   parameters={"NumChips": chips, "CarryBug": bug, "Fold": fold},
                   extra_env={"DE_CARRY_BUG": str(bug), "DE_FOLD": str(fold)},
                   testcase=tests)
