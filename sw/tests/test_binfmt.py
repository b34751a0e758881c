"""Binary formats, deserialisation and the frame-store data mapper (docs/isa.md §8)."""
import random

import pytest
from hypothesis import given, settings, strategies as st

from diffengine.formats import binfmt
from diffengine import isa
from diffengine.formats.asm import AsmError, format_command, parse_text
from diffengine.formats.binfmt import map_word
from diffengine.formats.disasm import disassemble, list_slots
from diffengine.isa import Command

M36 = isa.WORD_MASK

# ---- strategies (also used by test_cli / test_fuzz_parser) --------------------------


def commands_st(addr_max=isa.ADDR_MAX, value=None, eval0=None):
    """Random valid commands; `value`/`eval0` restrict the operands (for the frame store)."""
    xs = st.integers(0, addr_max)
    value = value if value is not None else st.integers(-(1 << 35), (1 << 35) - 1)
    eval0 = eval0 if eval0 is not None else st.integers(0, 4095)
    return st.one_of(
        st.builds(lambda x, dx, i: Command("EVAL0", x, dx, (i,)), xs, xs, eval0),
        st.builds(lambda x, dx, v: Command("EVAL", x, dx, tuple(v)), xs, xs,
                  st.lists(value, min_size=1, max_size=isa.MAX_EVAL_ORDER + 1)),
        st.builds(lambda op, x, dx, v: Command(op, x, dx, (v,)),
                  st.sampled_from(["SETI", "SETDI", "SETDDI", "SETPI", "SETPDI", "SETPDDI"]),
                  xs, xs, value),
        st.builds(lambda x, dx: Command("DIS", x, dx), xs, xs),
        st.builds(lambda v: Command("ACCMODE", values=(v,)), st.sampled_from([0, 1])),
        st.just(Command("REFRESH")),
        st.just(Command("NOP")),
    )


def fs_commands_st(window):
    """Commands that the frame store at `window` can hold exactly."""
    low = 4 + window
    value = st.integers(-(1 << 26), (1 << 26) - 1).map(lambda q: q << low)
    eval0 = st.integers(0, 63).map(lambda i: i << window)
    return commands_st(1023, value, eval0)


# ---- .de48 ------------------------------------------------------------------------


@settings(max_examples=150, deadline=None)
@given(st.lists(commands_st(), max_size=12))
def test_de48_round_trip_through_text(cmds):
    slots = isa.serialise(cmds)
    blob = binfmt.encode_de48(slots)
    assert blob[:8] == b"DE48\x00\x01\x00\x00"
    assert len(blob) == 8 + 6 * len(slots)
    back = binfmt.deserialise(binfmt.decode_de48(blob, "x.de48"), "x.de48")
    assert back == cmds
    text = disassemble(back)
    assert parse_text(text) == cmds               # asm -> bin -> disasm -> asm, exact
    assert parse_text(disassemble(back, unit=3)) == cmds


def test_de48_word_layout():
    blob = binfmt.encode_de48([(isa.ADDR_RANGE, 5 | 7 << 12), (isa.D_A, M36)])
    assert blob[8:14] == bytes.fromhex("800000007005")
    assert blob[14:20] == bytes.fromhex("444fffffffff")


@pytest.mark.parametrize("blob,where,msg", [
    (b"DE4", "byte 0", "too short"),
    (b"DE49\0\x01\0\0", "byte 0", "bad magic"),
    (b"DE48\0\x02\0\0", "byte 4", "version"),
    (b"DE48\0\x01\0\x01", "byte 6", "reserved"),
    (b"DE48\0\x01\0\0" + bytes(6) + b"\x01\x00", "byte 14", "truncated"),
])
def test_de48_bad_files(blob, where, msg):
    with pytest.raises(AsmError) as e:
        binfmt.decode_de48(blob, "f.de48")
    assert str(e.value).startswith(f"f.de48:{where}: ") and msg in str(e.value)


R = (isa.ADDR_RANGE, 1 | 2 << 12)


