"""The host tool fpga/ulx3s/de32_load.py against a simulated board: the pure-Python loader
model fpga/ulx3s/loader_model.py (no cocotb) behind a pty, with injected errors.

  * the model's protocol (loader version 2: X, F, Q, O, R, S): replies, checksum / field
    errors, skipped garbage (the retired 'W'), counters;
  * a scene (three .de32 files) loaded in one command through a pty with a corrupted
    byte inside an 'X' (NACKed 'E', re-sent) and a swallowed reply (timeout, re-sent):
    every frame read back from the model's SDRAM regions through its slot's frame table
    (frame_pack.read_back) equals the files; slots, sequence and output window;
  * a dropped link half-way: exit status 2, the state file names the last acknowledged
    packet, and --resume on a new link sends only the packets after it and completes;
  * a scene directory of .de48 streams plus an animation directory (frame000/ and a
    YPD1 delta), --window / --round: every frame's slot reads back to its streams, the
    lines the frames share are stored once, and --show plays one frame;
  * bad inputs name file and byte / slot / line; --help; the progress line.
SEED=<n> replays the random words.
"""
from __future__ import annotations

import json
import os
import pty
import random
import struct
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
ULX = HERE.parent.parent / "fpga" / "ulx3s"
sys.path.insert(0, str(ULX))
sys.path.insert(0, str(HERE.parent.parent / "sw"))

import de32_load as dl  # noqa: E402
import frame_pack  # noqa: E402
from loader_model import Device, Faults, LoaderModel  # noqa: E402

MARKER = frame_pack.MARKER_WORD

FAST = ["--abandon", "0.1"]          # the model abandons a partial command after 0.05 s


def seed() -> int:
    s = int(os.environ.get("SEED", random.randrange(1 << 30)))
    print(f"SEED={s}")
    return s


def board(model: LoaderModel, faults: Faults | None = None):
    """A pty: the device serves the master end; the host opens the slave's path."""
    master, slave = pty.openpty()
    path = os.ttyname(slave)
    dev = Device(master, model, faults, timeout=0.05)
    return dev, path, slave


def write_de32(path: Path, words, window=2, comp=False) -> None:
    path.write_bytes(b"DE32" + struct.pack(">HBB", 1, window, int(comp))
                     + b"".join(struct.pack(">I", w) for w in words))


def line_words(rng: random.Random, n: int, lines: int) -> list[int]:
    """n random frame-store words in `lines` lines of about equal length, each ending
    with the marker (no other word is a marker)."""
    assert n >= lines
    body = [w for w in (rng.randrange(1 << 32) for _ in range(2 * n))
            if not frame_pack.is_marker(w)][:n - lines]
    per, out = len(body) // lines, []
    for y in range(lines):
        out += body[y * per:(y + 1) * per if y < lines - 1 else len(body)] + [MARKER]
    return out


def scene(tmp: Path, rng: random.Random, n=(700, 513, 260), lines=12) -> tuple[list[str], list]:
    files, words = [], []
    for c, k in zip("rgb", n):
        w = line_words(rng, k, lines)
        write_de32(tmp / f"{c}.de32", w, window=c == "g" and 3 or 1, comp=c == "r")
        files.append(str(tmp / f"{c}.de32"))
        words.append(w)
    return files, words


def image(m: LoaderModel) -> dict[int, int]:
    """The model's SDRAM regions as controller word addresses (frame_pack.addr)."""
    return {frame_pack.addr(c, off): w for c in range(3) for off, w in m.mem[c].items()}


def read_slot(m: LoaderModel, ch: int, slot: int, vactive: int) -> list[int]:
    return frame_pack.read_back(image(m), ch, m.slots[ch][slot][0], vactive)


