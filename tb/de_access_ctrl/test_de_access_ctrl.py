"""cocotb tests for rtl/ctrl/de_access_ctrl.sv (+ de_video_timing.sv).

* test_timing_modes: Refresh period, hsync/vsync/de widths, periods and offsets exact
  to the clock for every mode (full frames of 640x480, 640x485, 1280x1024 and the test
  mode), and de aligned ArrayLatency cycles after each active line's Refresh.
* test_fair_rr: with 1..NumBuf backlogged buffers the grant rotates exactly.
* test_random_vs_model: random y-processor traffic (underload and overload) against a
  cycle-exact Python model of the controller: bus contents, grants, discards, late
  flags, ready strobes. The underload regime stays within HTotal - 2 slots a line and
  must have no late buffer and no drop.
* test_line_capacity: a line of HTotal - 2 command slots over all buffers is on time,
  one of HTotal - 1 makes exactly one buffer late (its marker misses the window).

The seed is printed; SEED=<n> replays.
"""

from __future__ import annotations

import os
import random
import sys
from collections import deque
from pathlib import Path

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge
from cocotb.utils import get_sim_time

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT / "sw"))
from diffengine import isa  # noqa: E402

W = isa.WORD_BITS
REFRESH = isa.REFRESH << W
MARKER = isa.REFRESH << W
TEST_MODE = dict(ha=16, hfp=2, hs=3, hbp=3, va=6, vfp=1, vs=2, vbp=2, hpol=0, vpol=0)
# The fixed modes from spec/video.toml (isa.VIDEO_MODES), the test mode from this build.
MODES = {i: dict(zip(("ha", "hfp", "hs", "hbp"), h)) | dict(zip(("va", "vfp", "vs", "vbp"), v))
         | dict(hpol=int(hp), vpol=int(vp)) for i, (_, h, v, hp, vp) in isa.VIDEO_MODES.items()}
MODES[isa.VIDEO_MODE_TEST] = TEST_MODE
PERIOD_NS = 10


def totals(m):
    return m["ha"] + m["hfp"] + m["hs"] + m["hbp"], m["va"] + m["vfp"] + m["vs"] + m["vbp"]


def get_seed() -> int:
    return int(os.environ.get("SEED", random.randrange(1 << 31)))


def now() -> int:
    return int(get_sim_time("ns")) // PERIOD_NS


def start_clock(dut):
    """Start the clock; return NumBuf and the test mode's totals (HTotal, VTotal)."""
    cocotb.start_soon(Clock(dut.clk_i, PERIOD_NS, unit="ns").start())
    return int(dut.NumBuf.value), *totals(TEST_MODE)


async def reset(dut, mode: int):
    from common.run import hold_reset
    await hold_reset(dut, 3, falling=False, mode_i=mode, buf_valid_i=0, buf_data_i=0)


async def edges(sig, rises: list, falls: list):
    async def one(trig, out):
        while True:
            await trig(sig)
            out.append(now())
    cocotb.start_soon(one(FallingEdge, falls))
    await one(RisingEdge, rises)