@pytest.mark.parametrize("slots,index,msg", [
    ([(isa.D_A, 0)], 0, "without a preceding address"),
    ([(isa.ACC, 0)], 0, "without a preceding address"),
    ([(isa.NOP, 0), (0x123, 0)], 1, "unknown identifier"),
    ([(isa.NOP, 5)], 0, "nonzero data"),
    ([(isa.REFRESH, 1 << 35)], 0, "nonzero data"),
    ([R], 0, "missing"),
    ([R, (isa.D_A, 0)], 1, "not closed by ACC"),
    ([R, (isa.D_A, 0), (isa.NOP, 0)], 2, "not closed by ACC"),
    ([R, (isa.D_B, 0), (isa.ACC, 0)], 1, "not a Table 7.2 sequence"),
    ([R, (isa.D_A, 0), (isa.D_B, 0), (isa.ACC, 0)], 1, "not a Table 7.2 sequence"),
    ([R, (isa.ACC, 0)], 1, "not a Table 7.2 sequence"),
    ([R, (isa.D_A, 0), (isa.ACC, 1)], 2, "ACC carries"),
    ([R, *[(isa.D_A_A_NP, 0)] * 9, (isa.ACC, 0)], 9, "not closed by ACC"),
    ([(isa.ADDR_PERIODIC, 1), (isa.D_A, 0), (isa.ACC, 0)], 1, "only SET"),
    ([(isa.ADDR_RANGE, 1 << 24), (isa.SET_A, 0)], 0, "block 2"),
    ([(isa.ADDR_DIS, 1 << 30)], 0, "block 2"),
])
def test_deserialise_rejects_malformed_streams(slots, index, msg):
    with pytest.raises(AsmError) as e:
        binfmt.deserialise(slots, "s.de48")
    assert str(e.value).startswith(f"s.de48:slot {index}: "), str(e.value)
    assert msg in str(e.value)


def test_deserialise_every_eval_order_and_set():
    for p in range(isa.MAX_EVAL_ORDER + 1):
        c = Command("EVAL", 3, 4, tuple(range(-p, 1)))
        assert binfmt.deserialise(isa.slots(c)) == [c]
    per = Command("SETPDI", 5, 9, (-1,))
    assert isa.slots(per)[0] == (isa.ADDR_PERIODIC, 9 | 5 << 12)  # period in block 0
    assert binfmt.deserialise(isa.slots(per)) == [per]


def test_list_slots():
    text = list_slots(isa.slots(Command("EVAL", 1, 2, (ONE := 1 << 24,))))
    assert "ADDR_RANGE" in text and "b0=1" in text and "D_A" in text and "ACC" in text
    assert f"{isa.format_fixed(ONE)}" in text


# ---- the data mapper ------------------------------------------------------------------

W = range(5)
# intensity operand -> 36-bit data, by hand from §8 (sign-extend 5-w bits, pad 4+w zeros)
HAND_INTENSITY = {
    0x0000001: [0x000000010, 0x000000020, 0x000000040, 0x000000080, 0x000000100],
    0x7FFFFFF: [0xFFFFFFFF0, 0xFFFFFFFE0, 0xFFFFFFFC0, 0xFFFFFFF80, 0xFFFFFFF00],
    0x4000000: [0xFC0000000, 0xF80000000, 0xF00000000, 0xE00000000, 0xC00000000],
    0x3FFFFFF: [0x03FFFFFF0, 0x07FFFFFE0, 0x0FFFFFFC0, 0x1FFFFFF80, 0x3FFFFFF00],
    0x0100000: [0x001000000, 0x002000000, 0x004000000, 0x008000000, 0x010000000],  # 1 window LSB
}
# 7-bit Eval0 field -> 12-bit pixel (sign-extend 5-w bits, pad w zeros)
HAND_EVAL0 = {
    0x01: [0x001, 0x002, 0x004, 0x008, 0x010],
    0x3F: [0x03F, 0x07E, 0x0FC, 0x1F8, 0x3F0],
    0x40: [0xFC0, 0xF80, 0xF00, 0xE00, 0xC00],
    0x7F: [0xFFF, 0xFFE, 0xFFC, 0xFF8, 0xFF0],
}


@pytest.mark.parametrize("w", W)
def test_mapper_intensity_by_hand(w):
    for op, want in HAND_INTENSITY.items():
        for idx in range(9, 19):  # every intensity-type LUT entry
            assert map_word(idx << 27 | op, w) == (isa.LUT[idx][1], want[w])


