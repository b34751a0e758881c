"""Issue 21 part 3, OBJ as users write it: every feature's small scene (sw/hsr/tests/obj/,
32x16) through the software pipeline (yproc scan + golden model) against the reference
renderer; what the reference makes of the one reader's output (`yproc read`: triangles,
corner normals, materials); and the errors for what cannot be read, with file:line, the
same through `yproc scan` and through the reference.

Features: `vn` with negative indices, `s` smoothing groups, quads and n-gons (convex,
concave, non-planar), `mtllib`/`usemtl` with Kd, d, Tr, Ks, Ns, and meshes with holes and
non-manifold edges."""
from __future__ import annotations

import math
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from diffengine.pipeline import demo as pipeline
from diffengine.model import reference
from diffengine.host import yproc

REPO = Path(__file__).resolve().parents[2]
OBJ = REPO / "sw/hsr/tests/obj"
FEATURES = ["vn_negative", "smoothing", "polygons", "mtl", "holes"]


@pytest.mark.parametrize("name", FEATURES)
def test_feature_scene_matches_reference(name, tmp_path):
    rep = pipeline.run(OBJ / f"{name}.scene", tmp_path, rtl=False, show_progress=False,
                       log=lambda *a: None)
    print(name, rep["psnr_db"], rep["outliers"]["count"], rep["error"])
    assert rep["outliers"]["count"] == 0, rep["outliers"]["first"]
    assert rep["psnr_db"] >= 45
    ref = np.load(next(tmp_path.glob(".reference_*.npy")))
    assert ref.std() > 100                        # a picture, not a flat field


# --- what the reference reads ---------------------------------------------------------

def _load(tmp_path, obj: str, mtl: dict[str, str] | None = None, scene_extra: str = ""):
    (tmp_path / "m.obj").write_text(obj)
    for k, v in (mtl or {}).items():
        (tmp_path / k).write_text(v)
    s = tmp_path / "s.scene"
    s.write_text("screen 32 16\nmaterial base 0.5 0.5 0.5\n" + scene_extra
                 + "obj m.obj material base\n")
    return reference.load_scene(s)


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def test_reference_vn_negative_index(tmp_path):
    sc = _load(tmp_path, (OBJ / "vn_negative.obj").read_text())
    # quad 2 (v2 v5 v6 v3 with vn2 vn4 vn4 vn3) is convex and planar: fan (0,1,2), (0,2,3)
    assert sc.pos.shape == (4, 3, 3)
    np.testing.assert_allclose(sc.nrm[2], [[0.5, 0, 1], [0.7, -0.3, 1], [0.7, -0.3, 1]])
    np.testing.assert_allclose(sc.nrm[3], [[0.5, 0, 1], [0.7, -0.3, 1], [0, 0.6, 1]])


def test_reference_smoothing_groups(tmp_path):
    sc = _load(tmp_path, (OBJ / "smoothing.obj").read_text())
    n = np.array([_unit(x) for x in sc.nrm.reshape(-1, 3)]).reshape(-1, 3, 3)
    # strips (two triangles each); strip 3 ('s off') is flat
    s3 = n[4:6].reshape(-1, 3)
    assert np.allclose(s3, s3[0])
    # x = -1 (strip 2, s 1) only averages strip 2 (strip 3 is 's off'): its face normal
    f2 = _unit(np.cross([1, 0, -0.8], [0, 1, 0]))
    i = np.argwhere(np.isclose(sc.pos[2:4, :, 0], -1))
    for t, c in i:
        np.testing.assert_allclose(n[2 + t, c], f2, atol=1e-12)
    # x = 2 is shared by strip 5 (s 2) and strip 6 (s 1): two different normals
    a = n[8:10][np.isclose(sc.pos[8:10, :, 0], 2)]
    b = n[10:12][np.isclose(sc.pos[10:12, :, 0], 2)]
    assert np.allclose(a, a[0]) and np.allclose(b, b[0]) and not np.allclose(a[0], b[0])


def test_reference_no_s_statement_is_all_smooth(tmp_path):
    text = (OBJ / "smoothing.obj").read_text().replace("s off", "").replace("s 1", "")
    sc = _load(tmp_path, text.replace("s 2", ""))
    n = np.array([_unit(x) for x in sc.nrm.reshape(-1, 3)]).reshape(-1, 3, 3)
    at = n[np.isclose(sc.pos[..., 0], 1)]          # shared by strips 4 and 5: one normal
    assert len(at) >= 4 and np.allclose(at, at[0])


