"""End-to-end cocotb tests for rtl/ctrl/display_controller.sv (full colour).

K y-processors per colour write random command streams (sw/diffengine randgen, one
stream per y-processor and colour, a marker after every line) through the write ports
with random stalls; the controller runs the small test video mode with arrays of one or
two chips. Checks:

* bus legality per colour: every word on an instruction bus comes from the buffer that
  holds the grant, commands are contiguous and whole (a command may only be cut by the
  Refresh), and what a buffer issues in the window of active line n is a prefix of its
  y-processor's line n (all of it when the buffer was done, i.e. not late);
* pixels: the RGB output sampled where blank is low equals, bit for bit,
  functional.render() of the complete commands issued in each line's window, in issue
  order (the interleaving of K y-processors is decided by the arbiter, so it is taken
  from the bus; its legality is the check above); the 8-bit window likewise;
* alignment: blank low exactly while the arrays show columns 0..HActive-1 (array
  pixel_valid one output register earlier), hsync/vsync at their exact offsets,
  align_err_o never set;
* Load Monitor read-out (host port, all three channels): every line record, the frame
  snapshot, the histogram and the totals equal what was observed on the buses, and
  TOTAL_DROPPED equals the words the y-processors wrote that never reached a bus.

test_frame_underload asserts that no line was late; test_frame_overload has lines that
need up to ~3x the window and asserts late lines and discards. Both print the bus
utilisation (non-Nop slots / window slots of active lines). SEED=<n> replays.
"""
from __future__ import annotations

import os
import random
import sys
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE.parent.parent / "sw"))

from diffengine.model import functional  # noqa: E402
from diffengine import isa
from diffengine.regress import randgen

NCH = 3
REFRESH_ID = isa.REFRESH
MASK48 = (1 << isa.RECORD_BITS) - 1
WB = isa.WORD_BITS          # a record is {identifier, data}: the identifier above bit WB
MAGIC_LSB = 24              # ID registers: the magic in ID[31:24] (docs/display-controller.md §6)


def reg_addr(ch: int, reg: int) -> int:
    """Host address of register `reg` of channel `ch` (spec/regs.toml)."""
    return (ch << isa.REG_CHAN_LSB) | reg


def geom(dut):
    g = {k: int(getattr(dut, k).value) for k in ("NumBuf", "NumChips", "CarryBug",
                                                 "BufDepth")}
    g.update(isa.video_mode_fields(int(dut.TestMode.value)))
    g["n_pe"] = 9 * g["NumChips"]
    g["SpanArray"] = int(dut.SpanArray.value)
    g["InReg"] = int(dut.InReg.value)
    # docs/array.md, "Pixel timing": NumChips + 3; with InReg (each PE's input
    # registered) 10 NumChips + 4.
    g["ArrayLatency"] = (int(dut.SpanLatency.value) if g["SpanArray"]
                         else 10 * g["NumChips"] + 4 if g["InReg"] else g["NumChips"] + 3)
    return g


def words_of(cmds) -> list[int]:
    return [(i << WB) | d for i, d in isa.serialise(cmds)]


def is_start(w: int) -> bool:
    return ((w >> WB) & (isa.ID_DATA | isa.ID_ACC)) == 0   # de_pkg::id_starts_cmd


def make_streams(seed: int, g: dict, n_lines: int, per_line, max_words: int | None):
    """streams[c][i] = list of n_lines lines, each a list of commands (no Refresh)."""
    streams = []
    for c in range(NCH):
        chan = []
        for i in range(g["NumBuf"]):
            lines = []
            rng = random.Random(seed * 131 + c * 17 + i)
            while len(lines) < n_lines:
                ln = [cm for cm in randgen.stream(rng.randrange(1 << 30), 1, g["n_pe"],
                                                  per_line) if cm.op != "REFRESH"]
                if max_words is not None:
                    while ln and len(words_of(ln)) > max_words:
                        ln.pop()
                lines.append(ln)
            chan.append(lines)
        streams.append(chan)
    return streams


