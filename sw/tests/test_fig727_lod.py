"""Fig. 7.27 rebuilt and the Load Monitor loop (issue 20 items 3 and 4; docs/yproc.md
sections 10 and 11), on a 32x16 copy of the shipped animation.

* The textured pattern lit by a wandering point light (sw/scenes/anim/fig7_27.anim):
  frame 0 plus the deltas equals every frame's full re-render (streams word for word),
  only a part of each line changes between frames (the texture term stays), and the
  RTL (the Verilated display controller, 4 chips, build shared with test_pipeline.py)
  plays the frames bit for bit like the golden model.
* The Load Monitor: with a short line (HTotal 80, capacity 78) and no look-ahead
  degradation the pattern overflows; yproc's model of the monitor's per-line record
  (yp_lod_monitor_line) equals what the RTL's Load Monitor records for every line
  (issued, late), on-time lines are still bit for bit the golden model's, and the
  closed loop (`--lod-loop`) ends the overflow within a few frames.
"""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from diffengine.pipeline import anim, demo as pipeline
from scene_files import scene_copy

REPO = Path(__file__).resolve().parents[2]
W, H = 32, 16
CHIPS = 4
FRAMES = 8          # of the shipped 48: enough for two legs of the light's wander
SHORT = (W, 4, 8, 36, H, 1, 2, 2)     # HTotal 80: window 79, capacity 78


def _anim(tmp: Path, frames: int = FRAMES) -> Path:
    scene_copy(REPO / "sw/scenes/anim/fig7_27.scene", tmp / "fig7_27.scene", (W, H))
    text = (REPO / "sw/scenes/anim/fig7_27.anim").read_text()
    text = text.replace("frames 48", f"frames {frames}").replace("from 0 to 47", f"from 0 to {frames - 1}")
    a = tmp / "fig7_27_small.anim"
    a.write_text(text)
    return a