@cocotb.test()
async def test_timing_modes(dut):
    """Sync/blank/Refresh timing exact for every mode (full frames)."""
    cocotb.start_soon(Clock(dut.clk_i, PERIOD_NS, unit="ns").start())
    lat = int(dut.ArrayLatency.value)
    modes = [0, 1, 2, 3] if os.environ.get("DE_ALL_MODES", "1") == "1" else [3]
    for mode in modes:
        m = MODES[mode]
        ht, vt = totals(m)
        await reset(dut, mode)
        rec = {k: ([], []) for k in ("hs", "vs", "de", "rf", "ra")}
        tasks = [cocotb.start_soon(edges(dut.hsync_o, *rec["hs"])),
                 cocotb.start_soon(edges(dut.vsync_o, *rec["vs"])),
                 cocotb.start_soon(edges(dut.de_o, *rec["de"])),
                 cocotb.start_soon(edges(dut.ev_refresh_o, *rec["rf"])),
                 cocotb.start_soon(edges(dut.ev_line_active_o, *rec["ra"]))]
        # Reset lands on the first blank line: run the blank (with the first vsync), one
        # full frame (with the second vsync) and a few lines.
        await ClockCycles(dut.clk_i, (vt - m["va"]) * ht + vt * ht + 3 * ht)
        for t in tasks:
            t.cancel()
        # Active-level pulse lists (polarity-aware).
        hs_on, hs_off = rec["hs"] if m["hpol"] else rec["hs"][::-1]
        vs_on, vs_off = rec["vs"] if m["vpol"] else rec["vs"][::-1]
        de_on, de_off = rec["de"]
        rf_on, _ = rec["rf"]
        ra_on, _ = rec["ra"]
        # Refresh: one per line, exactly ht apart.
        gaps = {b - a for a, b in zip(rf_on, rf_on[1:])}
        assert gaps == {ht}, f"mode {mode}: Refresh gaps {gaps}"
        assert len(rf_on) >= vt
        # de: ha wide, one per active line, each ArrayLatency after its line's Refresh.
        assert len(de_on) == m["va"] + 3
        assert {f - r for r, f in zip(de_on, de_off)} == {m["ha"]}, f"mode {mode}: de width"
        assert [r + lat for r in ra_on[:len(de_on)]] == de_on[:len(ra_on)], \
            f"mode {mode}: de not aligned with Refresh + ArrayLatency"
        # hsync: width hs, period ht, starts ha + hfp after de rises.
        hs_on = [t for t in hs_on if t > de_on[0]]
        hs_off = [t for t in hs_off if t > hs_on[0]]
        assert {f - r for r, f in zip(hs_on, hs_off)} == {m["hs"]}, f"mode {mode}: hsync width"
        assert {b - a for a, b in zip(hs_on, hs_on[1:])} == {ht}
        assert hs_on[0] - de_on[0] == m["ha"] + m["hfp"]
        # vsync: width vs lines, period vt lines, starts va + vfp lines after line 0.
        vs_off = [t for t in vs_off if t > vs_on[0]]
        assert {f - r for r, f in zip(vs_on, vs_off)} == {m["vs"] * ht}
        assert len(vs_on) == 2 and vs_on[1] - vs_on[0] == vt * ht
        assert vs_on[1] - de_on[0] == (m["va"] + m["vfp"]) * ht
        # Active lines per frame.
        frame = [t for t in de_on if de_on[0] <= t < de_on[0] + vt * ht]
        assert len(frame) == m["va"]
        dut._log.info("mode %d (%dx%d, totals %dx%d): Refresh every %d cycles, timing exact",
                      mode, m["ha"], m["va"], ht, vt, ht)


# ---------------------------------------------------------------------------------------
# Cycle-exact reference model of the controller's bus logic (docs/display-controller.md).

def is_start(w):
    # A command starts with a slot of no DATA / ACC class bit.
    return (w >> W) & (isa.ID_DATA | isa.ID_ACC) == 0


def is_marker(w):
    return (w >> W) == isa.REFRESH


class Model:
    def __init__(self, nb, m, skip_max=255):
        self.nb = nb
        self.ht, self.vt = totals(m)
        self.va = m["va"]
        self.h, self.v = 0, self.va
        self.owner = 0
        self.done = [0] * nb
        self.skip = [0] * nb
        self.skip_max = skip_max

    def step(self, bufs):
        """One clock: returns (ready vector, registered outputs) and pops bufs."""
        nb = self.nb
        line_start = self.h == 0
        nl = 0 if self.v == self.vt - 1 else self.v + 1
        win = (not line_start) and nl < self.va
        valid = [len(b) > 0 for b in bufs]
        head = [b[0] if b else 0 for b in bufs]
        start = [is_start(w) for w in head]
        mark = [is_marker(w) for w in head]
        skipping = [s > 0 for s in self.skip]
        elig = [valid[i] and start[i] and not mark[i] and not self.done[i] and not skipping[i]
                for i in range(nb)]
        o = self.owner
        cont = valid[o] and not start[o] and not self.done[o] and not skipping[o]
        issue, sel = False, o
        if win:
            if cont:
                issue = True
            else:
                for k in range(1, nb + 1):
                    idx = (o + k) % nb
                    if elig[idx]:
                        issue, sel = True, idx
                        break
                self.owner = sel
        ready = [0] * nb
        drop = [0] * nb
        late = [0] * nb
        new_done = list(self.done)
        new_skip = list(self.skip)
        for i in range(nb):
            mk = win and valid[i] and mark[i] and not self.done[i] and not skipping[i]
            if mk:
                new_done[i] = 1
            if skipping[i] and valid[i]:
                if mark[i]:
                    new_skip[i] -= 1
                else:
                    drop[i] = 1
            if line_start:
                if self.v < self.va and not self.done[i]:
                    late[i] = 1
                    new_skip[i] = min(new_skip[i] + 1, self.skip_max)
                new_done[i] = 0
            ready[i] = int((issue and sel == i) or mk or skipping[i])
        instr = REFRESH if line_start else (head[sel] if issue else 0)
        for i in range(nb):
            if ready[i] and valid[i]:
                bufs[i].popleft()
        out = dict(instr=instr, grant=(1 << sel) if issue else 0,
                   drop=sum(b << i for i, b in enumerate(drop)),
                   ev_late=sum(b << i for i, b in enumerate(late)),
                   ev_issue=int(issue), ev_free=int(win and not issue),
                   ev_refresh=int(line_start),
                   ev_line_active=int(line_start and self.v < self.va),
                   window=int(win), line=nl)
        self.done, self.skip = new_done, new_skip
        out["late"] = sum((s > 0) << i for i, s in enumerate(self.skip))
        out["done"] = sum(d << i for i, d in enumerate(self.done))
        if self.h == self.ht - 1:
            self.h = 0
            self.v = 0 if self.v == self.vt - 1 else self.v + 1
        else:
            self.h += 1
        return ready, out


