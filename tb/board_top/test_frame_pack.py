"""The host packer fpga/ulx3s/frame_pack.py (docs/sdram-frames-spec.md §1, §2, §6), pure
Python (no simulator):

  * round trip: every frame's word stream rebuilt from image() through its frame table
    equals the input, for random animations whose frames share, change and repeat lines;
  * layout: blocks and tables on 4-word boundaries, one marker per block and last, the
    writes disjoint, stats consistent with the image;
  * degenerate cases: empty lines (len-0 entries, no block), all lines identical (one
    block), a frame repeating an earlier frame (no new words, its table shared), a block
    of exactly 4095 words and one of 4096 (error), overflow of a small region, a stream
    with too few / too many lines or words after its last marker (errors naming frame,
    colour and line), more than 64 frames;
  * the preload file round trip (write_image / read_image_file) and the CLI (--help,
    --stats on a .de32 scene directory);
  * `make anim`'s 36 frames (yproc anim of cad_drag) fit the regions, sharing lines.
SEED=<n> replays the random streams.
"""
from __future__ import annotations

import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT / "fpga" / "ulx3s"))
sys.path.insert(0, str(ROOT / "sw"))

import frame_pack as fp  # noqa: E402
from diffengine import isa  # noqa: E402
from diffengine.formats import binfmt  # noqa: E402

M = fp.MARKER_WORD


def seed() -> int:
    s = int(os.environ.get("SEED", random.randrange(1 << 30)))
    print(f"SEED={s}")
    return s


def rand_word(rng: random.Random) -> int:
    """A random non-marker frame-store word."""
    while True:
        w = rng.getrandbits(32)
        if not fp.is_marker(w):
            return w


def rand_line(rng: random.Random, n: int) -> list[int]:
    return [rand_word(rng) for _ in range(n)] + [M | rng.choice([0, 0, 5])]


class Img:
    def __init__(self, words, window=2, comp=False):
        self.words, self.window, self.comp = words, window, comp


def stream(lines) -> list[int]:
    return [w for ln in lines for w in ln]


def check_plan(plan, frames, vactive, first_slot=0):
    """Round trip and layout invariants of a plan against its input frames."""
    img = plan.image()
    # the writes are disjoint and cover exactly the image
    assert sum(len(w) for _, _, w in plan.writes) == len(img)
    for c, off, words in plan.writes:
        assert off % fp.ALIGN == 0 and off + len(words) <= fp.REGION_WORDS
    for f, fr in enumerate(frames):
        for c, im in enumerate(fr):
            words, window, comp = fp._fields(im)
            toff = plan.tables[f][c]
            assert toff % fp.ALIGN == 0
            assert (c, first_slot + f, toff, window, comp) in plan.slots
            assert fp.read_back(img, c, toff, vactive) == list(words), f"frame {f} colour {c}"
            for v in range(vactive):
                off, n = fp.split_entry(img[fp.addr(c, toff + v)])
                assert off % fp.ALIGN == 0
                if n:
                    blk = [img[fp.addr(c, off + k)] for k in range(n)]
                    assert fp.is_marker(blk[-1]) and not any(map(fp.is_marker, blk[:-1]))
    for c, st in enumerate(plan.stats()):
        assert st["words_used"] == max((off + len(w) for ch, off, w in plan.writes if ch == c),
                                       default=0)
        assert st["lines_referenced"] == len(frames) * vactive
        assert st["words_referenced"] == sum(len(fp._fields(fr[c])[0]) for fr in frames)
        assert st["fits"]


def test_marker_is_the_isa_refresh():
    # the packer's marker is the word the block-RAM player pads with (the retired block-RAM player; rtl/board/de_frame_fetch.sv pads the same way)
    assert binfmt.map_word(M, 0) == (isa.REFRESH, 0)
    assert M == 0x0800_0000


def test_round_trip_random_animation():
    rng = random.Random(seed())
    vactive = 37
    pool = [rand_line(rng, rng.randrange(0, 40)) for _ in range(30)] + [[M]]
    frames, cur = [], [[rng.choice(pool) for _ in range(vactive)] for _ in range(3)]
    kept = []
    for f in range(9):
        if f == 6:
            cur = [list(ch) for ch in kept[2]]             # repeat frame 2's lines
        else:
            for ch in cur:
                for _ in range(rng.randrange(0, 8)):        # a few lines change
                    ch[rng.randrange(vactive)] = rng.choice(pool) if rng.random() < .5 \
                        else rand_line(rng, rng.randrange(1, 60))
        kept.append([list(ch) for ch in cur])
        frames.append([Img(stream(ch), window=c + 1, comp=c == 0) for c, ch in enumerate(cur)])
    plan = fp.pack(frames, vactive)
    check_plan(plan, frames, vactive)
    assert plan.sequence == (0, 9, 1, 1)
    for c in range(3):
        assert plan.tables[6][c] == plan.tables[2][c]       # the repeated frame shares its table
    # each distinct non-empty line of a colour is stored once
    for c, st in enumerate(plan.stats()):
        distinct = {tuple(ln) for fr in frames
                    for ln in fp.split_lines(fr[c].words, vactive) if tuple(ln) != (M,)}
        assert st["blocks_stored"] == len(distinct)


