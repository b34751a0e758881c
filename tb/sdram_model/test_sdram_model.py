"""cocotb tests of the timing-checking SDR SDRAM model sim/models/sdram_sdr16.sv.

The model is the toplevel; a raw-command driver plays the controller. Structure:
  Driver   - one command (cs/ras/cas/we, ba, a, dqm, dq) per clock, set at the falling
             edge for the next rising edge, whose index (edge) matches the model's cycle;
             at the same moment it samples dq_o/dq_oe_o, i.e. what that rising edge sees.
  Model    - a Python dict of 16-bit words (bank, row, col) written through the same
             burst order and DQM masks: the expected read data.
  Checker  - read bursts compared word by word at edge READ + CL + i; the model's error
             counter, last code and log line (its +sdram_log file) checked after each
             sequence.

Two builds (docs/sdram.md §1):
  tck8000  - 125 MHz, the MT48LC16M16A2-6A defaults: CL 3 only (CL 2 needs tCK >= 10 ns):
             legal sequences with zero errors, random traffic, and one sequence per
             violation that must raise exactly that error;
  tck10000 - 100 MHz with tRC raised to 90 ns, so that tRC is not implied by
             tRAS + tRP and its check can be shown alone: CL 2 and CL 3 legal sequences,
             the tRC violation.

SEED=<n> replays the random test (printed); SDRAM_RANDOM_OPS sets its length.
"""
from __future__ import annotations

import os
import random
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE.parent))
from common.run import drive  # noqa: E402

try:  # the pytest runner part does not need cocotb's simulator side
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge
except ImportError:  # pragma: no cover
    cocotb = None


# Error codes of the model (err_code_o, err_seen_o bit).
CODES = {"INIT": 1, "TRCD": 2, "TRP": 3, "TRAS": 4, "TRAS_MAX": 5, "TRC": 6, "TRRD": 7,
         "TRFC": 8, "TMRD": 9, "TWR": 10, "BANK": 11, "MODE": 12, "REFRESH": 13, "DQ": 14,
         "CKE": 15}

# Command encodings {ras_n, cas_n, we_n}.
CMD = {"NOP": 0b111, "ACT": 0b011, "READ": 0b101, "WRITE": 0b100, "PRE": 0b010,
       "REF": 0b001, "LMR": 0b000, "BST": 0b110}

NCOLS = 512