def make_cmd(rng, max_len=5):
    n = rng.choice([1, 1, 2, 3, 4, 5][:max_len])
    if n == 1:
        return [(rng.choice([isa.ADDR_EVAL0, isa.ADDR_DIS, isa.ACCMODE_ON]) << W)
                | rng.getrandbits(W)]
    ids = [isa.ADDR_RANGE] + [rng.choice([isa.D_A, isa.D_B, isa.D_B_C]) for _ in range(n - 2)] \
        + [isa.ACC]
    return [(i << W) | rng.getrandbits(W) for i in ids]


async def run_vs_model(dut, rng, n_cycles, feed_p, cmds_per_line, pre_lines=0,
                       line_budget=None):
    """Drive Python buffers fed with whole commands; compare DUT with Model every cycle.
    line_budget: at most this many command slots per active line summed over all buffers
    (a drawn command that would pass it is left out of the line)."""
    nb = int(dut.NumBuf.value)
    bufs = [deque() for _ in range(nb)]
    # Per-buffer y-processor: list of pending commands (lists of words), lines end in a
    # marker command.
    pending = [deque() for _ in range(nb)]
    n_lines = [0] * nb       # lines generated so far, per buffer
    used = {}                # active line index -> command slots given to it so far

    def new_line(i):
        k = n_lines[i]
        n_lines[i] += 1
        for _ in range(rng.randint(*cmds_per_line)):
            cmd = make_cmd(rng)
            if line_budget is not None:
                if used.get(k, 0) + len(cmd) > line_budget:
                    continue
                used[k] = used.get(k, 0) + len(cmd)
            pending[i].append(cmd)
        pending[i].append([MARKER | rng.getrandbits(12)])

    for i in range(nb):
        for _ in range(pre_lines):
            new_line(i)
            while pending[i]:
                bufs[i].extend(pending[i].popleft())

    def feed():
        for i in range(nb):
            if not pending[i]:
                new_line(i)
            if rng.random() < feed_p:
                bufs[i].extend(pending[i].popleft())

    return await drive_vs_model(dut, bufs, n_cycles, feed)


