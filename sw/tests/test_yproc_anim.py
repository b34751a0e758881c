"""`yproc anim`: the animation plays through incremental HSR updates and
frame deltas; applying the deltas to frame 0 gives, for every frame, exactly
the streams of a full re-render (`--full`), which play through the golden
model.  Uses only numpy and diffengine (docs/yproc.md, frame-delta format)."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
import yproc_common as yc  # noqa: E402

from diffengine.pipeline import anim  # noqa: E402

W, H = 64, 48


@pytest.fixture(scope="module")
def yproc():
    return yc.build_yproc()


def read_delta(path: Path):
    """frameNNN.delta -> frame, {colour: {line: words}} (the package's reader, which checks
    the magic, the version, every line's Refresh and that nothing trails)"""
    frame, w, h, chans = anim.read_delta(path)
    assert (w, h) == (W, H)
    return frame, dict(zip("rgb", chans))


def test_anim_deltas_equal_full_rerender(yproc, tmp_path):
    scene = yc.small_scene(yc.SCENES / "anim/anim.scene", tmp_path / "anim.scene", W, H)
    anim = (yc.SCENES / "anim/cad_drag.anim").read_text().replace("scene anim.scene", f"scene {scene}")
    (tmp_path / "a.anim").write_text(anim)
    out = tmp_path / "out"
    r = yc.run("anim", tmp_path / "a.anim", "-o", out, "--full")
    assert "frames differing from a full re-render: 0" in r.stdout
    st = json.loads((out / "anim_stats.json").read_text())
    nframes = st["frames"]
    assert nframes >= 30
    cur = {c: yc.split_lines((out / "frame000" / f"{c}.de48").read_bytes()[8:]) for c in "rgb"}
    changed_total = 0
    for f in range(1, nframes):
        frame, delta = read_delta(out / f"frame{f:03d}.delta")
        assert frame == f
        for c in "rgb":
            for y, words in delta[c].items():
                assert cur[c][y] != words, "a delta line must differ from the previous frame"
                cur[c][y] = words
            changed_total += len(delta[c])
            full = (out / f"frame{f:03d}" / f"{c}.de48").read_bytes()
            assert b"DE48\x00\x01\x00\x00" + b"".join(cur[c]) == full, f"frame {f} colour {c}"
        fs = st["frame"][f]
        assert [len(delta[c]) for c in "rgb"] == fs["changed_lines"]
    assert 0 < changed_total < 3 * H * (nframes - 1)
    # the last frame plays through the golden model
    last = out / f"frame{nframes - 1:03d}"
    for c in "rgb":
        pix = yc.golden(last / f"{c}.de48", W)
        assert pix.shape == (H, W) and pix.max() <= 4095


def test_anim_drag_of_624_faces_equals_full_rerender(yproc, tmp_path):
    """The CAD ball (624 faces) dragged through the glass and the column at 640x480: one
    hsr_change_many a frame (docs/hsr.md, "Damage repair").  Before its pieces were joined
    after the adds, frame 1 left 813 LLR domains where a build has 573, and 9 of its lines
    differed from the full re-render (the per-pixel coverage is summed over a prefix's
    domains in floating point, docs/yproc.md)."""
    scene = yc.small_scene(yc.SCENES / "cad/cad.scene", tmp_path / "cad.scene", 640, 480)
    (tmp_path / "ball.anim").write_text(f"scene {scene}\nframes 3\nmove 3 0.8 0 0.3 from 0 to 5\n")
    r = yc.run("anim", tmp_path / "ball.anim", "-o", tmp_path / "out")
    assert "frames differing from a full re-render: 0" in r.stdout
    st = json.loads((tmp_path / "out" / "anim_stats.json").read_text())
    assert [f["lines_differing_from_full"] for f in st["frame"][1:]] == [0, 0]
    assert all(f["changed_lines"][0] > 100 for f in st["frame"][1:])   # the ball did move
