"""The C functional model (sw/fmodel through diffengine.model.fast) against the numpy
golden model (diffengine.model.functional), which is the reference.

* command by command: every opcode, then random lines, run on both `functional._Line` and
  `fast.Line`; after each command every register (A, B, C, D) and flag (pA, pB, pC, dis,
  lock, Acc_mode) of every PE must be equal, with and without the §7.7 carry bug;
* whole streams: random frames (protect flags, periodic Sets with dX 0/1/n, Dis, Eval0,
  Acc_mode, Eval up to order 7, spans past the array, values wrapping modulo 2^36), the
  benchmark's frames, the shipped figure command files, the teapot and CAD scenes at
  640x480 through yproc in full colour, and an animation's changed lines;
* the decoder: corrupted streams are refused at the same slot as binfmt.deserialise.

Seeded; the seed is printed and SEED=<n> replays it
(`SEED=123 pytest -q sw/tests/test_fmodel.py`).
"""
from __future__ import annotations

import random
import re
import subprocess
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from diffengine import isa
from diffengine.bench import model as bench_model
from diffengine.formats import binfmt
from diffengine.formats.asm import AsmError, parse_file
from diffengine.host import yproc
from diffengine.model import fast, functional as F
from diffengine.pipeline import anim, demo
from test_functional_batch import _command, _seed, _stream

C = isa.Command
ONE = 1 << isa.FRAC_BITS
REPO = Path(__file__).resolve().parents[2]
REGS, FLAGS = ("A", "B", "C", "D"), ("pA", "pB", "pC", "dis", "lock")


def _words(cmds) -> bytes:
    return b"".join(((i << isa.WORD_BITS) | d).to_bytes(6, "big") for i, d in isa.serialise(cmds))


def _same_state(ref: F._Line, got: fast.Line, where: str) -> None:
    s, g = ref.s, got.state()
    for k in REGS:
        want = getattr(s, k) & F.MASK
        if not np.array_equal(want, g[k]):
            col = int(np.flatnonzero(want != g[k])[0])
            pytest.fail(f"{where}: register {k} differs first at column {col}: numpy "
                        f"{isa.format_fixed(int(want[col]))}, C {isa.format_fixed(int(g[k][col]))}")
    for k in FLAGS:
        if not np.array_equal(getattr(s, k), g[k]):
            col = int(np.flatnonzero(getattr(s, k) != g[k])[0])
            pytest.fail(f"{where}: flag {k} differs first at column {col}")
    assert s.acc_mode == g["acc_mode"], f"{where}: Acc_mode"
    assert np.array_equal(s.pixels(), got.pixels()), f"{where}: pixels"


def _lockstep(cmds, width: int, bug: bool, where: str) -> None:
    """Both models, one command at a time, the whole state compared after each."""
    ref, got = F._Line(width, bug), fast.Line(width, bug)
    for k, c in enumerate(cmds):
        ref.run(c)
        got.run(c)
        _same_state(ref, got, f"{where}, command {k} {c}")


