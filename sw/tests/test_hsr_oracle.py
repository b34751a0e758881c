"""Oracle for the exact hidden-surface removal of sw/hsr (docs/hsr.md).

Random 3D scenes (OBJ + scene file in tmp_path) go through `yproc hsr SCENE
--dump-input IN.json --dump-llr LLR.json`.  The seed is printed; `SEED=<n>`
replays it (`SEED=123 pytest -q sw/tests/test_hsr_oracle.py`).

Checks, per scene:

* projection: our own numpy projection of the OBJ faces (viewing, near clip,
  perspective, screen clip) agrees with the dumped, quantised MLR polygons up
  to the quantisation (|symmetric difference| <= perimeter x 1 unit);
* areas: the visible area of every MLR domain (sum of its LLR domains) equals a
  brute-force Shapely reference: the arrangement of all polygon boundaries and
  all pairwise plane-crossing lines is polygonised, and each face goes to the
  nearest plane at its representative point (ties: lower id);
* raster: the LLR, point-sampled 16x16 per pixel, equals a 16x16 supersampled
  numpy z-buffer render of the dumped input at the same sample points;
* parents: at random points the LLR domain's ordered prefix equals the depth
  sorted list of covering surfaces up to the first opaque one, and
  prefix + hidden_parents contains every covering surface.

Scene kinds: "layered" (tilted planar polygons in disjoint depth slabs, plus
coplanar overlapping copies), "meshes" (closed boxes / tetrahedra, faces meet
on shared edges, near-plane and screen clipping), "crossing" (tilted polygons
in a common depth range: genuine interpenetration).  Opaque and transparent
materials are mixed.

Tolerances (from the numeric policy in docs/hsr.md).  The policy decides the
depth order of two surfaces once per side of a cut line: an input edge line
within 1 unit (1/256 px) of the plane crossing, else the crossing rounded to
integer units; coincident planes put the lower id in front.  The area reference
applies exactly that rule (class PairRule) to a Shapely arrangement of the
polygon boundaries and the cut lines, so areas must agree to 1e-9 relative
(observed <= ~1e-14; Shapely's doubles are the only error).  The only slack is
the area of arrangement faces where the pairwise rule is not a total order
(three surfaces whose snapped cuts disagree within 1 unit of a crossing;
observed < 1e-6 px^2), which is added to the tolerance and printed.  The
z-buffer uses the pure planes, so a sample may differ from the LLR only within
1 unit of the plane crossing line of the two surfaces involved (asserted for
each differing sample; at silhouette edges of meshes and at interpenetrations a
few samples per scene do), and a pixel's coverage of an id may differ by at
most 16/256 (one row of samples; observed <= 3/256).

Incremental path (test_hsr_incremental): a random scene, then a random
sequence of add / remove / move / opacity operations applied by `yproc hsr
SCENE --ops OPS` (sw/hsr/tools/yproc_ops.c; docs/hsr.md "Operation file").
The resulting map must equal a full rebuild of the final scene (`--ops OPS
--rebuild`): per MLR id and per ordered parent prefix the same area (1e-9
relative) and the same region (|symmetric difference| <= 1e-9 relative),
except in the reference's ambiguous faces (where the pairwise rule is not a
total order, the result depends on insertion order; their area is the only
extra tolerance, observed ~1e-6 px^2 in a few percent of the scenes), and
every MLR id's visible area must equal the Shapely reference of the final
input (`--dump-input` after the operations), as above.  Bad operation files
must be rejected with "file:line: message" (test_hsr_ops_errors).
"""
from __future__ import annotations

import fcntl
import json
import math
import os
import random
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point, Polygon, box
from shapely.ops import polygonize, unary_union

from diffengine.host import yproc as yproc_tool

ROOT = Path(__file__).resolve().parents[2]
HSR = ROOT / "sw" / "hsr"
YPROC = HSR / "build" / "yproc"
S = 256.0          # units per pixel (HSR_SUBPIXEL)
W, H = 48, 36      # screen of the random scenes, pixels
SS = 16            # supersampling per pixel axis


