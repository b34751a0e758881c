"""Shared cocotb runner glue: one build folder per parameter set, paths independent
of the current directory, seeds printed so a random run can be replayed."""
from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

from cocotb_tools.runner import get_runner

REPO = Path(__file__).resolve().parents[2]
RTL = REPO / "rtl"


def rtl_files(core: str, target: str = "default") -> list[Path]:
    """The ordered file list of a FuseSoC core and target (rtl/*/*.core, tb/*/*.core),
    e.g. rtl_files("array") or rtl_files("diffengine:tb:de_pe"): scripts/filelist.py."""
    import importlib.util
    mod = sys.modules.get("filelist")
    if mod is None:
        spec = importlib.util.spec_from_file_location("filelist",
                                                      REPO / "scripts" / "filelist.py")
        mod = importlib.util.module_from_spec(spec)
        sys.modules["filelist"] = mod
        spec.loader.exec_module(mod)
    return mod.files(core, target)


def build_and_test(tb_dir: Path, toplevel: str, sources: list[Path], test_module: str,
                   parameters: dict | None = None, extra_env: dict | None = None,
                   testcase: str | None = None, waves: bool = False,
                   lint: bool = False) -> None:
    """Build `toplevel` from `sources` (cached per parameter set) and run `test_module`.
    lint=True builds with Verilator -Wall as an error (the blocks whose testbench is
    also their lint gate), otherwise warnings do not stop the build."""
    parameters = parameters or {}
    tag = "_".join(f"{k}{v}" for k, v in sorted(parameters.items())) or "default"
    tag = tag.replace("'", "")  # a Verilog literal's quote (98'h...), not in a folder name
    build_dir = tb_dir / f"sim_build_{tag}"
    runner = get_runner("verilator")
    # ccache, when installed, compiles the Verilated C++ (sim/Makefile does the same);
    # CCACHE_BASEDIR makes its hashes independent of where the checkout is, so a fresh
    # clone on a machine that built the same RTL before compiles nothing again.
    cache = shutil.which("ccache")
    if cache:
        os.environ.setdefault("CCACHE_BASEDIR", str(REPO))
    runner.build(
        sources=[str(s) for s in sources],
        hdl_toplevel=toplevel,
        parameters=parameters,
        build_dir=build_dir,
        build_args=(["-Wall", "-O1"] if lint else ["-Wno-fatal"])
        + ["-MAKEFLAGS", "CFG_CXXFLAGS_PCH_I=-include"]
        + (["-MAKEFLAGS", f"OBJCACHE={cache}"] if cache else [])
        + (["--trace-fst", "--trace-structs"] if waves else []),
        waves=waves,
    )
    env = dict(extra_env or {})
    env.setdefault("PYTHONPATH", os.pathsep.join([str(tb_dir), str(REPO / "tb"),
                                                  str(REPO / "sw")]))
    runner.test(
        test_module=test_module,
        hdl_toplevel=toplevel,
        build_dir=build_dir,
        test_dir=tb_dir,
        extra_env=env,
        testcase=testcase,
        waves=waves,
        results_xml=str(build_dir / "results.xml"),
    )


def seed_from_env(default: int | None = None) -> int:
    """The random seed: SEED from the environment, else a fresh one; always printed."""
    seed = int(os.environ.get("SEED", default if default is not None
                              else int.from_bytes(os.urandom(4), "little")))
    print(f"SEED={seed}  (re-run with SEED={seed})", file=sys.stderr)
    return seed


def drive(dut, **values) -> None:
    """Set the testbench's inputs: drive(dut, rst_i=1, valid_i=0, ...) (name=value)."""
    for name, value in values.items():
        getattr(dut, name).value = value


async def offer(dut, valid: str, ready: str, **values) -> None:
    """One valid/ready handshake on clk_i, from the falling edge the caller stands on:
    drive the values (name=value) with `valid` high, look at `ready` once the inputs have
    settled (ReadOnly: ready may be combinational), and return at the falling edge after
    the rising edge that took them, with `valid` low again."""
    from cocotb.triggers import FallingEdge, ReadOnly
    drive(dut, **{valid: 1}, **values)
    while True:
        await ReadOnly()
        taken = int(getattr(dut, ready).value)
        await FallingEdge(dut.clk_i)
        if taken:
            break
    getattr(dut, valid).value = 0


async def hold_reset(dut, rises: int, *, falling: bool = True, clock_ns: float | None = None,
                     **inputs) -> None:
    """The testbenches' reset: optionally start a clock_ns clock on clk_i, raise rst_i
    with the given inputs driven (name=value), wait `rises` rising edges of clk_i and,
    with `falling`, the falling edge after them, then release rst_i."""
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, RisingEdge
    if clock_ns is not None:
        cocotb.start_soon(Clock(dut.clk_i, clock_ns, unit="ns").start())
    drive(dut, rst_i=1, **inputs)
    for _ in range(rises):
        await RisingEdge(dut.clk_i)
    if falling:
        await FallingEdge(dut.clk_i)
    dut.rst_i.value = 0
