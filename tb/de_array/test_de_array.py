"""cocotb bench of the x-processor array (chips, boundaries, bypass, observation chain).

driver (instructions, one per clock, Refreshes spaced by the array width)
  -> monitor (pixels leaving the array; every PE's state through the hierarchy)
  -> golden models (structural.Array per cycle, functional.render per frame)
  -> in-order checkers.

Chip k's PEs see the same input stream as the structural model's PEs 9k.., one clock
later per chip boundary, so their state is compared with the model's history k cycles
back. Every random test prints its seed; SEED=<n> replays it.
"""
from __future__ import annotations

import os
import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge

from diffengine.model import functional
from diffengine import isa
from diffengine.regress import randgen
from diffengine.model import structural as st

NUM_PE = 9
FAULTY = (3, 10)  # PEs garbled by the FaultMask build (bypass test)
# de_array InReg: every PE registers its input (two clocks per PE position on the bus).
IN_REG = int(os.environ.get("DE_IN_REG", "0"))


def state_lag(q: int) -> int:
    """Cycles by which PE q sees the stream after the structural model's PE q (one
    register per PE): one per chip boundary before it; with InReg also its own input
    register and one more per PE before it (docs/array.md, "Pixel timing")."""
    return q // NUM_PE + (1 + q if IN_REG else 0)


def pixel_latency(k: int) -> int:
    """Rising edges from the one that clocks a Refresh in to the one after which column 0
    is on pix_o, for k chips and no PE bypassed (docs/array.md)."""
    return (NUM_PE + 1) * k + 3 if IN_REG else k + 2


def chips(dut) -> int:
    return int(dut.n_pe_o.value) // NUM_PE


def spaced(slots, n_pe):
    """Insert Nops so that two Refreshes are at least n_pe slots apart (7.4.1)."""
    out, since = [], n_pe
    for ident, data in slots:
        if ident == isa.REFRESH:
            while since < n_pe:
                out.append((0, 0))
                since += 1
            since = 0
        out.append((ident, data))
        since += 1
    return out + [(0, 0)] * (2 * n_pe + 40)


class Array:
    """Drives the DUT and collects pixels; optional per-cycle structural comparison."""

    def __init__(self, dut, check_state: bool = False, carry_bug: bool = False):
        self.dut = dut
        self.n = int(dut.n_pe_o.value)
        self.k = self.n // NUM_PE
        self.pixels: list[int] = []
        self.check_state = check_state
        self.model = st.Array(self.n, carry_bug) if check_state else None
        self.history: list[list[int]] = []
        self.cycles_checked = 0
        self.edge = 0                      # rising edges since play() began
        self.refresh_edges: list[int] = []  # edge that clocked each Refresh into the array
        self.pixel_edges: list[int] = []    # edge after which each pixel was on the output

    async def reset(self):
        from common.run import hold_reset
        await hold_reset(self.dut, 3, id_i=0, data_i=0, cfg_mode_i=0, cfg_bit_i=0,
                         obs_load_i=0, obs_shift_i=0)
        if self.model:
            self.model.reset()

    async def configure(self, bypass: set[int]):
        """Shift one bypass bit per PE in; the last PE's bit goes first."""
        d = self.dut
        d.cfg_mode_i.value = 1
        for pe in reversed(range(self.n)):
            d.cfg_bit_i.value = int(pe in bypass)
            await FallingEdge(d.clk_i)
        d.cfg_mode_i.value = 0

    def pe_dbg(self, q: int) -> int:
        c, i = divmod(q, NUM_PE)
        return int(self.dut.g_chip[c].u_chip.u_core.g_pe[i].pe_dbg.value)

    async def play(self, slots):
        d = self.dut
        for ident, data in slots:
            d.id_i.value = ident
            d.data_i.value = data
            await RisingEdge(d.clk_i)
            await ReadOnly()
            self.edge += 1
            if ident == isa.REFRESH:
                self.refresh_edges.append(self.edge)
            if int(d.pix_valid_o.value):
                self.pixels.append(int(d.pix_o.value))
                self.pixel_edges.append(self.edge)
            if self.model:
                self.model.step(ident, data)
                self.history.append(self.model.packed_state())
                self.compare_state()
            await FallingEdge(d.clk_i)
        assert not int(d.pix_collision_o.value), "pixel collision in the array"

    def compare_state(self):
        t = len(self.history) - 1
        for q in range(self.n):
            lag = state_lag(q)
            if t - lag < 0:
                continue
            want = self.history[t - lag][q]
            got = self.pe_dbg(q)
            if got != want:
                names = [n for n, _ in st.DBG_FIELDS]
                diffs = []
                for name, (lo, w) in zip(names, _field_pos()):
                    g, e = (got >> lo) & ((1 << w) - 1), (want >> lo) & ((1 << w) - 1)
                    if g != e:
                        diffs.append(f"{name}: rtl {g:#x} model {e:#x}")
                raise AssertionError(f"cycle {t}: PE {q} (chip {q // NUM_PE}) differs from "
                                     f"the structural model: " + "; ".join(diffs))
        self.cycles_checked += 1

    def frame(self) -> np.ndarray:
        assert len(self.pixels) % self.n == 0, f"{len(self.pixels)} pixels, width {self.n}"
        return np.array(self.pixels, dtype=np.uint16).reshape(-1, self.n)