# Every opcode, with what changes its effect: protect flags of each register for each
# Eval order, periodic Sets (dX 0, 1, n), Dis and Eval0 gating, Acc_mode, clipping.
OPCODE_CASES = {
    "eval_orders": [C("EVAL", 2, 9, (3 * ONE,)), C("EVAL", 0, 12, (ONE, -ONE // 3)),
                    C("EVAL", 4, 30, (-5 * ONE, ONE // 2, ONE // 7)),
                    C("EVAL", 1, 20, tuple((k + 1) * ONE // 5 for k in range(5))),
                    C("EVAL", 0, 40, tuple((-1) ** k * ONE // (k + 2) for k in range(8)))],
    "set_protect_low": [C("SETI", 5, 2, (9 * ONE,)), C("SETDI", 8, 1, (-ONE,)),
                        C("SETDDI", 11, 3, (ONE // 4,)), C("EVAL", 0, 20, (ONE, ONE, ONE))],
    "set_protect_order1_ignores_C": [C("SETDDI", 4, 1, (ONE,)), C("SETDI", 6, 1, (2 * ONE,)),
                                     C("EVAL", 0, 12, (0, ONE)), C("EVAL", 0, 12, (ONE,))],
    "set_protect_high_order": [C("SETI", 3, 1, (ONE,)), C("SETDI", 4, 1, (ONE,)),
                               C("SETDDI", 7, 1, (-ONE,)),
                               C("EVAL", 0, 16, (0, ONE, 0, ONE // 3, ONE // 9))],
    "setp": [C("SETPI", 3, 5, (7 * ONE,)), C("SETPDI", 1, 0, (ONE,)),
             C("SETPDDI", 0, 1, (ONE // 64,)), C("EVAL", 0, 35, (0, 0, 0)),
             C("SETPDI", 40, 3, (ONE,))],
    "dis": [C("DIS", 3, 4), C("EVAL", 0, 10, (ONE, ONE // 2)), C("DIS", 0, 2),
            C("DIS", 30, 500), C("EVAL", 1, 40, (2 * ONE,))],
    "eval0": [C("DIS", 6, 2), C("EVAL0", 2, 6, (100,)), C("EVAL", 0, 12, (ONE,)),
              C("EVAL0", 0, 12, (4095,)), C("EVAL0", 20, 0, (1,))],
    "acc_mode": [C("ACCMODE", values=(1,)), C("EVAL", 0, 20, (3 * ONE, -ONE // 2)),
                 C("EVAL", 0, 20, (-ONE, ONE // 4, ONE // 16)), C("ACCMODE", values=(0,)),
                 C("EVAL", 0, 20, (-ONE,))],
    "nop_and_clipping": [C("NOP"), C("EVAL", 35, 4095, (ONE, ONE)), C("EVAL", 4095, 4095, (ONE,)),
                         C("SETI", 4000, 100, (ONE,)), C("SETPDI", 4095, 7, (ONE,)), C("NOP")],
    "wrap": [C("EVAL", 0, 40, ((1 << 35) - 1, 1 << 34, -(1 << 35))),
             C("EVAL", 0, 40, (-(1 << 35), -1, 1))],
    "carry_fraction": [C("EVAL", 0, 40, (ONE - 1, ONE // 2 + 3, ONE // 3)),
                       C("SETDI", 9, 1, (ONE - 5,)), C("EVAL", 0, 40, (ONE // 2 + 1, ONE - 7))],
}


def test_opcode_cases_cover_every_command():
    seen = {c.op for case in OPCODE_CASES.values() for c in case}
    assert seen == set(isa.OPS) - {"REFRESH"}        # REFRESH: the stream tests below


@pytest.mark.parametrize("bug", [False, True], ids=["exact", "carry_bug"])
@pytest.mark.parametrize("case", sorted(OPCODE_CASES))
def test_every_opcode_command_by_command(case, bug):
    for width in (1, 17, 40):
        _lockstep(OPCODE_CASES[case], width, bug, f"{case} width {width}")


@pytest.mark.parametrize("bug", [False, True], ids=["exact", "carry_bug"])
def test_random_lines_command_by_command(bug):
    seed = _seed(0xC0DE + bug)
    print(f"test_random_lines_command_by_command bug={bug} seed {seed}")
    rng = random.Random(seed)
    for case in range(60 if bug else 120):
        width = rng.choice([1, 2, 9, 17, 40, 64, 100])
        cmds = [_command(rng, width, rng.choice([2, 7])) for _ in range(rng.randint(1, 40))]
        _lockstep(cmds, width, bug, f"seed {seed} case {case} width {width}")


def _check_frame(cmds, width, bug, where):
    want = F.render(cmds, width, carry_bug=bug)
    got = fast.render(cmds, width, carry_bug=bug)
    assert got.shape == want.shape, where
    if not np.array_equal(got, want):
        row = int(np.flatnonzero((got != want).any(axis=1))[0])
        pytest.fail(f"{where} width {width}: line {row} differs\n"
                    f"commands {isa.split_lines(cmds)[row]}\nC     {got[row].tolist()}\n"
                    f"numpy {want[row].tolist()}")


@pytest.mark.parametrize("bug", [False, True], ids=["exact", "carry_bug"])
def test_random_frames(bug):
    seed = _seed(0xF4A3 + bug)
    print(f"test_random_frames bug={bug} seed {seed}")
    rng = random.Random(seed)
    for case in range(40):
        width = rng.choice([1, 3, 9, 33, 64, 100, 640])
        _check_frame(_stream(rng, width, rng.randint(1, 12), rng.choice([2, 7])), width, bug,
                     f"seed {seed} case {case}")


def test_benchmark_frames():
    """The frames of `diffengine bench model` (eval-only and mixed), as benchmarked."""
    for mixed in (False, True):
        cmds = bench_model.random_frame(np.random.default_rng(1), mixed=mixed)
        _check_frame(cmds, 640, False, f"bench frame mixed={mixed}")


@pytest.mark.parametrize("name", sorted(p.name for p in (REPO / "sw/scenes").glob("fig7_*.cmd")))
def test_figure_command_files(name):
    """The source's instruction lists (Figs. 7.21, 7.25) with and without the carry bug."""
    cmds = parse_file(REPO / "sw/scenes" / name)
    for bug in (False, True):
        _check_frame(cmds, 640, bug, f"{name} carry_bug={bug}")


@pytest.fixture(scope="module")
def scans(tmp_path_factory):
    """yproc scan of the teapot and the CAD scene at 640x480: r/g/b.de48 each."""
    tmp = tmp_path_factory.mktemp("fmodel_scans")
    out = {}
    for name, scene in (("teapot", "teapot/teapot.scene"), ("cad", "cad/cad.scene")):
        demo.yproc_scan(REPO / "sw/scenes" / scene, tmp / name)
        out[name] = [tmp / name / f"{c}.de48" for c in "rgb"]
    return out


@pytest.mark.parametrize("name", ["teapot", "cad"])
def test_shipped_scenes_full_colour(scans, name):
    want = demo.golden(scans[name], 640, 480, model="numpy")
    got = fast.render_frame(scans[name], 640, 480)
    assert got.shape == (480, 640, 3) and got.std() > 100     # a picture
    assert np.array_equal(got, want), f"{name}: {(got != want).any(-1).sum()} pixels differ"
    assert np.array_equal(demo.golden(scans[name], 640, 480), want)   # the default: fast


def test_colour_frame_within_budget(scans):
    """Issue 19 item 4: a 640x480 colour frame in at most 50 ms. CPU time of this process,
    best of 5 (wall time on this shared machine says more about the load than the model;
    docs/performance.md, "Functional model in C", has both)."""
    data = [p.read_bytes() for p in scans["teapot"]]
    best = float("inf")
    for _ in range(5):
        t = time.process_time()
        fast.render_frame(data, 640, 480)
        best = min(best, time.process_time() - t)
    print(f"teapot colour frame: {best * 1e3:.1f} CPU ms")
    assert best < 0.050


def test_changed_lines_only(scans):
    """render_lines: a frame updated line by line equals the full render of the new
    streams; rows not named stay as they were."""
    seed = _seed(0x11E5)
    print(f"test_changed_lines_only seed {seed}")
    rng = random.Random(seed)
    teapot = [anim.lines_of_de48(p) for p in scans["teapot"]]
    cad = [anim.lines_of_de48(p) for p in scans["cad"]]
    img = fast.render_frame([anim.to_de48(ch) for ch in teapot], 640, 480)
    cur = [list(ch) for ch in teapot]
    for step in range(4):
        changes = [{}, {}, {}]
        for c in range(3):
            for y in rng.sample(range(480), rng.randint(0, 60)):
                changes[c][y] = cad[c][y]
                cur[c][y] = cad[c][y]
        n = fast.render_lines(img, changes)
        assert n == sum(len(ch) for ch in changes)
        full = fast.render_frame([anim.to_de48(ch) for ch in cur], 640, 480)
        assert np.array_equal(img, full), f"seed {seed} step {step}"
    ref = np.stack([F.render(binfmt.load_commands(anim.to_de48(cur[c]), "x")[0], 640)
                    for c in range(3)], -1)
    assert np.array_equal(img, ref)


def test_animation_changed_lines(tmp_path):
    """yproc anim's frame deltas applied with render_lines == numpy full re-renders."""
    scene = tmp_path / "lite.scene"
    src = (REPO / "sw/scenes/cad/cad.scene").read_text().splitlines()
    keep = [ln for ln in src if not ln.startswith("obj") or "ball" not in ln]
    scene.write_text("\n".join(ln.replace("obj ", f"obj {REPO}/sw/scenes/cad/", 1)
                               if ln.startswith("obj ") else ln for ln in keep)
                     .replace("screen 640 480", "screen 96 64") + "\n")
    a = tmp_path / "a.anim"
    a.write_text("scene lite.scene\nframes 6\nmove 3 -1.2 0 0.3 from 0 to 5\n"
                 "opacity glass 0.8 from 2 to 4\n")
    out = tmp_path / "anim"
    r = subprocess.run([str(yproc.build()), "anim", str(a), "-o", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    seq = anim.frames(out)
    W, H = 96, 64
    img = np.zeros((H, W, 3), dtype=np.uint16)
    changed = 0
    for f, chans in enumerate(seq):
        ch = [{y: chans[c][y] for y in range(len(chans[c]))
               if f == 0 or chans[c][y] != seq[f - 1][c][y]} for c in range(3)]
        changed += fast.render_lines(img, ch) if f else 0
        if f == 0:
            fast.render_lines(img, ch)
        ref = np.stack([F.render(binfmt.load_commands(anim.to_de48(chans[c]), "x")[0], W)
                        for c in range(3)], -1)
        assert np.array_equal(img[:len(chans[0])], ref), f"frame {f}"
    assert changed > 0


# ---- the decoder and refusals ----------------------------------------------------

_SLOT = re.compile(r"slot (\d+):")


def test_corrupted_streams_refused_at_the_same_slot():
    seed = _seed(0xBAD)
    print(f"test_corrupted_streams_refused_at_the_same_slot seed {seed}")
    rng = random.Random(seed)
    ids = [ident for _, ident, _ in isa.LUT] + [0x123, 0xfff]
    refused = 0
    for case in range(400):
        slots = isa.serialise(_stream(rng, 40, rng.randint(1, 4), 7))
        for _ in range(rng.randint(1, 3)):
            if not slots:
                break
            k = rng.randrange(len(slots))
            ident, data = slots[k]
            r = rng.random()
            if r < 0.4:
                ident = rng.choice(ids)
            elif r < 0.7:
                data = rng.choice([data ^ (1 << rng.randrange(36)), 1 << 24, 1])
            else:
                del slots[k]
                continue
            slots[k] = (ident, data)
        words = b"".join(((i << isa.WORD_BITS) | d).to_bytes(6, "big") for i, d in slots)
        try:
            cmds = binfmt.deserialise(slots, "s")
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")         # commands after the last Refresh
                want = F.render(cmds, 40)
            want_slot = None
            last = max((k for k, c in enumerate(cmds) if c.op == "REFRESH"), default=-1)
        except AsmError as e:
            want_slot = int(_SLOT.search(str(e)).group(1))
        out = np.zeros((len(slots), 40), dtype=np.uint16)
        try:
            n, trailing = fast.render_words(words, 40, out)
            got_slot = None
        except fast.FastModelError as e:
            got_slot = int(_SLOT.search(str(e)).group(1))
            assert not out.any(), "a refused stream wrote pixels"
        assert got_slot == want_slot, f"seed {seed} case {case}: numpy slot {want_slot}, C {got_slot}"
        if want_slot is None:
            assert np.array_equal(out[:n], want), f"seed {seed} case {case}"
            assert trailing == len(cmds) - 1 - last, f"seed {seed} case {case}: trailing"
        refused += want_slot is not None
    assert 50 < refused < 390          # both kinds of stream were tried


def test_errors_name_the_stream(tmp_path):
    good = tmp_path / "g.de48"
    good.write_bytes(binfmt.encode_de48(isa.serialise([C("EVAL", 0, 4, (ONE,)), C("REFRESH")])))
    bad = tmp_path / "b.de48"
    bad.write_bytes(good.read_bytes() + bytes.fromhex("200000000001"))     # ACC with data
    with pytest.raises(fast.FastModelError, match=r"b\.de48: slot 4: ACC without"):
        fast.render_frame([good, good, bad], 8, 2)
    with pytest.raises(fast.FastModelError, match="bad magic"):
        fast.render_frame([good, b"DE49" + bytes(4), good], 8, 2)
    with pytest.raises(fast.FastModelError, match="truncated"):
        fast.render_frame([good.read_bytes() + b"\0", good, good], 8, 2)
    many = tmp_path / "m.de48"
    many.write_bytes(binfmt.encode_de48(isa.serialise([C("REFRESH")] * 3)))
    with pytest.raises(fast.FastModelError, match=r"colour g|m\.de48"):
        fast.render_frame([good, many, good], 8, 2)
    img = np.full((2, 8, 3), 7, dtype=np.uint16)
    with pytest.raises(fast.FastModelError, match="colour b"):
        fast.render_lines(img, [{}, {}, {2: _words([C("REFRESH")])}])
    assert (img == 7).all()                                # nothing written
    with pytest.raises(fast.FastModelError):
        fast.Line(8).run(C("REFRESH"))
    with pytest.raises(fast.FastModelError):
        fast.Line(0)
    with pytest.warns(UserWarning, match="1 command"):
        assert fast.render([C("EVAL", 0, 2, (ONE,)), C("REFRESH"), C("NOP")], 4).shape == (1, 4)


def test_cli_model_level_fast(tmp_path):
    """`diffengine model --level fast` renders the same raw pixels as the numpy level."""
    import sys
    from diffengine.formats.frame import read_png16
    src = REPO / "sw/scenes/fig7_21a.cmd"
    out = {}
    for level in ("functional", "fast"):
        png = tmp_path / f"{level}.png"
        r = subprocess.run([sys.executable, "-m", "diffengine", "model", str(src), "-o", str(png),
                            "--raw", "--carry-bug", "--width", "64", "--level", level],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        out[level] = read_png16(png)
    assert out["fast"].any() and np.array_equal(out["fast"], out["functional"])
