"""cocotb tests of rtl/board/de_sdram_ctrl.sv against the timing-checking SDRAM model.

Toplevel tb_sdram_ctrl.sv: the controller drives sim/models/sdram_sdr16.sv over the
SDRAM pins; the model counts every timing or protocol violation (err_count_o).
Structure:
  Driver   - per clock (falling edge) offers at most one read request (4 words) and one
             write (1 word), each kept on its port until taken (the controller's
             contract; it stops the simulation otherwise); a request counts as taken
             when its port's ready was high (the readies depend on flip-flops only, not
             on valid, so they are read before driving).
  Monitor  - samples rd_valid_o / rd_data_o / rd_tag_o once per clock.
  Model    - a dict word address -> 32-bit word, updated in acceptance order (the
             controller serves requests in order), and the queue of expected read words.
  Checker  - every read word equals the model's, in order, with the request's tag; the
             SDRAM model's error counter stays 0; refreshes counted.

Builds: 125 MHz with CL 3 (the board's), 100 MHz with CL 2; power-up wait shortened
to 2 us. Tests:
  random_rw   - random writes and 4-word reads over a few rows of every bank (hits,
                misses, bank conflicts), reads verified against the dict;
  waiting_request - reads and writes of two rows of one bank back to back, each waiting
                at its port while the one before changes the bank's open row (the
                controller's open-row compare of a waiting request must be current);
  stream      - three "colours", each streaming its own bank sequentially (rows change
                every 256 words), for > 20 refresh intervals: data verified, 0 timing
                violations, REF count as due, and the sustained read bandwidth printed.
SEED=<n> replays (printed); SDRAM_CTRL_OPS / SDRAM_CTRL_CYCLES set the lengths.
"""
from __future__ import annotations

import os
import random
import sys
from collections import deque
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from common.run import drive  # noqa: E402

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge
except ImportError:  # pragma: no cover
    cocotb = None

# The build's clock and CAS latency (pytest passes them; see BUILDS).
TCK_PS = int(os.environ.get("SDRAM_TCK", "8000"))
CL = int(os.environ.get("SDRAM_CL", "3"))
AW = 23
REFI = 7_812_500 // TCK_PS          # clocks per tREFI


class Bench:
    def __init__(self, dut, rng: random.Random):
        self.dut = dut
        self.rng = rng
        self.mem: dict[int, int] = {}
        self.expect: deque[tuple[int, int]] = deque()   # (tag, word) in order
        self.cycle = 0
        self.words = 0
        self.first_word = None
        self.last_word = None

    async def start(self) -> None:
        dut = self.dut
        drive(dut, rst_i=1, wr_valid_i=0, rd_req_valid_i=0, wr_addr_i=0, wr_data_i=0,
              rd_req_addr_i=0, rd_req_tag_i=0)
        Clock(dut.clk_i, TCK_PS, unit="ps").start(start_high=False)
        for _ in range(3):
            await FallingEdge(dut.clk_i)
        dut.rst_i.value = 0
        while not int(dut.init_done_o.value):
            await FallingEdge(dut.clk_i)

    def monitor(self) -> None:
        dut = self.dut
        if int(dut.rd_valid_o.value):
            got = (int(dut.rd_tag_o.value), int(dut.rd_data_o.value))
            assert self.expect, f"cycle {self.cycle}: read word {got} nobody asked for"
            exp = self.expect.popleft()
            assert got == exp, f"cycle {self.cycle}: read (tag, word) {got[0]}, " \
                               f"{got[1]:#010x}, expected {exp[0]}, {exp[1]:#010x}"
            self.words += 1
            if self.first_word is None:
                self.first_word = self.cycle
            self.last_word = self.cycle
        if int(dut.u_sdram.err_count_o.value):
            code = int(dut.u_sdram.u_sdram.err_code_o.value)   # the model's own output
            raise AssertionError(f"cycle {self.cycle}: SDRAM model error code {code}")

    async def clock(self, rd=None, wr=None) -> tuple[bool, bool]:
        """One clock: offer read request rd=(addr, tag) and/or write wr=(addr, word)."""
        dut = self.dut
        await FallingEdge(dut.clk_i)
        self.cycle += 1
        self.monitor()
        rd_ready = int(dut.rd_req_ready_o.value)
        wr_ready = int(dut.wr_ready_o.value)
        assert not (rd_ready and wr_ready), f"cycle {self.cycle}: both ports ready"
        took_rd = took_wr = False
        drive(dut, rd_req_valid_i=int(rd is not None), wr_valid_i=int(wr is not None))
        if rd is not None:
            addr, tag = rd
            drive(dut, rd_req_addr_i=addr, rd_req_tag_i=tag)
            took_rd = bool(rd_ready)
            if took_rd:
                self.expect += [(tag, self.mem.get((addr & ~3) + i, 0)) for i in range(4)]
        if wr is not None:
            addr, word = wr
            drive(dut, wr_addr_i=addr, wr_data_i=word)
            took_wr = bool(wr_ready)
            if took_wr:
                self.mem[addr] = word
        return took_rd, took_wr

    async def drain(self) -> None:
        for _ in range(40):
            await self.clock()
        assert not self.expect, f"{len(self.expect)} read words never came"