class Bench:
    """Drivers (one per y-processor and colour) and a cycle sampler.

    skip_late: the y-processor listens to the bus (§7.5): once the Refresh of a line it is
    still writing has gone, it writes only that line's marker instead of the rest (the
    words would be discarded anyway). Otherwise it writes everything.
    """

    def __init__(self, dut, g, streams, stall_p, seed, skip_late=False):
        self.dut, self.g, self.streams = dut, g, streams
        self.rng = random.Random(seed)
        self.stall_p = stall_p
        self.skip_late = skip_late
        nb = g["NumBuf"]
        self.nb = nb
        # Word queues per port: every line's words followed by its marker.
        self.queues, self.line_of, self.marker_at = [], [], []
        for c in range(NCH):
            for i in range(nb):
                q, lo, mk = [], [], []
                for n, ln in enumerate(streams[c][i]):
                    ws = words_of(ln)
                    q += ws + [REFRESH_ID << WB]
                    lo += [n] * (len(ws) + 1)
                    mk.append(len(q) - 1)
                self.queues.append(q)
                self.line_of.append(lo)
                self.marker_at.append(mk)
        self.pos = [0] * (NCH * nb)
        self.cur = [None] * (NCH * nb)   # word being offered (valid held until taken)
        self.cur_line = [0] * (NCH * nb)
        # written[p][n]: words (markers excluded) of line n accepted by the buffer.
        self.written = [[0] * len(streams[0][0]) for _ in range(NCH * nb)]
        self.samples = []
        self.closed = 0                  # active lines whose Refresh has gone
        self.n_refresh = 0
        self.stop = False

    async def drive(self):
        dut, nb = self.dut, self.nb
        while not self.stop:
            await FallingEdge(dut.clk_i)
            ready = int(dut.wr_ready_o.value)
            valid = 0
            data = 0
            for p in range(NCH * nb):
                q = self.queues[p]
                if self.cur[p] is None and self.pos[p] < len(q):
                    n = self.line_of[p][self.pos[p]]
                    if self.skip_late and n < self.closed:
                        self.pos[p] = self.marker_at[p][n]
                    if self.rng.random() >= self.stall_p:
                        self.cur[p] = q[self.pos[p]]
                        self.cur_line[p] = self.line_of[p][self.pos[p]]
                        self.pos[p] += 1
                if self.cur[p] is not None:
                    valid |= 1 << p
                    data |= self.cur[p] << (isa.RECORD_BITS * p)
                    if (ready >> p) & 1:   # ready depends on registers only
                        if (self.cur[p] >> WB) != REFRESH_ID:
                            self.written[p][self.cur_line[p]] += 1
                        self.cur[p] = None
            dut.wr_valid_i.value = valid
            dut.wr_data_i.value = data

    def all_written(self) -> bool:
        return all(self.pos[p] == len(self.queues[p]) and self.cur[p] is None
                   for p in range(NCH * self.nb))

    async def monitor(self):
        dut = self.dut
        core = dut.u_core
        grants = [core.g_ch[c].u_ac.grant_o for c in range(NCH)]
        drops = [core.g_ch[c].u_ac.drop_o for c in range(NCH)]
        while True:
            await RisingEdge(dut.clk_i)
            await ReadOnly()
            if (int(core.instr_o.value) & MASK48) >> WB == REFRESH_ID:
                v = (self.g["TestVActive"] + self.n_refresh) % self.g["VTotal"]
                self.closed += v < self.g["TestVActive"]
                self.n_refresh += 1
            self.samples.append(dict(
                instr=int(core.instr_o.value),
                grant=[int(x.value) for x in grants],
                drop=[int(x.value) for x in drops],
                done=int(dut.done_o.value),
                pv=int(core.pix_valid_i.value),
                rgb=int(dut.rgb_o.value),
                rgb8=int(dut.rgb8_o.value),
                blank=int(dut.blank_o.value),
                hs=int(dut.hsync_o.value),
                vs=int(dut.vsync_o.value),
                err=int(dut.align_err_o.value),
            ))