def test_tuple_frames_and_slots():
    # de32_load's Image tuples (words, window, comp) are accepted; slots start at first_slot
    lines = [[1, 2, M], [M], [3, M]]
    fr = [(stream(lines), 4, True)] * 3
    plan = fp.pack([fr, fr], 3, first_slot=10, hold=7, loop=False)
    check_plan(plan, [fr, fr], 3, first_slot=10)
    assert plan.sequence == (10, 2, 7, 0)
    assert sorted(s[1] for s in plan.slots) == [10, 10, 10, 11, 11, 11]


def test_empty_lines():
    vactive = 8
    fr = [Img([M] * vactive)] * 3
    plan = fp.pack([fr], vactive)
    check_plan(plan, [fr], vactive)
    for c, st in enumerate(plan.stats()):
        assert st["empty_lines"] == vactive and st["blocks_stored"] == 0
        assert st["words_used"] == vactive                 # the table only
        assert all(plan.image()[fp.addr(c, v)] == 0 for v in range(vactive))
    # a marker with a non-zero operand is not the canonical marker: stored as a block
    fr = [Img([M | 1] + [M] * (vactive - 1))] * 3
    plan = fp.pack([fr], vactive)
    check_plan(plan, [fr], vactive)
    assert plan.stats()[0]["blocks_stored"] == 1


def test_all_lines_identical():
    rng = random.Random(seed())
    line = rand_line(rng, 9)
    vactive = 480
    fr = [Img(line * vactive)] * 3
    plan = fp.pack([fr], vactive)
    check_plan(plan, [fr], vactive)
    st = plan.stats()[1]
    assert st["blocks_stored"] == 1 and st["words_used"] == 12 + 480
    assert st["words_referenced"] == 10 * 480


def test_frame_repeating_an_earlier_frame():
    rng = random.Random(seed())
    vactive = 5
    a = [Img(stream(rand_line(rng, 3) for _ in range(vactive))) for _ in range(3)]
    b = [Img(stream(rand_line(rng, 3) for _ in range(vactive))) for _ in range(3)]
    frames = [a, b, a]
    plan = fp.pack(frames, vactive)
    check_plan(plan, frames, vactive)
    assert [plan.tables[2][c] for c in range(3)] == [plan.tables[0][c] for c in range(3)]
    two = fp.pack([a, b], vactive)
    assert plan.stats()[0]["words_used"] == two.stats()[0]["words_used"]
    assert len(plan.slots) == 9 and plan.sequence == (0, 3, 1, 1)
    assert plan.stats()[0]["tables_stored"] == 2


def test_max_length_block():
    rng = random.Random(seed())
    big = rand_line(rng, fp.MAX_LEN - 1)                  # 4095 words with its marker
    fr = [Img(big + [M])] * 3
    plan = fp.pack([fr], 2)
    check_plan(plan, [fr], 2)
    e = plan.image()[fp.addr(0, plan.tables[0][0])]
    assert fp.split_entry(e) == (0, fp.MAX_LEN)
    fr = [Img(big + [M]), Img(rand_line(rng, fp.MAX_LEN) + [M]), Img(big + [M])]
    with pytest.raises(fp.PackError, match=r"frame 0 colour g line 0: 4096 words"):
        fp.pack([fr], 2)


def test_region_overflow():
    rng = random.Random(seed())
    vactive = 4
    frames = [[Img(stream(rand_line(rng, 10) for _ in range(vactive))) for _ in range(3)]
              for _ in range(3)]
    # per frame and colour: 4 blocks of 12 words + a 4-word table = 52 words
    fp.pack(frames, vactive, region_words=156)              # exactly full
    with pytest.raises(fp.PackError, match=r"frame 2 colour r line 3: region overflow"):
        fp.pack(frames, vactive, region_words=155)
    with pytest.raises(fp.PackError, match=r"frame 2 colour r line 2: region overflow"):
        fp.pack(frames, vactive, region_words=130)


def test_wrong_line_counts():
    fr = [Img([1, M, 2, M])] * 3
    with pytest.raises(fp.PackError, match=r"frame 0 colour r line 2: the stream has 2 lines, "
                                           r"vactive is 3"):
        fp.pack([fr], 3)
    fr = [Img([1, M, M, M]), Img([1, M, M, M, M]), Img([M, M, M])]
    with pytest.raises(fp.PackError, match=r"frame 0 colour g line 3: more than 3 lines"):
        fp.pack([fr], 3)
    fr = [Img([M, M, M]), Img([M, M, M]), Img([M, M, M, 7])]
    with pytest.raises(fp.PackError, match=r"frame 0 colour b line 3: 1 word\(s\) after"):
        fp.pack([fr], 3)
    with pytest.raises(fp.PackError, match=r"65 frame\(s\)"):
        fp.pack([[Img([M])] * 3] * 65, 1)
    with pytest.raises(fp.PackError, match=r"frame 1: 2 colours"):
        fp.pack([[Img([M])] * 3, [Img([M])] * 2], 1)