# ---------------------------------------------------------------------- the model
def test_model_protocol():
    m = LoaderModel()
    R = 1 << 21
    assert m.feed(dl.cmd_x(1, 3, [0x11223344, 0x55667788])) == b"K"
    assert m.mem[1] == {3: 0x11223344, 4: 0x55667788}
    bad = bytearray(dl.cmd_x(1, 3, [0xAAAAAAAA]))
    bad[-1] ^= 1
    assert m.feed(bytes(bad)) == b"E" and m.cerr == 1
    assert m.mem[1][3] == 0xAAAAAAAA, "words are written as they arrive, like the RTL"
    assert m.feed(dl.cmd_x(3, 0, [1])) == b"E"             # colour out of range
    assert m.feed(dl.cmd_x(0, R - 1, [1, 2])) == b"E"      # runs off the region
    assert m.mem[0] == {R - 1: 1}
    assert m.feed(dl.cmd_x(0, 0, [])) == b"E"              # no words
    assert m.feed(b"\x00\x01") == b"" and m.kerr == 5      # 3 fields + 2 garbage bytes
    assert m.feed(dl.with_chk(b"W\x00\x00\x00\x00\x00")) == b"" and m.kerr == 12  # retired
    assert m.feed(dl.cmd_f(2, 5, 96, 4, True)) == b"K" and m.slots[2] == {5: (96, 4, True)}
    for f in (dl.cmd_f(2, 5, 96, 5, True), dl.cmd_f(2, 64, 96, 0, False),
              dl.cmd_f(2, 5, 97, 0, False), dl.cmd_f(2, 5, R, 0, False)):
        assert m.feed(f) == b"E", f.hex()                   # window, slot, alignment, region
    assert m.feed(dl.cmd_q(3, 61, 2, True)) == b"K" and m.sequence == (3, 61, 2, 1)
    for q in (dl.cmd_q(3, 62, 2, True), dl.cmd_q(0, 0, 1, False), dl.cmd_q(0, 1, 0, False),
              dl.with_chk(b"Q\x00\x01\x01\x02"), dl.cmd_q(64, 1, 1, False)):
        assert m.feed(q) == b"E", q.hex()
    assert m.feed(dl.cmd_o(3, False)) == b"K" and m.out8 == (3, 0)
    m.regs[0x3000] = 0xDC310004
    assert m.feed(dl.with_chk(b"R\x30\x00")) == b"R\xdc\x31\x00\x04"
    s = m.feed(dl.with_chk(b"S"))
    assert len(s) == 16 and s[:4] == b"S\x02\x01\x15"
    assert struct.unpack(">HHH", s[4:10]) == (0, 1, 5 + 7 + 4 + 5) and s[13] == 3
    assert s[14:] == b"\0\0"
    assert m.feed(b"X\x00") == b"" and m.busy() and m.idle() == b"T" and not m.busy()


