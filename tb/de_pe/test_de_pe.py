"""cocotb 2 testbench for rtl/xproc/de_pe.sv, compared every cycle with structural.py.

Layout (Forencich style): the cocotb tests and the pytest runner live in this file; the
runner builds tb/de_pe/de_pe_chain.sv (N PEs behind the input skew) once per parameter
set into tb/de_pe/sim_build_<params> and runs the cocotb tests in it.

Structure (like cocotb's matrix_multiplier example):
  Driver   - drives one instruction per clock at the falling edge (Nop when idle).
  Monitor  - after each rising edge (ReadOnly) samples the inputs that were clocked in
             and every PE's state (dbg_o) and pixel outputs.
  Model    - sw/diffengine/model/structural.py Array, stepped with the sampled inputs.
  Checker  - in order: the RTL state after edge k must equal the model after step k,
             every field of every PE, every cycle.

Env: SEED replays the random tests (each prints the SEED to give); DE_RANDOM_CMDS sets the
length of random_streams (default 400 commands);
WAVES=1 dumps a trace.
"""
from __future__ import annotations

import os
import random
import sys
from collections import deque
from pathlib import Path

import numpy as np

TB_DIR = Path(__file__).resolve().parent
ROOT = TB_DIR.parent.parent
sys.path.insert(0, str(ROOT / "sw"))

from diffengine.model import functional  # noqa: E402
from diffengine import isa
from diffengine.model import structural as st  # noqa: E402

try:  # the pytest runner does not need a simulator; the cocotb part does
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge
except ImportError:  # pragma: no cover
    cocotb = None

N_PE = int(os.environ.get("DE_N_PE", "9"))
CARRY_BUG = int(os.environ.get("DE_CARRY_BUG", "0"))
# de_pe InReg: each PE registers its input, so PE p sees the stream p + 1 clocks after the
# model's PE p (which has one register per PE); its state is compared with the model's
# history that many cycles back.
IN_REG = int(os.environ.get("DE_IN_REG", "0"))
FIX = 1 << isa.FRAC_BITS  # 1.0 in 12.24


def C(op, x=0, dx=0, *values):
    return isa.Command(op, x, dx, tuple(values))


# ---- testbench components ----------------------------------------------------------------

class Driver:
    """Feeds (identifier, data) slots into the chain, one per clock, Nop when idle."""

    def __init__(self, dut):
        self.dut = dut
        self.queue: deque[tuple[int, int]] = deque()

    def send(self, slots) -> None:
        self.queue.extend(slots)

    async def run(self) -> None:
        while True:
            await FallingEdge(self.dut.clk_i)
            ident, data = self.queue.popleft() if self.queue else (isa.NOP, 0)
            self.dut.id_i.value = ident
            self.dut.data_i.value = data


class Monitor:
    """Samples, after each rising edge, the inputs just clocked in and all PE state."""

    def __init__(self, dut, callback):
        self.dut = dut
        self.callback = callback

    async def run(self) -> None:
        dut = self.dut
        while True:
            await RisingEdge(dut.clk_i)
            await ReadOnly()
            self.callback(
                rst=int(dut.rst_i.value),
                ident=int(dut.id_i.value),
                data=int(dut.data_i.value),
                dbg=dut.dbg_o.value.to_unsigned(),
                pix_valid=dut.pix_valid_o.value.to_unsigned(),
                pix=dut.pix_o.value.to_unsigned(),
            )