@pytest.fixture(scope="session")
def yproc():
    """Build sw/hsr/build/yproc once (locked: pytest -n workers share it)."""
    lock = Path(tempfile.gettempdir()) / "hsr_yproc_build.lock"
    with open(lock, "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        r = subprocess.run(["make", "-C", str(HSR), "build/yproc"], capture_output=True, text=True)
        fcntl.flock(fh, fcntl.LOCK_UN)
    assert r.returncode == 0, r.stdout + r.stderr
    return YPROC


def _seed(salt: int) -> tuple[int, int]:
    base = int(os.environ["SEED"]) if "SEED" in os.environ else random.randrange(1 << 32)
    return base, base ^ salt


# ---------------------------------------------------------------- scenes

def _rot(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    a, b, c, d = q
    return np.array([[a*a+b*b-c*c-d*d, 2*(b*c-a*d), 2*(b*d+a*c)],
                     [2*(b*c+a*d), a*a-b*b+c*c-d*d, 2*(c*d-a*b)],
                     [2*(b*d-a*c), 2*(c*d+a*b), a*a-b*b-c*c+d*d]])


def _planar_face(rng, centre, size, zlo, zhi, nvert):
    """Convex planar polygon around centre (eye space), depth within [zlo, zhi]."""
    ang = np.sort(rng.uniform(0, 2 * np.pi, nvert))
    r = size * rng.uniform(0.4, 1.0, nvert)
    pts2 = np.stack([r * np.cos(ang), r * np.sin(ang)], 1)
    # tilted plane z = centre_z + gx*x + gy*y, gradients limited to the slab
    g = rng.uniform(-1, 1, 2)
    span = np.abs(pts2 @ g).max() + 1e-9
    g *= min(1.0, (zhi - zlo) / 2 / span) * rng.uniform(0.2, 1.0)
    zc = (zlo + zhi) / 2
    return [(centre[0] + x, centre[1] + y, zc + g[0] * x + g[1] * y) for x, y in pts2]


def make_scene(kind: str, rng) -> tuple[list[list[tuple]], list[int], dict]:
    """Faces (eye-space = world-space points, camera at origin looking down -z),
    material index per face, and the materials {index: (name, opacity)}."""
    mats = {0: ("op_a", 1.0), 1: ("op_b", 1.0), 2: ("glass", 0.5), 3: ("smoke", 0.25)}
    faces, fm = [], []

    def mat():
        return int(rng.choice(4, p=[0.4, 0.3, 0.2, 0.1]))

    if kind in ("layered", "crossing"):
        n = int(rng.integers(10, 19))
        for i in range(n):
            if kind == "layered":      # disjoint depth slabs, shuffled insertion order
                zlo, zhi = -(2.0 + 0.6 * i + 0.5), -(2.0 + 0.6 * i)
            else:                       # common depth range: planes interpenetrate
                zlo, zhi = -7.0, -2.5
            zc = (zlo + zhi) / 2
            half = 0.55 * -zc           # visible half-width at that depth (fov 60, aspect 4:3)
            centre = rng.uniform(-half, half, 2) * np.array([4 / 3, 1.0])
            size = -zc * rng.uniform(0.12, 0.45)
            faces.append(_planar_face(rng, centre, size, zlo, zhi, int(rng.choice([3, 3, 4, 5]))))
            fm.append(mat())
        if kind == "layered":           # coplanar overlapping copies: lower id in front
            for i in rng.choice(len(faces), int(rng.integers(0, 3)), replace=False):
                a, b, c = (np.array(v) for v in faces[i][:3])
                nrm = np.cross(b - a, c - a)
                t = rng.uniform(-0.3, 0.3, 2) * -a[2] * 0.3
                dz = -(nrm[0] * t[0] + nrm[1] * t[1]) / nrm[2]
                faces.append([(x + t[0], y + t[1], z + dz) for x, y, z in faces[i]])
                fm.append(mat())
        order = rng.permutation(len(faces))
        faces = [faces[i] for i in order]
        fm = [fm[i] for i in order]
    elif kind == "meshes":
        # closed boxes and tetrahedra in disjoint depth slabs; one crosses the
        # near plane, some stick out of the screen.
        nobj = int(rng.integers(3, 6))
        for k in range(nobj):
            zc = -(2.2 + 1.6 * k)
            R = _rot(rng)
            half = 0.55 * -zc
            c = np.array([*(rng.uniform(-half, half, 2) * np.array([4 / 3, 1.0])), zc])
            sz = 0.45
            if k == 0 and rng.random() < 0.5:   # straddles the near plane (0.1)
                c[2], sz = -0.15, 0.1
            m = mat()
            if rng.random() < 0.5:
                e = rng.uniform(0.5, 1.0, 3) * sz
                v = np.array([[sx, sy, sz_] for sx in (-1, 1) for sy in (-1, 1) for sz_ in (-1, 1)], float) * e
                quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
            else:
                v = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float) * sz
                quads = [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]
            v = v @ R.T + c
            for q in quads:
                faces.append([tuple(v[i]) for i in q])
                fm.append(m)
    else:
        raise ValueError(kind)
    return faces, fm, mats


def as_read(scene: Path, mats):
    """The faces and their material keys as the reader stores them (`yproc read`,
    docs/hsr.md "OBJ", polygons): a polygon that is not convex and planar (make_scene's
    random radii can make one concave) becomes its triangles, consecutive MLR ids."""
    d = yproc_tool.read_scene(scene)
    V = d["vertices"]
    key = {name: k for k, (name, _) in mats.items()}
    names = [m["name"] for m in d["materials"]]
    cv, F = d["corners"]["vertex"], d["faces"]
    faces = [[tuple(V[c]) for c in cv[a:a + n]] for a, n in zip(F["first"], F["count"])]
    return faces, [key[names[m]] for m in F["material"]]


def write_scene(tmp: Path, faces, fm, mats) -> Path:
    lines = ["# test_hsr_oracle random scene"]
    for f in faces:
        for p in f:
            lines.append("v %.17g %.17g %.17g" % p)
    k = 1
    cur = None
    for f, m in zip(faces, fm):
        if m != cur:
            lines.append(f"usemtl {mats[m][0]}")
            cur = m
        lines.append("f " + " ".join(str(k + i) for i in range(len(f))))
        k += len(f)
    (tmp / "scene.obj").write_text("\n".join(lines) + "\n")
    sc = [f"screen {W} {H}", "camera eye 0 0 0 at 0 0 -1 up 0 1 0 fov 60", "near 0.1",
          "light 0 0 1 0.8", "ambient 0.2", "background 1 1 1", "grid 8"]
    for name, op in mats.values():
        sc.append(f"material {name} 0.5 0.5 0.5 opacity {op}")
    sc.append("obj scene.obj material op_a")
    p = tmp / "t.scene"
    p.write_text("\n".join(sc) + "\n")
    return p


# ---------------------------------------------------------------- geometry

def eo_polygon(rings) -> shapely.Geometry:
    """Even-odd union of rings (pixel coordinates)."""
    g = Polygon()
    for r in rings:
        if len(r) >= 3:
            g = g.symmetric_difference(shapely.make_valid(Polygon(r)))
    return g


def inside(rings, X, Y):
    """Even-odd point-in-polygon for sample arrays X, Y."""
    res = np.zeros(X.shape, bool)
    allp = np.concatenate([np.asarray(r, float) for r in rings if len(r)]) if rings else np.zeros((0, 2))
    if len(allp) == 0:
        return res
    lo, hi = allp.min(0), allp.max(0)
    sel = (X >= lo[0]) & (X <= hi[0]) & (Y >= lo[1]) & (Y <= hi[1])
    x, y = X[sel], Y[sel]
    acc = np.zeros(x.shape, bool)
    for r in rings:
        r = np.asarray(r, float)
        x0, y0 = r[:, 0], r[:, 1]
        x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
        for a0, b0, a1, b1 in zip(x0, y0, x1, y1):
            if b0 == b1:
                continue
            c = (b0 > y) != (b1 > y)
            xi = a0 + (y - b0) * (a1 - a0) / (b1 - b0)
            acc ^= c & (x < xi)
    res[sel] = acc
    return res


def project_face(face):
    """Python twin of project.c for the fixed test camera: eye space = world."""
    f = (H / 2) / math.tan(math.radians(60) / 2)
    pts = [p for p in face]

    def clip(poly, key, lim):
        out = []
        n = len(poly)
        for i in range(n):
            a, b = poly[i], poly[(i + 1) % n]
            da, db = key(a) - lim, key(b) - lim
            if da <= 0:
                out.append(a)
            if (da < 0 < db) or (da > 0 > db):
                t = da / (da - db)
                out.append(tuple(a[k] + t * (b[k] - a[k]) for k in range(len(a))))
        return out

    pts = clip(pts, lambda p: p[2], -0.1)
    scr = [(W / 2 + f * x / -z, H / 2 - f * y / -z) for x, y, z in pts]
    scr = clip(scr, lambda p: -p[0], 0)
    scr = clip(scr, lambda p: p[0], W)
    scr = clip(scr, lambda p: -p[1], 0)
    scr = clip(scr, lambda p: p[1], H)
    return scr


def zplane(pl, x, y):
    return pl[0] * x + pl[1] * y + pl[2]


def crossing_dist(pa, pb, x, y):
    """Distance (px) of (x, y) from the line where planes pa and pb meet."""
    da, db = pa[0] - pb[0], pa[1] - pb[1]
    g = math.hypot(da, db)
    if g == 0:
        return math.inf
    return abs(da * x + db * y + pa[2] - pb[2]) / g


# ---------------------------------------------------------------- reference

def _llround(v: float) -> int:
    return int(math.copysign(math.floor(abs(v) + 0.5), v))


def _edge_lines(rings_px):
    """Canonical integer lines (dx, dy, k), dy > 0, of the non-horizontal edges."""
    out = []
    for r in rings_px:
        pts = [(_llround(x * S), _llround(y * S)) for x, y in r]
        for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]):
            dx, dy = x1 - x0, y1 - y0
            if dy == 0:
                continue
            g = math.gcd(dx, dy)
            dx, dy = dx // g, dy // g
            if dy < 0:
                dx, dy = -dx, -dy
            out.append((dx, dy, x0 * dy - y0 * dx))
    return out