async def read_reg(dut, addr: int) -> int:
    """One register read per clock; call right after a falling edge."""
    dut.reg_addr_i.value = addr
    await RisingEdge(dut.clk_i)       # address sampled
    await FallingEdge(dut.clk_i)      # data valid one clock later
    return int(dut.reg_rdata_o.value)


def analyse_bus(bench):
    """Per channel: the windows of active lines (in order), each with the words issued per
    buffer, the complete commands in issue order, free/issued counts and late buffers."""
    g, nb = bench.g, bench.nb
    out = []
    refresh_at = []
    for c in range(NCH):
        refresh_at.append([t for t, s in enumerate(bench.samples)
                           if ((s["instr"] >> (isa.RECORD_BITS * c + WB)) & isa.ID_MASK)
                           == REFRESH_ID])
        assert refresh_at[c] == refresh_at[0], "colour channels out of lockstep"
        assert all(b - a == g["HTotal"] for a, b in zip(refresh_at[c], refresh_at[c][1:]))
        wins = []
        k = 0                    # Refresh counter
        cur = dict(words=[], per_buf=[[] for _ in range(nb)], order=[], nops=0)
        prev_owner = None        # buffer of the previous slot's word (None: Nop/Refresh)
        for t, s in enumerate(bench.samples):
            w = (s["instr"] >> (isa.RECORD_BITS * c)) & MASK48
            gr = s["grant"][c]
            if (w >> WB) == REFRESH_ID:
                assert gr == 0, f"ch{c} t={t}: Refresh with a grant"
                # Refresh k is the one of line VActive + k (reset starts in the blank).
                v = (g["TestVActive"] + k) % g["VTotal"]
                if v < g["TestVActive"]:
                    done = (bench.samples[t - 1]["done"] >> (c * nb)) & ((1 << nb) - 1)
                    cur["late"] = [not (done >> i) & 1 for i in range(nb)]
                    cur["line"] = v
                    cur["t"] = t
                    wins.append(cur)
                else:
                    assert not cur["words"], f"ch{c}: words in a blank line's window"
                k += 1
                cur = dict(words=[], per_buf=[[] for _ in range(nb)], order=[], nops=0)
                prev_owner = None
                continue
            if gr == 0:
                assert w == 0, f"ch{c} t={t}: non-Nop {w:012x} without a grant"
                cur["nops"] += 1
                prev_owner = None
                continue
            assert gr & (gr - 1) == 0, f"ch{c} t={t}: grant {gr:b} not one-hot"
            i = gr.bit_length() - 1
            if not is_start(w):
                assert prev_owner == i, f"ch{c} t={t}: continuation slot not contiguous"
            cur["words"].append(w)
            cur["per_buf"][i].append(w)
            cur["order"].append((i, w))
            prev_owner = i
        out.append(wins)
    return out


def commands_in_order(bench, c, n, win):
    """Complete commands of window n in issue order; checks prefixes of the y-lines."""
    nb = bench.nb
    # Split each buffer's issued words into its line's commands.
    expect_cmds = [bench.streams[c][i][n] if n < len(bench.streams[c][i]) else []
                   for i in range(nb)]
    slot_lists = [[words_of([cm]) for cm in expect_cmds[i]] for i in range(nb)]
    for i in range(nb):
        full = [w for sl in slot_lists[i] for w in sl]
        got = win["per_buf"][i]
        assert got == full[:len(got)], f"ch{c} line {n} buf {i}: not a prefix of its line"
        if not win["late"][i]:
            assert got == full, f"ch{c} line {n} buf {i}: done but incomplete"
    # Walk the issue order, consuming whole commands per buffer.
    idx = [0] * nb       # next command per buffer
    fill = [0] * nb      # slots of that command already seen
    order = []
    for i, _w in win["order"]:
        fill[i] += 1
        if fill[i] == len(slot_lists[i][idx[i]]):
            order.append(expect_cmds[i][idx[i]])
            idx[i] += 1
            fill[i] = 0
    return order


