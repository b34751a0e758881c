#!/usr/bin/env python3
"""CAD-like test scene for yproc (docs/yproc.md): several objects, one
transparent, interpenetrating parts.  Standard library only; triangles only.

    python3 sw/scenes/cad/make_cad.py [-o DIR]

writes DIR/{plate,column,bracket,ball,glass,slider,pane}.obj and sky.ppm;
cad.scene, cad_sky.scene and ../anim/anim.scene refer to them.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path


def box(cx, cy, cz, sx, sy, sz, rot_y=0.0):
    """axis box (rotated about y), 12 triangles, own vertices per face so a
    smooth material would still look flat"""
    c, s = math.cos(rot_y), math.sin(rot_y)

    def p(x, y, z):
        return (cx + c * x + s * z, cy + y, cz - s * x + c * z)
    hx, hy, hz = sx / 2, sy / 2, sz / 2
    quads = [  # counter-clockwise seen from outside
        [(-hx, -hy, hz), (hx, -hy, hz), (hx, hy, hz), (-hx, hy, hz)],
        [(hx, -hy, -hz), (-hx, -hy, -hz), (-hx, hy, -hz), (hx, hy, -hz)],
        [(hx, -hy, hz), (hx, -hy, -hz), (hx, hy, -hz), (hx, hy, hz)],
        [(-hx, -hy, -hz), (-hx, -hy, hz), (-hx, hy, hz), (-hx, hy, -hz)],
        [(-hx, hy, hz), (hx, hy, hz), (hx, hy, -hz), (-hx, hy, -hz)],
        [(-hx, -hy, -hz), (hx, -hy, -hz), (hx, -hy, hz), (-hx, -hy, hz)],
    ]
    verts, tris = [], []
    for q in quads:
        b = len(verts)
        verts += [p(*v) for v in q]
        tris += [(b, b + 1, b + 2), (b, b + 2, b + 3)]
    return verts, tris


def cylinder(cx, cz, y0, y1, r, n=32):
    """smooth side (shared vertices) + caps (own vertices)"""
    verts, tris = [], []
    for i in range(n):
        a = 2 * math.pi * i / n
        verts += [(cx + r * math.cos(a), y0, cz + r * math.sin(a)), (cx + r * math.cos(a), y1, cz + r * math.sin(a))]
    for i in range(n):
        j = (i + 1) % n
        tris += [(2 * i, 2 * i + 1, 2 * j + 1), (2 * i, 2 * j + 1, 2 * j)]
    side = len(tris)
    for y, up in ((y1, True), (y0, False)):
        c = len(verts)
        verts.append((cx, y, cz))
        for i in range(n):
            a = 2 * math.pi * i / n
            verts.append((cx + r * math.cos(a), y, cz + r * math.sin(a)))
        for i in range(n):
            a, b = c + 1 + i, c + 1 + (i + 1) % n
            tris.append((c, b, a) if up else (c, a, b))
    return verts, tris, side


def sphere(cx, cy, cz, r, nu=24, nv=14):
    verts, tris = [(cx, cy + r, cz)], []
    for j in range(1, nv):
        t = math.pi * j / nv
        for i in range(nu):
            a = 2 * math.pi * i / nu
            verts.append((cx + r * math.sin(t) * math.cos(a), cy + r * math.cos(t), cz + r * math.sin(t) * math.sin(a)))
    verts.append((cx, cy - r, cz))
    bottom = len(verts) - 1

    def ring(j, i):
        return 1 + (j - 1) * nu + i % nu
    for i in range(nu):
        tris.append((0, ring(1, i + 1), ring(1, i)))
        tris.append((bottom, ring(nv - 1, i), ring(nv - 1, i + 1)))
    for j in range(1, nv - 1):
        for i in range(nu):
            a, b, c, d = ring(j, i), ring(j, i + 1), ring(j + 1, i + 1), ring(j + 1, i)
            tris += [(a, b, c), (a, c, d)]
    return verts, tris


def write(path: Path, verts, tris, comment, groups=None):
    lines = [f"# {comment}"] + ["v %.6f %.6f %.6f" % v for v in verts]
    for k, t in enumerate(tris):
        if groups and k in groups:
            lines.append(f"usemtl {groups[k]}")
        lines.append("f %d %d %d" % (t[0] + 1, t[1] + 1, t[2] + 1))
    path.write_text("\n".join(lines) + "\n")


def write_sky(path: Path, w: int = 80, h: int = 60) -> None:
    """background picture for cad_sky.scene: a sky gradient with a sun disc and
    banded hills (binary PPM, 8 bit; yproc scales it to the screen)"""
    px = bytearray()
    for y in range(h):
        for x in range(w):
            t = y / (h - 1)
            r, g, b = 0.55 + 0.35 * t, 0.7 + 0.25 * t, 0.95
            if (x - 62) ** 2 + (y - 12) ** 2 < 30:
                r, g, b = 1.0, 0.95, 0.7
            if y > 40 + 4 * math.sin(x / 7.0):
                r, g, b = 0.35, 0.55 - 0.004 * (y - 40), 0.3
            px += bytes(int(round(255 * v)) for v in (r, g, b))
    path.write_bytes(b"P6\n%d %d\n255\n" % (w, h) + bytes(px))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", default=str(Path(__file__).parent))
    out = Path(ap.parse_args().o)
    out.mkdir(parents=True, exist_ok=True)
    write(out / "plate.obj", *box(0, -0.1, 0, 4.0, 0.2, 3.0), "base plate (flat)")
    v, t, side = cylinder(-0.7, -0.2, -0.5, 1.6, 0.45)      # pierces the plate
    write(out / "column.obj", v, t, "column: smooth side, flat caps", {0: "steel", side: "steel_cap"})
    write(out / "bracket.obj", *box(0.1, 0.5, -0.2, 1.8, 0.35, 0.5, rot_y=0.5), "bracket through the column (flat)")
    write(out / "ball.obj", *sphere(1.0, 0.55, 0.5, 0.55), "ball resting in the plate (smooth, specular)")
    write(out / "glass.obj", *box(0.3, 0.7, 1.3, 3.0, 1.4, 0.04), "glass panel in front (transparent)")
    # for sw/scenes/anim: a small block to drag and a two-triangle pane
    write(out / "slider.obj", *box(1.2, 0.2, -0.6, 0.5, 0.4, 0.5), "slider block (flat), dragged in the animation")
    write_sky(out / "sky.ppm")
    write(out / "pane.obj", [(-1.9, 0.0, -1.2), (-0.2, 0.0, -1.2), (-0.2, 1.3, -1.2), (-1.9, 1.3, -1.2)],
          [(0, 1, 2), (0, 2, 3)], "glass pane at the back (transparent)")


if __name__ == "__main__":
    main()
