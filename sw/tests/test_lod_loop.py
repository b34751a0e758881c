"""The Load Monitor loop with the Verilated display controller in it, and the check before
emission (issue 20 item 4; docs/yproc.md section 10), on a 32x16 copy of Fig. 7.27's
animation with a short line (HTotal 80: capacity 78, the textured pattern overflows at
full quality).

* `diffengine anim --lod-loop --rtl` (anim.lod_loop(rtl=True)): yproc runs with
  --monitor-stdin and after each frame reads the Load Monitor's line table of the
  Verilated `display_controller` that played the frame. Its decisions (every line's level
  in every frame) are the same as with yproc's model of the monitor, the controller's
  record equals the model's in every frame, and the loop really acts (late lines in frame
  0, levels lowered).
* With the check before emission (--lod-predict) no frame has a late line, in yproc's
  model and in the controller, from frame 0 on; quality is still lowered only where needed.
"""
from __future__ import annotations

import numpy as np
import pytest

from diffengine.pipeline import anim
from test_fig727_lod import SHORT, H, _anim

CAP = 78
CHIPS = 4


@pytest.mark.parametrize("predict", [False, True], ids=["loop", "predict"])
def test_loop_decisions_are_the_same_with_the_rtl_and_the_model(tmp_path, predict):
    a = _anim(tmp_path, frames=6)
    model = anim.lod_loop(a, tmp_path / "model", predict=predict, capacity=CAP)
    rtl = anim.lod_loop(a, tmp_path / "rtl", predict=predict, rtl=True, chips=CHIPS, test=SHORT,
                        log=lambda *_: None)
    assert rtl["capacity"] == CAP and rtl["frames_played"] == 6
    assert model["frames_differing_from_full"] == 0 and rtl["frames_differing_from_full"] == 0
    for f, (m, r) in enumerate(zip(model["frame"], rtl["frame"])):
        assert r["monitor"] == "stdin" and r["model_agrees"] == 1, f"frame {f}: controller != model"
        assert r["levels"] == m["levels"], f"frame {f}: the loop decided differently"
        assert r["issued"] == m["issued"] and r["overflow_lines"] == m["overflow_lines"]
    lv = np.array([f["levels"] for f in rtl["frame"]])
    assert lv[-1].mean() < 5                               # the loop lowered quality
    # frame 0 is emitted at full quality by the loop alone; the check lowers its lines first
    assert (lv[0] == 5).all() != predict
    ov = [f["overflow_lines"] for f in rtl["frame"]]
    if predict:
        # lines over the capacity were lowered before the controller saw them
        assert ov == [0] * 6, ov
        assert rtl["frame"][0]["lowered_before_emit"] > 0
    else:
        # the loop alone: frame 0 overflows (it has no record yet), then none
        assert ov[0] > 0 and all(v == 0 for v in ov[2:]), ov


def test_monitor_stdin_rejects_a_bad_record(tmp_path):
    import subprocess
    from diffengine.pipeline.demo import build_yproc
    a = _anim(tmp_path, frames=2)
    r = subprocess.run([str(build_yproc()), "anim", str(a), "-o", str(tmp_path / "o"), "--lod-loop",
                        "--monitor-stdin"], input="0 1 2 3\n", capture_output=True, text=True)
    assert r.returncode == 1 and "bad monitor record" in r.stderr, r.stderr
    r = subprocess.run([str(build_yproc()), "anim", str(a), "-o", str(tmp_path / "o"), "--monitor-stdin"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "needs --lod-loop" in r.stderr
    assert H == 16


def _comb(tmp, tess: bool):
    """lod_comb.anim at 48x24, 16 frames (the comb in at frames 0-3, out at 6-9), with or
    without `tessellation 1 0.15 3` (versions of 64, then fewer teeth)."""
    from pathlib import Path
    from scene_files import scene_copy
    repo = Path(__file__).resolve().parents[2]
    scene_copy(repo / "sw/scenes/anim/lod_comb.scene", tmp / "lod_comb.scene", (48, 24))
    a = tmp / f"comb{int(tess)}.anim"
    a.write_text("scene lod_comb.scene\nframes 16\ntexture pattern 0.25 0.4 1 0.8 0.55 7 8\n"
                 "pointlight 0 0.4 0.3 0.9 falloff 1.5\n" + ("tessellation 1 0.15 3\n" if tess else "")
                 + "move 1 4.6 0 0 from 0 to 3\nmove 1 4.6 0 0 from 6 to 9\n")
    return a


def test_tessellation_ends_what_level_0_cannot_with_the_rtl_in_the_loop(tmp_path):
    """The comb at 48x24 on an 80-slot line (HTotal 82): with the check alone, level 0 does
    not fit while the comb is in view (late lines); with tessellation the comb goes to a
    coarser version before the frame is emitted and the controller records no late line in
    any frame, with the same decisions (levels and mesh versions) as on yproc's model."""
    geom = (48, 4, 8, 82 - 60, 24, 1, 2, 2)
    plain = anim.lod_loop(_comb(tmp_path, False), tmp_path / "plain", predict=True, capacity=80)
    assert sum(f["overflow_lines"] for f in plain["frame"]) > 0          # level 0 is not enough
    model = anim.lod_loop(_comb(tmp_path, True), tmp_path / "model", predict=True, capacity=80)
    rtl = anim.lod_loop(_comb(tmp_path, True), tmp_path / "rtl", predict=True, rtl=True, chips=6,
                        test=geom, log=lambda *_: None)
    assert rtl["capacity"] == 80 and rtl["frames_played"] == 16
    assert rtl["frames_differing_from_full"] == 0
    assert rtl["frame"][0]["tess_faces"][0][0] == 64 and rtl["frame"][0]["tess_faces"][0][2] < 64
    for f, (m, r) in enumerate(zip(model["frame"], rtl["frame"])):
        assert r["overflow_lines"] == 0 and r["model_agrees"] == 1, f"frame {f}"
        assert r["levels"] == m["levels"] and r["tess"] == m["tess"], f"frame {f}"
    assert max(f["tess"][0] for f in rtl["frame"]) > 0                   # made coarser
    assert sum(f["tess_coarsened"] for f in rtl["frame"]) > 0