async def drive_vs_model(dut, bufs, n_cycles, feed=None):
    """Reset to the test mode, then drive `bufs` (one deque of words per buffer; `feed()`
    tops them up before every cycle) and compare every output with Model each cycle."""
    nb = int(dut.NumBuf.value)
    await reset(dut, 3)
    model = Model(nb, TEST_MODE)
    exp = None
    log = []
    for _ in range(n_cycles):
        if feed is not None:
            feed()
        dut.buf_valid_i.value = sum((len(b) > 0) << i for i, b in enumerate(bufs))
        dut.buf_data_i.value = sum((b[0] if b else 0) << (48 * i) for i, b in enumerate(bufs))
        await ReadOnly()
        if exp is not None:
            got = dict(instr=dut.instr_o.value.to_unsigned(),
                       grant=dut.grant_o.value.to_unsigned(),
                       drop=dut.drop_o.value.to_unsigned(),
                       ev_late=dut.ev_late_o.value.to_unsigned(),
                       ev_issue=int(dut.ev_issue_o.value),
                       ev_free=int(dut.ev_free_o.value),
                       ev_refresh=int(dut.ev_refresh_o.value),
                       ev_line_active=int(dut.ev_line_active_o.value),
                       window=int(dut.window_o.value),
                       line=dut.line_o.value.to_unsigned(),
                       late=dut.late_o.value.to_unsigned(),
                       done=dut.done_o.value.to_unsigned())
            assert got == exp, f"cycle {now()}: DUT {got} != model {exp}"
            log.append(got)
        ready, exp = model.step(bufs)
        assert dut.buf_ready_o.value.to_unsigned() == sum(r << i for i, r in enumerate(ready))
        await RisingEdge(dut.clk_i)
    dut.buf_valid_i.value = 0
    return log