class Checker:
    """Steps the structural model with what the monitor saw and compares every field."""

    def __init__(self, n_pe: int, carry_bug: bool, log):
        self.model = st.Array(n_pe, carry_bug)
        self.n = n_pe
        self.log = log
        self.cycles = 0
        self.slots = 0
        self.pixels: list[list[int]] = [[] for _ in range(n_pe)]
        self.error: str | None = None
        # How many cycles PE p lags the model, and the model's snapshots, newest last:
        # (packed state, pixel valid, pixel) per PE after each step.
        self.lag = [(p + 1) * IN_REG for p in range(n_pe)]
        self.history: list[tuple] = []

    def snapshot(self) -> tuple:
        s = self.model.state()
        return (self.model.packed_state(), [int(v) for v in s["pix_valid"]],
                [int(v) for v in s["pix"]])

    def lagged(self, p: int) -> tuple[int, int, int]:
        """The model's PE p as the RTL's PE p should show it now (its lag back)."""
        words, valid, pix = self.history[max(0, len(self.history) - 1 - self.lag[p])]
        return words[p], valid[p], pix[p]

    def expected_dbg(self) -> int:
        v = 0
        for p in range(self.n):
            v |= self.lagged(p)[0] << (p * st.DBG_WIDTH)
        return v

    def sample(self, rst, ident, data, dbg, pix_valid, pix) -> None:
        if self.error:
            return
        if rst:
            # A synchronous reset clears every PE in the same cycle, whatever its lag:
            # each lagging PE then sees only Nops (which keep the reset state) until the
            # stream reaches it, so its view of the past is the reset state too.
            self.model.reset()
            self.history = [self.snapshot()] * (len(self.history) + 1)
        else:
            self.model.step(ident, data)
            self.slots += ident != isa.NOP
            self.history.append(self.snapshot())
        self.cycles += 1
        exp = self.expected_dbg()
        if dbg != exp:
            self.error = self.describe(dbg, exp, ident)
            return
        for p in range(self.n):
            v = (pix_valid >> p) & 1
            px = (pix >> (p * 12)) & 0xFFF
            _, want_v, want_px = self.lagged(p)
            if v != want_v or px != want_px:
                self.error = f"cycle {self.model.cycle}: pixel port of PE {p} {v}/{px:#x}"
                return
            if v:
                self.pixels[p].append(px)

    def describe(self, got: int, exp: int, ident: int) -> str:
        lines = [f"mismatch after edge {self.model.cycle} (input id {ident:#05x})"]
        mask = (1 << st.DBG_WIDTH) - 1
        for p in range(self.n):
            g, e = (got >> (p * st.DBG_WIDTH)) & mask, (exp >> (p * st.DBG_WIDTH)) & mask
            pos = st.DBG_WIDTH
            for name, w in st.DBG_FIELDS:
                pos -= w
                fg, fe = (g >> pos) & ((1 << w) - 1), (e >> pos) & ((1 << w) - 1)
                if fg != fe:
                    lines.append(f"  PE {p} {name}: rtl {fg:#x} model {fe:#x}")
        return "\n".join(lines[:40])


class Env:
    def __init__(self, dut):
        self.dut = dut
        self.driver = Driver(dut)
        self.checker = Checker(N_PE, bool(CARRY_BUG), dut._log)
        self.monitor = Monitor(dut, self.checker.sample)

    async def start(self) -> None:
        dut = self.dut
        Clock(dut.clk_i, 10, unit="ns").start(start_high=False)
        dut.rst_i.value = 1
        dut.id_i.value = 0
        dut.data_i.value = 0
        cocotb.start_soon(self.monitor.run())
        for _ in range(2):
            await FallingEdge(dut.clk_i)
        dut.rst_i.value = 0
        cocotb.start_soon(self.driver.run())

    async def run(self, commands, tail: int | None = None) -> None:
        """Send a command list, wait until it has drained, fail on the first mismatch."""
        self.driver.send(isa.serialise(commands))
        while self.driver.queue:
            await FallingEdge(self.dut.clk_i)
            self.check()
        for _ in range(tail if tail is not None else N_PE * (1 + IN_REG) + 4):
            await FallingEdge(self.dut.clk_i)
            self.check()

    def check(self) -> None:
        assert self.checker.error is None, self.checker.error

    def rows(self, start: int = 0) -> np.ndarray:
        """Pixel rows seen so far (PE p's k-th pixel belongs to the k-th Refresh)."""
        k = min(len(px) for px in self.checker.pixels)
        return np.array([px[start:k] for px in self.checker.pixels], dtype=np.uint16).T


