"""UART receiver rtl/board/de_uart_rx.sv at the board's 78.125 MHz / 3 Mbaud (26 clocks
per bit), cocotb on Verilator, and de_uart_link's elaboration check of the bit period
(verilator --lint-only).

test_rx_line (toplevel de_uart_rx, run by test_rx): random bytes sent at 3 Mbaud x (1 + skew), skew drawn
from +-1.5 % per byte, arrive exactly, one valid pulse each, no framing error; a low
glitch shorter than half a bit (1..12 clocks) yields neither byte nor error, and the
byte after it arrives; a stop bit of 0 gives one frame_err_o pulse and no byte, and the
receiver takes the next byte once the line is idle again.
test_rate_check: de_uart_link at 78.125 MHz and 76.5 MHz (1.96 % off) elaborates; at
25 MHz (8.33 clocks per bit, 4 % off) and 40 MHz (2.5 %) elaboration fails with the reason.
test_bit_period_range: de_uart_rx refuses fewer than 4 clocks per bit, de_uart_tx 0.
SEED=<n> replays.
"""
from __future__ import annotations

import random
import shutil
import subprocess
import sys
from pathlib import Path

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, Timer

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
CLK_HZ, BAUD = 78_125_000, 3_000_000   # the board's UART clock and rate


class Mon:
    def __init__(self, dut):
        self.dut, self.bytes, self.ferr = dut, [], 0
        cocotb.start_soon(self._run())

    async def _run(self):
        while True:
            await RisingEdge(self.dut.clk_i)
            if int(self.dut.valid_o.value):
                self.bytes.append(int(self.dut.data_o.value))
            if int(self.dut.frame_err_o.value):
                self.ferr += 1


async def send(dut, b: int, bit_ps: int, stop: int = 1) -> None:
    for bit in [0] + [(b >> i) & 1 for i in range(8)] + [stop]:
        dut.rx_i.value = bit
        await Timer(bit_ps, unit="ps")
    dut.rx_i.value = 1
    await Timer(bit_ps, unit="ps")


@cocotb.test()
async def test_rx_line(dut):
    from common.run import seed_from_env
    rng = random.Random(seed_from_env())
    cpb = int(dut.ClkPerBit.value)
    assert cpb == (CLK_HZ + BAUD // 2) // BAUD, cpb
    clk_ps = round(1e12 / CLK_HZ)
    bit = round(1e12 / BAUD)
    cocotb.start_soon(Clock(dut.clk_i, clk_ps, unit="ps").start())
    dut.rx_i.value = 1
    dut.rst_i.value = 1
    await ClockCycles(dut.clk_i, 4)
    dut.rst_i.value = 0
    mon = Mon(dut)
    want = []
    for _ in range(60):
        b = rng.randrange(256)
        await send(dut, b, round(bit * (1 + rng.uniform(-0.015, 0.015))))
        want.append(b)
    await ClockCycles(dut.clk_i, 2 * cpb)
    assert mon.bytes == want and mon.ferr == 0, (mon.bytes, want, mon.ferr)

    for glitch in range(1, cpb // 2 - 1):
        mon.bytes.clear()
        dut.rx_i.value = 0
        await ClockCycles(dut.clk_i, glitch)
        dut.rx_i.value = 1
        await Timer(12 * bit, unit="ps")
        assert mon.bytes == [] and mon.ferr == 0, f"glitch of {glitch} clocks: {mon.bytes}"
        await send(dut, 0xA5 ^ glitch, bit)
        await ClockCycles(dut.clk_i, 2 * cpb)
        assert mon.bytes == [0xA5 ^ glitch], f"byte after a {glitch}-clock glitch: {mon.bytes}"

    mon.bytes.clear()
    await send(dut, 0x3C, bit, stop=0)
    await ClockCycles(dut.clk_i, 2 * cpb)
    assert mon.ferr == 1 and mon.bytes == [], (mon.ferr, mon.bytes)
    await send(dut, 0xC3, bit)
    await ClockCycles(dut.clk_i, 2 * cpb)
    assert mon.bytes == [0xC3] and mon.ferr == 1
    dut._log.info(f"{len(want)} skewed bytes, glitches 1..{cpb // 2 - 2} clocks rejected, "
                  f"framing error reported (ClkPerBit {cpb})")


def test_rx():
    from common.run import build_and_test, rtl_files
    build_and_test(HERE, "de_uart_rx", rtl_files("board", "uart"),
                   "test_uart",
                   parameters=dict(ClkPerBit=(CLK_HZ + BAUD // 2) // BAUD), testcase="test_rx_line")


@pytest.mark.parametrize("clk_hz,ok", [(78_125_000, True), (76_500_000, True),
                                       (25_000_000, False), (40_000_000, False)])
def test_rate_check(clk_hz, ok, tmp_path):
    """de_uart_link's elaboration (no -Wno-fatal, as in lint and synthesis) passes iff the
    error < 2 %."""
    from common.run import rtl_files
    vl = shutil.which("verilator")
    assert vl, "verilator not on PATH"
    r = subprocess.run([vl, "--lint-only", "-Wall", f"-GClkHz={clk_hz}", "-GBaud=3000000",
                        "--top-module", "de_uart_link", *map(str, rtl_files("board", "uart")), "--Mdir", str(tmp_path)],
                       capture_output=True, text=True)
    if ok:
        assert r.returncode == 0, r.stderr
    else:
        assert r.returncode != 0, f"{clk_hz} Hz elaborated: {r.stderr}"
        assert "off by 2 % or more" in r.stderr and "mid-bit sampling" in r.stderr, r.stderr


@pytest.mark.parametrize("mod,cpb,ok", [("de_uart_rx", 3, False), ("de_uart_rx", 4, True),
                                        ("de_uart_tx", 0, False), ("de_uart_tx", 1, True)])
def test_bit_period_range(mod, cpb, ok, tmp_path):
    """The halves alone: the receiver needs 4 clocks per bit or more (half a bit to reject
    a glitch), the transmitter 1 or more."""
    from common.run import rtl_files
    vl = shutil.which("verilator")
    assert vl, "verilator not on PATH"
    r = subprocess.run([vl, "--lint-only", "-Wall", f"-GClkPerBit={cpb}", "--top-module", mod,
                        *map(str, rtl_files("board", "uart")), "--Mdir", str(tmp_path)],
                       capture_output=True, text=True)
    assert (r.returncode == 0) == ok, r.stderr
    if not ok:
        assert f"{mod}: ClkPerBit must be" in r.stderr, r.stderr
