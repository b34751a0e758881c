"""cocotb tests for rtl/ctrl/de_load_monitor.sv (the Load Monitor).

Random Access-Controller event streams (underload and heavy overload: late buffers and
discards every line) drive the monitor; a Python model of the counters gives the exact
expected value of every register, which is read back through the host port after each
frame (snapshot, histogram, per-line table, cumulative counters). The seed is printed;
SEED=<n> replays.
"""

from __future__ import annotations

import os
import random
from pathlib import Path

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge

from diffengine import isa

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent

HT, VA, VT = 24, 6, 11  # the test mode of de_video_timing
MAGIC_LSB = 24          # the ID register: the magic in ID[31:24] (docs/display-controller.md §6)


def get_seed() -> int:
    return int(os.environ.get("SEED", random.randrange(1 << 31)))


class Model:
    def __init__(self, nb, bins, shift):
        self.nb, self.bins, self.shift = nb, bins, shift
        self.ln_issued = self.ln_free = 0
        self.live = self._zero()
        self.snap = self._zero()
        self.frames = self.tot_drop = self.tot_late = 0
        self.last_line = self.last_rec = 0
        self.lines = {}

    def _zero(self):
        return dict(issued=0, free=0, drop=0, late=0, max=0, hist=[0] * self.bins)

    def cycle(self, refresh, active, line, last, late, issue, free, drop):
        n_drop = bin(drop).count("1")
        self.live["drop"] += n_drop
        self.tot_drop += n_drop
        if refresh and active:
            n_late = bin(late).count("1")
            # the line record (de_load_monitor.sv), not a data word
            rec = ((int(n_late > 0) << 31) | (n_late << 24)  # isa-literal-ok
                   | (self.ln_free << 12) | self.ln_issued)
            self.live["issued"] += self.ln_issued
            self.live["free"] += self.ln_free
            self.live["late"] += int(n_late > 0)
            self.tot_late += int(n_late > 0)
            self.live["max"] = max(self.live["max"], self.ln_issued)
            self.live["hist"][min(self.ln_issued >> self.shift, self.bins - 1)] += 1
            self.last_line, self.last_rec = line, rec
            self.lines[line] = rec
        if last:
            self.snap = self.live
            self.live = self._zero()
            self.frames += 1
        if refresh:
            self.ln_issued = self.ln_free = 0
        else:
            self.ln_issued += issue
            self.ln_free += free

    def regs(self):
        r = {1: self.frames, 2: self.snap["issued"], 3: self.snap["free"],
             4: self.snap["late"], 5: self.snap["drop"], 6: self.snap["max"],
             7: self.last_line, 8: self.last_rec, 9: self.tot_drop, 10: self.tot_late}
        for b in range(self.bins):
            r[0x40 + b] = self.snap["hist"][b]
        for ln, rec in self.lines.items():
            r[0x400 + ln] = rec
        return r


async def read_reg(dut, addr):
    dut.reg_addr_i.value = addr
    await RisingEdge(dut.clk_i)
    await ReadOnly()
    v = dut.reg_rdata_o.value.to_unsigned()
    await RisingEdge(dut.clk_i)
    return v


@cocotb.test()
async def test_counts_under_overload(dut):
    """Random underload/overload frames: every register exact."""
    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    seed = get_seed()
    dut._log.info("SEED=%d (set SEED=%d to replay)", seed, seed)
    rng = random.Random(seed)
    nb = int(dut.NumBuf.value)
    bins = int(dut.NumBins.value)
    shift = int(dut.BinShift.value)
    ev = ["ev_refresh_i", "ev_line_active_i", "ev_line_i", "ev_last_line_i", "ev_late_i",
          "ev_issue_i", "ev_free_i", "drop_i"]
    from common.run import hold_reset
    await hold_reset(dut, 3, falling=False, reg_addr_i=0, **dict.fromkeys(ev, 0))
    assert await read_reg(dut, isa.LM_REG_ID) == \
        (isa.LM_ID_MAGIC << MAGIC_LSB) | (bins << 16) | (shift << 12) | (nb << 8) | 1
    model = Model(nb, bins, shift)
    full = (1 << nb) - 1
    # (issue probability, late probability per buffer, drop probability per buffer)
    regimes = [(0.3, 0.0, 0.0), (1.0, 0.7, 0.5), (0.8, 0.2, 0.1), (0.0, 0.0, 0.0),
               (1.0, 1.0, 1.0)]
    v = VA  # like the controller: start at the first blank line
    for frame in range(10):
        p_issue, p_late, p_drop = regimes[frame % len(regimes)]
        for _ in range(VT):
            for h in range(HT):
                refresh = h == 0
                active = refresh and v < VA
                nxt = 0 if v == VT - 1 else v + 1
                win = not refresh and nxt < VA
                issue = int(win and rng.random() < p_issue)
                free = int(win and not issue)
                late = sum(int(rng.random() < p_late) << i for i in range(nb)) if active else 0
                drop = sum(int(rng.random() < p_drop) << i for i in range(nb)) & full
                last = int(refresh and v == VA - 1)
                vals = dict(ev_refresh_i=int(refresh), ev_line_active_i=int(active),
                            ev_line_i=v, ev_last_line_i=last, ev_late_i=late,
                            ev_issue_i=issue, ev_free_i=free, drop_i=drop)
                for k, x in vals.items():
                    getattr(dut, k).value = x
                model.cycle(int(refresh), int(active), v, last, late, issue, free, drop)
                dut.reg_addr_i.value = rng.choice([1, 2, 5, 8, 0x400, 0x40])
                await RisingEdge(dut.clk_i)
                if h == HT - 1:
                    v = nxt
        # Quiesce the events and read everything back.
        for name in ev:
            getattr(dut, name).value = 0
        for addr, want in sorted(model.regs().items()):
            got = await read_reg(dut, addr)
            assert got == want, f"frame {frame}: reg 0x{addr:03x} = {got:#x}, model {want:#x}"
        dut._log.info("frame %d: snapshot issued=%d free=%d late_lines=%d dropped=%d max=%d",
                      frame, model.snap["issued"], model.snap["free"], model.snap["late"],
                      model.snap["drop"], model.snap["max"])
    # Overload really happened and issued + free = window size for every active line.
    assert model.tot_drop > 0 and model.tot_late > 0
    for rec in model.lines.values():
        assert (rec & 0xFFF) + ((rec >> 12) & 0xFFF) == HT - 1


def _build_and_run(nb: int, bins: int, shift: int):
    from common.run import build_and_test, rtl_files

    seed = get_seed()
    print(f"de_load_monitor NumBuf={nb} NumBins={bins} BinShift={shift} SEED={seed}")
    params = {"NumBuf": nb, "NumBins": bins, "BinShift": shift, "MaxLines": 16}
    # rtl/ctrl/de_display_core.core
    build_and_test(HERE, "de_load_monitor", rtl_files("display_core", "load_monitor"),
                   "test_de_load_monitor", params, {"SEED": str(seed)}, lint=True)


@pytest.mark.parametrize("nb,bins,shift", [(8, 5, 2), (1, 3, 3)])
def test_de_load_monitor(nb, bins, shift):
    _build_and_run(nb, bins, shift)