def _field_pos():
    """(lsb, width) of each DBG_FIELDS entry in the packed debug word (MSB first)."""
    pos, lsb = [], st.DBG_WIDTH
    for _, w in st.DBG_FIELDS:
        lsb -= w
        pos.append((lsb, w))
    return pos


def seed() -> int:
    s = int(os.environ.get("SEED", random.randrange(1 << 31)))
    cocotb.log.info(f"SEED={s} (replay with SEED={s})")
    return s


async def start(dut, **kw) -> Array:
    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    arr = Array(dut, **kw)
    await arr.reset()
    return arr


def carry_bug(dut) -> bool:
    return bool(int(os.environ.get("DE_CARRY_BUG", "0")))


@cocotb.test()
async def directed_boundaries(dut):
    """Spans at PE 0, the last PE, across every chip boundary, dX 0 and 1."""
    arr = await start(dut)
    n = arr.n
    one = 1 << isa.FRAC_BITS
    cmds = []
    for b in range(NUM_PE, n, NUM_PE):  # every chip boundary
        cmds += [isa.Command("EVAL", b - 2, 4, (10 * one, 3 * one, one // 2)),
                 isa.Command("SETI", b, 1, (100 * one,)), isa.Command("REFRESH")]
    cmds += [isa.Command("EVAL", 0, 1, (7 * one,)), isa.Command("EVAL", n - 1, 1, (9 * one,)),
             isa.Command("EVAL", 3, 0, (5 * one,)), isa.Command("EVAL", n - 2, 10, (1, one)),
             isa.Command("EVAL0", 0, n, (4095,)), isa.Command("REFRESH"),
             isa.Command("EVAL", 0, n, (0, one // 3, one // 1000)), isa.Command("REFRESH")]
    await arr.play(spaced(isa.serialise(cmds), n))
    want = functional.render(cmds, n, carry_bug=carry_bug(dut))
    np.testing.assert_array_equal(arr.frame(), want)
    # docs/array.md: a Refresh on id_i in the cycle ending with edge R puts column q
    # on pix_o after edge R + NumChips + 2 + q (InReg: R + 10 NumChips + 3 + q).
    want_lat = pixel_latency(arr.k)
    for line, r in enumerate(arr.refresh_edges):
        edges = arr.pixel_edges[line * n:(line + 1) * n]
        assert edges == list(range(edges[0], edges[0] + n)), f"line {line}: gaps {edges}"
        assert edges[0] - r == want_lat, f"line {line}: latency {edges[0] - r}, want {want_lat}"


@cocotb.test()
async def every_pe_every_cycle(dut):
    """Random streams: all PEs' registers and flags equal the structural model's."""
    arr = await start(dut, check_state=True, carry_bug=carry_bug(dut))
    cmds = randgen.stream(seed(), int(os.environ.get("N_STATE", 400)), arr.n, (1, 12))
    await arr.play(spaced(isa.serialise(cmds), arr.n))
    np.testing.assert_array_equal(arr.frame(),
                                  functional.render(cmds, arr.n, carry_bug=carry_bug(dut)))
    dut._log.info(f"{arr.cycles_checked} cycles x {arr.n} PEs equal the structural model")


@cocotb.test()
async def observation_chain(dut):
    """Load every PE's controller outputs and shift them out serially (7.4.5)."""
    arr = await start(dut, check_state=True, carry_bug=carry_bug(dut))
    rng = random.Random(seed())
    cmds = [randgen.command(rng, arr.n) for _ in range(30)]
    slots = isa.serialise(cmds)[:-1]  # stop mid-stream so flags are set
    await arr.play(slots)
    d = dut
    d.id_i.value, d.data_i.value = 0, 0
    d.obs_load_i.value = 1
    await RisingEdge(d.clk_i)   # the load samples the state after the last slot
    await FallingEdge(d.clk_i)
    d.obs_load_i.value = 0
    d.obs_shift_i.value = 1
    flag_names = ("pA", "pB", "pC", "dis", "lock", "acc_mode", "act")
    ctl_names = ("xz1", "act1", "prot1", "c1", "act2", "prot2", "c2", "e0wr2",
                 "accen2", "accc2", "accen3", "accc3")
    width = dict(st.DBG_FIELDS)
    # The observation word: the flags, id1 and the control bits (spec/isa.toml [debug]).
    obs_w = sum(width[n] for n in flag_names + ("id1",) + ctl_names)
    bits = []
    for _ in range(arr.n * obs_w):
        await ReadOnly()
        bits.append(int(d.obs_bit_o.value))
        await FallingEdge(d.clk_i)
    d.obs_shift_i.value = 0
    # The last chip's words come first; in a chip, PE 0's word first, LSB first.
    words = [sum(b << i for i, b in enumerate(bits[w * obs_w:(w + 1) * obs_w]))
             for w in range(arr.n)]
    order = [c * NUM_PE + i for c in reversed(range(arr.k)) for i in range(NUM_PE)]
    pos = dict(zip([n for n, _ in st.DBG_FIELDS], _field_pos()))
    t = len(arr.history) - 1
    for word, q in zip(words, order):
        dbg = arr.history[t - state_lag(q)][q]
        f = lambda name: (dbg >> pos[name][0]) & ((1 << pos[name][1]) - 1)  # noqa: E731
        flags = 0
        for name in flag_names:
            flags = (flags << 1) | f(name)
        ctl = 0
        for name in ctl_names:
            ctl = (ctl << 1) | f(name)
        want = (((flags << width["id1"]) | f("id1")) << len(ctl_names)) | ctl
        assert word == want, f"PE {q}: observed {word:#010x}, model {want:#010x}"


TABLE_7_5_COMPENSATED = (  # (dI, I) per PE, Table 7.5 right-hand columns
    ["000.000000", "000.400000", "000.800000", "000.c00000", "002.000000", "002.400000",
     "002.800000", "002.c00000", "004.000000"],
    ["000.000000", "000.000000", "000.400000", "000.c00000", "002.800000", "004.800000",
     "006.c00000", "00a.400000", "00e.000000"])


@cocotb.test()
async def table_7_5_through_the_mapper(dut):
    """Table 7.5 on chip 0: the Eval3 goes through the data mapper's reference
    (binfmt.map_word, against which rtl/proto/de_data_mapper.sv is tested), with
    compensation when the array has the fault. Registers B (dI) and A (I) of PEs 0..8
    match the source's correct or compensated columns digit for digit."""
    from diffengine.formats import binfmt
    arr = await start(dut)
    bug = carry_bug(dut)
    cmd = isa.Command("EVAL", 0, 9, (0, 0, 1 << 23))  # ddI = 0x000.800000
    words = binfmt.framestore_encode([cmd], window=0)
    slots = [binfmt.map_word(w, 0, compensate=bug) for w in words]
    # The last PE sees the slots 8+2 cycles later (InReg: 8+1+8+2).
    await arr.play(slots + [(0, 0)] * (16 + 9 * IN_REG))
    want_di, want_i = TABLE_7_5_COMPENSATED if bug else (
        ["000.000000", "000.800000", "001.000000", "001.800000", "002.000000",
         "002.800000", "003.000000", "003.800000", "004.000000"],
        ["000.000000", "000.000000", "000.800000", "001.800000", "003.000000",
         "005.000000", "007.800000", "00a.800000", "00e.000000"])
    pos = dict(zip([n for n, _ in st.DBG_FIELDS], _field_pos()))
    for q in range(9):
        dbg = arr.pe_dbg(q)
        a = (dbg >> pos["A"][0]) & isa.WORD_MASK
        b = (dbg >> pos["B"][0]) & isa.WORD_MASK
        assert isa.format_fixed(b)[2:] == want_di[q], f"PE {q} dI {isa.format_fixed(b)}"
        assert isa.format_fixed(a)[2:] == want_i[q], f"PE {q} I {isa.format_fixed(a)}"


@cocotb.test()
async def bypass_equals_smaller_array(dut):
    """With faulty PEs (and random others) bypassed, the array equals a smaller one."""
    faulty = set(FAULTY) if int(os.environ.get("DE_FAULTY", "0")) else set()
    arr = await start(dut)
    rng = random.Random(seed())
    bypass = faulty | {q for q in range(arr.n) if rng.random() < 0.25}
    await arr.configure(bypass)
    width = arr.n - len(bypass)
    cmds = randgen.stream(rng.randrange(1 << 30), 600, width, (1, 15))
    # The array still has n_pe PEs on the bus; the first `width` pixels of a line are
    # the remaining PEs' and the rest never come (bypassed PEs drive no pixel).
    await arr.play(spaced(isa.serialise(cmds), arr.n))
    got = np.array(arr.pixels, dtype=np.uint16).reshape(-1, width)
    np.testing.assert_array_equal(got, functional.render(cmds, width, carry_bug=carry_bug(dut)))
    # The bypass is registered (docs/array.md): the pixels of a line still leave without
    # a gap, one clock later per bypassed PE than from an array without bypass.
    want_lat = pixel_latency(arr.k) + len(bypass)
    for line, r in enumerate(arr.refresh_edges):
        edges = arr.pixel_edges[line * width:(line + 1) * width]
        assert edges == list(range(edges[0], edges[0] + width)), f"line {line}: gaps {edges}"
        assert edges[0] - r == want_lat, f"line {line}: latency {edges[0] - r}, want {want_lat}"
    dut._log.info(f"bypassed {sorted(bypass)}: {got.shape[0]} lines equal a {width}-PE array, "
                  f"latency {want_lat} clocks")


# ---- pytest runners: one build folder per parameter set --------------------------------

RUNS = [  # (chips, carry_bug, faulty, in_reg)
    (1, 0, 0, 0), (2, 0, 0, 0), (2, 1, 0, 0), (2, 0, 1, 0),
    # InReg: the chip the FPGA flow builds (each PE's input registered).
    (2, 0, 0, 1), (2, 1, 1, 1),
]


@pytest.mark.parametrize("chips,bug,faulty,in_reg", RUNS,
                         ids=[f"chips{c}_bug{b}_faulty{f}" + ("_inreg" if r else "")
                              for c, b, f, r in RUNS])
def test_de_array(chips, bug, faulty, in_reg):
    from common.run import build_and_test, rtl_files
    here = Path(__file__).resolve().parent
    srcs = rtl_files("array", "sim")
    mask = sum(1 << q for q in FAULTY) if faulty else 0
    params = {"NumChips": chips, "CarryBug": bug}
    if faulty:
        params["FaultMask"] = mask
    if in_reg:
        params["InReg"] = 1
    build_and_test(here, "de_array", srcs, "test_de_array", parameters=params,
                   extra_env={"DE_CARRY_BUG": str(bug), "DE_FAULTY": str(faulty),
                              "DE_IN_REG": str(in_reg)},
                   testcase="bypass_equals_smaller_array" if faulty else None)