async def fresh_env(dut) -> Env:
    env = Env(dut)
    await env.start()
    return env


# ---- (a) every command, directed ----------------------------------------------------------

def directed_cases() -> list[tuple[str, list, list | None]]:
    """(name, commands ending in Refresh, expected pixel row or None = functional)."""
    z = [0] * N_PE
    f = FIX
    cases = [
        ("nop", [C("NOP"), C("NOP")], z),
        # Dis / Set directly before the Refresh: the next case fails if dis / pA survive
        ("dis_then_refresh", [C("EVAL", 0, 9, f), C("DIS", 0, 9)], [1] * 9),
        ("eval0", [C("EVAL0", 2, 3, 100)], [0, 0, 100, 100, 100, 0, 0, 0, 0]),
        ("eval0_dx0", [C("EVAL0", 2, 0, 100)], z),
        ("eval0_first_wins", [C("EVAL0", 1, 2, 5), C("EVAL0", 0, 4, 9)],
         [9, 5, 5, 9, 0, 0, 0, 0, 0]),
        ("seti_then_refresh", [C("SETI", 0, 9, 7 * f)], z),
        ("eval1", [C("EVAL", 1, 4, 5 * f)], [0, 5, 5, 5, 5, 0, 0, 0, 0]),
        ("eval1_past_end", [C("EVAL", 7, 100, 3 * f)], [0] * 7 + [3, 3]),
        ("eval1_x_beyond", [C("EVAL", 12, 3, 3 * f)], z),
        ("eval2", [C("EVAL", 0, 9, 0, f)], list(range(9))),
        ("eval3", [C("EVAL", 0, 9, 0, 0, f // 2)], None),
        ("eval_accumulates", [C("EVAL", 0, 5, 2 * f), C("EVAL", 3, 5, 1 * f)],
         [2, 2, 2, 3, 3, 1, 1, 1, 0]),
        *[(f"eval{p + 1}", [C("EVAL", 1, 7, *[(k + 1) * f // 8 for k in range(p + 1)])], None)
          for p in range(3, isa.MAX_EVAL_ORDER + 1)],
        ("seti", [C("SETI", 3, 1, 7 * f), C("EVAL", 0, 9, f)], [1, 1, 1, 7, 7, 7, 7, 7, 7]),
        ("setdi", [C("SETDI", 4, 1, -f), C("EVAL", 0, 9, 0, f)], None),
        ("setddi", [C("SETDDI", 2, 3, f), C("EVAL", 0, 9, 0, 0, 0)], None),
        ("setpi", [C("SETPI", 1, 3, 9 * f), C("EVAL", 0, 9, 2 * f)],
         [2, 9, 9, 9, 9, 9, 9, 9, 9]),
        ("setpdi", [C("SETPDI", 0, 4, 3 * f), C("EVAL", 0, 9, 0, f)], None),
        ("setpddi_p0", [C("SETPDDI", 5, 0, f), C("EVAL", 0, 9, 0, 0, 0)], None),
        ("seti_order3", [C("SETI", 3, 1, 7 * f), C("EVAL", 0, 9, 0, 0, 0, f // 4)], None),
        ("dis", [C("DIS", 2, 2), C("EVAL", 0, 9, 3 * f), C("EVAL", 0, 9, f)],
         [4, 4, 1, 1, 4, 4, 4, 4, 4]),
        ("dis_eval0", [C("DIS", 1, 1), C("EVAL0", 0, 3, 8)], [8, 0, 8, 0, 0, 0, 0, 0, 0]),
        ("accmode_on", [C("ACCMODE", 0, 0, 1), C("EVAL", 0, 9, 4 * f, -f)],
         [4, 3, 2, 1, 0, 0, 0, 0, 0]),
        ("accmode_off", [C("ACCMODE", 0, 0, 1), C("ACCMODE", 0, 0, 0),
                         C("EVAL", 0, 9, 4 * f, -f)], None),
        ("negative_wraps", [C("EVAL", 0, 2, -f)], [0xFFF, 0xFFF] + [0] * 7),
        # same-cycle hazards of the skewed pipeline (docs/xproc.md section 6)
        ("acc_then_eval0", [C("EVAL", 0, 9, 5 * f), C("EVAL0", 2, 2, 7)],
         [5, 5, 7, 7, 5, 5, 5, 5, 5]),
        ("acc_then_accmode", [C("EVAL", 0, 9, -f), C("ACCMODE", 0, 0, 1),
                              C("EVAL", 0, 9, -f)], None),
        ("acc_then_seti", [C("EVAL", 0, 9, 2 * f), C("SETI", 1, 1, 5 * f),
                           C("EVAL", 0, 9, f)], None),
        ("dis_then_eval", [C("DIS", 0, 9), C("EVAL", 0, 9, f)], z),
        ("acc_then_dis", [C("EVAL", 0, 9, f), C("DIS", 0, 9), C("EVAL", 0, 9, 2 * f)],
         [1] * 9),
        ("eval0_then_eval0", [C("EVAL0", 0, 9, 3), C("EVAL0", 0, 9, 4)], [3] * 9),
        ("eval0_then_dis", [C("EVAL0", 0, 1, 3), C("DIS", 1, 1), C("EVAL", 0, 9, f)],
         [3, 0, 1, 1, 1, 1, 1, 1, 1]),
        ("carry_block0", [C("EVAL", 0, 9, 0xFFF, 1)], None),
        ("carry_block1", [C("EVAL", 0, 9, 0xFFF000, 0x1000)], None),
    ]
    return cases


@cocotb.test() if cocotb else (lambda f: f)
async def directed_commands(dut):
    """Every command (and each same-cycle hazard) on its own line; exact pixels."""
    env = await fresh_env(dut)
    cases = directed_cases()
    stream = []
    for _, cmds, _ in cases:
        stream += cmds + [C("REFRESH")]
    # Refreshes back to back, then the array idles (Nop) before each case.
    stream = [C("REFRESH"), C("REFRESH")] + stream
    await env.run(stream)
    rows = env.rows()
    assert len(rows) == len(cases) + 2
    assert not rows[:2].any()
    for i, (name, cmds, want) in enumerate(cases):
        ref = functional.render(cmds + [C("REFRESH")], N_PE, bool(CARRY_BUG))[0]
        got = rows[i + 2]
        assert np.array_equal(got, ref), f"{name}: rtl {got.tolist()} functional {ref.tolist()}"
        if want is not None and not CARRY_BUG:
            assert got.tolist() == want, f"{name}: rtl {got.tolist()} expected {want}"
    dut._log.info("directed: %d cases, %d cycles compared", len(cases), env.checker.cycles)


@cocotb.test() if cocotb else (lambda f: f)
async def acc_then_refresh(dut):
    """ACC directly followed by Refresh: the pixel forwards the same-cycle D write."""
    env = await fresh_env(dut)
    stream = [C("EVAL", 0, 9, 0, FIX), C("REFRESH"), C("EVAL", 3, 2, 6 * FIX), C("REFRESH")]
    await env.run(stream)
    rows = env.rows()
    assert rows[0].tolist() == list(range(9))
    assert rows[1].tolist() == [0, 0, 0, 6, 6, 0, 0, 0, 0]


@cocotb.test() if cocotb else (lambda f: f)
async def reset_mid_stream(dut):
    """rst_i for one cycle with a line half done and slots still in flight clears every
    register, flag and pipeline stage: the next line's pixels are those of a fresh array
    (and the model, reset in the same cycle, matches every cycle before and after)."""
    env = await fresh_env(dut)
    dirty = [C("EVAL", 0, 9, 5 * FIX, FIX // 7), C("SETI", 2, 4, 3 * FIX), C("DIS", 1, 3),
             C("ACCMODE", 0, 0, 1), C("EVAL0", 4, 2, 9 * FIX), C("EVAL", 0, 9, FIX, FIX)]
    await env.run(dirty, tail=2)           # the last slots are still inside the chain
    dut.rst_i.value = 1
    await FallingEdge(dut.clk_i)
    dut.rst_i.value = 0
    env.check()
    clean = [C("EVAL", 1, 7, FIX), C("REFRESH")]
    await env.run(clean)
    rows = env.rows()
    assert len(rows) == 1, rows
    assert rows[0].tolist() == [0, 1, 1, 1, 1, 1, 1, 1, 0]
    ref = functional.render(clean, N_PE, bool(CARRY_BUG))[0]
    assert np.array_equal(rows[0], ref)


# ---- (b) random well-formed command streams, every cycle -----------------------------------

@cocotb.test() if cocotb else (lambda f: f)
async def random_streams(dut):
    """Random well-formed command streams; model and RTL compared every cycle."""
    seed = int(os.environ.get("SEED", random.randrange(1 << 32)))
    count = int(os.environ.get("DE_RANDOM_CMDS", "400"))
    dut._log.info("random_streams: SEED=%d DE_RANDOM_CMDS=%d CarryBug=%d (replay: "
                  "SEED=%d pytest tb/de_pe)", seed, count, CARRY_BUG, seed)
    print(f"random_streams SEED={seed}")
    rng = np.random.default_rng(seed)
    env = await fresh_env(dut)
    cmds = st.random_commands(rng, N_PE, count)
    await env.run(cmds)
    rows = env.rows()
    ref = functional.render(cmds, N_PE, bool(CARRY_BUG))
    assert np.array_equal(rows, ref), f"SEED={seed}: pixels differ from functional.py"
    dut._log.info("random_streams: SEED=%d %d commands, %d slots, %d cycles, %d lines OK",
                  seed, len(cmds), env.checker.slots, env.checker.cycles, len(rows))


@cocotb.test() if cocotb else (lambda f: f)
async def random_identifiers(dut):
    """Any sequence of the 19 identifiers with random data (not well-formed): the RTL
    and the structural model must still agree every cycle (same equations)."""
    # The printed SEED is the one to replay with (SEED=<n> pytest tb/de_pe); the stream
    # is drawn from it xor a constant, so one SEED gives this test and random_streams
    # different streams.
    seed = int(os.environ.get("SEED", random.randrange(1 << 32)))
    dut._log.info("random_identifiers: SEED=%d (replay: SEED=%d pytest tb/de_pe)", seed, seed)
    print(f"random_identifiers SEED={seed}")
    rng = np.random.default_rng(seed ^ 0x5A5A)
    env = await fresh_env(dut)
    ids = [ident for _, ident, _ in isa.LUT]
    slots = []
    for _ in range(int(os.environ.get("DE_RANDOM_IDS", "600"))):
        ident = ids[int(rng.integers(0, len(ids)))]
        if rng.random() < 0.5:
            data = isa.blocks_word((int(rng.integers(0, 4)), int(rng.integers(0, 4)),
                                    int(rng.integers(0, 1 << isa.BLOCK_BITS))))
        else:
            data = int(rng.integers(0, 1 << isa.WORD_BITS))
        slots.append((ident, data))
    env.driver.send(slots)
    while env.driver.queue:
        await FallingEdge(dut.clk_i)
        env.check()
    for _ in range(N_PE + 4):
        await FallingEdge(dut.clk_i)
        env.check()


# ---- (c) Table 7.5 ------------------------------------------------------------------------

TABLE_7_5 = {  # column: (dI, I) as 0xIII.FFFFFF per PE, from the source
    "correct": (
        ["000.000000", "000.800000", "001.000000", "001.800000", "002.000000",
         "002.800000", "003.000000", "003.800000", "004.000000"],
        ["000.000000", "000.000000", "000.800000", "001.800000", "003.000000",
         "005.000000", "007.800000", "00a.800000", "00e.000000"]),
    "erroneous": (
        ["000.000000", "000.800000", "002.000000", "002.800000", "004.000000",
         "004.800000", "006.000000", "006.800000", "008.000000"],
        ["000.000000", "000.000000", "000.800000", "002.800000", "006.000000",
         "00a.000000", "00e.800000", "014.800000", "01c.000000"]),
}


def _fixed(s: str) -> int:
    i, fr = s.split(".")
    return (int(i, 16) << isa.FRAC_BITS) | int(fr, 16)


@cocotb.test() if cocotb else (lambda f: f)
async def table_7_5(dut):
    """Eval3 (0, 9, 0, 0, 0.5) on 9 PEs: B = dI and A = I per PE as in Table 7.5."""
    assert N_PE == 9
    env = await fresh_env(dut)
    await env.run([C("EVAL", 0, 9, 0, 0, FIX // 2)])
    s = env.checker.model.state()  # equal to the RTL state (checked every cycle)
    col = "erroneous" if CARRY_BUG else "correct"
    di, i = TABLE_7_5[col]
    got_b = [isa.format_fixed(int(v))[2:] for v in s["B"]]
    got_a = [isa.format_fixed(int(v))[2:] for v in s["A"]]
    assert got_b == di, f"{col} dI: {got_b}"
    assert got_a == i, f"{col} I: {got_a}"
    # and read the RTL directly, not only through the model
    dbg = dut.dbg_o.value.to_unsigned()
    pos_a = st.DBG_WIDTH - isa.DBG_FIELDS[0][1]   # A: the first field, MSB first
    for p in range(9):
        word = (dbg >> (p * st.DBG_WIDTH + pos_a)) & isa.WORD_MASK
        assert word == _fixed(i[p]), f"PE {p} A {isa.format_fixed(word)}"
    await env.run([C("REFRESH")])
    assert env.rows()[-1].tolist() == [isa.pixel_of(_fixed(v)) for v in i]


# ---- pytest runner --------------------------------------------------------------------------

def _sources() -> list[Path]:
    from common.run import rtl_files   # tb/de_pe/de_pe_tb.core
    return rtl_files("diffengine:tb:de_pe")


def _run(carry_bug: int, n_pe: int = 9, compact: int = 0, in_reg: int = 0) -> None:
    from cocotb_tools.runner import get_runner

    runner = get_runner("verilator")
    params = {"N": n_pe, "CarryBug": carry_bug, "Compact": compact, "InReg": in_reg}
    build_dir = TB_DIR / f"sim_build_N{n_pe}_CarryBug{carry_bug}_Compact{compact}_InReg{in_reg}"
    runner.build(
        sources=_sources(),
        hdl_toplevel="de_pe_chain",
        parameters=params,
        build_dir=build_dir,
        build_args=["-Wno-fatal", "-O3"],
        waves=bool(int(os.environ.get("WAVES", "0"))),
    )
    env = {"DE_CARRY_BUG": str(carry_bug), "DE_N_PE": str(n_pe), "DE_IN_REG": str(in_reg),
           "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT / "sw"),
                                                       os.environ.get("PYTHONPATH")]))}
    # Under pytest the runner itself fails the test if a cocotb test failed.
    runner.test(
        hdl_toplevel="de_pe_chain",
        test_module="test_de_pe",
        test_dir=TB_DIR,
        build_dir=build_dir,
        extra_env=env,
        waves=bool(int(os.environ.get("WAVES", "0"))),
    )


try:
    import pytest

    # Compact: de_pe's two forms of its timing-only logic (the fast one with the
    # identifier copy, IdCopy); the cycle behaviour must be the same in both.
    @pytest.mark.parametrize("compact", [0, 1])
    @pytest.mark.parametrize("carry_bug", [0, 1])
    def test_de_pe(carry_bug, compact):
        _run(carry_bug, compact=compact)

    # InReg: the PE with its input registered (de_chip InReg, the chip of the FPGA flow):
    # the same states, each PE one clock later per position.
    @pytest.mark.parametrize("carry_bug", [0, 1])
    def test_de_pe_in_reg(carry_bug):
        _run(carry_bug, in_reg=1)
except ImportError:  # pragma: no cover
    pass