@cocotb.test()
async def test_fair_rr(dut):
    """1..NumBuf backlogged buffers: the grant rotates one command at a time."""
    nb, ht, vt = start_clock(dut)
    for n_active in range(1, nb + 1):
        for cmd_len in (1, 3):
            await reset(dut, 3)
            active = sorted(random.Random(n_active).sample(range(nb), n_active))
            # Every active buffer holds 40 commands then its marker (overload).
            bufs = {i: deque() for i in active}
            for i in active:
                ids = [isa.ADDR_EVAL0] if cmd_len == 1 else [isa.ADDR_RANGE, isa.D_A, isa.ACC]
                for c in range(40):
                    for ident in ids:
                        bufs[i].append((ident << W) | (i << 8) | c)
                bufs[i].append(MARKER)
            grants = []
            for _ in range((vt - TEST_MODE["va"]) * ht + 2):
                dut.buf_valid_i.value = sum(1 << i for i in active if bufs[i])
                dut.buf_data_i.value = sum(bufs[i][0] << (48 * i) for i in active if bufs[i])
                await ReadOnly()
                rdy = dut.buf_ready_o.value.to_unsigned()
                g = dut.grant_o.value.to_unsigned()
                if g:
                    grants.append(g.bit_length() - 1)
                for i in active:
                    if rdy >> i & 1 and bufs[i]:
                        bufs[i].popleft()
                await RisingEdge(dut.clk_i)
            # The first active window has ht - 1 slots, all granted (overload).
            assert len(grants) == ht - 1, grants
            first = active.index(grants[0])
            expect = [active[(first + k // cmd_len) % n_active] for k in range(ht - 1)]
            assert grants == expect, f"{n_active} active, cmd_len {cmd_len}: {grants}"
            # After reset the owner is 0: the first grant goes to the first active buffer
            # after 0 (or 0 itself when it is the only one).
            after0 = [i for i in active if i > 0] + [i for i in active if i == 0]
            assert grants[0] == after0[0]
    dut._log.info("round-robin exact for 1..%d buffers", nb)


@cocotb.test()
async def test_random_vs_model(dut):
    """Random traffic, underload and overload, cycle-exact against the model."""
    nb, ht, vt = start_clock(dut)
    seed = get_seed()
    dut._log.info("SEED=%d (set SEED=%d to replay)", seed, seed)
    frames = 6
    stats = []
    # (feed probability per cycle, offered load in windows, lines preloaded); a command
    # averages 2.5 slots, so load L means about L * (ht - 1) / 2.5 commands per line.
    # Regime 0 is underload by construction, not just on average: the draw is up to
    # cpl[1] commands of up to 5 slots per buffer and line (40 slots for NumBuf 8, about
    # 1 seed in 60 drew a line over the window), so its lines get a budget of
    # HTotal - 2 slots over all buffers, the most a window can carry with every marker
    # delivered in it (docs/display-controller.md §2.1; test_line_capacity). Its feed
    # (p = 0.5 a cycle, two lines preloaded, at most two items a line consumed against
    # about 12 fed) keeps every buffer lines ahead, so no buffer can be late there.
    for k, (feed_p, load, pre) in enumerate([(0.5, 0.4, 2), (0.9, 1.6, 1),
                                             (0.05, 0.6, 0), (1.0, 3.0, 3)]):
        rng = random.Random(seed + k)
        per_buf = load * (ht - 1) / 2.5 / nb
        cpl = (0, max(1, round(2 * per_buf)))
        log = await run_vs_model(dut, rng, frames * vt * ht, feed_p, cpl, pre,
                                 line_budget=ht - 2 if k == 0 else None)
        issued = sum(g["ev_issue"] for g in log)
        drops = sum(bin(g["drop"]).count("1") for g in log)
        lates = sum(bin(g["ev_late"]).count("1") for g in log)
        stats.append((issued, drops, lates))
        dut._log.info("regime %d: issued %d, dropped %d, late buffer-lines %d",
                      k, issued, drops, lates)
    assert stats[3][1] > 0, "overload (discard) never exercised"
    assert all(s[0] > 0 for s in stats), "a regime issued nothing"
    assert stats[0][1] == 0, "underload regime dropped instructions"
    assert stats[0][2] == 0, "a buffer was late in the underload regime"


def _line_stream(nb, lens, owners):
    """Buffers holding active line 0 (commands of `lens` slots, command j in buffer
    owners[j]) and then empty lines 1..5 (markers only)."""
    bufs = [deque() for _ in range(nb)]
    for j, (n, i) in enumerate(zip(lens, owners)):
        if n == 1:
            bufs[i].append((isa.ADDR_EVAL0 << W) | j)
        else:
            ids = [isa.ADDR_RANGE] + [isa.D_A] * (n - 2) + [isa.ACC]
            bufs[i].extend((ident << W) | j for ident in ids)
    for i in range(nb):
        bufs[i].extend([MARKER] * TEST_MODE["va"])
    return bufs


@cocotb.test()
async def test_line_capacity(dut):
    """A window takes HTotal - 2 command slots on time over all buffers, not HTotal - 1."""
    nb, ht, vt = start_clock(dut)
    # The blank lines (line 0's window is the last one's), then lines 0..5: one frame.
    n_cycles = vt * ht + 2
    # One-slot commands spread over the buffers, and a mix ending in a 5-slot command.
    mixes = {"1-slot": lambda total: [1] * total,
             "mixed": lambda total: [3, 2, 4, 1] * ((total - 5) // 10)
             + [1] * ((total - 5) % 10) + [5]}
    for name, mix in mixes.items():
        for total, late_expected in ((ht - 2, 0), (ht - 1, 1)):
            lens = mix(total)
            assert sum(lens) == total
            bufs = _line_stream(nb, lens, [j % nb for j in range(len(lens))])
            log = await drive_vs_model(dut, bufs, n_cycles)
            issued = sum(g["ev_issue"] for g in log)
            lates = sum(bin(g["ev_late"]).count("1") for g in log)
            drops = sum(bin(g["drop"]).count("1") for g in log)
            assert issued == total, f"{name}, {total} slots: issued {issued}"
            # Late with HTotal - 1: the bus is busy in every slot of the window, so the
            # buffer whose command takes the last slot has its marker at the head only
            # at the Refresh; nothing else of its line is left, so only that marker is
            # discarded and no word is dropped.
            assert lates == late_expected, f"{name}, {total} slots: {lates} late buffers"
            assert drops == 0, f"{name}, {total} slots: {drops} dropped"
            assert all(not b for b in bufs), f"{name}, {total} slots: buffers not drained"
    dut._log.info("line capacity HTotal - 2 = %d slots on time, HTotal - 1 late (%d buffers)",
                  ht - 2, nb)


def _build_and_run(num_buf: int, latency: int, all_modes: bool):
    from common.run import build_and_test, rtl_files

    seed = get_seed()
    print(f"de_access_ctrl NumBuf={num_buf} ArrayLatency={latency} SEED={seed}")
    build_and_test(HERE, "de_access_ctrl", rtl_files("display_core", "access_ctrl"),
                   "test_de_access_ctrl", {"NumBuf": num_buf, "ArrayLatency": latency},
                   {"SEED": str(seed), "DE_ALL_MODES": "1" if all_modes else "0"}, lint=True)


@pytest.mark.parametrize("num_buf,latency,all_modes", [(8, 3, True), (3, 0, False),
                                                       (1, 5, False)])
def test_de_access_ctrl(num_buf, latency, all_modes):
    _build_and_run(num_buf, latency, all_modes)