def test_reader_keeps_convex_planar_polygons_whole_and_splits_the_others(tmp_path):
    def faces(obj):
        (tmp_path / "m.obj").write_text(obj)
        (tmp_path / "s.scene").write_text("screen 32 16\nobj m.obj\n")
        f = yproc.read_scene(tmp_path / "s.scene")["faces"]
        return f["count"], f["poly"]
    quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
    assert faces(quad) == ([4], [0])
    # the dart: reflex corner 2; ear clipping cuts it into two triangles of one polygon
    dart = "v -1 -1 0\nv 0 -0.2 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3 4\n"
    assert faces(dart) == ([3, 3], [0, 0])
    twisted = "v 0 0 0.3\nv 1 0 -0.3\nv 1 1 0.3\nv 0 1 -0.3\nf 1 2 3 4\n"
    assert faces(twisted) == ([3, 3], [0, 0])
    sc = _load(tmp_path, (OBJ / "polygons.obj").read_text())
    assert len(sc.pos) == 3 + 4 + 2 + 2 + 2


def test_reference_mtl_materials(tmp_path):
    obj = (OBJ / "mtl.obj").read_text()
    sc = _load(tmp_path, obj, {"mats.mtl": (OBJ / "mats.mtl").read_text()},
               scene_extra="material green 0.1 0.7 0.2\n")
    m = {k: sc.materials[i] for k, i in zip(["red", "glass", "shiny", "green", "nosuch"],
                                           sc.mat[::2])}
    assert m["red"].kd == (0.8, 0.1, 0.1) and m["red"].opacity == 1
    assert m["glass"].opacity == 0.5 and m["glass"].ks == pytest.approx(0.2)
    assert m["glass"].n == 20
    assert m["shiny"].kd == (0.2, 0.2, 0.2) and m["shiny"].opacity == 0.75
    assert m["green"].kd == (0.1, 0.7, 0.2)          # the scene file's green wins
    assert m["nosuch"].name == "base"                # else the obj line's material


def test_reference_holes_and_non_manifold_load(tmp_path):
    sc = _load(tmp_path, (OBJ / "holes.obj").read_text())
    assert len(sc.pos) == 14 and np.isfinite(sc.nrm).all()


# --- errors: file:line and meaning, through yproc and through the reference ------------

ERRORS = [
    # (obj text, mtl files, expected message after "m.obj:LINE: " or "x.mtl:LINE: ")
    ("v 0 0 0\nvn 0 0 x\n", {}, "m.obj:2: bad or non-finite number 'x'"),
    ("v 0 0 0\nvn 0 0\n", {}, "m.obj:2: 'vn' needs 3 numbers"),
    ("vn 0 0 0\n", {}, "m.obj:1: 'vn' has zero length"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n", {},
     "m.obj:5: normal index 2 out of range (1..1)"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//-2 2//1 3//1\n", {},
     "m.obj:5: normal index -2 out of range (1..1)"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n", {},
     "m.obj:4: texture index 1 out of range (1..0)"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 2 3\n", {}, "m.obj:4: vertex index -4 out of range (1..3)"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2 3\n", {}, "m.obj:4: bad vertex index '1/'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", {}, "m.obj:4: bad vertex index '1/1/1/1'"),
    ("v 0 0 0 1 2\n", {}, "m.obj:1: 'v' needs 3 coordinates"),
    ("s on\n", {}, "m.obj:1: 's' needs a group number >= 0 or 'off'"),
    ("s -1\n", {}, "m.obj:1: 's' needs a group number >= 0 or 'off'"),
    ("usemtl\n", {}, "m.obj:1: 'usemtl' needs one name"),
    ("\nmtllib\n", {}, "m.obj:2: 'mtllib' needs a file name"),
    ("\n\nmtllib nosuch.mtl\n", {}, "m.obj:3: cannot read MTL file"),
    ("mtllib x.mtl\n", {"x.mtl": "# c\nKd 1 0 0\n"}, "x.mtl:2: 'Kd' before 'newmtl'"),
    ("mtllib x.mtl\n", {"x.mtl": "newmtl a\nKd 1 0\n"}, "x.mtl:2: 'Kd' needs 1 or 3 finite"),
    ("mtllib x.mtl\n", {"x.mtl": "newmtl a\nKd spectral a.spd\n"}, "x.mtl:2: 'Kd' needs 1 or 3"),
    ("mtllib x.mtl\n", {"x.mtl": "newmtl a\n\nd 1.5\n"}, "x.mtl:3: 'd' needs one number in [0,1]"),
    ("mtllib x.mtl\n", {"x.mtl": "newmtl a\nTr x\n"}, "x.mtl:2: 'Tr' needs one number in [0,1]"),
    ("mtllib x.mtl\n", {"x.mtl": "newmtl a\nNs -1\n"}, "x.mtl:2: 'Ns' needs one finite number"),
    ("mtllib x.mtl\n", {"x.mtl": "newmtl a\nKs -1\n"}, "x.mtl:2: 'Ks' must be >= 0"),
    ("mtllib x.mtl\n", {"x.mtl": "newmtl\n"}, "x.mtl:1: 'newmtl' needs one name"),
]


