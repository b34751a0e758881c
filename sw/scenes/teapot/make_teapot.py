#!/usr/bin/env python3
"""Utah teapot (Newell 1975, public domain) as a triangle mesh + yproc scene.

    python3 sw/scenes/teapot/make_teapot.py [-n 8] [-o DIR] [--screen 640 480]

writes DIR/teapot.obj (n x n quads per Bezier patch, each split into two
triangles; zero-area triangles at the lid and bottom poles dropped, so
64 n^2 - 8 n triangles: n = 25 gives 39800, the ~40K of section 5.3.3) and
DIR/teapot.scene (camera looking at the teapot from the side, y up).  Only the
standard library is needed; `teapot_triangles(n)` is importable.

Patch table: the 10 patches of the classic reduced form (rim, body x2, lid x2
and bottom are mirrored in x and y, handle and spout in y only: 32 patches),
control points in Newell's coordinates (z up).
"""
from __future__ import annotations

import argparse
from pathlib import Path

# 16 control-point indices per patch (row-major 4 x 4)
PATCHES = [
    # rim
    (102, 103, 104, 105, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
    # body
    (12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27),
    (24, 25, 26, 27, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40),
    # lid
    (96, 96, 96, 96, 97, 98, 99, 100, 101, 101, 101, 101, 0, 1, 2, 3),
    (0, 1, 2, 3, 106, 107, 108, 109, 110, 111, 112, 113, 114, 115, 116, 117),
    # bottom
    (118, 118, 118, 118, 124, 122, 119, 121, 123, 126, 125, 120, 40, 39, 38, 37),
    # handle
    (41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55, 56),
    (53, 54, 55, 56, 57, 58, 59, 60, 61, 62, 63, 64, 28, 65, 66, 67),
    # spout
    (68, 69, 70, 71, 72, 73, 74, 75, 76, 77, 78, 79, 80, 81, 82, 83),
    (80, 81, 82, 83, 84, 85, 86, 87, 88, 89, 90, 91, 92, 93, 94, 95),
]
FOUR_WAY = 6   # the first 6 patches are mirrored in x and y, the rest in y only

POINTS = [
    (0.2, 0, 2.7), (0.2, -0.112, 2.7), (0.112, -0.2, 2.7), (0, -0.2, 2.7),
    (1.3375, 0, 2.53125), (1.3375, -0.749, 2.53125), (0.749, -1.3375, 2.53125),
    (0, -1.3375, 2.53125), (1.4375, 0, 2.53125), (1.4375, -0.805, 2.53125),
    (0.805, -1.4375, 2.53125), (0, -1.4375, 2.53125), (1.5, 0, 2.4), (1.5, -0.84, 2.4),
    (0.84, -1.5, 2.4), (0, -1.5, 2.4), (1.75, 0, 1.875), (1.75, -0.98, 1.875),
    (0.98, -1.75, 1.875), (0, -1.75, 1.875), (2, 0, 1.35), (2, -1.12, 1.35),
    (1.12, -2, 1.35), (0, -2, 1.35), (2, 0, 0.9), (2, -1.12, 0.9), (1.12, -2, 0.9),
    (0, -2, 0.9), (-2, 0, 0.9), (2, 0, 0.45), (2, -1.12, 0.45), (1.12, -2, 0.45),
    (0, -2, 0.45), (1.5, 0, 0.225), (1.5, -0.84, 0.225), (0.84, -1.5, 0.225),
    (0, -1.5, 0.225), (1.5, 0, 0.15), (1.5, -0.84, 0.15), (0.84, -1.5, 0.15),
    (0, -1.5, 0.15), (-1.6, 0, 2.025), (-1.6, -0.3, 2.025), (-1.5, -0.3, 2.25),
    (-1.5, 0, 2.25), (-2.3, 0, 2.025), (-2.3, -0.3, 2.025), (-2.5, -0.3, 2.25),
    (-2.5, 0, 2.25), (-2.7, 0, 2.025), (-2.7, -0.3, 2.025), (-3, -0.3, 2.25),
    (-3, 0, 2.25), (-2.7, 0, 1.8), (-2.7, -0.3, 1.8), (-3, -0.3, 1.8), (-3, 0, 1.8),
    (-2.7, 0, 1.575), (-2.7, -0.3, 1.575), (-3, -0.3, 1.35), (-3, 0, 1.35),
    (-2.5, 0, 1.125), (-2.5, -0.3, 1.125), (-2.65, -0.3, 0.9375), (-2.65, 0, 0.9375),
    (-2, -0.3, 0.9), (-1.9, -0.3, 0.6), (-1.9, 0, 0.6), (1.7, 0, 1.425),
    (1.7, -0.66, 1.425), (1.7, -0.66, 0.6), (1.7, 0, 0.6), (2.6, 0, 1.425),
    (2.6, -0.66, 1.425), (3.1, -0.66, 0.825), (3.1, 0, 0.825), (2.3, 0, 2.1),
    (2.3, -0.25, 2.1), (2.4, -0.25, 2.025), (2.4, 0, 2.025), (2.7, 0, 2.4),
    (2.7, -0.25, 2.4), (3.3, -0.25, 2.4), (3.3, 0, 2.4), (2.8, 0, 2.475),
    (2.8, -0.25, 2.475), (3.525, -0.25, 2.49375), (3.525, 0, 2.49375),
    (2.9, 0, 2.475), (2.9, -0.15, 2.475), (3.45, -0.15, 2.5125), (3.45, 0, 2.5125),
    (2.8, 0, 2.4), (2.8, -0.15, 2.4), (3.2, -0.15, 2.4), (3.2, 0, 2.4), (0, 0, 3.15),
    (0.8, 0, 3.15), (0.8, -0.45, 3.15), (0.45, -0.8, 3.15), (0, -0.8, 3.15),
    (0, 0, 2.85), (1.4, 0, 2.4), (1.4, -0.784, 2.4), (0.784, -1.4, 2.4), (0, -1.4, 2.4),
    (0.4, 0, 2.55), (0.4, -0.224, 2.55), (0.224, -0.4, 2.55), (0, -0.4, 2.55),
    (1.3, 0, 2.55), (1.3, -0.728, 2.55), (0.728, -1.3, 2.55), (0, -1.3, 2.55),
    (1.3, 0, 2.4), (1.3, -0.728, 2.4), (0.728, -1.3, 2.4), (0, -1.3, 2.4), (0, 0, 0),
    (1.425, -0.798, 0), (1.5, 0, 0.075), (1.425, 0, 0), (0.798, -1.425, 0),
    (0, -1.5, 0.075), (0, -1.425, 0), (1.5, -0.84, 0.075), (0.84, -1.5, 0.075),
]


def _bernstein(t: float) -> tuple[float, float, float, float]:
    s = 1.0 - t
    return (s * s * s, 3 * s * s * t, 3 * s * t * t, t * t * t)


def patches() -> list[list[tuple[float, float, float]]]:
    """The 32 patches as 16 control points each (Newell coordinates, z up)."""
    out = []
    for k, idx in enumerate(PATCHES):
        cp = [POINTS[i] for i in idx]
        signs = [(1, 1)] + ([(1, -1), (-1, 1), (-1, -1)] if k < FOUR_WAY else [(1, -1)])
        for sx, sy in signs:
            out.append([(sx * x, sy * y, z) for x, y, z in cp])
    return out


def patch_flips() -> list[bool]:
    """Per patch of patches(): True if it is mirrored in one axis only, which reverses
    its orientation (its triangles must be wound the other way round to face out)."""
    out = []
    for k in range(len(PATCHES)):
        signs = [(1, 1)] + ([(1, -1), (-1, 1), (-1, -1)] if k < FOUR_WAY else [(1, -1)])
        out += [sx * sy < 0 for sx, sy in signs]
    return out


def _area2(a, b, c) -> float:
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return (n[0] ** 2 + n[1] ** 2 + n[2] ** 2) ** 0.5


def teapot_triangles(n: int):
    """(vertices, triangles): vertices in y-up world coordinates (x, z, -y of
    Newell's), triangles as 0-based index triples; zero-area ones dropped.

    Vertices that coincide (patch seams, the mirrored halves, the poles) are welded
    into one, so that smooth normals averaged over the faces sharing a vertex are
    continuous across patch boundaries (the teapot's patches join with a common
    tangent plane); unwelded, every seam shows as a shading crease."""
    verts, tris = [], []
    index: dict = {}
    for cp, flip in zip(patches(), patch_flips()):
        grid = []
        for i in range(n + 1):
            bu = _bernstein(i / n)
            for j in range(n + 1):
                bv = _bernstein(j / n)
                p = [0.0, 0.0, 0.0]
                for a in range(4):
                    for b in range(4):
                        w = bu[a] * bv[b]
                        q = cp[4 * a + b]
                        p[0] += w * q[0]; p[1] += w * q[1]; p[2] += w * q[2]
                v = (p[0], p[2], -p[1])
                key = tuple(round(x, 9) + 0.0 for x in v)     # + 0.0: -0 and 0 weld
                if key not in index:
                    index[key] = len(verts)
                    verts.append(v)
                grid.append(index[key])
        for i in range(n):
            for j in range(n):
                k = i * (n + 1) + j
                a, b, c, d = grid[k], grid[k + 1], grid[k + n + 1], grid[k + n + 2]
                for t in (((a, d, c), (a, b, d)) if flip else ((a, c, d), (a, d, b))):
                    if len(set(t)) == 3 and _area2(verts[t[0]], verts[t[1]], verts[t[2]]) > 1e-12:
                        tris.append(t)
    return verts, tris


def write_obj(path: Path, n: int) -> int:
    verts, tris = teapot_triangles(n)
    lines = [f"# Utah teapot (Newell, public domain), {n} x {n} per patch, {len(tris)} triangles",
             "usemtl teapot"]
    lines += ["v %.9g %.9g %.9g" % v for v in verts]
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in tris]
    path.write_text("\n".join(lines) + "\n")
    return len(tris)