class PairRule:
    """Depth order of two MLR surfaces as the numeric policy of docs/hsr.md
    states it (a twin of order_canon() in separate.c): the crossing line inside
    the common extent is replaced by an input edge line within 1 unit of it, else
    by the line through its two end points rounded to integer units; the order
    on each side is evaluated far from that line.  Coordinates in units."""

    def __init__(self, p, q, pp, pq, ep, eq, lines_p, lines_q):
        # p has the lower id
        def fz(x, y):
            return (pp[0] - pq[0]) * x + (pp[1] - pq[1]) * y + (pp[2] - pq[2])
        tie = True
        self.cut = None          # ("line", dx, dy, k) or ("h", y)
        self.front = [tie, tie]  # p in front on side 0 (left / below) and side 1
        self.crossing = None     # true crossing end points (units), for tolerances
        bl, bb = max(ep[0], eq[0]), max(ep[1], eq[1])
        br, bt = min(ep[2], eq[2]), min(ep[3], eq[3])
        self.box = (bl, bb, br, bt)
        if bl > br or bb > bt:
            return
        cx = [float(bl), float(br), float(br), float(bl)]
        cy = [float(bb), float(bb), float(bt), float(bt)]
        f, lo, hi, zmag = [], math.inf, -math.inf, 0.0
        for i in range(4):
            f.append(fz(cx[i], cy[i]))
            z1 = abs(pp[0] * cx[i] + pp[1] * cy[i] + pp[2])
            z2 = abs(pq[0] * cx[i] + pq[1] * cy[i] + pq[2])
            zmag = max(zmag, z1, z2)
            lo, hi = min(lo, f[i]), max(hi, f[i])
        if hi - lo <= 1e-12 * zmag and abs(hi) <= 1e-12 * zmag:
            return
        fc = fz((cx[0] + cx[1]) / 2, (cy[0] + cy[2]) / 2)
        if lo >= 0 or hi <= 0:
            fr = (True if lo < 0 else tie) if hi <= 0 else False
            self.front = [fr, fr]
            return
        px, py = [], []
        for i in range(4):
            j = (i + 1) & 3
            if (f[i] <= 0) == (f[j] <= 0):
                continue
            t = f[i] / (f[i] - f[j])
            px.append(cx[i] + t * (cx[j] - cx[i]))
            py.append(cy[i] + t * (cy[j] - cy[i]))
        fcf = True if fc < 0 else (False if fc > 0 else tie)
        self.front = [fcf, fcf]
        if len(px) < 2 or bb == bt:
            return
        self.crossing = (px[0], py[0], px[1], py[1])
        x0, y0, x1, y1 = _llround(px[0]), _llround(py[0]), _llround(px[1]), _llround(py[1])
        D = float(br - bl) + float(bt - bb) + 16
        mx, my = (px[0] + px[1]) / 2.0, (py[0] + py[1]) / 2.0
        gz = math.hypot(pp[0] - pq[0], pp[1] - pq[1])

        def splits_like(L):
            # the line splits the extent's corners as the crossing does (corners within a
            # unit of either line aside): near both crossing points is not enough when
            # the planes cross only in a corner of the extent (splits_like in separate.c)
            ln, sgn = math.hypot(L[0], L[1]), 0
            for i in range(4):
                de = (cx[i] * L[1] - cy[i] * L[0] - L[2]) / ln
                if abs(de) <= 1 or abs(f[i]) <= gz:
                    continue
                sg = 1 if (de > 0) == (f[i] > 0) else -1
                if sgn and sg != sgn:
                    return False
                sgn = sg
            return True

        best, bl_ = 1.0, None
        for L in lines_p + lines_q:
            ln = math.hypot(L[0], L[1])
            d0 = abs(px[0] * L[1] - py[0] * L[0] - L[2]) / ln
            d1 = abs(px[1] * L[1] - py[1] * L[0] - L[2]) / ln
            if max(d0, d1) < best and splits_like(L):
                best, bl_ = max(d0, d1), L
        if bl_ is None and x0 == x1 and y0 == y1:
            return
        if bl_ is None and y0 == y1:
            if not splits_like((1, 0, -y0)):
                return
            self.cut = ("h", y0)
            nx, ny = 0.0, 1.0
        else:
            if bl_ is None:
                dx, dy = x1 - x0, y1 - y0
                g = math.gcd(dx, dy)
                dx, dy = dx // g, dy // g
                if dy < 0:
                    dx, dy = -dx, -dy
                if not splits_like((dx, dy, x0 * dy - y0 * dx)):
                    return
                bl_ = (dx, dy, x0 * dy - y0 * dx)
            self.cut = ("line",) + bl_
            ln = math.hypot(bl_[0], bl_[1])
            nx, ny = bl_[1] / ln, -bl_[0] / ln
        fr = fz(mx + D * nx, my + D * ny)
        fl = fz(mx - D * nx, my - D * ny)
        self.front = [True if fl < 0 else (False if fl > 0 else tie),
                      True if fr < 0 else (False if fr > 0 else tie)]

    def p_in_front(self, x, y):
        """x, y in units (not on the cut line)."""
        if self.cut is None:
            return self.front[0]
        if self.cut[0] == "h":
            return self.front[1 if y > self.cut[1] else 0]
        _, dx, dy, k = self.cut
        return self.front[1 if x * dy - y * dx - k > 0 else 0]

    def cut_segment_px(self):
        """The cut line clipped to the common extent (pixels), or None."""
        if self.cut is None:
            return None
        bl, bb, br, bt = (v / S for v in self.box)
        if self.cut[0] == "h":
            return LineString([(bl - 1, self.cut[1] / S), (br + 1, self.cut[1] / S)])
        _, dx, dy, k = self.cut          # x = (k + y dx) / dy
        return LineString([((k + (bb - 1) * S * dx) / dy / S, bb - 1),
                           ((k + (bt + 1) * S * dx) / dy / S, bt + 1)])


