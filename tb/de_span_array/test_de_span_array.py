"""cocotb bench of the span-serial virtual array rtl/varray/de_span_array.sv.

Driver (valid/ready slot stream, with random idle clocks: the slot rate is below the core
clock) -> monitor (pixel stream with its columns) -> golden model -> in-order checker.
The golden models are the functional one for command streams (functional.render) and
the cycle-level structural one for raw slot streams (structural.Array: every slot of the
19 atomic instructions in any order, orphan data slots included). Every random test
prints its seed; SEED=<n> replays it.
"""
from __future__ import annotations

import os
import random
from fractions import Fraction
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, Timer

from diffengine.formats import asm
from diffengine.model import functional, structural
from diffengine import isa
from diffengine.regress import randgen

SCENES = Path(__file__).resolve().parents[2] / "sw" / "scenes"
ONE = 1 << isa.FRAC_BITS


class Bench:
    """Driver and monitor around one de_span_array."""

    def __init__(self, dut, idle: float = 0.0, seed: int = 0, n: int | None = None):
        self.dut = dut
        self.n = n or int(dut.NumCols.value)   # a netlist has no parameters: give n
        self.idle = idle                 # probability of an idle clock between slots
        self.rng = random.Random(seed)
        self.pixels: list[tuple[int, int]] = []   # (column, pixel) in output order
        self.cycle = 0
        self.refresh_cycles: list[int] = []       # clock of each line's last pixel
        cocotb.start_soon(self._monitor())

    async def _monitor(self):
        d = self.dut
        while True:
            await RisingEdge(d.clk_i)
            await ReadOnly()
            self.cycle += 1
            if int(d.pix_valid_o.value):
                self.pixels.append((int(d.pix_col_o.value), int(d.pix_o.value)))
                if len(self.pixels) % self.n == 0:
                    self.refresh_cycles.append(self.cycle)

    async def reset(self):
        from common.run import hold_reset
        await hold_reset(self.dut, 1, instr_valid_i=0, id_i=0, data_i=0)

    async def offer(self, ident: int, data: int):
        """Hold one slot on the port until the array takes it (ready in the same clock);
        returns at the falling edge after the clock that took it."""
        from common.run import offer
        await offer(self.dut, "instr_valid_i", "instr_ready_o", id_i=ident, data_i=data)

    async def play(self, slots, gap: int = 0):
        """Offer each slot until the array takes it, with random idle clocks between
        (idle), and `gap` idle clocks after each slot; with neither, back to back."""
        d = self.dut
        await FallingEdge(d.clk_i)
        for ident, data in slots:
            for _ in range(gap):
                d.instr_valid_i.value = 0
                await FallingEdge(d.clk_i)
            while self.idle and self.rng.random() < self.idle:
                d.instr_valid_i.value = 0
                await FallingEdge(d.clk_i)
            await self.offer(ident, data)

    async def play_paced(self, slots, rate, htotal: int):
        """The display's bus: slot k of a line of `htotal` slots (Nops pad each line) is
        due at clock floor(k * rate) (span_timing.slot_due: `rate` may be a Fraction, the
        board's 25/8 core clocks per pixel clock). A slot the array does not take in time
        waits (in hardware: a FIFO in front); returns the clocks at which each Refresh was
        due and the largest backlog in slots. self.offered gets the clock (from the first
        slot's due time) at which each slot was first offered."""
        from diffengine.bench.span_timing import last_due, slot_due
        d = self.dut
        due_refresh, backlog, k, base = [], 0, 0, self.cycle
        self.offered = []
        line: list = []
        lines = []
        for ident, data in slots:
            line.append((ident, data))
            if ident == isa.REFRESH:
                lines.append(line[:-1] + [(isa.NOP, 0)] * (htotal - len(line)) + [line[-1]])
                line = []
        for ln in lines:
            assert len(ln) == htotal, f"a line of {len(ln)} slots: more than HTotal {htotal}"
            for ident, data in ln:
                due = slot_due(k, rate)
                while self.cycle < base + due:
                    await FallingEdge(d.clk_i)
                # Slots due but not yet taken: how far the array is behind the bus.
                backlog = max(backlog, last_due(self.cycle - base, rate) - k)
                if ident == isa.REFRESH:
                    due_refresh.append(base + due)
                self.offered.append(self.cycle - base)
                await self.offer(ident, data)
                k += 1
        return due_refresh, backlog

    async def drain(self):
        d = self.dut
        await FallingEdge(d.clk_i)
        d.instr_valid_i.value = 0
        for _ in range(100000):
            await ReadOnly()
            if not int(d.busy_o.value):
                break
            await FallingEdge(d.clk_i)
        else:
            raise AssertionError("de_span_array still busy after 100000 clocks")
        for _ in range(4):
            await RisingEdge(d.clk_i)

    def frame(self) -> np.ndarray:
        n = self.n
        assert len(self.pixels) % n == 0, f"{len(self.pixels)} pixels: not whole lines of {n}"
        cols = [c for c, _ in self.pixels]
        for line in range(len(cols) // n):
            got = cols[line * n:(line + 1) * n]
            assert got == list(range(n)), f"line {line}: columns out of order: {got[:20]}"
        return np.array([p for _, p in self.pixels], dtype=np.uint16).reshape(-1, n)

    def check(self, cmds, carry_bug: bool) -> np.ndarray:
        frame = self.frame()
        want = functional.render(cmds, self.n, carry_bug=carry_bug)
        assert frame.shape == want.shape, f"{frame.shape[0]} lines, model {want.shape[0]}"
        for y in range(want.shape[0]):
            bad = np.flatnonzero(frame[y] != want[y])
            assert not bad.size, (f"line {y} column {bad[0]}: RTL {frame[y, bad[0]]:#05x}, "
                                  f"model {want[y, bad[0]]:#05x} ({bad.size} columns differ)")
        return frame


def bug() -> bool:
    return bool(int(os.environ.get("DE_CARRY_BUG", "0")))


def seed_of(dut) -> int:
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    dut._log.info(f"SEED={seed} (replay with SEED={seed})")
    return seed


async def start(dut, idle: float = 0.0, seed: int = 0, n: int | None = None) -> Bench:
    cocotb.start_soon(Clock(dut.clk_i, 10, unit="ns").start())
    await Timer(1, unit="ns")
    b = Bench(dut, idle, seed, n)
    await b.reset()
    return b


@cocotb.test()
async def random_streams(dut):
    """Random command streams (randgen, Eval0-Eval8, Set/SetP/Dis/Acc_mode) equal the
    functional model, with random idle clocks between slots."""
    seed = seed_of(dut)
    b = await start(dut, idle=0.5, seed=seed)
    cmds = randgen.stream(seed, int(os.environ.get("N_CMDS", 400)), b.n, (1, 14))
    await b.play(isa.serialise(cmds))
    await b.drain()
    frame = b.check(cmds, bug())
    dut._log.info(f"{frame.shape[0]} lines x {b.n} columns equal the functional model")


@cocotb.test()
async def slot_soup(dut):
    """Raw slot streams: the 19 atomic instructions in any order (orphan data and ACC
    slots, address slots with no data, Refreshes back to back; not a data slot right
    behind an ACC or an Eval0, which docs/isa.md leaves undefined) equal the structural
    model, PE by PE."""
    seed = seed_of(dut)
    b = await start(dut, seed=seed)
    n = b.n
    # The generator (randgen.slot_soup) leaves out a data slot right behind an ACC or an
    # Eval0 address slot: docs/isa.md section 6 leaves both undefined.
    slots = randgen.slot_soup(seed, int(os.environ.get("N_SLOTS", 1500)), n)
    await b.play(slots)
    await b.drain()
    frame = b.frame()
    arr = structural.Array(n, bug())
    arr.run(slots)
    arr.flush()
    lines = sum(1 for s in slots if s[0] == isa.REFRESH)
    want = np.zeros((lines, n), dtype=np.uint16)
    seen = np.zeros(n, dtype=np.int64)
    for _, p, v in arr.events:
        want[seen[p], p] = v
        seen[p] += 1
    for y in range(lines):
        bad = np.flatnonzero(frame[y] != want[y])
        assert not bad.size, (f"line {y} column {bad[0]}: RTL {frame[y, bad[0]]:#05x}, "
                              f"structural {want[y, bad[0]]:#05x}")
    dut._log.info(f"{len(slots)} raw slots, {lines} lines equal the structural model")


@cocotb.test()
async def hazards_and_splits(dut):
    """Back-to-back passes over the same and overlapping columns (the in-flight check),
    every Eval order (groups longer than MaxSlots are split), periodic Sets with dX = 0
    and past the end, spans clipped at both ends."""
    b = await start(dut)
    n = b.n
    cmds = []
    for k in range(12):                       # the same column, one command after another
        cmds.append(isa.Command("EVAL", 3, 1, (ONE // 3 + k, ONE // 5)))
    for k in range(10):                       # overlapping, shifting spans
        cmds.append(isa.Command("EVAL", k, 3, (2 * ONE, -ONE // 7, ONE // 64)))
    cmds += [isa.Command("SETPDI", 1, 0, (ONE,)), isa.Command("SETPI", n - 1, 3, (5 * ONE,)),
             isa.Command("SETPDDI", 2, 5, (ONE // 9,)), isa.Command("SETDDI", n - 2, 9, (ONE,)),
             isa.Command("EVAL", 0, 4095, (ONE, ONE // 2, ONE // 100)), isa.Command("REFRESH")]
    for order in range(8):                    # Eval1..Eval8
        vals = tuple(((-1) ** k) * (ONE >> (2 * k)) for k in range(order + 1))
        cmds += [isa.Command("SETDI", 5, 3, (ONE // 3,)), isa.Command("DIS", 6, 1),
                 isa.Command("EVAL", 1, n, vals), isa.Command("EVAL0", 0, 2, (4000,)),
                 isa.Command("ACCMODE", values=(order % 2,)),
                 isa.Command("EVAL", 0, n - 1, (-ONE, ONE // 8)), isa.Command("REFRESH")]
    await b.play(isa.serialise(cmds))
    await b.drain()
    b.check(cmds, bug())


@cocotb.test()
async def forwarding(dut):
    """Passes on one column d clocks apart around the forwarding window (an earlier token
    of the column in the first K stages holds the next one back; from write back on, or
    one or two clocks past it, its state is bypassed to it): fillers of 0..K+5 columns
    elsewhere between them, behind full-width passes that fill the pass table, every kind
    of pass (Eval0, Dis, Eval0-Eval5 with splits, Set) and Refreshes among them (the bank
    changes: nothing may be bypassed across one). Equal to the functional model. Then the
    clocks per pass of one column over and over: at most max(K+1, the front end's) with
    Forward, at least K+4 without (the column's whole trip through the pipeline)."""
    b = await start(dut)
    n, k, fwd = b.n, int(dut.MaxSlots.value), int(dut.Forward.value)
    c, f0 = 3, 10
    kinds = [lambda j: isa.Command("EVAL0", c, 1, (100 + j,)),
             lambda j: isa.Command("DIS", c, 1),
             lambda j: isa.Command("SETI", c, 1, (ONE // (j + 2),))]
    kinds += [lambda j, m=m: isa.Command("EVAL", c, 1, tuple(
        ((-1) ** i) * ((ONE // (3 + j % 5)) >> (2 * i)) for i in range(m))) for m in range(1, 7)]
    cmds = []
    for f in range(k + 6):
        cmds += [isa.Command("EVAL", 0, n, (ONE // 2, ONE // 64, -ONE // 4096, ONE // 65536))] * 2
        for j, kind in enumerate(kinds):
            cmds.append(kind(j + f))
            if f:
                cmds.append(isa.Command("EVAL", f0, f, (ONE // 4, ONE // 128)))
            if j == 4 and f % 3 == 1:
                cmds.append(isa.Command("REFRESH"))
        cmds.append(isa.Command("REFRESH"))
    await b.play(isa.serialise(cmds))
    await b.drain()
    b.check(cmds, bug())

    # Timing: one column, 48 times over, against the same stream without them.
    from diffengine.bench import span_timing
    lead = [isa.Command("EVAL", 0, n, (ONE // 2, ONE // 64))] * 2
    same = [isa.Command("EVAL", 5, 1, (ONE // (j + 3),)) for j in range(48)]
    clocks = []
    for body in ([], same):
        b.pixels.clear()
        t0 = b.cycle
        await b.play(isa.serialise(lead + body + [isa.Command("REFRESH")]))
        await b.drain()
        clocks.append(b.cycle - t0)
    slots = isa.serialise(same)
    passes = sum(len(ln) - 1 for ln in span_timing.passes_of(
        slots + [(isa.REFRESH, 0)], n, k))
    front = (len(slots) + passes) / passes      # a slot per clock, a clock per commit
    rate = (clocks[1] - clocks[0]) / passes
    dut._log.info(f"one column over and over: {rate:.2f} clocks per pass (K = {k}, "
                  f"Forward = {fwd}, front end {front:.2f})")
    if fwd:
        assert rate <= max(k + 1, front) + 0.5, f"{rate:.2f} clocks per pass with forwarding"
    else:
        assert rate >= k + 4 - 0.5, f"{rate:.2f} clocks per pass without forwarding"


@cocotb.test()
async def reset_mid_stream(dut):
    """rst_i for one clock with passes in flight: the next line is a fresh array's."""
    b = await start(dut)
    n = b.n
    dirty = [isa.Command("EVAL", 0, n, (5 * ONE, ONE // 7)),
             isa.Command("SETI", 0, n, (3 * ONE,)), isa.Command("ACCMODE", values=(1,)),
             isa.Command("EVAL0", 2, 3, (77,)), isa.Command("DIS", 0, n)]
    await b.play(isa.serialise(dirty))
    d = dut
    d.rst_i.value = 1
    await FallingEdge(d.clk_i)
    d.rst_i.value = 0
    b.pixels.clear()
    cmds = [isa.Command("EVAL", 1, n - 2, (-ONE, ONE // 4)), isa.Command("REFRESH")]
    await b.play(isa.serialise(cmds))
    await b.drain()
    b.check(cmds, bug())


@cocotb.test()
async def figure_lists(dut):
    """The seed's Fig. 7.21 / 7.25 command lists (the columns that fit the array)."""
    b = await start(dut, idle=0.3, seed=1)
    cmds = []
    for path in sorted(SCENES.glob("fig7_*.cmd")):
        cmds += asm.parse_file(path)
    cmds = [c for c in cmds if c.op in ("REFRESH", "ACCMODE", "NOP") or c.x < b.n]
    await b.play(isa.serialise(cmds))
    await b.drain()
    b.check(cmds, bug())


@cocotb.test()
async def paced_driver(dut):
    """The paced driver (play_paced, what `diffengine bench span` measures the lag with):
    on a light stream the array never holds a slot back, so slot k must be offered at
    exactly floor(k * ratio) clocks after the first: 0, 3, 6, 9, 12, 15, 18, 21, 25, ...
    at the board's 25/8, k * 3 at ratio 3 (the old integer pacer), 0, 3, 6, 10, ... at
    10/3; no backlog, and the frame equals the functional model."""
    b = await start(dut)
    n = b.n
    while int(dut.busy_o.value):          # the reset sweep
        await FallingEdge(dut.clk_i)
    htotal = 40                           # slots per line; a line >= 120 clocks > the drain
    cmds = []
    for ratio in (Fraction(25, 8), Fraction(3), Fraction(10, 3)):
        part = []
        for y in range(4):
            part += [isa.Command("EVAL", (3 * y) % n, 2, (ONE // (y + 2), ONE // 64)),
                     isa.Command("SETI", n - 3, 2, (ONE // 3,)),
                     isa.Command("EVAL0", 1, 1, (40 + y,)), isa.Command("REFRESH")]
        cmds += part
        slots = isa.serialise(part)
        _, backlog = await b.play_paced(slots, ratio, htotal)
        await b.drain()
        want = [int(k * ratio.numerator / ratio.denominator) for k in range(len(b.offered))]
        assert len(b.offered) == 4 * htotal, f"{len(b.offered)} slots offered"
        bad = [k for k, (o, w) in enumerate(zip(b.offered, want)) if o != w]
        assert not bad, (f"ratio {ratio}: slot {bad[0]} offered at clock {b.offered[bad[0]]}, "
                         f"due at floor({bad[0]} x {ratio}) = {want[bad[0]]}")
        assert backlog == 0, f"ratio {ratio}: backlog {backlog} on a light stream"
        dut._log.info(f"ratio {ratio}: {len(want)} slots at floor(k x ratio), first "
                      f"{b.offered[:10]}")
    b.check(cmds, bug())


@cocotb.test(skip=not os.environ.get("DE_SPAN_STREAM"))
async def stream_file(dut):
    """A whole .de48 frame (DE_SPAN_STREAM) as fast as the array takes it: the frame must
    equal the functional model, and the clocks each line took go to DE_SPAN_OUT (JSON)."""
    import json
    from diffengine.formats import binfmt
    path = Path(os.environ["DE_SPAN_STREAM"])
    slots = binfmt.decode_de48(path.read_bytes(), str(path))
    cmds = binfmt.deserialise(slots, str(path))
    # DE_SPAN_RATE: core clocks per slot, "3", "3.125" or "25/8"; 0 = unpaced.
    rate = Fraction(os.environ.get("DE_SPAN_RATE", "0"))
    b = await start(dut)
    while int(dut.busy_o.value):          # the reset sweep
        await FallingEdge(dut.clk_i)
    t0 = b.cycle
    res = {"stream": str(path), "columns": b.n, "max_slots": int(dut.MaxSlots.value),
           "forward": int(dut.Forward.value), "prefetch": int(dut.Prefetch.value),
           "pass_aw": int(dut.PassAw.value)}
    if rate:
        # Paced like the display's bus: HTotal slots per line, slot k at floor(k * rate).
        htotal = int(os.environ.get("DE_SPAN_HTOTAL", 800))
        due, backlog = await b.play_paced(slots, rate, htotal)
        await b.drain()
        lag = [e - d for e, d in zip(b.refresh_cycles, due)]
        res.update(rate=str(rate), htotal=htotal, backlog_slots=backlog,
                   lag_clocks=lag)
        msg = (f"paced at 1 slot / {rate} clocks: last pixel of a line at most {max(lag)} "
               f"clocks after its Refresh was due, backlog at most {backlog} slots")
    else:
        # Back to back, as a FIFO with a backlog hands slots over (DE_SPAN_GAP=1: the
        # idle clock after every slot that this driver used to leave).
        gap = int(os.environ.get("DE_SPAN_GAP", "0"))
        await b.play(slots, gap)
        await b.drain()
        res["gap"] = gap
        ends = [t0] + b.refresh_cycles
        per_line = [ends[i + 1] - ends[i] for i in range(len(ends) - 1)]
        res.update(clocks_per_line=per_line, clocks_total=b.cycle - t0)
        msg = (f"clocks per line mean {sum(per_line) / len(per_line):.0f}, "
               f"max {max(per_line)}")
    b.check(cmds, bug())
    out = os.environ.get("DE_SPAN_OUT")
    if out:
        Path(out).write_text(json.dumps(res) + "\n")
    dut._log.info(f"{path.name}: {len(b.refresh_cycles)} lines equal the model; {msg}")


# ---- pytest runners ---------------------------------------------------------------------
# (columns, slots per pass, carry bug, Forward, Prefetch): 37 columns (odd, not a power of
# two) with a pass per Eval3; 2 slots per pass splits every Eval into 2-5 passes, with the
# carry fault; 130 columns take the figure lists whole; the same 37 columns without
# forwarding and prefetch (the hazard wait in full, a load clock per pass); 1 slot per
# pass with forwarding alone.
RUNS = [(37, 4, 0, 1, 1), (37, 2, 1, 1, 1), (130, 9, 0, 1, 1), (37, 4, 0, 0, 0),
        (37, 1, 0, 1, 0)]
EXTRA = {}
if os.environ.get("DE_SPAN_STREAM"):   # diffengine bench span: one full-width build
    RUNS = [(int(os.environ.get("DE_SPAN_COLS", 648)),
             int(os.environ.get("DE_SPAN_SLOTS", 4)), 0,
             int(os.environ.get("DE_SPAN_FWD", 1)), int(os.environ.get("DE_SPAN_PF", 1)))]
    EXTRA = {"PassAw": int(os.environ.get("DE_SPAN_PASSAW", 5))}


@pytest.mark.parametrize("cols,slots,bug,fwd,pf", RUNS,
                         ids=[f"cols{c}_slots{s}_bug{b}_fwd{f}_pf{p}" for c, s, b, f, p in RUNS])
def test_de_span_array(cols, slots, bug, fwd, pf):
    from common.run import build_and_test, rtl_files
    here = Path(__file__).resolve().parent
    build_and_test(here, "de_span_array", rtl_files("span_array", "sim"),
                   "test_de_span_array",
                   parameters={"NumCols": cols, "MaxSlots": slots, "CarryBug": bug,
                               "Forward": fwd, "Prefetch": pf, **EXTRA},
                   extra_env={"DE_CARRY_BUG": str(bug)},
                   testcase="stream_file" if os.environ.get("DE_SPAN_STREAM") else None)