@pytest.mark.parametrize("w", W)
def test_mapper_address_and_eval0_by_hand(w):
    for op7, pix in HAND_EVAL0.items():
        word = 6 << 27 | op7 << 20 | 1000 << 10 | 1023
        assert map_word(word, w) == (isa.ADDR_EVAL0, pix[w] << 24 | 1000 << 12 | 1023)
    assert map_word(4 << 27 | 5 << 10 | 1023, w) == (isa.ADDR_RANGE, 5 << 12 | 1023)
    assert map_word(5 << 27 | 5 << 10 | 7, w) == (isa.ADDR_PERIODIC, 5 << 12 | 7)
    assert map_word(7 << 27 | 3 << 10 | 2, w, True) == (isa.ADDR_DIS, 3 << 12 | 2)


@pytest.mark.parametrize("w", W)
def test_mapper_none_type_and_unused_indices(w):
    for idx, ident in [(0, isa.NOP), (1, isa.REFRESH), (2, isa.ACCMODE_ON),
                       (3, isa.ACCMODE_OFF), (8, isa.ACC)]:
        assert map_word(idx << 27 | 0x5A5A5A5, w, True) == (ident, 0)
    for idx in range(19, 32):
        assert map_word(idx << 27 | 0x7FFFFFF, w, True) == (isa.NOP, 0)


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 4), st.integers(9, 18), st.integers(0, (1 << 27) - 1))
def test_mapper_compensation_matches_isa(w, idx, op):
    ident, plain = map_word(idx << 27 | op, w)
    signed = (op - (1 << 27) if op >> 26 else op) << (4 + w)
    assert plain == signed & M36
    assert map_word(idx << 27 | op, w, True) == (ident, isa.to_word(isa.compensate(signed)))


def test_mapper_compensation_table_7_5_values():
    # dI = 0.5 pixel at window 0: operand 0.5 * 2^20 -> data 0x000.800000 -> comp 0x000.400000
    assert map_word(10 << 27 | 1 << 19, 0, True) == (isa.D_B, 0x000400000)
    # negative: -0.5 -> 0xfff.800000 -> fraction halved, no sign fill (isa.md §7)
    assert map_word(10 << 27 | ((-(1 << 19)) & 0x7FFFFFF), 0, True) == (isa.D_B, 0xFFF400000)


def test_mapper_rejects_bad_arguments():
    with pytest.raises(ValueError):
        map_word(1 << 32, 0)
    with pytest.raises(ValueError):
        map_word(0, 5)


# ---- frame-store encoding -----------------------------------------------------------


@pytest.mark.parametrize("w", W)
@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_framestore_round_trip(w, data):
    cmds = data.draw(st.lists(fs_commands_st(w), max_size=10))
    words = binfmt.framestore_encode(cmds, w)
    assert len(words) == len(isa.serialise(cmds))
    blob = binfmt.encode_de32(words, w, compensate=True)
    assert blob[:8] == b"DE32\x00\x01" + bytes([w, 1])
    words2, w2, comp = binfmt.decode_de32(blob, "f.de32")
    assert (words2, w2, comp) == (words, w, True)
    assert binfmt.deserialise(binfmt.framestore_slots(words, w)) == cmds
    # with compensation: exactly isa.compensate on every intensity slot
    comp_slots = binfmt.framestore_slots(words, w, True)
    assert comp_slots == binfmt.compensate_slots(isa.serialise(cmds))


def test_framestore_word_layout():
    cmd = Command("EVAL", 3, 4, (1 << 24,))  # I = 1.0 pixel at window 1: operand 1 << 19
    assert binfmt.framestore_encode([cmd], 1) == [4 << 27 | 4 << 10 | 3, 9 << 27 | 1 << 19,
                                                  8 << 27]
    per = Command("SETPI", 10, 7, (0,))
    assert binfmt.framestore_encode([per], 0)[0] == 5 << 27 | 10 << 10 | 7
    e0 = Command("EVAL0", 1, 2, (20,))
    assert binfmt.framestore_encode([e0], 2) == [6 << 27 | 5 << 20 | 2 << 10 | 1]