def seed() -> int:
    s = int(os.environ.get("SEED", random.randrange(1 << 32)))
    print(f"de_sdram_ctrl SEED={s}  (re-run with SEED={s})")
    return s


def addr_of(bank: int, row: int, colw: int) -> int:
    return (bank << 21) | (row << 8) | colw


@cocotb.test() if cocotb else (lambda f: f)
async def random_rw(dut):
    """Random writes and reads over 3 rows per bank: every word read back right, 0 model
    errors."""
    s = seed()
    rng = random.Random(s)
    b = Bench(dut, rng)
    await b.start()
    rows = {bank: [rng.randrange(8192) for _ in range(3)] for bank in range(4)}

    def rand_addr():
        bank = rng.randrange(4)
        return addr_of(bank, rng.choice(rows[bank]), rng.randrange(256))

    n_ops = int(os.environ.get("SDRAM_CTRL_OPS", "600"))
    pend_rd = pend_wr = None
    done = 0
    # A request stays on its port until it is taken (the controller checks that).
    while done < n_ops or pend_rd is not None or pend_wr is not None:
        if pend_rd is None and done < n_ops and rng.random() < 0.4:
            pend_rd = (rand_addr() & ~3, rng.randrange(4))
        if pend_wr is None and done < n_ops and rng.random() < 0.6:
            pend_wr = (rand_addr(), rng.randrange(1 << 32))
        took_rd, took_wr = await b.clock(pend_rd, pend_wr)
        if took_rd:
            pend_rd, done = None, done + 1
        if took_wr:
            pend_wr, done = None, done + 1
    await b.drain()
    dut._log.info("random_rw SEED=%d: %d requests, %d words read, %d clocks, %d REFs, "
                  "0 violations", s, n_ops, b.words, b.cycle, int(dut.u_sdram.ref_count_o.value))


@cocotb.test() if cocotb else (lambda f: f)
async def waiting_request(dut):
    """A request waits at its port while the one before it changes the rows of its bank:
    the controller must use an open-row compare made after that change, not the one of
    the clock the request arrived. Per round, in one bank, rows X and A hold different
    words: read X (X open), read A (a miss: PRECHARGE, ACT) with the next read of X put
    on the port in the clock A is taken, while X is still open (a compare kept from then
    says "row open" and reads row A's words), then writes and reads of both rows back to
    back, a write waiting beside a read; every word checked, 0 violations."""
    s = seed()
    rng = random.Random(s)
    b = Bench(dut, rng)
    await b.start()
    rounds = int(os.environ.get("SDRAM_CTRL_ROUNDS", "40"))
    for r in range(rounds):
        bank = r % 4
        row_x, row_a = rng.sample(range(8192), 2)
        col = rng.randrange(64) * 4
        for row in (row_x, row_a):
            for i in range(4):
                wr = (addr_of(bank, row, col + i), rng.randrange(1 << 32))
                while not (await b.clock(None, wr))[1]:
                    pass
        # Back to back, each put on its port in the clock after the one before is taken.
        ops = [("r", row_x), ("r", row_a), ("r", row_x), ("w", row_a), ("r", row_x),
               ("r", row_a), ("w", row_x), ("r", row_x), ("r", row_a)]
        rng.shuffle(ops[3:])
        ops = [(op, addr_of(bank, row, col + rng.randrange(4) if op == "w" else col))
               for op, row in ops]
        i = 0
        side = None
        word = rng.randrange(1 << 32)
        while i < len(ops):
            op, addr = ops[i]
            rd = (addr, bank) if op == "r" else None
            wr = (addr, word) if op == "w" else None
            # Now and then the read after a write waits beside it from the write's first
            # clock on (a request stays on its port until taken); either may go first.
            if (op == "w" and side is None and i + 1 < len(ops) and ops[i + 1][0] == "r"
                    and rng.random() < 0.5):
                side = (ops[i + 1][1], bank)
            took_rd, took_wr = await b.clock(rd or side, wr)
            if op == "w" and took_rd:                # the side read went first
                ops.pop(i + 1)
                side = None
            elif (op == "r" and took_rd) or (op == "w" and took_wr):
                i += 1
                word = rng.randrange(1 << 32)
                if side is not None:                 # the side read is now the head
                    side = None
        if r % 8 == 7:
            await b.drain()
    await b.drain()
    dut._log.info("waiting_request SEED=%d: %d rounds, %d words read, %d clocks, "
                  "0 violations", s, rounds, b.words, b.cycle)