def test_image_file_round_trip(tmp_path):
    rng = random.Random(seed())
    fr = [Img(stream(rand_line(rng, 5) for _ in range(6))) for _ in range(3)]
    plan = fp.pack([fr], 6)
    n = plan.write_image(tmp_path / "img.hex")
    assert fp.read_image_file(tmp_path / "img.hex") == plan.image() and n == len(plan.image())
    (tmp_path / "bad.hex").write_text("# c\n000000 00000001\n12 zz\n")
    with pytest.raises(fp.PackError, match=r"bad.hex:3:"):
        fp.read_image_file(tmp_path / "bad.hex")


def test_cli(tmp_path):
    rng = random.Random(seed())
    scene = tmp_path / "scene"
    scene.mkdir()
    for c in "rgb":
        (scene / f"{c}.de32").write_bytes(
            binfmt.encode_de32(stream(rand_line(rng, 4) for _ in range(480)), 2))
    tool = str(ROOT / "fpga" / "ulx3s" / "frame_pack.py")
    r = subprocess.run([sys.executable, tool, "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "--stats" in r.stdout
    r = subprocess.run([sys.executable, tool, str(scene), str(scene), "--stats", "--image",
                        str(tmp_path / "i.hex")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "2 frame(s)" in r.stdout and "all colours fit: yes" in r.stdout
    img = fp.read_image_file(tmp_path / "i.hex")
    assert len(img) == 3 * (480 * 8 + 480)                 # 480 blocks of 5->8 words + table
    r = subprocess.run([sys.executable, tool, str(scene), "--vactive", "479"],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "frame 0 colour r line 479: more than 479" in r.stderr


def test_make_anim_fits(tmp_path):
    """`make anim`'s 36 frames (sw/scenes/anim/cad_drag.anim, `yproc anim` as `make anim`
    and board_sim run it) packed at window 2, rounded (de32_load.py --window 2 --round):
    they fit each colour's 2^21-word region, sharing lines (docs/board-frames.md §1:
    1.11-1.12 M words, 53 %; 1.77 M without sharing), one slot each, looping; frames read
    back through their tables equal the tool's conversion of their streams. Each distinct
    line is converted once (the conversion is per slot, so a frame's words are its lines'
    words in order; checked on frame 0 against de32_load's whole-stream conversion)."""
    sys.path.insert(0, str(ROOT / "fpga" / "ulx3s"))
    import de32_load
    from diffengine.pipeline import anim

    subprocess.run(["make", "-s", "-C", str(ROOT / "sw" / "yproc"), "build/yproc"], check=True)
    r = subprocess.run([str(ROOT / "sw/yproc/build/yproc"), "anim",
                        str(ROOT / "sw/scenes/anim/cad_drag.anim"), "-o", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    seq = anim.frames(tmp_path)
    assert len(seq) == 36
    cache: dict[bytes, list[int]] = {}

    def words(lines, name):
        out = []
        for ln in lines:
            if ln not in cache:
                cache[ln] = de32_load.de48_image(anim.to_de48([ln]), name, 2, True)[0]
            out += cache[ln]
        return out

    frames = [[(words(fr[c], f"frame {f} {'rgb'[c]}"), 2, False) for c in range(3)]
              for f, fr in enumerate(seq)]
    for c in range(3):
        whole = de32_load.de48_image(anim.to_de48(seq[0][c]), "frame 0", 2, True)[0]
        assert frames[0][c][0] == whole
    plan = fp.pack(frames, 480)
    assert plan.fits()
    assert plan.sequence == (0, 36, 1, 1)
    assert len(plan.slots) == 3 * 36
    for c, st in enumerate(plan.stats()):
        print(f"colour {'rgb'[c]}: {st['words_used']:,} words used "
              f"({100 * st['words_used'] / fp.REGION_WORDS:.1f} %), "
              f"{st['words_referenced']:,} referenced, {st['blocks_stored']:,} blocks, "
              f"{st['tables_stored']} tables")
        assert st["fits"] and st["words_used"] <= fp.REGION_WORDS
        assert st["lines_referenced"] == 36 * 480
        assert st["words_used"] < 0.7 * st["words_referenced"], "lines are shared"
        assert st["blocks_stored"] < 36 * 480 // 2
    img = plan.image()
    for f in (0, 1, 15, 20, 35):
        for c in range(3):
            assert fp.read_back(img, c, plan.tables[f][c], 480) == frames[f][c][0], (f, c)