@pytest.mark.parametrize("cmd,w,msg", [
    (Command("EVAL", 1024, 1, (0,)), 0, "X = 1024"),
    (Command("DIS", 0, 1024), 0, "dX = 1024"),
    (Command("SETPI", 1, 2000, (0,)), 0, "dX = 2000"),
    (Command("EVAL", 0, 1, (1 << 3,)), 0, "precision below bit 4"),
    (Command("EVAL", 0, 1, (1 << 7,)), 4, "precision below bit 8"),
    (Command("SETI", 0, 1, (64 << 24,)), 0, "27-bit"),
    (Command("SETI", 0, 1, (-(65 << 24),)), 0, "27-bit"),
    (Command("EVAL0", 0, 1, (64,)), 0, "7-bit"),
    (Command("EVAL0", 0, 1, (3,)), 1, "7-bit"),
])
def test_framestore_refuses_what_does_not_fit(cmd, w, msg):
    cmd = Command(cmd.op, cmd.x, cmd.dx, cmd.values, line=7)
    with pytest.raises(AsmError) as e:
        binfmt.framestore_encode([Command("NOP"), cmd], w, "f.cmd")
    assert str(e.value).startswith("f.cmd:7: ") and msg in str(e.value)


def test_framestore_edges_that_fit():
    w = 0
    ok = [Command("SETI", 0, 1, (-(64 << 24),)), Command("SETI", 0, 1, ((64 << 24) - 16,)),
          Command("EVAL0", 1023, 1023, (63,)), Command("EVAL0", 0, 0, (4095,))]
    words = binfmt.framestore_encode(ok, w)
    assert binfmt.deserialise(binfmt.framestore_slots(words, w)) == ok


def test_framestore_reports_every_bad_command():
    cmds = parse_text("Eval1 (2000, 1, 0)\nNop\nEval1 (0, 1, 0x000.000001)\n", "g.cmd")
    with pytest.raises(AsmError) as e:
        binfmt.framestore_encode(cmds, 0, "g.cmd")
    assert [w for w, _ in e.value.errors] == [1, 3]


@pytest.mark.parametrize("blob,where", [
    (b"DE32\0\x01\x05\0", "byte 6"),
    (b"DE32\0\x01\x00\x02", "byte 7"),
    (b"DE32\0\x01\x00\x00\0\0\0", "byte 8"),
    (b"DE48\0\x01\x00\x00", "byte 0"),
])
def test_de32_bad_files(blob, where):
    with pytest.raises(AsmError) as e:
        binfmt.decode_de32(blob, "f.de32")
    assert str(e.value).startswith(f"f.de32:{where}: ")


def test_load_commands_detects_kind():
    cmds = [Command("EVAL", 1, 2, (1 << 24,)), Command("REFRESH")]
    de48 = binfmt.encode_de48(isa.serialise(cmds))
    de32 = binfmt.encode_de32(binfmt.framestore_encode(cmds, 0), 0, True)
    text = "\n".join(format_command(c) for c in cmds).encode()
    assert binfmt.load_commands(de48, "a")[0] == cmds
    assert binfmt.load_commands(text, "a")[0] == cmds
    assert binfmt.load_commands(de32, "a", mapped=False)[0] == cmds
    mapped, info = binfmt.load_commands(de32, "a")
    assert info == ("de32", 0, True)
    assert mapped[0].values == (isa.compensate(1 << 24),)


def test_word_blocks_are_the_isa_split():
    """isa.word_blocks / blocks_word: the one place the 36-bit word is cut into its 12-bit
    blocks in Python (binfmt, disasm, trace and the inspector use them; de_pkg::word_blk is
    the RTL's)."""
    w = 0x123_456_789
    assert isa.word_blocks(w) == (0x789, 0x456, 0x123)
    assert isa.blocks_word((0x789, 0x456, 0x123)) == w
    assert isa.block_bits(0) == (isa.BLOCK_BITS - 1, 0)
    assert isa.block_bits(isa.BLOCKS - 1) == (isa.WORD_BITS - 1, isa.WORD_BITS - isa.BLOCK_BITS)
    rng = random.Random(17)
    for _ in range(200):
        w = rng.randrange(1 << isa.WORD_BITS)
        b = isa.word_blocks(w)
        assert len(b) == isa.BLOCKS and all(0 <= x <= isa.BLOCK_MASK for x in b)
        assert isa.blocks_word(b) == w