def interior_point(fc):
    """A point strictly inside face fc.  GEOS' representative_point can fall
    outside thin faces (seen on a 0.76 px^2 sliver); then use the centroid of
    the largest triangle of a constrained triangulation."""
    rp = fc.representative_point()
    if fc.contains(rp):
        return rp
    tris = sorted(shapely.get_parts(shapely.constrained_delaunay_triangles(fc)),
                  key=lambda t: -t.area)
    for t in tris:
        c = t.centroid
        if fc.contains(c):
            return c
    return None


class Oracle:
    def __init__(self, P):
        self.ids = [p["id"] for p in P]
        self.polys = [eo_polygon(p["rings"]) for p in P]
        self.planes_px = [p["plane"] for p in P]
        self.planes_u = [(a / S, b / S, c) for a, b, c in self.planes_px]
        self.opaque = [p["opacity"] >= 1.0 for p in P]
        self.ext = [tuple(_llround(v * S) for v in g.bounds) if not g.is_empty else None
                    for g in self.polys]
        self.lines = [_edge_lines(p["rings"]) for p in P]
        self.tree = shapely.STRtree(self.polys)
        self.rules = {}

    def rule(self, a, b):
        key = (min(a, b), max(a, b))
        if key not in self.rules:
            p, q = key
            self.rules[key] = PairRule(p, q, self.planes_u[p], self.planes_u[q], self.ext[p],
                                       self.ext[q], self.lines[p], self.lines[q])
        return self.rules[key]

    def in_front(self, a, b, x, y):
        """Surface a in front of b at pixel (x, y) by the policy rule."""
        r = self.rule(a, b)
        f = r.p_in_front(x * S, y * S)
        return f if a < b else not f

    def order(self, cover, x, y):
        """Front-to-back order of the surfaces covering (x, y); None if the
        pairwise relation is not a total order there."""
        import functools
        out = sorted(cover, key=functools.cmp_to_key(
            lambda a, b: -1 if self.in_front(a, b, x, y) else 1))
        for i in range(len(out)):
            for j in range(i + 1, len(out)):
                if not self.in_front(out[i], out[j], x, y):
                    return None
        return out

    def visible_areas(self):
        """Shapely arrangement of boundaries + policy cut lines; every face goes
        to the surface in front of all others covering it.  Returns (area per id,
        ambiguous area, pure-plane crossing length per id in px)."""
        polys = self.polys
        lines = [p.boundary for p in polys if not p.is_empty]
        cross_len = {i: 0.0 for i in self.ids}
        for a, pa in enumerate(polys):
            if pa.is_empty:
                continue
            for b in self.tree.query(pa):
                b = int(b)
                if b <= a or polys[b].is_empty:
                    continue
                inter = pa.intersection(polys[b])
                if inter.area <= 0:
                    continue
                r = self.rule(a, b)
                seg = r.cut_segment_px()
                if seg is not None:
                    lines.append(seg)
                if r.crossing is not None:
                    x0, y0, x1, y1 = (v / S for v in r.crossing)
                    L = LineString([(x0, y0), (x1, y1)]).intersection(inter).length
                    cross_len[a] += L
                    cross_len[b] += L
        area = {i: 0.0 for i in self.ids}
        ambiguous = 0.0
        for fc in polygonize(unary_union(lines)):
            rp = interior_point(fc)
            if rp is None:
                ambiguous += fc.area
                continue
            cover = [int(k) for k in self.tree.query(rp) if polys[int(k)].contains(rp)]
            if not cover:
                continue
            o = self.order(cover, rp.x, rp.y)
            if o is None:
                ambiguous += fc.area
            else:
                area[o[0]] += fc.area
        return area, ambiguous, cross_len


