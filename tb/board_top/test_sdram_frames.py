"""de_sdram_frames alone on the timing-checking SDRAM model (tb_sdram_frames.sv).

The frame store's fetchers, slots and sequencer run on the pixel clock and send their
burst requests across to the SDRAM clock (docs/sdram.md §5); these tests check that
path at a pixel clock slower (25 MHz) and faster (~143 MHz) than the 125 MHz SDRAM
clock, with a player that stalls at random, so the prefetch credit is what keeps the
FIFO from overflowing (the RTL stops the simulation with $fatal if a push ever finds
it full):

* random frames of three colours (line blocks of 1-23 words, empty lines, a table of
  VActive entries not a multiple of 4), loaded with X, slots with F, a two-slot looping
  sequence with Q; malformed lines with up to 8 early markers (each dropped: its
  reserved credit must come back, or the fetcher stalls) and lines whose last word is
  not a marker (replaced);
* every word each player takes is compared with the expected stream: some black frames
  (VActive markers each) before the Q, then the sequence's frames in order, each word
  with its slot's window and compensation flag, exactly one marker per line;
* the malformed-line count, no late line, 0 SDRAM timing violations, refreshes seen.

SEED=<n> replays a run; the seed is printed.
"""
from __future__ import annotations

import os
import random
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
MARKER = 0x0800_0000
NCH = 3
TYP_X, TYP_F, TYP_Q = 1, 2, 3


def is_marker(w: int) -> bool:
    return (w >> 27) & 0x1F == 1


def cmd_x(ch: int, off: int, word: int) -> int:
    return TYP_X << 55 | ch << 53 | off << 32 | word


def cmd_f(ch: int, slot: int, table: int, win: int, comp: int) -> int:
    return TYP_F << 55 | ch << 53 | slot << 47 | table << 26 | win << 23 | comp << 22


def cmd_q(first: int, count: int, hold: int, loop: int) -> int:
    return TYP_Q << 55 | first << 47 | count << 40 | hold << 32 | loop << 31


def random_word(rng: random.Random) -> int:
    while True:
        w = rng.getrandbits(32)
        if not is_marker(w):
            return w