def _yproc(a: Path, out: Path, *extra) -> dict:
    res = subprocess.run([str(pipeline.build_yproc()), "anim", str(a), "-o", str(out), *map(str, extra)],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stdout + res.stderr
    return json.loads((out / "anim_stats.json").read_text())


@pytest.fixture(scope="module")
def played(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fig727")
    st = _yproc(_anim(tmp), tmp / "out", "--full", "--capacity", "798")
    return tmp, st, anim.frames(tmp / "out")


def test_fig727_frames_equal_full_rerender_and_few_instructions_change(played):
    tmp, st, seq = played
    assert len(seq) == FRAMES and st["frames_differing_from_full"] == 0
    for f in range(1, FRAMES):
        full = [anim.lines_of_de48(tmp / "out" / f"frame{f:03d}" / f"{c}.de48") for c in "rgb"]
        assert seq[f] == full, f"frame {f}: deltas applied != full re-render"
    h = anim.changed_histogram(st, seq)
    # the light moves every frame: every lit line changes, but only its light terms
    assert min(h["changed_lines"]) > 3 * H // 2
    assert 0 < h["median_changed_lines"] < 0.5 * h["mean_slots_per_line"]
    # cross-check yproc's LCS count on one line with an independent one over the words
    f, c, y = 3, 0, H // 2
    old = [seq[f - 1][c][y][i:i + 6] for i in range(0, len(seq[f - 1][c][y]) - 6, 6)]
    new = [seq[f][c][y][i:i + 6] for i in range(0, len(seq[f][c][y]) - 6, 6)]
    import difflib
    sm = difflib.SequenceMatcher(a=old, b=new, autojunk=False)
    kept = sum(b.size for b in sm.get_matching_blocks())
    assert st["frame"][f]["changed_slots"][c][y] >= len(new) - kept   # commands, not words, are kept whole
    assert st["frame"][f]["changed_slots"][c][y] > 0


def test_fig727_rtl_plays_the_frames_like_the_golden_model(played):
    tmp, _, seq = played
    gold = [anim.golden_frame(fr, W) for fr in seq]
    assert not (gold[0] == gold[-1]).all()            # the light really moved
    assert gold[0].std() > 50                          # a textured picture, not a flat field
    frames, st = anim.play_rtl(seq, W, H, CHIPS, tmp)
    assert frames.shape[0] == FRAMES and st["load_monitor"]["R"]["total_late_lines"] == 0
    for f in range(FRAMES):
        np.testing.assert_array_equal(frames[f], gold[f], err_msg=f"frame {f}")


# Temporally coherent fitting (docs/yproc.md section 11): a slow light (legs of 512
# frames) at tolerance 4, where the previous frame's colour functions mostly still hold.
COH_TOL = 4


@pytest.fixture(scope="module")
def coherent(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fig727coh")
    slow = anim.anim_variant(_anim(tmp), tmp / "fig7_27_slow.anim", FRAMES, leg=512)
    assert "wander 0 2718 512 " in slow.read_text() and f"frames {FRAMES}" in slow.read_text()
    st = {}
    for name, flags in (("coh", ("--coherent",)), ("plain", ())):
        st[name] = _yproc(slow, tmp / name, "--full", "--expect", "--cmd", "--tol", COH_TOL, *flags)
    return tmp, st, anim.frames(tmp / "coh")


def test_coherent_frames_within_tolerance_and_fewer_changes(coherent):
    tmp, st, seq = coherent
    assert st["coh"]["coherent"] == 1 and st["coh"]["frames_differing_from_full"] == 0
    # frame 0 plus the deltas equals every frame's full re-render from the same previous
    # frame (word for word)
    for f in range(FRAMES):
        full = [anim.lines_of_de48(tmp / "coh" / f"frame{f:03d}" / f"{c}.de48") for c in "rgb"]
        assert seq[f] == full, f"frame {f}: deltas applied != full re-render"
    # the error bound holds against the exact shading in every frame (the golden model,
    # not yproc's own array model): 1/2 + the three terms' tolerance (base, texture,
    # specular; partly covered pixels at 1/64)
    bound = 0.5 + 3 * COH_TOL + 0.05
    for f in range(FRAMES):
        ideal = np.fromfile(tmp / "coh" / f"frame{f:03d}" / "ideal.f64", dtype="<f8").reshape(3, H, W)
        err = float(np.abs(anim.golden_frame(seq[f], W).transpose(2, 0, 1) - ideal).max())
        assert err <= bound, f"frame {f}: worst pixel {err:.3f} > {bound}"
        assert abs(err - st["coh"]["frame"][f]["max_abs_err"]) < 1e-3
    # fewer changed instructions than refitting every frame at the same tolerance
    coh, plain = (np.array([f["changed_slots"] for f in st[k]["frame"][1:]]).sum() for k in ("coh", "plain"))
    assert 0 < coh < 0.8 * plain, (coh, plain)


def test_coherent_frames_play_on_the_rtl_like_the_golden_model(coherent):
    tmp, st, seq = coherent
    # the streams carry what only coherent fitting emits: resyncs onto an old spline
    # (SetI and SetdI inside an Eval3's span) and the edge pixels' own Eval1
    text = "".join((tmp / "coh" / f"frame{f:03d}" / f"{c}.cmd").read_text() for f in range(1, FRAMES) for c in "rgb")
    assert text.count("SetI (") > 20 and text.count("SetdI (") > 20 and ", 1, 0x" in text
    gold = [anim.golden_frame(fr, W) for fr in seq]
    assert not (gold[0] == gold[-1]).all()            # the light really moved
    frames, rst = anim.play_rtl(seq, W, H, CHIPS, tmp)
    assert rst["load_monitor"]["R"]["total_late_lines"] == 0
    for f in range(FRAMES):
        np.testing.assert_array_equal(frames[f], gold[f], err_msg=f"frame {f}")


def test_load_monitor_model_equals_rtl_and_loop_ends_overflow(tmp_path):
    a = _anim(tmp_path, frames=4)
    cap = pipeline.capacity(3, SHORT)
    assert cap == 78
    # open loop: full quality, no look-ahead degradation -> lines overflow
    st = _yproc(a, tmp_path / "open", "--capacity", cap, "--no-degrade")
    assert all(f["overflow_lines"] > 0 for f in st["frame"])
    seq = anim.frames(tmp_path / "open")
    frames, rst = anim.play_rtl(seq[-1:], W, H, CHIPS, tmp_path, test=SHORT)
    lm = rst["load_monitor"]
    # the Load Monitor's line table holds the last frame: per line the largest issued
    # count of the three colours and whether any was late, as yproc's model says
    issued = np.max([lm[c]["line_issued"] for c in "RGB"], axis=0)
    late = np.zeros(H, bool)
    for c in "RGB":
        late[lm[c]["late_line_numbers"]] = True
    last = st["frame"][-1]
    assert issued.tolist() == last["issued"]
    assert int(late.sum()) == last["overflow_lines"] and late.any()
    gold = anim.golden_frame(seq[-1], W)
    for y in range(H):
        if not late[y]:
            np.testing.assert_array_equal(frames[0, y], gold[y], err_msg=f"on-time line {y}")
    # closed loop: the overflow ends within 3 frames and stays away
    st = _yproc(_anim(tmp_path, frames=8), tmp_path / "loop", "--capacity", cap, "--lod-loop")
    ov = [f["overflow_lines"] for f in st["frame"]]
    assert ov[0] > 0 and all(v == 0 for v in ov[3:]), ov
    assert st["frame"][-1]["mean_level"] < 5          # the quality paid for it