def expected_frame(bench, wins):
    """golden[c] = rows of HActive pixels, one per active window, from the model."""
    g = bench.g
    gold = []
    for c in range(NCH):
        rows = []
        for n, win in enumerate(wins[c]):
            cmds = commands_in_order(bench, c, n, win) + [isa.Command("REFRESH")]
            rows.append(functional.render(cmds, g["n_pe"], carry_bug=bool(g["CarryBug"]))
                        [0][:g["TestHActive"]])
        gold.append(np.array(rows, dtype=np.int64))
    return gold


def out8(p: int, w: int, sat: bool) -> int:
    sh = p >> w
    if not sat:
        return sh & 0xFF
    if p >> 11:
        return 0
    return 0xFF if sh > 0xFF else sh


def check_video(bench, gold, w8, sat8):
    g = bench.g
    S = bench.samples
    ha, ht = g["TestHActive"], g["HTotal"]
    rows = [[] for _ in range(NCH)]
    rises = []
    for t, s in enumerate(S):
        assert s["err"] == 0, f"t={t}: align_err_o set"
        if s["blank"] == 0:
            # The output register holds what the arrays showed one cycle earlier.
            assert S[t - 1]["pv"] == 0b111, f"t={t}: blank low but no pixel from an array"
            if S[t - 1]["blank"] == 1:
                rises.append(t)
                assert S[t - 2]["pv"] == 0, f"t={t}: blank falls after column 0"
                for c in range(NCH):
                    rows[c].append([])
            for c in range(NCH):
                p = (s["rgb"] >> (12 * c)) & 0xFFF
                rows[c][-1].append(p)
                assert ((s["rgb8"] >> (8 * c)) & 0xFF) == out8(p, w8, sat8), \
                    f"t={t}: 8-bit window"
        else:
            assert s["rgb"] == 0 and s["rgb8"] == 0, f"t={t}: pixel data while blank"
    if S[-1]["blank"] == 0:           # the simulation ended inside a line
        for c in range(NCH):
            rows[c].pop()
    for c in range(NCH):
        assert all(len(r) == ha for r in rows[c]), \
            f"active lines of the wrong length: {[len(r) for r in rows[c]]}"
    n = min(len(rows[0]), len(gold[0]))
    assert n >= g["TestVActive"] * 2, f"only {n} lines compared"
    for c in range(NCH):
        got = np.array(rows[c][:n], dtype=np.int64)
        bad = np.argwhere(got != gold[c][:n])
        assert bad.size == 0, (f"colour {c}: {len(bad)} pixels differ, first at line/col "
                               f"{bad[0]}: got {got[tuple(bad[0])]} want "
                               f"{gold[c][tuple(bad[0])]}")
    # Sync: active low in the test mode, at exact offsets from the line start.
    for t0 in rises:
        for dt in range(ht):
            if t0 + dt >= len(S):
                break
            hs_on = ha + g["TestHFp"] <= dt < ha + g["TestHFp"] + g["TestHSync"]
            assert S[t0 + dt]["hs"] == (0 if hs_on else 1), f"hsync at line start+{dt}"
    # Line starts are HTotal apart; vsync starts VFp+1 lines after the last active line
    # of a frame and lasts VSync lines.
    va = g["TestVActive"]
    for f in range(len(rises) // va):
        last = rises[(f + 1) * va - 1]
        vs0 = last + (g["TestVFp"] + 1) * ht
        for t in range(last, min(vs0 + (g["TestVSync"] + 1) * ht, len(S))):
            want = 0 if vs0 <= t < vs0 + g["TestVSync"] * ht else 1
            assert S[t]["vs"] == want, f"vsync at t={t}"
    for a, b in zip(rises, rises[1:]):
        assert b - a == ht or b - a == ht * (g["VTotal"] - va + 1)
    return n


async def run_frames(dut, stall_p, per_line, max_words, frames, w8, sat8, overload,
                     skip_late=False):
    seed = int(os.environ.get("SEED", random.randrange(1 << 30)))
    dut._log.info(f"SEED={seed}")
    g = geom(dut)
    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    if g["SpanArray"]:
        # The span-serial arrays' core clock: unrelated phase, ~16.7x (the test lines are
        # short, 24 slots, and the random spans long for them).
        cocotb.start_soon(Clock(dut.clk_core_i, 600, unit="ps").start())
    n_lines = frames * g["TestVActive"]
    streams = make_streams(seed, g, n_lines, per_line, max_words)
    bench = Bench(dut, g, streams, stall_p, seed, skip_late)
    from common.run import hold_reset
    await hold_reset(dut, 3, mode_i=3, wr_valid_i=0, wr_data_i=0, reg_addr_i=0,
                     out8_shift_i=w8, out8_sat_i=int(sat8), cfg_mode_i=0, cfg_bit_i=0,
                     obs_load_i=0, obs_shift_i=0)
    cocotb.start_soon(bench.monitor())
    cocotb.start_soon(bench.drive())
    ht, vt, va = g["HTotal"], g["VTotal"], g["TestVActive"]
    # The last active line of the last frame is refreshed (vt - va) + frames*vt - 1 lines
    # after reset (h = 0 of the first vertical-blank line).
    last_refresh = ((vt - va) + (frames - 1) * vt + va - 1) * ht + 1
    await ClockCycles(dut.clk_i, last_refresh + 2)
    await FallingEdge(dut.clk_i)
    # Snapshot and line table of the last frame: stable through its vertical blank.
    regs = {}
    for c in range(NCH):      # the line table first: line 0 is rewritten after the blank
        for ln in range(va):
            regs[(c, isa.LM_LINE_BASE + ln)] = await read_reg(
                dut, reg_addr(c, isa.LM_LINE_BASE + ln))
    for c in range(NCH):
        for a in range(isa.LM_REG_ID, isa.LM_REG_LAST_REC + 1):
            regs[(c, a)] = await read_reg(dut, reg_addr(c, a))
        for b in range(int(dut.NumBins.value)):
            regs[(c, isa.LM_HIST_BASE + b)] = await read_reg(dut, reg_addr(c, isa.LM_HIST_BASE + b))
    info = await read_reg(dut, reg_addr(isa.REG_INFO_CHAN, isa.CTRL_REG_ID))
    # Let every late line drain before the totals are read.
    for _ in range(40):
        await ClockCycles(dut.clk_i, ht)
        if bench.all_written():
            break
    await ClockCycles(dut.clk_i, 2 * ht)
    await FallingEdge(dut.clk_i)
    assert bench.all_written(), "y-processors could not write everything"
    tot, t_read = {}, {}
    for c in range(NCH):
        tot[(c, isa.LM_REG_TOTAL_DROP)] = await read_reg(dut, reg_addr(c, isa.LM_REG_TOTAL_DROP))
        t_read[c] = len(bench.samples)
        tot[(c, isa.LM_REG_TOTAL_LATE)] = await read_reg(dut, reg_addr(c, isa.LM_REG_TOTAL_LATE))
    bench.stop = True
    all_wins = analyse_bus(bench)
    # The windows whose lines belong to the streams.
    wins = [w[:n_lines] for w in all_wins]
    gold = expected_frame(bench, wins)
    n = check_video(bench, gold, w8, sat8)

    # ---- Load Monitor read-out vs the buses ---------------------------------------
    assert info == ((isa.CTRL_ID_MAGIC << MAGIC_LSB) | (NCH << 20) | (g["NumBuf"] << 16)
                    | g["ArrayLatency"])
    nbins, shift = int(dut.NumBins.value), int(dut.BinShift.value)
    util = []
    total_late_lines = 0
    for c in range(NCH):
        ws = wins[c]
        assert len(ws) == n_lines
        frame = ws[-va:]
        assert regs[(c, isa.LM_REG_ID)] == (isa.LM_ID_MAGIC << MAGIC_LSB) | (nbins << 16) | \
            (shift << 12) | (g["NumBuf"] << 8) | 1
        assert regs[(c, isa.LM_REG_FRAMES)] == frames, f"ch{c}: FRAME_COUNT"
        issued = [len(w["words"]) for w in frame]
        free = [w["nops"] for w in frame]
        late = [sum(w["late"]) for w in frame]
        for w in ws:
            assert len(w["words"]) + w["nops"] == ht - 1, "window length"
        assert regs[(c, isa.LM_REG_ISSUED)] == sum(issued), f"ch{c}: SNAP_ISSUED"
        assert regs[(c, isa.LM_REG_FREE)] == sum(free), f"ch{c}: SNAP_FREE"
        assert regs[(c, isa.LM_REG_LATE)] == sum(1 for x in late if x), f"ch{c}: SNAP_LATE_LINES"
        assert regs[(c, isa.LM_REG_MAX_ISSUED)] == max(issued), f"ch{c}: SNAP_MAX_ISSUED"
        assert regs[(c, isa.LM_REG_LAST_LINE)] == va - 1, f"ch{c}: LAST_LINE"
        hist = [0] * nbins
        for x in issued:
            hist[min(x >> shift, nbins - 1)] += 1
        assert [regs[(c, isa.LM_HIST_BASE + b)] for b in range(nbins)] == hist, f"ch{c}: histogram"
        for ln in range(va):
            # the Load Monitor's line record (de_load_monitor.sv), not a data word
            rec = ((int(late[ln] > 0) << 31) | (late[ln] << 24)  # isa-literal-ok
                   | (free[ln] << 12) | issued[ln])
            assert regs[(c, isa.LM_LINE_BASE + ln)] == rec, f"ch{c}: LINE[{ln}] record"
        assert regs[(c, isa.LM_REG_LAST_REC)] == regs[(c, isa.LM_LINE_BASE + va - 1)], \
            f"ch{c}: LAST_REC"
        # Discards: every word a y-processor wrote for a line but that never reached
        # the bus (markers excluded).
        dropped = 0
        for n_, w in enumerate(ws):
            for i in range(g["NumBuf"]):
                dropped += bench.written[c * g["NumBuf"] + i][n_] - len(w["per_buf"][i])
        dr = tot[(c, isa.LM_REG_TOTAL_DROP)]
        assert dr == dropped, f"ch{c}: TOTAL_DROPPED {dr} != {dropped}"
        # Late lines up to the read, including any after the streams ended.
        lates = sum(1 for w in all_wins[c] if w["t"] < t_read[c] and any(w["late"]))
        assert tot[(c, isa.LM_REG_TOTAL_LATE)] == lates, f"ch{c}: TOTAL_LATE_LINES"
        total_late_lines += sum(1 for w in ws if any(w["late"]))
        per_line = [len(w["words"]) / (ht - 1) for w in ws]
        util.append((sum(per_line) / len(per_line), min(per_line), max(per_line)))
    dut._log.info(f"{n} lines x 3 colours bit-exact; bus utilisation (active windows) "
                  f"R/G/B mean (min..max per line) = "
                  f"{', '.join(f'{u[0]:.3f} ({u[1]:.3f}..{u[2]:.3f})' for u in util)}; late lines "
                  f"{total_late_lines}; dropped words "
                  f"{[tot[(c, isa.LM_REG_TOTAL_DROP)] for c in range(NCH)]}")
    if overload:
        assert total_late_lines > 0 and sum(tot[(c, isa.LM_REG_TOTAL_DROP)] for c in range(NCH)) > 0
    else:
        assert total_late_lines == 0, "underload test had a late line"
    return util


def frames_for(g) -> int:
    # Six frames of the small test modes; two frames when the line is long.
    return 6 if g["HTotal"] < 100 else 2


def overload_per_line(g) -> tuple[int, int]:
    # randgen commands average about 4.5 slots: lines of ~1.3x to ~4x a y-processor's
    # share of the window, ~2.7x on average (at least 2..7 commands).
    hi = max(7, round(4 * (g["HTotal"] - 1) / g["NumBuf"] / 4.5))
    return (hi // 3, hi)


@cocotb.test()
async def test_frame_underload(dut):
    """No line exceeds its window: every command of every y-processor is shown."""
    g = geom(dut)
    per_y = (g["HTotal"] - 1) // g["NumBuf"] - 1
    await run_frames(dut, stall_p=0.25, per_line=(0, 3), max_words=per_y,
                     frames=frames_for(g), w8=2, sat8=True, overload=False)


@cocotb.test()
async def test_frame_overload(dut):
    """Overloaded lines, y-processors that write everything: late lines, discards."""
    g = geom(dut)
    util = await run_frames(dut, stall_p=0.1, per_line=overload_per_line(g),
                            max_words=None, frames=frames_for(g), w8=4, sat8=False,
                            overload=True)
    UTIL["write_all"] = util


@cocotb.test()
async def test_frame_overload_listening(dut):
    """Overloaded lines, y-processors that skip the rest of a line once it is late."""
    g = geom(dut)
    util = await run_frames(dut, stall_p=0.1, per_line=overload_per_line(g),
                            max_words=None, frames=frames_for(g), w8=1, sat8=True,
                            overload=True, skip_late=True)
    UTIL["skip_late"] = util
    out = os.environ.get("DE_UTIL_OUT")
    if out:
        Path(out).parent.mkdir(exist_ok=True)
        Path(out).write_text(repr({k: [tuple(round(x, 4) for x in u) for u in v]
                                   for k, v in UTIL.items()}) + "\n")


UTIL: dict[str, list[float]] = {}


# ---- pytest runner: one build folder per parameter set -------------------------------

RUNS = {
    # 2 chips = 18 PEs >= HActive 16; line 24 slots, frame 11 lines.
    "chips2_bug0": dict(NumChips=2, CarryBug=0, NumBuf=2, BufDepth=32, NumBins=4,
                        BinShift=3, MaxLines=8),
    # 1 chip = 9 PEs: HActive 9, line 17 slots; the carry bug in all three arrays.
    "chips1_bug1": dict(NumChips=1, CarryBug=1, NumBuf=3, BufDepth=16, NumBins=4,
                        BinShift=2, MaxLines=8,
                        TestMode=isa.video_mode_param((9, 2, 3, 3), (6, 1, 2, 2))),
    # Busy frame with 640x480's line: HTotal 800 (window 799 slots), 9 active columns
    # (one chip; the pixels are still checked), 16 active lines, 4 y-processors with the
    # default buffers. Gives the bus-utilisation figure of docs/performance.md.
    "busy800": dict(NumChips=1, CarryBug=0, NumBuf=4, BufDepth=16, NumBins=16,
                    BinShift=7, MaxLines=16,
                    TestMode=isa.video_mode_param((9, 16, 96, 679), (16, 1, 2, 2))),
    # The arrays of the FPGA flow's chip (de_array InReg = 1: each PE's input registered):
    # the same frames, ArrayLatency 24 clocks instead of 5.
    "chips2_bug0_inreg": dict(NumChips=2, CarryBug=0, NumBuf=2, BufDepth=32, NumBins=4,
                              BinShift=3, MaxLines=8, InReg=1),
    # The span-serial array (docs/fpga.md 3) in place of each de_array: 18 columns in
    # block RAM on its own clock, pixels 30 pixel clocks after the Refresh.
    "span_chips2": dict(NumChips=2, CarryBug=0, NumBuf=2, BufDepth=32, NumBins=4,
                        BinShift=3, MaxLines=8, SpanArray=1, SpanLatency=30),
}


@pytest.mark.parametrize("name", list(RUNS))
def test_display_controller(name):
    from common.run import build_and_test, rtl_files
    srcs = rtl_files("display_controller", "sim")
    build_and_test(HERE, "display_controller", srcs, "test_display_controller",
                   parameters=RUNS[name],
                   extra_env={"DE_UTIL_OUT": str(HERE / "sim_build_util" / f"{name}.txt")})