# ---------------------------------------------------------------------- scene over a pty
def test_scene_with_errors(tmp_path):
    rng = random.Random(seed())
    files, words = scene(tmp_path, rng)
    m = LoaderModel()
    # 'S' is 2 bytes; the first 'X' (64 words) is 264: corrupt a data byte of the second
    # 'X', swallow the reply to the fourth packet.
    dev, path, slave = board(m, Faults(corrupt_rx={2 + 264 + 100}, drop_reply={4}))
    st = tmp_path / "state.json"
    rc = dl.main([path, *files, "--words", "64", "--state", str(st), "--shift", "2",
                  *FAST])
    dev.stop()
    os.close(slave)
    assert rc == 0
    assert m.cerr == 1, "the corrupted byte must fail the checksum"
    for c in range(3):
        assert read_slot(m, c, 0, 12) == words[c], f"colour {c} differs"
    assert [m.slots[c][0][1:] for c in range(3)] == [(1, True), (3, False), (1, False)]
    assert m.sequence == (0, 1, 1, 0)
    assert m.out8 == (2, 1)
    plan = frame_pack.pack([[(words[c], 0, False) for c in range(3)]], 12)
    n_x = sum(-(-len(w) // 64) for _, _, w in plan.writes)
    s = json.loads(st.read_text())
    assert s["acked"] == s["packets"] == n_x + 3 + 2
    # Re-sends: the NACKed packet and the one whose reply was lost (both idempotent).
    assert dev.replies.count(b"E") == 1
    assert m.writes == sum(len(w) for _, _, w in plan.writes) + 64 + 64


def test_dropped_link_and_resume(tmp_path, capsys):
    rng = random.Random(seed())
    files, words = scene(tmp_path, rng)
    m = LoaderModel()
    st = tmp_path / "state.json"
    args = [*files, "--words", "32", "--state", str(st), *FAST]
    dev, path, slave = board(m, Faults(drop_link_after=5000))
    rc = dl.main([path, *args])
    dev.stop()
    os.close(slave)
    assert rc == 2 and dev.dropped
    assert "--resume" in capsys.readouterr().err
    acked = json.loads(st.read_text())["acked"]
    plan = frame_pack.pack([[(words[c], 0, False) for c in range(3)]], 12)
    sizes = [min(32, len(w) - k) for _, _, w in plan.writes for k in range(0, len(w), 32)]
    sent = 2                                    # the 'S' of the size check
    for k in range(acked):
        sent += 8 + 4 * sizes[k]
    assert 0 < acked and sent <= 5000 < sent + 8 + 4 * sizes[acked], (acked, sent)
    # Resume on a new link: the board kept its memory; only packets >= acked are sent.
    before = m.writes
    dev2, path2, slave2 = board(m)
    assert dl.main([path2, *args, "--resume"]) == 0
    dev2.stop()
    os.close(slave2)
    # The interrupted 'X' is still open in the board: the new link's first 'S' (2 bytes)
    # may complete one more of its words (at an address the resumed packets rewrite)
    # before the board abandons it ('T', and the tool re-sends the 'S').
    assert m.writes - before - (sum(sizes) - sum(sizes[:acked])) in (0, 1)
    for c in range(3):
        assert read_slot(m, c, 0, 12) == words[c]
    assert json.loads(st.read_text())["acked"] == json.loads(st.read_text())["packets"]
    # A finished load resumes to nothing; another load's state is refused with its file.
    dev3, path3, slave3 = board(m)
    assert dl.main([path3, *args, "--resume"]) == 0
    assert dl.main([path3, *args, "--resume", "--shift", "4"]) == 1
    dev3.stop()
    os.close(slave3)
    assert f"{st}:1: written for another load" in capsys.readouterr().err


# ---------------------------------------------------------------------- .de48 + animation
def _line(rng, w):
    from diffengine import isa
    from diffengine.formats import binfmt
    cmds = []
    for _ in range(rng.randrange(1, 4)):
        x = rng.randrange(0, 600)
        v = [rng.randrange(-1000, 1000) << (4 + w) for _ in range(2)]
        cmds.append(isa.Command("EVAL", x, rng.randrange(1, 40), tuple(v)))
    cmds.append(isa.Command("REFRESH"))
    return binfmt.encode_de48(isa.serialise(cmds))[binfmt.HEADER_LEN:]


@pytest.mark.parametrize("layout", ["yproc", "make_anim"])
def test_scene_dir_and_anim(tmp_path, layout):
    """layout yproc: `yproc anim -o DIR` (frame000/ and the deltas in DIR); make_anim:
    `make anim`'s out/anim, which keeps them in out/anim/streams/ and is what the
    documented command (docs/board.md §3.3) gives --anim."""
    from diffengine.formats import binfmt
    rng = random.Random(seed())
    w, h = 2, 5
    streams = tmp_path / "anim" / ("streams" if layout == "make_anim" else "")
    f0 = streams / "frame000"
    f0.mkdir(parents=True)
    lines = [[_line(rng, w) for _ in range(h)] for _ in range(3)]
    for c, ch in enumerate("rgb"):
        (f0 / f"{ch}.de48").write_bytes(b"DE48" + struct.pack(">HH", 1, 0) + b"".join(lines[c]))
    # Frame 1: line 2 of green and line 4 of blue change (YPD1, sw/diffengine/pipeline/anim.py).
    new = {1: {2: _line(rng, w)}, 2: {4: _line(rng, w)}}
    d = bytearray(b"YPD1" + struct.pack(">4H", 1, 1, 640, h))
    for c in range(3):
        ch = new.get(c, {})
        d += struct.pack(">I", len(ch))
        for y, words in ch.items():
            d += struct.pack(">HI", y, len(words) // 6) + words
    (streams / "frame001.delta").write_bytes(bytes(d))

    m = LoaderModel()
    dev, path, slave = board(m)
    rc = dl.main([path, str(f0), "--anim", str(tmp_path / "anim"), "--window", str(w),
                  "--state", str(tmp_path / "s.json"), "--show", "2", *FAST])
    dev.stop()
    os.close(slave)
    assert rc == 0
    frames = [lines, lines, [lines[0], [new[1].get(y, lines[1][y]) for y in range(h)],
                             [new[2].get(y, lines[2][y]) for y in range(h)]]]
    for c in range(3):
        for f, fr in enumerate(frames):
            slots = binfmt.decode_de48(b"DE48\0\1\0\0" + b"".join(fr[c]))
            cmds = binfmt.deserialise(slots)
            want = binfmt.framestore_encode(cmds, w)
            assert read_slot(m, c, f, h) == want, f"frame {f} colour {c}"
            assert m.slots[c][f][1:] == (w, False)
        # Frames 0 and 1 are equal: one table; frame 2 stores only its changed line.
        assert m.slots[c][0][0] == m.slots[c][1][0]
    assert m.slots[0][2][0] == m.slots[0][0][0], "red did not change: its table is shared"
    assert m.sequence == (2, 1, 1, 0), "--show 2 plays frame 2 alone"
    used = [len(m.mem[c]) for c in range(3)]
    per_frame = [sum(len(binfmt.framestore_encode(binfmt.deserialise(binfmt.decode_de48(
        b"DE48\0\1\0\0" + b"".join(fr[c]))), w)) for fr in frames) for c in range(3)]
    assert all(u < p for u, p in zip(used, per_frame)), (used, per_frame)


# ---------------------------------------------------------------------- errors, help
def test_bad_inputs_name_file(tmp_path, capsys, monkeypatch):
    rng = random.Random(seed())
    files, _ = scene(tmp_path, rng, n=(4, 4, 4), lines=2)
    Path(files[1]).write_bytes(Path(files[1]).read_bytes()[:-2])
    assert dl.main(["/nonexistent", *files]) == 1
    assert f"{files[1]}:byte 22: truncated" in capsys.readouterr().err
    # A scene that is not there: named (was "give a scene directory or three files").
    assert dl.main(["/nonexistent", str(tmp_path / "no_scene")]) == 1
    assert f"{tmp_path / 'no_scene'}: no such file or directory" in capsys.readouterr().err
    # A .de48 value below the window's grid: an error naming file and slot, unless --round.
    from diffengine import isa
    from diffengine.formats import binfmt
    sl = isa.serialise([isa.Command("EVAL", 1, 2, (3, 1 << 20)), isa.Command("REFRESH")])
    for c in "rgb":
        (tmp_path / f"{c}.de48").write_bytes(binfmt.encode_de48(sl))
    de48 = [str(tmp_path / f"{c}.de48") for c in "rgb"]
    assert dl.main(["/nonexistent", *de48, "--window", "1"]) == 1
    err = capsys.readouterr().err
    assert f"{de48[0]}:slot 2:" in err and "--round" in err, err
    img = dl.read_image(de48[0], 1, True)
    assert len(img[0]) == len(sl)
    # A broken state file: its line.
    st = tmp_path / "st.json"
    st.write_text('{"plan": "x",\n "acked": }\n')
    write_de32(Path(files[1]), line_words(rng, 3, 2))
    m = LoaderModel()
    dev, path, slave = board(m)
    assert dl.main([path, *files, "--state", str(st), "--resume", *FAST]) == 1
    assert f"{st}:2:" in capsys.readouterr().err
    # A colour with another number of lines: the packer's error names frame, colour, line.
    write_de32(Path(files[2]), line_words(rng, 6, 3))
    assert dl.main([path, *files, "--state", str(st), *FAST]) == 1
    err = capsys.readouterr().err
    assert f"{files[2]}: frame 0 colour b line 2" in err, err
    # A board with the version-1 loader (block-RAM frame stores): refused, named.
    write_de32(Path(files[2]), line_words(rng, 6, 2))
    import loader_model
    monkeypatch.setattr(loader_model, "VERSION", 1)
    assert dl.main([path, *files, "--state", str(st), *FAST]) == 1
    assert "loader version 1" in capsys.readouterr().err
    dev.stop()
    os.close(slave)


def test_help_and_progress(capsys):
    with pytest.raises(SystemExit) as e:
        dl.main(["--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert "--resume" in out and "--anim" in out

    class Tty:
        def __init__(self):
            self.text = ""

        def isatty(self):
            return True

        def write(self, s):
            self.text += s

        def flush(self):
            pass

    t = Tty()
    p = dl.Progress(300_000, t)
    p.update(150_000)
    p.finish()
    assert t.text.startswith("\r[" + "#" * 15) and t.text.endswith("\n"), t.text
    line = p.line()
    assert "150.0/300.0 kB" in line and "kB/s" in line and "ETA" in line, line
    assert line.startswith("[" + "#" * 15 + " " * 15 + "]"), line


def _line_pixels(slots) -> "np.ndarray":
    """One line of 12-bit pixels: the C functional model of (ident, data) slots."""
    import numpy as np
    from diffengine import isa
    from diffengine.model import fast
    row = np.zeros((1, 640), dtype=np.uint16)
    fast.render_words(b"".join(((i << isa.WORD_BITS) | d).to_bytes(6, "big") for i, d in slots),
                      640, row)
    return row[0].astype(int)


def test_de48_bright_intensities_need_gain(tmp_path, capsys):
    """make demo's scenes reach 4,095 pixel units; the 27-bit operand holds |v| < 1,024 at
    window 4 (docs/formats.md §3). Gain 0 clamps them (reported on stderr, naming the
    stream) and the line no longer looks like the stream; gain 1 halves every intensity
    and the output window one bit lower (pixel[10:3]) shows make demo's 8 bits
    (pixel[11:4]) exactly."""
    from diffengine import isa
    from diffengine.formats import asm, binfmt
    # Intensities are 12-bit two's complement: -1800 shows as pixel 2,296.
    text = ("Eval1 (0, 200, 1800)\nEval2 (200, 240, 1500, 2.25)\n"
            "Eval3 (440, 200, -1800, -3.5, 0.0078125)\nRefresh\n")
    slots = isa.serialise(asm.parse_text(text, "bright.txt"))
    de48 = binfmt.encode_de48(slots)
    want = (_line_pixels(slots) >> 4) & 0xFF
    assert want.max() > 1024 >> 4                      # the line is bright

    words, window, _ = dl.de48_image(de48, "bright.de48", 4, True, 0)
    err = capsys.readouterr().err
    assert "bright.de48" in err and "clamped" in err and "--gain 1" in err
    got0 = (_line_pixels(binfmt.framestore_slots(words, window)) >> 4) & 0xFF
    assert (got0 != want).sum() > 100                  # clamped: a different line

    words, window, _ = dl.de48_image(de48, "bright.de48", 4, True, 1)
    assert "clamped" not in capsys.readouterr().err
    got1 = (_line_pixels(binfmt.framestore_slots(words, window)) >> 3) & 0xFF
    assert (got1 == want).all()

    # At window 0 the range is +-64 pixel units: even gain 3 clamps, and says what to do.
    dl.de48_image(de48, "bright.de48", 0, True, 3)
    assert "higher --window" in capsys.readouterr().err

    with pytest.raises(dl.LoadError, match="--gain 4 outside 0..3"):
        dl.de48_image(de48, "bright.de48", 4, True, 4)