# ---------------------------------------------------------------- the test

def run_yproc(yproc, scene: Path, tmp: Path, *extra, tag: str = ""):
    """`yproc hsr SCENE [extra] --dump-input --dump-llr`: (input, LLR) JSON."""
    inp, llr = tmp / f"in{tag}.json", tmp / f"llr{tag}.json"
    r = subprocess.run([str(yproc), "hsr", str(scene), *extra, "--dump-input", str(inp), "--dump-llr", str(llr)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(inp.read_text()), json.loads(llr.read_text())


CASES = [(k, i) for k in ("layered", "meshes", "crossing") for i in range(6)]


@pytest.mark.parametrize("kind,idx", CASES, ids=[f"{k}{i}" for k, i in CASES])
def test_hsr_oracle(yproc, tmp_path, kind, idx):
    base, seed = _seed(0x4853 * (idx + 1) + 7 * len(kind))
    print(f"test_hsr_oracle[{kind}{idx}] seed {seed} (SEED={base} replays)")
    rng = np.random.default_rng(seed)
    faces, fm, mats = make_scene(kind, rng)
    scene = write_scene(tmp_path, faces, fm, mats)
    faces, fm = as_read(scene, mats)
    inp, llr = run_yproc(yproc, scene, tmp_path)
    where = f"[{kind}{idx}] seed {seed} (SEED={base} replays)"

    P = inp["polygons"]
    assert [p["id"] for p in P] == list(range(len(faces))), where
    orc = Oracle(P)
    ids, polys, planes = orc.ids, orc.polys, orc.planes_px
    for p, g, fc, m in zip(P, polys, faces, fm):
        assert p["opacity"] == mats[m][1], where
        # C area of the MLR domain vs Shapely area of its rings
        assert abs(g.area - p["area_px2"]) <= 1e-9 * max(1.0, p["area_px2"]), (where, p["id"])
        # projection cross-check (quantisation: each vertex moves <= 1/512 px per axis)
        mine = project_face(fc)
        mp = shapely.make_valid(Polygon(mine)) if len(mine) >= 3 else Polygon()
        tol = (mp.length + g.length) * (1.0 / S) + 1e-9
        assert mp.symmetric_difference(g).area <= tol, (where, p["id"], mp.symmetric_difference(g).area, tol)

    D = llr["domains"]
    for d in D:
        g = eo_polygon(d["rings"])
        assert d["mlr"] == d["parents"][0], where
        assert abs(g.area - d["area_px2"]) <= 1e-9 * max(1.0, d["area_px2"]) + 1e-9, where

    # ---- areas vs the Shapely arrangement (policy cut lines), exact to 1e-9
    ref, ambiguous, cross_len = orc.visible_areas()
    got = {i: 0.0 for i in ids}
    for d in D:
        got[d["mlr"]] += d["area_px2"]
    worst = 0.0
    for i in ids:
        err = abs(got[i] - ref[i])
        scale = max(ref[i], polys[i].area, 1.0)
        tol = 1e-9 * scale + ambiguous
        worst = max(worst, err / scale)
        assert err <= tol, (f"{where}: MLR {i} visible area C {got[i]!r} reference {ref[i]!r} "
                            f"diff {err:.3g} > tol {tol:.3g} (pure-plane crossing length "
                            f"{cross_len[i]:.3g} px, ambiguous area {ambiguous:.3g})")
    total_in = unary_union([p for p in polys if not p.is_empty]).area
    assert abs(sum(got.values()) - total_in) <= 1e-9 * max(total_in, 1.0), where
    # the arrangement itself: faces tile the union (no overlapping / missing faces)
    assert abs(sum(ref.values()) + ambiguous - total_in) <= 1e-9 * max(total_in, 1.0), where
    print(f"  {len(ids)} faces, {len(D)} LLR domains, max area rel. diff {worst:.3g}, "
          f"ambiguous {ambiguous:.3g} px2, crossing length {sum(cross_len.values()) / 2:.3g} px")

    # ---- raster: LLR point-sampled vs supersampled z-buffer at the same samples
    off = 0.0123456789        # keeps samples off the integer-unit edge lattice
    sx = (np.arange(W * SS) + 0.5) / SS + off
    sy = (np.arange(H * SS) + 0.5) / SS + off * 0.7071
    X, Y = np.meshgrid(sx, sy)
    zbest = np.full(X.shape, 1e300)
    zid = np.full(X.shape, -1)
    for i, p in zip(ids, P):
        m = inside(p["rings"], X, Y)
        z = zplane(planes[i], X, Y)
        take = m & (z < zbest - 1e-12 * np.abs(zbest))   # ids ascending: ties keep the lower id
        zbest[take] = z[take]
        zid[take] = i
    lid = np.full(X.shape, -1)
    for d in D:
        m = inside(d["rings"], X, Y)
        assert not (m & (lid >= 0)).any(), f"{where}: LLR domains overlap at a sample"
        lid[m] = d["mlr"]
    assert ((lid >= 0) == (zid >= 0)).all(), f"{where}: LLR union != input union at a sample"
    diff = np.argwhere(lid != zid)
    for r_, c_ in diff:
        a, b = lid[r_, c_], zid[r_, c_]
        dist = crossing_dist(planes[a], planes[b], X[r_, c_], Y[r_, c_])
        assert dist <= 1.0001 / S, (f"{where}: sample ({X[r_, c_]:.6f},{Y[r_, c_]:.6f}) LLR {a} "
                                    f"z-buffer {b}: {dist * S:.3f} units from their crossing line")
    # per-pixel coverage of each id
    maxcov = 0.0
    for i in set(np.unique(lid)) | set(np.unique(zid)):
        if i < 0:
            continue
        cl = (lid == i).reshape(H, SS, W, SS).mean(axis=(1, 3))
        cz = (zid == i).reshape(H, SS, W, SS).mean(axis=(1, 3))
        maxcov = max(maxcov, float(np.abs(cl - cz).max()))
    assert maxcov <= SS / (SS * SS), (where, maxcov)
    print(f"  raster: {len(diff)} of {X.size} samples differ, max per-pixel coverage diff {maxcov:.4f}")

    # ---- parents at random points
    ux0, uy0, ux1, uy1 = unary_union([p for p in polys if not p.is_empty]).bounds
    pts = np.stack([rng.uniform(ux0, ux1, 3000), rng.uniform(uy0, uy1, 3000)], 1)
    cov = np.stack([inside(p["rings"], pts[:, 0], pts[:, 1]) for p in P], 0)
    dom = np.full(len(pts), -1)
    for k, d in enumerate(D):
        dom[inside(d["rings"], pts[:, 0], pts[:, 1])] = k
    checked = covered = 0
    for t, (x, y) in enumerate(pts):
        cover = [i for i in ids if cov[i, t]]
        if not cover:
            assert dom[t] < 0, where
            continue
        covered += 1
        order = orc.order(cover, x, y)
        if order is None:
            continue
        k = next((n for n, i in enumerate(order) if orc.opaque[i]), len(order) - 1)
        d = D[dom[t]]
        assert d["parents"] == order[:k + 1], (f"{where}: at ({x:.4f},{y:.4f}) parents {d['parents']} "
                                               f"expected prefix {order[:k + 1]}")
        assert set(order) <= set(d["parents"]) | set(d["hidden_parents"]), where
        checked += 1
    assert covered > 0 and checked >= 0.99 * covered, (where, checked, covered)


# ---------------------------------------------------------------- incremental path

def random_ops(rng, mlr_count: int, n_ops: int) -> list[str]:
    """Random add / remove / move / opacity operations over MLR ids (docs/hsr.md,
    "Operation file").  Translations are whole units (1/256 px); an add with a
    zero translation makes an exactly coincident copy (lower id in front)."""
    alive, gone, nm, ops = list(range(mlr_count)), [], mlr_count, []

    def shift():
        if rng.random() < 0.15:
            return 0.0, 0.0
        return tuple(int(v) / S for v in rng.integers(-int(W * S / 3), int(W * S / 3), 2))

    for _ in range(n_ops):
        kind = rng.choice(["add", "remove", "move", "opacity"], p=[0.25, 0.25, 0.35, 0.15])
        if kind != "add" and len(alive) < 2:
            kind = "add"
        if kind == "add":
            src = int(rng.choice(alive + gone))
            dx, dy = shift()
            ops.append(f"add {src} {dx!r} {dy!r}")
            alive.append(nm)
            nm += 1
        elif kind == "remove":
            i = int(rng.choice(alive))
            alive.remove(i)
            gone.append(i)
            ops.append(f"remove {i}")
        elif kind == "move":
            dx, dy = shift()
            ops.append(f"move {int(rng.choice(alive))} {dx!r} {dy!r}")
        else:
            ops.append(f"opacity {int(rng.choice(alive))} {float(rng.choice([1.0, 1.0, 0.5, 0.25]))!r}")
    return ops


INC_CASES = [(k, i) for k in ("layered", "meshes", "crossing") for i in range(3)]


@pytest.mark.parametrize("kind,idx", INC_CASES, ids=[f"{k}{i}" for k, i in INC_CASES])
def test_hsr_incremental(yproc, tmp_path, kind, idx):
    base, seed = _seed(0x1DC * (idx + 3) + 11 * len(kind))
    where = f"[inc {kind}{idx}] seed {seed} (SEED={base} replays)"
    print(f"test_hsr_incremental{where}")
    rng = np.random.default_rng(seed)
    faces, fm, mats = make_scene(kind, rng)
    scene = write_scene(tmp_path, faces, fm, mats)
    faces, fm = as_read(scene, mats)
    ops = random_ops(rng, len(faces), int(rng.integers(8, 21)))
    opsf = tmp_path / "ops.txt"
    opsf.write_text("# test_hsr_incremental\n" + "\n".join(ops) + "\n")
    inp, inc = run_yproc(yproc, scene, tmp_path, "--ops", str(opsf), tag="_inc")
    inp2, full = run_yproc(yproc, scene, tmp_path, "--ops", str(opsf), "--rebuild", tag="_full")
    assert inp == inp2, where
    nm = inp["mlr_count"]
    assert inc["mlr_count"] == full["mlr_count"] == nm == len(faces) + sum(o.startswith("add") for o in ops), where

    # The reference first: its ambiguous area (faces where the pairwise depth rule
    # of the policy is not a total order, three surfaces whose snapped cuts disagree
    # within 1 unit) is the only place where the result may depend on insertion
    # order, so it is the only slack between the incremental map and the rebuild.
    P = {p["id"]: p for p in inp["polygons"]}
    full_p = [P.get(i, {"id": i, "rings": [], "plane": [0.0, 0.0, 0.0], "opacity": 1.0}) for i in range(nm)]
    orc = Oracle(full_p)
    ref, ambiguous, cross_len = orc.visible_areas()

    # ---- incremental map == full rebuild: per id and per ordered prefix, area and region
    def by(D, key):
        area, geo = {}, {}
        for d in D:
            k = key(d)
            area[k] = area.get(k, 0.0) + d["area_px2"]
            geo.setdefault(k, []).append(eo_polygon(d["rings"]))
        return area, {k: unary_union(v) for k, v in geo.items()}

    worst_inc = 0.0
    for key in (lambda d: d["mlr"], lambda d: tuple(d["parents"])):
        ai, gi = by(inc["domains"], key)
        af, gf = by(full["domains"], key)
        for k in set(ai) | set(af):
            scale = max(af.get(k, 0.0), P[k if isinstance(k, int) else k[0]]["area_px2"], 1.0)
            err = abs(ai.get(k, 0.0) - af.get(k, 0.0))
            worst_inc = max(worst_inc, err / scale)
            assert err <= 1e-9 * scale + ambiguous, (f"{where}: {k} incremental {ai.get(k)!r} rebuild "
                                                     f"{af.get(k)!r} (ambiguous {ambiguous:.3g} px2)")
            sd = gi.get(k, Polygon()).symmetric_difference(gf.get(k, Polygon())).area
            assert sd <= 1e-9 * scale + 2 * ambiguous, f"{where}: {k} regions differ by {sd:.3g} px^2"

    # ---- against the Shapely reference of the final scene (removed ids: empty)
    got = {i: 0.0 for i in range(nm)}
    for d in inc["domains"]:
        assert d["mlr"] in P and all(p in P for p in d["parents"] + d["hidden_parents"]), where
        got[d["mlr"]] += d["area_px2"]
    worst = 0.0
    for i in range(nm):
        scale = max(ref[i], orc.polys[i].area, 1.0)
        err = abs(got[i] - ref[i])
        worst = max(worst, err / scale)
        assert err <= 1e-9 * scale + ambiguous, (f"{where}: MLR {i} visible area after the operations "
                                                 f"{got[i]!r} reference {ref[i]!r} (ambiguous {ambiguous:.3g})")
    total_in = unary_union([g for g in orc.polys if not g.is_empty]).area
    assert abs(sum(got.values()) - total_in) <= 1e-9 * max(total_in, 1.0), where
    print(f"  {len(ops)} operations, {nm} MLR ids ({len(P)} present), {len(inc['domains'])} LLR domains, "
          f"max area rel. diff vs rebuild {worst_inc:.3g}, vs reference {worst:.3g}, "
          f"ambiguous {ambiguous:.3g} px2")


BAD_OPS = [("frob 1", "unknown operation"), ("remove", "takes 1 arguments"), ("remove 999", "out of range"),
           ("remove -1", "out of range"), ("move 0 1", "takes 3 arguments"), ("move 0 nan 1", "bad translation"),
           ("move 0 1 inf", "bad translation"), ("add 0 1e300 0", "bad translation"),
           ("move 0 40000 0", "beyond"), ("opacity 0 1.5", "opacity must be"), ("opacity 0 x", "opacity must be"),
           ("remove 1x", "bad id"), ("remove 0\nmove 0 1 1", "was removed")]


def test_hsr_ops_errors(yproc, tmp_path):
    rng = np.random.default_rng(5)
    faces, fm, mats = make_scene("layered", rng)
    scene = write_scene(tmp_path, faces, fm, mats)
    for text, msg in BAD_OPS:
        f = tmp_path / "bad.txt"
        f.write_text("# comment\n\nopacity 0 1\n" + text + "\n")
        line = 4 + text.count("\n")
        r = subprocess.run([str(yproc), "hsr", str(scene), "--ops", str(f)], capture_output=True, text=True)
        assert r.returncode == 1, (text, r.stderr)
        assert r.stderr.startswith(f"{f}:{line}: ") and msg in r.stderr, (text, r.stderr)