def cycles(ps: int, tck: int) -> int:
    return -(-ps // tck)


class Timing:
    """The model's parameters in clocks (same rounding as the model)."""

    def __init__(self, tck: int, trc_ps: int = 60000, tinit_ns: int = 2000):
        self.tck = tck
        self.rcd = cycles(18000, tck)
        self.rp = cycles(18000, tck)
        self.ras = cycles(42000, tck)
        self.ras_max = 120_000_000 // tck
        self.rc = cycles(trc_ps, tck)
        self.rrd = cycles(12000, tck)
        self.rfc = cycles(60000, tck)
        self.wr = cycles(12000, tck)
        self.mrd = 2
        self.refi = 64_000_000 * 1000 // 8192 // tck
        self.ref_max = self.refi * 9
        self.init = cycles(tinit_ns * 1000, tck)


# ---- testbench components ---------------------------------------------------------------

class Driver:
    """Raw commands, one per clock; returns what DQ shows at that command's edge."""

    def __init__(self, dut):
        self.dut = dut
        self.edge = 0           # index of the rising edge the next command is sampled at
        self.seen: dict[int, tuple[int, int]] = {}   # edge -> (oe, dq) sampled there

    async def step(self, cmd="NOP", ba=0, a=0, dqm=0, dq=0, cs=True, cke=1):
        dut = self.dut
        await FallingEdge(dut.clk_i)
        dut.cs_n_i.value = 0 if cs else 1
        c = CMD[cmd]
        dut.ras_n_i.value = (c >> 2) & 1
        dut.cas_n_i.value = (c >> 1) & 1
        dut.we_n_i.value = c & 1
        dut.ba_i.value = ba
        dut.a_i.value = a
        dut.dqm_i.value = dqm
        dut.dq_i.value = dq
        dut.cke_i.value = cke
        oe = int(dut.dq_oe_o.value)
        self.seen[self.edge] = (oe, int(dut.dq_o.value) if oe else -1)
        e = self.edge
        self.edge += 1
        return e

    async def nop(self, n: int) -> None:
        for _ in range(n):
            await self.step()


class Sdram:
    """Legal command sequences on top of the driver, mirrored by a Python memory."""

    def __init__(self, dut, t: Timing, log_path: Path):
        self.dut = dut
        self.t = t
        self.drv = Driver(dut)
        self.mem: dict[tuple[int, int, int], int] = {}
        self.cl = 0
        self.bl = 0
        self.wb_single = False
        self.log_path = log_path
        self.last_ref = None

    async def power_on(self) -> None:
        dut = self.dut
        await FallingEdge(dut.clk_i)
        drive(dut, rst_i=1, cs_n_i=1, ras_n_i=1, cas_n_i=1, we_n_i=1, cke_i=1, ba_i=0, a_i=0,
              dqm_i=0, dq_i=0)
        await FallingEdge(dut.clk_i)
        await FallingEdge(dut.clk_i)
        dut.rst_i.value = 0
        # The next rising edge is the model's cycle 0 (inputs NOP); Driver.step waits
        # for the falling edge after it, so its first command is cycle 1.
        self.drv = Driver(dut)
        self.drv.edge = 1
        self.mem.clear()
        self.cl = self.bl = 0
        self.last_ref = None

    async def init(self, cl=3, bl=1, wb_single=False, lmr=True) -> None:
        t = self.t
        await self.drv.nop(t.init + 1)
        await self.drv.step("PRE", a=1 << 10)
        await self.drv.nop(t.rp - 1)
        for _ in range(2):
            await self.ref()
        if lmr:
            await self.lmr(cl, bl, wb_single)

    async def ref(self) -> None:
        self.last_ref = await self.drv.step("REF")
        await self.drv.nop(self.t.rfc - 1)

    async def lmr(self, cl, bl, wb_single=False, interleaved=False) -> None:
        code = {1: 0, 2: 1, 4: 2, 8: 3, NCOLS: 7}[bl]
        a = code | (int(interleaved) << 3) | (cl << 4) | (int(wb_single) << 9)
        await self.drv.step("LMR", a=a)
        await self.drv.nop(self.t.mrd - 1)
        self.cl, self.bl, self.wb_single = cl, bl, wb_single

    def burst_cols(self, col: int, n: int) -> list[int]:
        bl = self.bl
        if bl >= NCOLS:
            return [(col + i) % NCOLS for i in range(n)]
        return [(col & ~(bl - 1)) | ((col + i) & (bl - 1)) for i in range(n)]

    async def write(self, bank, row, col, data, dqm=None, ap=False, n=None):
        """ACT, WRITE (n beats of the burst, BST after n if a full page), recovery, PRE."""
        t = self.t
        n = n if n is not None else (1 if self.wb_single else self.bl)
        assert len(data) == n
        dqm = dqm or [0] * n
        act = await self.drv.step("ACT", ba=bank, a=row)
        # With auto-precharge the precharge (tWR after the last data) must not come
        # before tRAS: the model assumes no tRAS lockout.
        await self.wait_until(act + (max(t.rcd, t.ras - (n - 1) - t.wr) if ap else t.rcd))
        cols = self.burst_cols(col, n) if not self.wb_single else [col]
        w = None
        for i in range(n):
            if i == 0:
                w = await self.drv.step("WRITE", ba=bank, a=col | (int(ap) << 10),
                                        dqm=dqm[0], dq=data[0])
            else:
                await self.drv.step(dqm=dqm[i], dq=data[i])
            old = self.mem.get((bank, row, cols[i]), 0)
            m = dqm[i]
            new = ((old if m & 2 else data[i]) & 0xFF00) | ((old if m & 1 else data[i]) & 0xFF)
            self.mem[(bank, row, cols[i])] = new
        last = w + n - 1
        if self.bl >= NCOLS and not self.wb_single:
            await self.drv.step("BST", dqm=3)        # data at the BST edge is not written
            last = w + n - 1
        if ap:
            # Auto-precharge: tWR after the last data, then tRP, before the bank's next ACT.
            await self.wait_until(max(last + t.wr + t.rp, act + t.rc))
        else:
            await self.wait_until(max(last + t.wr, act + t.ras))
            p = await self.drv.step("PRE", ba=bank)
            await self.wait_until(max(p + t.rp, act + t.rc))

    async def read(self, bank, row, col, ap=False, n=None, dqm_off=()):
        """ACT, READ, collect n words at READ + CL + i, PRE; returns the words (-1 = hi-Z)."""
        t = self.t
        n = n if n is not None else self.bl
        act = await self.drv.step("ACT", ba=bank, a=row)
        # Auto-precharge starts BL clocks after the READ: not before tRAS.
        await self.wait_until(act + (max(t.rcd, t.ras - self.bl) if ap else t.rcd))
        r = await self.drv.step("READ", ba=bank, a=col | (int(ap) << 10))
        # DQM high at edge r + CL + i - 2 turns word i off.
        for e in range(r + 1, r + self.cl + n + 1):
            i = e + 2 - (r + self.cl)
            await self.drv.step(dqm=3 if i in dqm_off else 0)
        if self.bl >= NCOLS:
            pass  # the full-page read below is cut by the PRECHARGE
        last_needed = r + self.cl + n - 1
        if ap:
            await self.wait_until(max(r + self.bl + t.rp, act + t.rc, last_needed + 1))
        else:
            # PRECHARGE may go CL-1 clocks before the last wanted word.
            await self.wait_until(max(act + t.ras, last_needed - self.cl + 1))
            p = await self.drv.step("PRE", ba=bank)
            await self.wait_until(max(p + t.rp, act + t.rc, last_needed + 1))
        words = [self.drv.seen[r + self.cl + i][1] for i in range(n)]
        return words, self.burst_cols(col, n)

    async def wait_until(self, edge: int) -> None:
        while self.drv.edge < edge:
            await self.drv.step()

    def expect(self, bank, row, cols) -> list[int]:
        return [self.mem.get((bank, row, c), 0) for c in cols]

    # ---- checker ----
    def errors(self) -> int:
        return int(self.dut.err_count_o.value)

    def log_lines(self) -> list[str]:
        try:
            return self.log_path.read_text().splitlines()
        except FileNotFoundError:
            return []


async def start(dut, tck: int, trc_ps: int = 60000) -> Sdram:
    # Power-on with the pins idle before the first edge (the model checks from edge 0).
    dut.rst_i.value = 1
    dut.cke_i.value = 1
    for name in ("cs_n_i", "ras_n_i", "cas_n_i", "we_n_i"):
        getattr(dut, name).value = 1
    Clock(dut.clk_i, tck, unit="ps").start(start_high=False)
    s = Sdram(dut, Timing(tck, trc_ps), Path(os.environ["SDRAM_LOG"]))
    await s.power_on()
    return s


def tck_of(dut) -> int:
    return int(os.environ.get("SDRAM_TCK", "8000"))


# ---- legal sequences ----------------------------------------------------------------------

async def legal_bursts(dut, cls) -> None:
    tck = tck_of(dut)
    s = await start(dut, tck, int(os.environ.get("SDRAM_TRC", "60000")))
    rng = random.Random(1)
    for cl in cls:
        await s.power_on()
        await s.init(cl=cl, bl=1)
        assert int(dut.init_done_o.value) == 1
        for bl in (1, 2, 4, 8, NCOLS):
            await s.lmr(cl, bl)
            for bank in range(4):
                row = rng.randrange(8192)
                col = rng.randrange(NCOLS)      # unaligned: the burst wraps in its block
                n = bl if bl < NCOLS else 20
                data = [rng.randrange(1 << 16) for _ in range(n)]
                await s.write(bank, row, col, data, n=n)
                words, cols = await s.read(bank, row, col, n=n)
                assert words == s.expect(bank, row, cols), \
                    f"CL{cl} BL{bl} bank {bank}: read {words} expected {s.expect(bank, row, cols)}"
            # Auto-precharge (not with a full page, which the part does not allow).
            if bl < NCOLS:
                data = [rng.randrange(1 << 16) for _ in range(bl)]
                await s.write(2, 77, 5, data, ap=True)
                words, cols = await s.read(2, 77, 5, ap=True)
                assert words == s.expect(2, 77, cols), f"CL{cl} BL{bl} auto-precharge"
        # Byte masks on write: the masked byte keeps its old value.
        await s.lmr(cl, 4)
        await s.write(1, 100, 8, [0x1111, 0x2222, 0x3333, 0x4444])
        await s.write(1, 100, 8, [0xAAAA, 0xBBBB, 0xCCCC, 0xDDDD], dqm=[0, 1, 2, 3])
        words, cols = await s.read(1, 100, 8)
        assert words == [0xAAAA, 0xBB22, 0x33CC, 0x4444], [hex(w) for w in words]
        # Read masks: DQM two clocks before turns the word's driver off.
        words, _ = await s.read(1, 100, 8, dqm_off=(1, 3))
        assert words == [0xAAAA, -1, 0x33CC, -1], words
        # Single-location write bursts (A9) with BL 4 reads.
        await s.lmr(cl, 4, wb_single=True)
        await s.write(3, 9, 2, [0x5A5A])
        words, cols = await s.read(3, 9, 0)
        assert words == s.expect(3, 9, cols)
        # Two banks interleaved: ACT b0, ACT b1 (tRRD), READ b0, READ b1 back to back.
        await s.lmr(cl, 4)
        await s.write(0, 1, 0, [1, 2, 3, 4])
        await s.write(1, 2, 0, [5, 6, 7, 8])
        t = s.t
        a0 = await s.drv.step("ACT", ba=0, a=1)
        await s.drv.nop(t.rrd - 1)
        a1 = await s.drv.step("ACT", ba=1, a=2)
        await s.wait_until(a1 + t.rcd)
        r0 = await s.drv.step("READ", ba=0, a=0)
        await s.drv.nop(3)
        r1 = await s.drv.step("READ", ba=1, a=0 | 1 << 10)
        await s.wait_until(max(a0 + t.ras, r1 + 4 - cl + 1))
        await s.drv.step("PRE", ba=0)
        await s.wait_until(r1 + cl + 4 + t.rp + 2)
        got = [s.drv.seen[r0 + cl + i][1] for i in range(8)]
        assert got == [1, 2, 3, 4, 5, 6, 7, 8], got
        # Refresh in between: legal spacing, the data stays.
        await s.ref()
        words, cols = await s.read(0, 1, 0)
        assert words == [1, 2, 3, 4]
        assert s.errors() == 0, "\n".join(s.log_lines()[-10:])
        dut._log.info("legal bursts CL%d: %d edges, 0 violations", cl, s.drv.edge)


@cocotb.test() if cocotb else (lambda f: f)
async def legal_sequences(dut):
    """Init, write and read back: BL 1/2/4/8/full page, unaligned starts (wrap), CL 3
    (and CL 2 where the clock allows it), auto-precharge, write and read DQM masks,
    single-location writes, two banks interleaved, refresh: every word right, 0 errors."""
    tck = tck_of(dut)
    await legal_bursts(dut, (2, 3) if tck >= 10000 else (3,))


@cocotb.test() if cocotb else (lambda f: f)
async def random_traffic(dut):
    """Random legal traffic: writes and reads of random bursts (BL, bank, row, column,
    masks, auto-precharge), CL changes, refreshes as due; every read equals the mirror."""
    seed = int(os.environ.get("SEED", random.randrange(1 << 32)))
    print(f"random_traffic SEED={seed}  (re-run with SEED={seed})")
    dut._log.info("random_traffic: SEED=%d", seed)
    rng = random.Random(seed)
    tck = tck_of(dut)
    s = await start(dut, tck, int(os.environ.get("SDRAM_TRC", "60000")))
    cls = (2, 3) if tck >= 10000 else (3,)
    await s.init(cl=rng.choice(cls), bl=4)
    written: list[tuple[int, int, int]] = []
    for op in range(int(os.environ.get("SDRAM_RANDOM_OPS", "150"))):
        if s.drv.edge - s.last_ref > s.t.refi:
            await s.ref()
        x = rng.random()
        if x < 0.1:
            await s.lmr(rng.choice(cls), rng.choice((1, 2, 4, 8)))
        elif x < 0.55 or not written:
            bank, row, col = rng.randrange(4), rng.randrange(8192), rng.randrange(NCOLS)
            data = [rng.randrange(1 << 16) for _ in range(s.bl)]
            dqm = [rng.choice((0, 0, 0, 1, 2, 3)) for _ in range(s.bl)]
            await s.write(bank, row, col, data, dqm=dqm, ap=rng.random() < 0.3)
            written.append((bank, row, col))
        else:
            bank, row, col = rng.choice(written)
            words, cols = await s.read(bank, row, col, ap=rng.random() < 0.3)
            exp = s.expect(bank, row, cols)
            assert words == exp, f"SEED={seed} op {op}: read {words} expected {exp}"
    assert s.errors() == 0, f"SEED={seed}: " + "\n".join(s.log_lines()[-10:])
    dut._log.info("random_traffic SEED=%d: %d edges, 0 violations", seed, s.drv.edge)


@cocotb.test() if cocotb else (lambda f: f)
async def refresh_postponed_legal(dut):
    """REFs exactly (RefPostpone+1) x tREFI apart (8 postponed, then caught up): no error."""
    s = await start(dut, tck_of(dut), int(os.environ.get("SDRAM_TRC", "60000")))
    await s.init()
    for _ in range(2):
        await s.wait_until(s.last_ref + s.t.ref_max)
        await s.ref()
    assert s.errors() == 0, "\n".join(s.log_lines()[-5:])


# ---- violations: each sequence commits exactly one -----------------------------------------

async def v_init_wait(s):
    await s.drv.nop(5)
    await s.drv.step("PRE", a=1 << 10)          # inside the 100 us (here 2 us) wait


async def v_init_no_lmr(s):
    await s.init(lmr=False)
    await s.drv.step("ACT", ba=0, a=1)          # no LOAD MODE REGISTER yet


async def v_trcd(s):
    await s.init()
    a = await s.drv.step("ACT", ba=0, a=3)
    await s.wait_until(a + s.t.rcd - 1)
    await s.drv.step("READ", ba=0, a=0)
    await s.wait_until(a + s.t.ras)
    await s.drv.step("PRE", ba=0)


async def v_trp(s):
    await s.init()
    a = await s.drv.step("ACT", ba=0, a=3)
    await s.wait_until(a + s.t.ras)
    p = await s.drv.step("PRE", ba=0)
    await s.wait_until(p + s.t.rp - 1)
    await s.drv.step("ACT", ba=0, a=4)


async def v_tras(s):
    await s.init()
    a = await s.drv.step("ACT", ba=2, a=3)
    await s.wait_until(a + s.t.ras - 1)
    await s.drv.step("PRE", ba=2)


async def v_tras_ap(s):
    await s.init(bl=1)
    a = await s.drv.step("ACT", ba=1, a=3)
    await s.wait_until(a + s.t.rcd)
    await s.drv.step("READ", ba=1, a=1 << 10)   # auto-precharge at READ + 1 < tRAS
    await s.drv.nop(20)


async def v_trrd(s):
    await s.init()
    a = await s.drv.step("ACT", ba=0, a=3)
    await s.wait_until(a + s.t.rrd - 1)
    await s.drv.step("ACT", ba=1, a=3)


async def v_trfc(s):
    await s.init()
    r = await s.drv.step("REF")
    await s.wait_until(r + s.t.rfc - 1)
    await s.drv.step("ACT", ba=0, a=3)


async def v_trfc_ref(s):
    await s.init()
    r = await s.drv.step("REF")
    await s.wait_until(r + s.t.rfc - 1)
    await s.drv.step("REF")


async def v_tmrd(s):
    await s.init()
    m = await s.drv.step("LMR", a=3 << 4 | 2)
    await s.wait_until(m + s.t.mrd - 1)
    await s.drv.step("ACT", ba=0, a=3)


async def v_twr(s):
    await s.init()
    a = await s.drv.step("ACT", ba=3, a=3)
    await s.wait_until(a + s.t.ras - s.t.wr + 1)
    w = await s.drv.step("WRITE", ba=3, a=0, dq=0x1234)
    await s.wait_until(w + s.t.wr - 1)
    await s.drv.step("PRE", ba=3)


async def v_bank_read_idle(s):
    await s.init()
    await s.drv.step("READ", ba=1, a=0)


async def v_bank_act_active(s):
    await s.init()
    a = await s.drv.step("ACT", ba=1, a=3)
    await s.wait_until(a + s.t.rc)
    await s.drv.step("ACT", ba=1, a=4)


async def v_mode_read_before_lmr(s):
    await s.init(lmr=False)
    await s.drv.step("READ", ba=0, a=0)


async def v_mode_bad_cl(s):
    await s.init()
    await s.drv.step("LMR", a=1 << 4)           # CL 1: reserved on this part


async def v_mode_fullpage_ap(s):
    await s.init(bl=NCOLS)
    a = await s.drv.step("ACT", ba=0, a=3)
    await s.wait_until(a + s.t.rcd)
    await s.drv.step("READ", ba=0, a=1 << 10)   # full page with auto-precharge
    await s.drv.step("BST")
    await s.drv.nop(20)


async def v_mode_cl2_too_fast(s):
    await s.init()
    await s.drv.step("LMR", a=2 << 4)           # CL 2 at 125 MHz: tCK(2) is 10 ns


async def v_refresh(s):
    await s.init()
    await s.wait_until(s.last_ref + s.t.ref_max + 2)


async def v_dq(s):
    await s.init(bl=4)
    a = await s.drv.step("ACT", ba=0, a=3)
    await s.wait_until(a + s.t.rcd)
    r = await s.drv.step("READ", ba=0, a=0)
    await s.wait_until(r + s.cl)                 # read data is on DQ now
    w = await s.drv.step("WRITE", ba=0, a=0, dq=1)  # ... and no DQM masked it
    await s.wait_until(max(a + s.t.ras, w + 3 + s.t.wr))
    await s.drv.step("PRE", ba=0)


async def v_cke(s):
    await s.init()
    await s.drv.step(cke=0)


async def v_tras_max(s):
    # A row open 120 us: the refresh interval (9 x 7.8 us) is broken first, necessarily.
    await s.init()
    a = await s.drv.step("ACT", ba=0, a=3)
    await s.wait_until(a + s.t.ras_max + 3)


async def v_trc(s):
    await s.init()
    a = await s.drv.step("ACT", ba=0, a=3)
    await s.wait_until(a + s.t.ras)
    p = await s.drv.step("PRE", ba=0)
    await s.wait_until(max(p + s.t.rp, a + s.t.rc - 1))
    assert s.drv.edge < a + s.t.rc, "tRC is implied by tRAS + tRP in this build"
    await s.drv.step("ACT", ba=0, a=4)


VIOLATIONS_125 = [  # (name, sequence, expected codes in order)
    ("init_wait", v_init_wait, ["INIT"]),
    ("init_act_before_lmr", v_init_no_lmr, ["INIT"]),
    ("trcd", v_trcd, ["TRCD"]),
    ("trp", v_trp, ["TRP"]),
    ("tras", v_tras, ["TRAS"]),
    ("tras_auto_precharge", v_tras_ap, ["TRAS"]),
    ("trrd", v_trrd, ["TRRD"]),
    ("trfc_act", v_trfc, ["TRFC"]),
    ("trfc_ref", v_trfc_ref, ["TRFC"]),
    ("tmrd", v_tmrd, ["TMRD"]),
    ("twr", v_twr, ["TWR"]),
    ("bank_read_idle", v_bank_read_idle, ["BANK"]),
    ("bank_act_active", v_bank_act_active, ["BANK"]),
    ("mode_read_before_lmr", v_mode_read_before_lmr, ["MODE"]),
    ("mode_cl_reserved", v_mode_bad_cl, ["MODE"]),
    ("mode_fullpage_auto_precharge", v_mode_fullpage_ap, ["MODE"]),
    ("mode_cl2_too_fast", v_mode_cl2_too_fast, ["MODE"]),
    ("refresh_interval", v_refresh, ["REFRESH"]),
    ("dq_contention", v_dq, ["DQ"]),
    ("cke_low", v_cke, ["CKE"]),
    ("tras_max", v_tras_max, ["REFRESH", "TRAS_MAX"]),
]
VIOLATIONS_100 = [("trc", v_trc, ["TRC"])]


async def run_violations(dut, table) -> None:
    tck = tck_of(dut)
    s = await start(dut, tck, int(os.environ.get("SDRAM_TRC", "60000")))
    only = os.environ.get("SDRAM_VIOLATION")
    for name, seq, expect in table:
        if only and name != only:
            continue
        await s.power_on()
        n_log = len(s.log_lines())
        await seq(s)
        await s.drv.nop(3)
        lines = s.log_lines()[n_log:]
        got = [ln.split(": ")[2] for ln in lines]
        assert s.errors() == len(expect) and got == expect, \
            f"{name}: expected {expect}, model reported {s.errors()}:\n" + "\n".join(lines)
        assert int(dut.err_code_o.value) == CODES[expect[-1]]
        seen = int(dut.err_seen_o.value)
        assert seen == sum(1 << CODES[e] for e in set(expect)), f"{name}: err_seen {seen:#x}"
        dut._log.info("%-30s -> %s", name, " | ".join(lines))


@cocotb.test() if cocotb else (lambda f: f)
async def violations(dut):
    """Each sequence commits exactly the named violation: the counter goes up by exactly
    the expected number and the log names it (code, cycle, what)."""
    await run_violations(dut, VIOLATIONS_125 if tck_of(dut) == 8000 else VIOLATIONS_100)


# ---- pytest runner --------------------------------------------------------------------------

BUILDS = {
    # 125 MHz, the part's -6A timings (the board's clock, docs/sdram.md).
    "tck8000": ({"TckPs": 8000, "TinitNs": 2000}, {"SDRAM_TCK": "8000"}),
    # 100 MHz (CL 2 legal) with tRC 90 ns > tRAS + tRP, for the tRC check.
    "tck10000": ({"TckPs": 10000, "TinitNs": 2000, "TrcPs": 90000},
                 {"SDRAM_TCK": "10000", "SDRAM_TRC": "90000"}),
}


def _run(build: str) -> None:
    from cocotb_tools.runner import get_runner

    params, env = BUILDS[build]
    build_dir = HERE / f"sim_build_{build}"
    log = build_dir / "sdram_sdr16.log"
    runner = get_runner("verilator")
    # As tb/common/run.py's build_and_test (ccache through OBJCACHE, tb/conftest.py), plus
    # the +sdram_log plusarg that it has no argument for.
    from common.run import rtl_files
    srcs = [str(f) for f in rtl_files("diffengine:sim:sdram_sdr16")]   # sim/models/sdram_sdr16.core
    runner.build(sources=srcs, hdl_toplevel="sdram_sdr16", parameters=params,
                 build_dir=build_dir,
                 build_args=["-Wno-fatal", "-MAKEFLAGS", "CFG_CXXFLAGS_PCH_I=-include"])
    env = dict(env, SDRAM_LOG=str(log),
               PYTHONPATH=os.pathsep.join([str(HERE), str(HERE.parent), str(ROOT / "sw")]))
    runner.test(hdl_toplevel="sdram_sdr16", test_module="test_sdram_model",
                build_dir=build_dir, test_dir=HERE, extra_env=env,
                plusargs=[f"+sdram_log={log}"], results_xml=str(build_dir / "results.xml"))
    if build == "tck8000":
        _run_preload(runner, build_dir, env)


def _run_preload(runner, build_dir: Path, env: dict) -> None:
    """The back-door preload (test_sdram_preload.py) on the same build: a random image
    (SEED replays it) read back through READs; then a malformed image must stop the
    simulation with an error naming the file and line."""
    import json
    import subprocess

    from test_sdram_preload import write_image
    s = int(os.environ.get("SEED", random.randrange(1 << 30)))
    print(f"SEED={s}")
    image = build_dir / "preload.hex"
    words = write_image(image, random.Random(s))
    (build_dir / "preload.json").write_text(json.dumps({str(a): w for a, w in words.items()}))
    results = build_dir / "results_preload.xml"
    runner.test(hdl_toplevel="sdram_sdr16", test_module="test_sdram_preload",
                build_dir=build_dir, test_dir=HERE, results_xml=str(results),
                extra_env=dict(env, SDRAM_IMAGE_JSON=str(build_dir / "preload.json")),
                plusargs=[f"+sdram_log={build_dir / 'preload.log'}", f"+sdram_image={image}"])
    text = results.read_text()
    assert 'name="preload"' in text and "<failure" not in text, text
    # A malformed line: the model's $fatal names file and line (run the simulator binary
    # directly: no cocotb test is needed for an error at time 0).
    bad = build_dir / "bad.hex"
    bad.write_text("# ok\n000010 12345678\n000011 zz\n")
    exe = build_dir / "sdram_sdr16"                     # the runner's -o
    r = subprocess.run([str(exe), f"+sdram_image={bad}"], capture_output=True, text=True,
                       timeout=60, env=dict(os.environ, COCOTB_TEST_MODULES="test_sdram_preload",
                                            TOPLEVEL="sdram_sdr16", SDRAM_IMAGE_JSON="-"))
    out = r.stdout + r.stderr
    assert r.returncode != 0 and f"{bad}:3: want '<addr> <word>' in hex" in out, out


try:
    import pytest

    @pytest.mark.parametrize("build", list(BUILDS))
    def test_sdram_model(build):
        _run(build)
except ImportError:  # pragma: no cover
    pass
