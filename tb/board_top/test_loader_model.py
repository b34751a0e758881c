"""The host tool's simulated board, fpga/ulx3s/loader_model.py, against the RTL it models,
rtl/board/de_loader.sv (cocotb on Verilator, toplevel de_loader).

One random byte stream drives both, byte by byte: valid 'X' 'F' 'Q' 'O' 'R' 'S' commands
(loader version 2), commands with a flipped byte (checksum error), bad fields (colour 3,
window 5, an offset past the 2^21-word region, a word run crossing its end, 0 words, a
table offset not a multiple of 4, slot 64, a sequence past slot 63, hold 0, loop 2),
garbage bytes between commands (the retired 'W' and 'P' among them), UART framing errors
inside commands, and commands cut short and left idle until the loader abandons them.
The reply bytes, every word the RTL sends to the SDRAM side (colour, offset, word), the
slots, the sequence and the output window must be identical. A mismatch names the step
and the command.
SEED=<n> replays.
"""
from __future__ import annotations

import random
import sys
from pathlib import Path

import cocotb
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

HERE = Path(__file__).resolve().parent
ULX = HERE.parent.parent / "fpga" / "ulx3s"
sys.path.insert(0, str(ULX))

import de32_load as dl  # noqa: E402
from loader_model import REGION, LoaderModel  # noqa: E402

REG = 0xDC310004