def make_frames(rng: random.Random, va: int):
    """Per colour, two frames of va lines; each line one of: empty (len 0), a good
    block, a block with early markers, a block whose last word is not a marker. Returns
    (writes, slots, expect) with writes {ch: [(off, word)]}, slots {ch: [(table_off,
    win, comp)]}, expect {ch: [frame0 words, frame1 words]} (what the player must take,
    as (comp, win, word)), and the malformed lines per sequence period."""
    writes = {c: [] for c in range(NCH)}
    slots = {c: [] for c in range(NCH)}
    expect = {c: [] for c in range(NCH)}
    n_mal = 0
    for c in range(NCH):
        off = rng.randrange(0, 64) * 4
        for f in range(2):
            win, comp = rng.randrange(5), rng.randrange(2)
            entries, words_out = [], []
            for v in range(va):
                kind = rng.choice(["empty", "good", "good", "early", "nolast"])
                if v == 0:
                    kind = "good"        # a frame starts with a data word (see check)
                if kind == "empty":
                    entries.append(0)
                    words_out.append(MARKER)
                    continue
                n = rng.randrange(1, 23)
                blk = [random_word(rng) for _ in range(n)] + [MARKER]
                if kind == "early":
                    for _ in range(rng.randrange(1, 9)):
                        blk.insert(rng.randrange(0, len(blk)), MARKER)
                elif kind == "nolast":
                    blk[-1] = random_word(rng)
                if kind == "good" and v == 0:
                    blk[0] = random_word(rng)
                # Expected: early markers dropped, the last word a marker.
                exp = [w for w in blk[:-1] if not is_marker(w)] + [MARKER]
                mal = any(is_marker(w) for w in blk[:-1]) or not is_marker(blk[-1])
                n_mal += mal
                words_out += exp
                writes[c] += [(off + i, w) for i, w in enumerate(blk)]
                entries.append(len(blk) << 20 | off // 4)
                off += -(-len(blk) // 4) * 4
            table = off
            writes[c] += [(table + i, e) for i, e in enumerate(entries)]
            off += -(-va // 4) * 4 + 4 * rng.randrange(0, 3)
            slots[c].append((table, win, comp))
            expect[c].append([(comp, win, w) for w in words_out])
    return writes, slots, expect, n_mal


# ====================================================================== cocotb test
try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import ClockCycles, FallingEdge, Timer
except ImportError:  # pytest collection without cocotb's simulator
    cocotb = None

if cocotb is not None:
    @cocotb.test()
    async def test_frames(dut):
        from common.run import offer
        seed = int(os.environ.get("SEED", random.randrange(1 << 30)))
        rng = random.Random(seed)
        pix_ps = int(os.environ.get("PIX_PS", "40000"))
        stall = float(os.environ.get("STALL", "0.6"))
        va = int(os.environ.get("VACTIVE", "7"))
        n_frames = int(os.environ.get("FRAMES", "8"))
        dut._log.info(f"SEED={seed} pixel clock {pix_ps} ps, SDRAM 8000 ps, stall {stall}, "
                      f"VActive {va}")
        dut.rst_i.value = 1
        dut.vactive_i.value = va
        dut.cmd_valid_i.value = 0
        dut.cmd_i.value = 0
        dut.wr_ready_i.value = 0
        # Pixel clock at a phase of its own.
        cocotb.start_soon(Clock(dut.clk_sdram_i, 8000, unit="ps").start())
        await Timer(rng.randrange(1, 8000), unit="ps")
        cocotb.start_soon(Clock(dut.clk_i, pix_ps, unit="ps").start())
        await ClockCycles(dut.clk_i, 8)
        await ClockCycles(dut.clk_sdram_i, 8)
        dut.rst_i.value = 0

        writes, slots, expect, n_mal_period = make_frames(rng, va)
        taken = {c: [] for c in range(NCH)}

        async def player():
            """The display controller's side: ready at random (a stalling player)."""
            while True:
                await FallingEdge(dut.clk_i)
                dut.wr_ready_i.value = sum(1 << c for c in range(NCH)
                                           if rng.random() >= stall)
                t = int(dut.take_o.value)
                if t:
                    d = int(dut.take_data_o.value)
                    for c in range(NCH):
                        if t >> c & 1:
                            x = d >> (36 * c) & (1 << 36) - 1
                            taken[c].append((x >> 35, x >> 32 & 7, x & 0xFFFF_FFFF))

        cocotb.start_soon(player())

        async def send(cmd: int):
            """Valid from a falling edge until the command is taken (common.run.offer)."""
            await FallingEdge(dut.clk_i)
            await offer(dut, "cmd_valid_i", "cmd_ready_o", cmd_i=cmd)

        # Writes interleaved between colours, in random order of runs.
        all_w = [(c, o, w) for c in range(NCH) for (o, w) in writes[c]]
        for c, o, w in all_w:
            await send(cmd_x(c, o, w))
        for c in range(NCH):
            for s, (tbl, win, comp) in enumerate(slots[c]):
                await send(cmd_f(c, s, tbl, win, comp))
        await send(cmd_q(0, 2, 1, 1))
        dut._log.info(f"loaded {len(all_w)} words; waiting for {n_frames} frames")

        # Expected stream after the black frames: slot 0, 1, 0, 1, ...
        def want(c: int, n: int) -> list:
            out = []
            k = 0
            while len(out) < n:
                out += expect[c][k % 2]
                k += 1
            return out[:n]

        def black(got: list) -> int:
            nb = 0
            while nb < len(got) and got[nb][2] == MARKER:
                nb += 1
            return nb

        need = {c: sum(len(expect[c][k % 2]) for k in range(n_frames)) for c in range(NCH)}
        for _ in range(4000):
            await ClockCycles(dut.clk_i, 200)
            if all(len(taken[c]) - black(taken[c]) >= need[c] for c in range(NCH)):
                break
        for c in range(NCH):
            got = taken[c]
            # Black frames first: VActive markers each (window / flag of no slot).
            nb = black(got)
            assert nb % va == 0, f"colour {c}: {nb} leading markers, not whole black frames"
            seq = got[nb:]
            assert len(seq) >= need[c], (
                f"colour {c}: only {len(seq)} of {need[c]} words taken after {nb // va} "
                f"black frames (stalled: credit lost?)")
            exp = want(c, len(seq))
            for i, (g, e) in enumerate(zip(seq, exp)):
                assert g == e, (f"colour {c} word {i} after {nb // va} black frames: got "
                                f"{g[0]}/{g[1]}/{g[2]:#010x}, want {e[0]}/{e[1]}/{e[2]:#010x}")
            dut._log.info(f"colour {c}: {nb // va} black frames, then {len(seq)} words "
                          f"({len(seq) / sum(len(x) for x in expect[c]) * 2:.1f} frames) exact")
        mal = int(dut.malformed_o.value)
        assert mal >= min(255, n_mal_period * (n_frames // 2)), (
            f"malformed lines {mal}, want >= {n_mal_period} per two frames")
        assert int(dut.late_o.value) == 0
        assert int(dut.u_sdram.err_count_o.value) == 0, "SDRAM timing violations"
        assert int(dut.u_sdram.ref_count_o.value) > 0, "no refresh seen"
        dut._log.info(f"malformed lines counted {mal}; SDRAM refreshes "
                      f"{int(dut.u_sdram.ref_count_o.value)}, 0 violations")


# ====================================================================== pytest runners
@pytest.mark.parametrize("kind", ["slow", "fast"])
def test_sdram_frames(kind):
    """slow: the board's ratio, pixel clock 25 MHz against the SDRAM's 125 MHz. fast: a
    pixel clock faster than the SDRAM clock (~143 MHz), so the crossing runs the other
    way round. Both with a player that stalls 60 % of its clocks and PfDepth 16, where
    the credit decides every burst."""
    from common.run import build_and_test, rtl_files
    env = {"PIX_PS": "40000" if kind == "slow" else "7000"}
    build_and_test(HERE, "tb_sdram_frames", rtl_files("diffengine:tb:board_top", "frames"),
                   "test_sdram_frames", parameters=dict(PfDepth=16, SdTinitNs=2000),
                   extra_env=env, testcase="test_frames")