@cocotb.test() if cocotb else (lambda f: f)
async def stream(dut):
    """Three colours stream their own banks (4-word requests round robin) for more than
    20 refresh intervals; data checked, 0 violations; sustained bandwidth measured."""
    s = seed()
    rng = random.Random(s)
    b = Bench(dut, rng)
    await b.start()
    span = 1024                                      # words per colour: 4 rows
    # Load a pattern through the write port.
    for c in range(3):
        for w in range(span):
            wr = (addr_of(c, 100 + c, 0) + w, rng.randrange(1 << 32))
            while not (await b.clock(None, wr))[1]:
                pass
    await b.drain()
    refs0 = int(dut.u_sdram.ref_count_o.value)
    cycles = int(os.environ.get("SDRAM_CTRL_CYCLES", str(22 * REFI)))
    pos = [0, 0, 0]
    c = 0
    b.words, b.first_word = 0, None
    start = b.cycle
    req = None
    # The window's last request is kept on the port until it is taken.
    while b.cycle - start < cycles or req is not None:
        if req is None:
            req = (addr_of(c, 100 + c, 0) + pos[c], c)
        took, _ = await b.clock(req, None)
        if took:
            pos[c] = (pos[c] + 4) % span
            c = (c + 1) % 3
            req = None
    # Count the words that came within the window (the first word arrives CL + a few
    # clocks after the first request).
    window_words = b.words
    await b.drain()
    refs = int(dut.u_sdram.ref_count_o.value) - refs0
    span_clk = b.last_word - b.first_word + 1
    f_mhz = 1e6 / TCK_PS
    wps = window_words / span_clk                    # 32-bit words per SDRAM clock
    mbs = wps * 4 * f_mhz
    per_px = wps * f_mhz / 25.0
    msg = (f"stream SEED={s}: {window_words} words in {span_clk} clocks at {f_mhz:.0f} MHz "
           f"= {wps:.4f} words/clock ({100 * wps * 2:.1f} % of the data bus), "
           f"{mbs:.1f} MB/s, {per_px:.3f} words per 25 MHz pixel clock; {refs} REFs "
           f"(tREFI {REFI} clocks), 0 violations")
    print(msg)
    dut._log.info(msg)
    out = os.environ.get("SDRAM_CTRL_RESULT")
    if out:
        Path(out).write_text(msg + "\n")
    assert refs >= cycles // REFI, f"{refs} REFs in {cycles} clocks"
    assert wps * 2 > 0.9, "sustained read bandwidth below 90 % of the data bus"


# ---- pytest runner --------------------------------------------------------------------------

BUILDS = {"125mhz_cl3": (8000, 3), "100mhz_cl2": (10000, 2)}

try:
    import pytest

    @pytest.mark.parametrize("build", list(BUILDS))
    def test_de_sdram_ctrl(build):
        from common.run import build_and_test, rtl_files
        tck, cl = BUILDS[build]
        srcs = rtl_files("diffengine:tb:de_sdram_ctrl")   # tb/de_sdram_ctrl/de_sdram_ctrl_tb.core
        build_and_test(HERE, "tb_sdram_ctrl", srcs, "test_de_sdram_ctrl",
                       parameters={"TckPs": tck, "CasLatency": cl},
                       extra_env={"SDRAM_TCK": str(tck), "SDRAM_CL": str(cl)})
except ImportError:  # pragma: no cover
    pass