def scene_text(obj_name: str = "teapot.obj", width: int = 640, height: int = 480,
               fov: float = 30.0, grid: int = 32, extra: str = "") -> str:
    """Side view (eye slightly above the lid plane), teapot filling the screen."""
    return (f"# Utah teapot seen from the side (Kuijk 1995, section 5.4.3)\n"
            f"screen {width} {height}\n"
            f"camera eye 0.3 3.2 10.5 at 0.25 1.45 0 up 0 1 0 fov {fov:g}\n"
            f"light 0.4 0.8 0.6 0.8\nambient 0.2\nbackground 1 1 1\ngrid {grid}\n"
            f"material teapot 0.8 0.75 0.6\n"
            f"obj {obj_name} material teapot\n" + extra)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-n", type=int, default=8, help="quads per patch side (default 8: 4064 triangles)")
    ap.add_argument("-o", "--outdir", type=Path, default=Path(__file__).resolve().parent)
    ap.add_argument("--screen", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    ap.add_argument("--fov", type=float, default=30.0)
    ap.add_argument("--grid", type=int, default=32)
    a = ap.parse_args()
    a.outdir.mkdir(parents=True, exist_ok=True)
    nt = write_obj(a.outdir / "teapot.obj", a.n)
    (a.outdir / "teapot.scene").write_text(scene_text("teapot.obj", *a.screen, a.fov, a.grid))
    print(f"wrote {a.outdir / 'teapot.obj'} ({nt} triangles) and {a.outdir / 'teapot.scene'}")


if __name__ == "__main__":
    main()