def _yproc_error(tmp_path: Path) -> str:
    exe = pipeline.build_yproc()
    res = subprocess.run([str(exe), "scan", str(tmp_path / "s.scene"), "-o",
                          str(tmp_path / "out")], capture_output=True, text=True)
    assert res.returncode != 0
    return res.stderr


@pytest.mark.parametrize("obj,mtl,msg", ERRORS, ids=[e[2].split(": ", 1)[1][:40] for e in ERRORS])
def test_errors_name_file_and_line_in_both_paths(tmp_path, obj, mtl, msg):
    fname, line, text = msg.split(":", 2)
    with pytest.raises(reference.SceneError) as e:
        _load(tmp_path, obj, mtl)
    assert f"{tmp_path / fname}:{line}:{text}" in str(e.value)
    assert f"{tmp_path / fname}:{line}:{text}" in _yproc_error(tmp_path)


def test_nowrap_check_names_mtl_line(tmp_path):
    _load(tmp_path, "mtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n",
          {"x.mtl": "newmtl ok\nKd 0.1\nnewmtl hot\nKd 0.9 0.5 0.5\nKs 0.3\n"})
    err = _yproc_error(tmp_path)
    assert f"{tmp_path / 'x.mtl'}:3: material 'hot' can exceed intensity 1 in R" in err


def test_suzanne_reads_as_quads_with_authored_normals():
    sc = reference.load_scene(REPO / "sw/scenes/meshes/suzanne.scene")
    assert len(sc.pos) == 968 and math.isfinite(sc.nrm.sum())


# --- random token soup: the reader never fails without naming the file and line -------

SOUP = ["v", "vn", "vt", "f", "s", "usemtl", "mtllib", "0", "1", "-1", "2", "3", "-3", "0.5",
        "1//1", "1/1/1", "-2//-1", "2//-1", "1/1", "1/", "off", "x", "nan", "1e999", "0x1p1",
        "grey", "m.mtl", "#", " ", " ", " ", "\n", "\n", "\n\t", "\nf 1 2 3 ", "\nf -1 -2 ",
        "\nf 1//1 2//1 3//1\n", "\nf 1/1/1 3/1/1 2/1/-1 ", "\nusemtl grey\n", "\nmtllib m.mtl\n",
        "\ns 1\n", "\nv 1 1 1\n", "\nvn 0 1 0\n"]
MTL = "newmtl grey\nKd 0.5\nnewmtl hot\nKd 1 1 1\n"


def _c_status(tmp_path: Path) -> tuple[bool, str]:
    exe = pipeline.build_yproc()
    res = subprocess.run([str(exe), "hsr", str(tmp_path / "s.scene"), "--svg",
                          str(tmp_path / "o.svg")], capture_output=True, text=True)
    return res.returncode == 0, res.stderr


@pytest.mark.parametrize("seed", range(6))
def test_token_soup_is_read_or_refused_at_a_line(tmp_path, seed):
    """Every soup is either read (and the reference gets finite triangles and normals from
    it) or refused by `yproc hsr` and by the reference with one "m.obj:N:" / "m.mtl:N:"
    message, the same one."""
    print("seed", seed)
    rng = np.random.default_rng(seed)
    head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\n"
    where = re.compile(r"(m\.obj|m\.mtl):(\d+): ")
    for _ in range(40):
        body = "".join(rng.choice(SOUP) + (" " if rng.random() < 0.6 else "")
                       for _ in range(rng.integers(1, 30)))
        try:
            sc = _load(tmp_path, head + body, {"m.mtl": MTL})
            py_ok, py_err = True, ""
            assert np.isfinite(sc.pos).all() and np.isfinite(sc.nrm).all(), head + body
        except reference.SceneError as e:
            py_ok, py_err = False, str(e)
        c_ok, c_err = _c_status(tmp_path)
        assert py_ok == c_ok, (head + body, py_err, c_err)
        if not py_ok:
            assert where.search(py_err) and py_err.strip() == c_err.strip(), \
                (head + body, py_err, c_err)