def random_command(rng: random.Random) -> tuple[str, bytes]:
    k = rng.randrange(12)
    if k < 4:
        ch = 3 if rng.random() < 0.1 else rng.randrange(3)
        n = rng.randrange(0, 6)
        off = rng.choice([rng.randrange(64), REGION - rng.randrange(1, 8),
                          REGION + rng.randrange(4), rng.randrange(REGION)])
        return "X", dl.cmd_x(ch, off, [rng.randrange(1 << 32) for _ in range(n)])
    if k < 6:
        bad = rng.random() < 0.3
        return "F", dl.cmd_f(rng.randrange(4) if bad else rng.randrange(3),
                             rng.randrange(66) if bad else rng.randrange(64),
                             rng.choice([rng.randrange(REGION), 4 * rng.randrange(REGION // 4),
                                         REGION + 4 * rng.randrange(4)]),
                             rng.randrange(6) if bad else rng.randrange(5), rng.random() < 0.5)
    if k < 7:
        if rng.random() < 0.3:
            return "Q", dl.with_chk(b"Q" + bytes(rng.randrange(256) for _ in range(4)))
        first = rng.randrange(64)
        return "Q", dl.cmd_q(first, rng.randrange(1, 65 - first), rng.randrange(1, 256),
                             rng.random() < 0.5)
    if k < 8:
        # A version-1 command: its bytes are garbage to version 2 (counted, skipped).
        return "old", dl.with_chk(b"W" + bytes([0, 0, 1, 0, 1]) + bytes(4))
    if k < 7:
        return "O", dl.with_chk(b"O" + bytes([rng.randrange(6), rng.randrange(2)]))
    if k < 8:
        return "R", dl.with_chk(b"R" + rng.randrange(1 << 14).to_bytes(2, "big"))
    if k < 9:
        return "S", dl.with_chk(b"S")
    return "garbage", bytes([rng.choice([0x00, 0x41, 0xFF, 0x4A])])


@cocotb.test()
async def test_model_equals_rtl(dut):
    from common.run import hold_reset, seed_from_env
    rng = random.Random(seed_from_env())
    tmo = 1 << int(dut.TimeoutBits.value)
    await hold_reset(dut, 3, falling=False, clock_ns=10,
                     rx_valid_i=0, rx_ferr_i=0, frame_i=0, align_err_i=0, rx_data_i=0,
                     pending_i=0, pix_collision_i=0, sd_cmd_ready_i=1, malformed_i=0, late_i=0,
                     reg_rdata_i=REG, tx_ready_i=1)

    model = LoaderModel(regs={a: REG for a in range(1 << 14)})
    rtl_mem: list[dict] = [{}, {}, {}]
    rtl_slots: list[dict] = [{}, {}, {}]
    rtl_seq = [None]
    rtl_tx = bytearray()

    async def watch():
        while True:
            await RisingEdge(dut.clk_i)
            await ReadOnly()
            if int(dut.tx_valid_o.value) and int(dut.tx_ready_i.value):
                rtl_tx.append(int(dut.tx_data_o.value))
            if int(dut.sd_cmd_valid_o.value):
                v = int(dut.sd_cmd_o.value)
                typ, ch = v >> 55, v >> 53 & 3
                if typ == 1:                                   # X word
                    rtl_mem[ch][v >> 32 & (REGION - 1)] = v & 0xFFFFFFFF
                elif typ == 2:                                 # F
                    rtl_slots[ch][v >> 47 & 63] = (v >> 26 & (REGION - 1), v >> 23 & 7,
                                                   bool(v >> 22 & 1))
                elif typ == 3:                                 # Q
                    rtl_seq[0] = (v >> 47 & 63, v >> 40 & 127, v >> 32 & 255, v >> 31 & 1)
                else:
                    raise AssertionError(f"command type 0 from the loader: {v:#x}")
    cocotb.start_soon(watch())

    async def byte(b: int, ferr: bool = False):
        await RisingEdge(dut.clk_i)
        dut.rx_valid_i.value = 0 if ferr else 1
        dut.rx_ferr_i.value = 1 if ferr else 0
        dut.rx_data_i.value = b
        await RisingEdge(dut.clk_i)
        dut.rx_valid_i.value = 0
        dut.rx_ferr_i.value = 0
        await ClockCycles(dut.clk_i, 4)

    want_tx = bytearray()
    kinds: dict[str, int] = {}
    for step in range(300):
        what, pkt = random_command(rng)
        fault = rng.random()
        data = bytearray(pkt)
        cut = None
        ferr_at = None
        if what != "garbage" and fault < 0.1:
            data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
            what += "+flip"
        elif what != "garbage" and fault < 0.17 and len(data) > 2:
            cut = rng.randrange(1, len(data) - 1)
            what += f"+cut{cut}"
        elif what != "garbage" and fault < 0.22 and len(data) > 2:
            ferr_at = rng.randrange(1, len(data) - 1)
            what += f"+ferr{ferr_at}"
        key = what.rstrip("0123456789")
        kinds[key] = kinds.get(key, 0) + 1
        for k, b in enumerate(data[:cut]):
            if k == ferr_at:
                await byte(0, ferr=True)
                model.framing_error()
                continue
            await byte(b)
            want_tx += model.feed(bytes([b]))
        if cut is not None or ferr_at is not None:
            await ClockCycles(dut.clk_i, tmo + 8)      # the loader abandons it: 'T'
            want_tx += model.idle()
        await ClockCycles(dut.clk_i, 40)               # the reply leaves (<= 16 bytes)
        assert bytes(rtl_tx) == bytes(want_tx), (
            f"step {step} ({what}, {pkt.hex()}): RTL replies {bytes(rtl_tx[-20:]).hex()} "
            f"model {bytes(want_tx[-20:]).hex()}")
        assert rtl_mem == model.mem, f"step {step} ({what}): SDRAM words differ"
        assert rtl_slots == model.slots, f"step {step} ({what}): slots differ"
        assert rtl_seq[0] == model.sequence, f"step {step} ({what}): sequences differ"
    assert int(dut.out8_shift_o.value) == model.out8[0]
    assert int(dut.out8_sat_o.value) == model.out8[1]
    # A flipped length field can leave a command open across the last steps: let both
    # abandon it ('T') before the final status request.
    await ClockCycles(dut.clk_i, tmo + 8)
    want_tx += model.idle()
    await ClockCycles(dut.clk_i, 40)
    assert bytes(rtl_tx) == bytes(want_tx), "the final abandon differs"
    st = model.feed(dl.with_chk(b"S"))
    await byte(0x53)
    await byte(0xAD)
    await ClockCycles(dut.clk_i, 40)
    assert bytes(rtl_tx[-16:]) == st, f"status: RTL {bytes(rtl_tx[-16:]).hex()} model {st.hex()}"
    assert st[4:10] != b"\0" * 6, "no error was counted: the injections did not happen"
    assert model.writes > 50 and any(model.slots) and model.sequence is not None, \
        "too few valid X / F / Q: the comparison is weak"
    dut._log.info(f"300 commands, replies, SDRAM words, slots and sequence identical "
                  f"({model.writes} words written, {sum(map(len, model.slots))} slots); "
                  f"status {st.hex()}; kinds {kinds}")


def test_loader_model():
    from common.run import RTL, build_and_test
    build_and_test(HERE, "de_loader", [RTL / "board" / "de_loader.sv"], "test_loader_model",
                   parameters=dict(TimeoutBits=6), testcase="test_model_equals_rtl")
