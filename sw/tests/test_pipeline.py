"""The whole `make demo` pipeline on tiny screens (diffengine.pipeline.demo, `diffengine demo`).

Scenes: the shipped CAD scene (transparent glass, specular, flat, interpenetrating) and
the Phong teapot, re-framed to a 32x16 screen; 4 chips (36 PEs) per colour, the
controller in test mode with a 640x480-length line (build shared with
test_dc_harness.py). Checks: RTL frame == golden model frame bit for bit, PSNR against
the 16x16 reference >= 38 dB, anti-aliasing on has no more error on edge pixels than off,
and a 30-frame animation played through frame deltas equals full re-renders (streams
word for word, golden frames, and the RTL fed all 30 frames in one run).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from diffengine.pipeline import anim, demo as pipeline
from diffengine.formats import frame
from diffengine.model import reference
from scene_files import scene_copy

REPO = Path(__file__).resolve().parents[2]
W, H = 32, 16
CHIPS = 4


def _tiny(tmp: Path, src: Path, name: str, background: str | None = None) -> Path:
    return scene_copy(src, tmp / name, (W, H), background)


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("scenes")
    return {
        "cad": _tiny(tmp, REPO / "sw/scenes/cad/cad.scene", "cad32.scene"),
        # as shipped: background B = 1.0 is the largest pixel value (4095), so the line
        # term plus its rounding half sits at the wrap; yproc must keep every pixel clear
        "teapot": _tiny(tmp, REPO / "sw/scenes/teapot/teapot_phong.scene", "teapot32.scene"),
        # a background picture carried by Eval0 (the reference reads the same PPM)
        "cad_sky": _tiny(tmp, REPO / "sw/scenes/cad/cad_sky.scene", "cad_sky32.scene"),
    }


@pytest.mark.parametrize("name", ["cad", "teapot", "cad_sky"])
def test_pipeline_rtl_equals_golden_and_psnr(scenes, name, tmp_path):
    rep = pipeline.run(scenes[name], tmp_path, chips=CHIPS, show_progress=False,
                       log=lambda *a: None)
    print(json.dumps({k: rep[k] for k in ("stages", "psnr_db", "error")}))
    assert rep["mode"] == 3 and rep["screen"] == [W, H]
    assert rep["bit_identical"] is True, rep.get("first_difference")
    assert rep["psnr_db"] >= pipeline.MIN_PSNR
    assert rep["outliers"]["count"] == 0, rep["outliers"]["first"]
    assert (tmp_path / rep["outliers"]["map"]).is_file()
    for c in "RGB":
        assert rep["load_monitor"][c]["total_late_lines"] == 0
        assert rep["load_monitor"][c]["issued"] == sum(rep["commands_per_line"][c])
    assert rep["rtl"]["align_err"] == 0 and rep["rtl"]["frames"] == 1
    rtl = frame.read_png16(tmp_path / "demo.png")
    gold = frame.read_png16(tmp_path / "demo_golden.png")
    assert rtl.shape == (H, W, 3) and (rtl == gold).all()
    assert rtl.std() > 50                       # a picture, not a flat field
    assert json.loads((tmp_path / "demo_report.json").read_text())["psnr_db"] == rep["psnr_db"]


@pytest.mark.parametrize("name", ["cad", "teapot"])
def test_antialiasing_edges_no_worse(scenes, name, tmp_path):
    info: dict = {}
    ref = reference.render_file(scenes[name], info=info)
    edges = info["edges"]
    assert 20 < edges.sum() < W * H - 20
    err = {}
    for aa in (True, False):
        d = tmp_path / ("aa" if aa else "noaa")
        pipeline.yproc_scan(scenes[name], d, aa=aa, extra=("--capacity", "798"))
        g = pipeline.golden([d / f"{c}.de48" for c in "rgb"], W, H).astype(np.float64)
        err[aa] = np.abs(g - ref)[edges].mean()
    print(f"{name}: mean |error| on {edges.sum()} edge pixels: AA on {err[True]:.1f}, "
          f"off {err[False]:.1f} pixel units")
    assert err[True] <= err[False]


# The CAD scene without its 624-face ball (yproc anim re-runs the HSR per frame, and
# --full once more): plate, column, bracket, a slider block that is dragged, glass.
LITE = """screen 32 16
camera eye 2.2 3.0 6.0 at 0.1 0.3 0 up 0 1 0 fov 40
light 0.5 0.9 0.6 0.5
light -0.7 0.4 0.5 0.25 0.25 0.3
ambient 0.15
background 0.95 0.95 0.97
material plate 0.55 0.6 0.65 flat
material steel 0.7 0.72 0.75 specular 0.3 40
material bracket 0.8 0.45 0.2 flat specular 0.2 20
material glass 0.35 0.6 0.7 opacity 0.35 specular 0.25 80 flat
obj {cad}/plate.obj material plate
obj {cad}/column.obj material steel
obj {cad}/bracket.obj material bracket
obj {cad}/slider.obj material bracket
obj {cad}/glass.obj material glass
"""
ANIM = """# 30 frames: slider dragged, glass more opaque, key light swung
scene lite32.scene
frames 30
move 3 -1.7 0 0.3 from 0 to 14
opacity glass 0.7 from 8 to 18
light 0 -0.6 0.9 0.4 from 16 to 29
"""


def test_animation_deltas_equal_full_rerender(tmp_path):
    (tmp_path / "lite32.scene").write_text(LITE.format(cad=REPO / "sw/scenes/cad"))
    a = tmp_path / "drag.anim"
    a.write_text(ANIM)
    out = tmp_path / "anim"
    res = subprocess.run([str(pipeline.build_yproc()), "anim", str(a), "-o", str(out),
                          "--full", "--capacity", "798"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    seq = anim.frames(out)
    assert len(seq) == 30
    changed = 0
    gold = []
    for f, streams in enumerate(seq):
        full = seq[0] if f == 0 else [anim.lines_of_de48(out / f"frame{f:03d}" / f"{c}.de48")
                                      for c in "rgb"]
        assert streams == full, f"frame {f}: deltas applied != full re-render"
        if f:
            changed += sum(a != b for c in range(3) for a, b in zip(seq[f][c], seq[f - 1][c]))
        gold.append(anim.golden_frame(full, W))
    assert changed > 30                                   # the deltas carry real changes
    assert not (gold[0] == gold[-1]).all()
    # the RTL, fed the incremental streams of all 30 frames one after the other
    frames, st = anim.play_rtl(seq, W, H, CHIPS, tmp_path)
    assert frames.shape[0] == 30 and st["load_monitor"]["R"]["total_late_lines"] == 0
    for f in range(30):
        np.testing.assert_array_equal(frames[f], gold[f], err_msg=f"frame {f}")


def test_demo_cli_help_mentions_chips():
    res = subprocess.run([sys.executable, "-m", "diffengine", "demo", "--help"],
                         capture_output=True, text=True)
    assert res.returncode == 0 and "smaller screen" in res.stdout.replace("\n", " ") or \
        "9*CHIPS" in res.stdout


def test_outliers_counts_a_wrong_pixel_on_a_smooth_surface_not_at_an_edge():
    """reference.outliers: a pixel 0.2 of full scale off where the reference is flat is
    one; the same error on a step edge (the box filter's legitimate difference) is not."""
    ref = np.full((8, 12, 3), 2000.0)
    ref[:, 8:] = 500.0                              # a step edge between columns 7 and 8
    img = np.round(ref).astype(np.uint16)
    assert not reference.outliers(img, ref).any()
    img[3, 3] += int(0.2 * 4095)                    # on the flat part
    img[3, 8] += int(0.2 * 4095)                    # on the edge
    m = reference.outliers(img, ref)
    assert m.sum() == 1 and m[3, 3]
    img[5, 2] += int(0.14 * 4095)                   # below the error threshold
    assert reference.outliers(img, ref).sum() == 1
    pic = reference.outlier_map(img, m)
    assert pic.shape == (8, 12, 3) and pic.dtype == np.uint8
    assert (pic[2:5, 2:5] == (255, 0, 0)).all() and (pic[6, 6] != (255, 0, 0)).any()
