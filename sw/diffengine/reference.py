"""Numpy reference renderer: z-buffer + per-sample Phong, 16x16 supersampled.

The shading model is the normative one shared with the C y-processor (docs/shading.md):
directional lights, ambient, per-vertex smooth normals (area-weighted, `vn` overrides,
`flat` materials use the face normal), two-sided, perspective-correct barycentric normal
interpolation, local viewer, I_c = A kd_c + sum_l I_l,c (kd_c max(0, N.L) +
KS max(0, E.R)^N), transparency o I_front + (1 - o) C_behind front to back over the
`background`. 1.0 = 4095 pixel units.

Geometry mirrors sw/hsr/src/project.c exactly: the camera basis (w = eye - at, u = up x w,
v = w x u), f = (H/2) / tan(fov/2), near clipping at z_eye <= -near in eye space, screen
x = W/2 + f x_e / -z_e, y = H/2 - f y_e / -z_e (y down), vertices quantised to
1/256 pixel (llround) like the HSR's input. Pixel (x, y) covers [x, x+1) x [y, y+1).

Sampling: S x S sub-samples per pixel at the sub-square centres (x + (i + 0.5)/S, ...),
a z-buffer per sub-sample (depth = 1/distance along the view axis, affine in screen
space as in project.c), per-sample Phong with the true per-point normal and eye vector,
transparency resolved per sub-sample by depth peeling, box average. S = 1 is the
point-sampled (anti-aliasing off) image at pixel centres. Sample ties on an edge follow
a top-left rule, so a sample on an edge shared by two triangles is counted once.

Work is done in bands of pixel rows (memory bounded: about 60 MB per band of 16 rows at
S = 16 and 640 columns), triangles binned per band.
"""
from __future__ import annotations

import math
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

SUBPIXEL = 256          # HSR_SUBPIXEL: the HSR quantises vertices to 1/256 pixel
PIXEL_SCALE = 4095.0    # intensity 1.0 = 4095 pixel units


class SceneError(ValueError):
    """A scene or OBJ file the reference cannot read ("file:line: message")."""


@dataclass
class Material:
    name: str
    kd: tuple[float, float, float]
    opacity: float = 1.0
    ks: float = 0.0
    n: float = 1.0
    flat: bool = False


@dataclass
class Scene:
    width: int = 640
    height: int = 480
    eye: tuple = (0.0, 0.0, 5.0)
    at: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    fov: float = 60.0
    near: float = 0.1
    ambient: float = 0.2
    background: tuple = (1.0, 1.0, 1.0)
    # `background image FILE`: (H, W, 3) in 1.0 units, scaled to the screen as yproc does
    background_image: np.ndarray = None
    lights: list = field(default_factory=list)       # [(L unit (3,), I rgb (3,))]
    materials: list = field(default_factory=list)
    # Triangles (after fan triangulation of polygons): world positions (T,3,3), vertex
    # normals (T,3,3) (unnormalised is fine; flat faces carry the face normal), material
    # index (T,).
    pos: np.ndarray = None
    nrm: np.ndarray = None
    mat: np.ndarray = None


def _nums(tok, n, where):
    try:
        v = [float(t) for t in tok[:n]]
    except ValueError:
        raise SceneError(f"{where}: bad number") from None
    if len(v) != n or not all(math.isfinite(x) for x in v):
        raise SceneError(f"{where}: needs {n} finite numbers")
    return v


def _tokens(line: str) -> list[str]:
    return line.split("#", 1)[0].split()


def _newell(p: np.ndarray) -> np.ndarray:
    """Newell normal of polygon(s) p (..., n, 3): unnormalised, |.| = 2 area."""
    q = np.roll(p, -1, axis=-2)
    return np.stack([((p[..., 1] - q[..., 1]) * (p[..., 2] + q[..., 2])).sum(-1),
                     ((p[..., 2] - q[..., 2]) * (p[..., 0] + q[..., 0])).sum(-1),
                     ((p[..., 0] - q[..., 0]) * (p[..., 1] + q[..., 1])).sum(-1)], -1)


# --- OBJ and MTL, as sw/hsr/src/obj.c, mtl.c and poly.c read them (docs/hsr.md) -------

_MAX_LINE = 4095          # obj.c: a line of 4096 characters or more is an error
_MAX_ITEMS = 512          # obj.c: tokens per line
PLANAR_TOL = 1e-6         # poly.c: a polygon is planar to 1e-6 of its bounding box diagonal


def _read_text(path: Path, what: str, where: str) -> str:
    try:
        data = path.read_bytes()
    except OSError as e:
        raise SceneError(f"{where}cannot read {what} file '{path}' ({e.strerror})") from None
    if b"\0" in data:
        raise SceneError(f"{where}cannot read {what} file '{path}' (NUL byte)")
    return data.decode("utf-8", errors="surrogateescape")


def _lines(text: str, name):
    """(line number, tokens) as obj.c's scene_tokens: split on space, tab and CR, a token
    starting with '#' ends the line."""
    for lineno, line in enumerate(text.split("\n"), 1):
        if len(line) > _MAX_LINE // 4 and len(line.encode("utf-8", "surrogateescape")) > _MAX_LINE:
            raise SceneError(f"{name}:{lineno}: line too long")   # bytes, as in C
        tok = []
        for t in line.replace("\t", " ").replace("\r", " ").split(" "):
            if not t:
                continue
            if t[0] == "#":
                break
            tok.append(t)
        if len(tok) > _MAX_ITEMS:
            raise SceneError(f"{name}:{lineno}: too many items on one line")
        if tok:
            yield lineno, tok


def _num(t: str) -> float | None:
    """strtod + isfinite: a finite number, or None."""
    if not t.isascii() or "_" in t:
        return None
    try:
        v = float.fromhex(t) if "0x" in t.lower() else float(t)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def _int(t: str) -> int | None:
    if not t or not t.isascii() or "_" in t or t.strip() != t:
        return None
    try:
        return int(t, 10)
    except ValueError:
        return None


def _triangulate(P) -> tuple[list, bool]:
    """poly.c's poly_triangulate on points P (n, 3) as Python floats, the same arithmetic in
    the same order: (triangles as index triples, whole), whole = convex and planar."""
    n = len(P)
    N = [0.0, 0.0, 0.0]
    lo, hi, c = list(P[0]), list(P[0]), [0.0, 0.0, 0.0]
    for a in range(n):
        p, r = P[a], P[(a + 1) % n]
        N[0] += (p[1] - r[1]) * (p[2] + r[2])
        N[1] += (p[2] - r[2]) * (p[0] + r[0])
        N[2] += (p[0] - r[0]) * (p[1] + r[1])
        for k in range(3):
            c[k] += p[k]
            lo[k] = min(lo[k], p[k])
            hi[k] = max(hi[k], p[k])
    ax = 0
    if abs(N[1]) > abs(N[ax]):
        ax = 1
    if abs(N[2]) > abs(N[ax]):
        ax = 2
    i, j, sign = (ax + 1) % 3, (ax + 2) % 3, (1.0 if N[ax] >= 0 else -1.0)

    def cross2(a, b, cc):
        A, B, C = P[a], P[b], P[cc]
        return sign * ((B[i] - A[i]) * (C[j] - A[j]) - (B[j] - A[j]) * (C[i] - A[i]))

    cv = all(cross2((k + n - 1) % n, k, (k + 1) % n) >= 0 for k in range(n)) and \
        all(cross2(0, k, k + 1) >= 0 and cross2(0, 1, k + 1) >= 0 for k in range(1, n - 1))
    ln = math.sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2])
    diag = math.sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1])
                     + (hi[2] - lo[2]) * (hi[2] - lo[2]))
    dev = 0.0
    if ln > 0:
        for a in range(n):
            d = 0.0
            for k in range(3):
                d += (P[a][k] - c[k] / n) * (N[k] / ln)
            dev = max(dev, abs(d))
    whole = n == 3 or (cv and ln > 0 and dev <= PLANAR_TOL * diag)
    tris = []
    if not cv:
        idx = list(range(n))
        while len(idx) > 3:
            m, found = len(idx), -1
            for k in range(m):
                a, b, cc = idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]
                if not cross2(a, b, cc) > 0:
                    continue
                if any(t not in (a, b, cc) and cross2(a, b, t) >= 0 and cross2(b, cc, t) >= 0
                       and cross2(cc, a, t) >= 0 for t in idx):
                    continue
                found = k
                break
            if found < 0:
                break           # self-intersecting or degenerate: fan the rest
            tris.append((idx[(found + m - 1) % m], idx[found], idx[(found + 1) % m]))
            del idx[found]
        tris += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
        return tris, whole
    return [(0, k, k + 1) for k in range(1, n - 1)], whole


def _read_mtl(path: Path, where: str, materials: list) -> dict[str, int]:
    """mtl.c: append the .mtl file's materials; returns name -> index (last one counts)."""
    text = _read_text(path, "MTL", where + ": ")
    found: dict[str, int] = {}
    cur = None
    for lineno, tok in _lines(text, path):
        k, at = tok[0], f"{path}:{lineno}"
        if k == "newmtl":
            if len(tok) != 2:
                raise SceneError(f"{at}: 'newmtl' needs one name")
            if len(tok[1].encode("utf-8", "surrogateescape")) >= 64:
                raise SceneError(f"{at}: material name too long")
            cur = Material(tok[1], (0.8, 0.8, 0.8))
            found[tok[1]] = len(materials)
            materials.append(cur)
            continue
        if k not in ("Kd", "Ks", "Ns", "d", "Tr"):
            continue
        if cur is None:
            raise SceneError(f"{at}: '{k}' before 'newmtl'")
        if k in ("Kd", "Ks"):
            v = [_num(t) for t in tok[1:]]
            if len(v) not in (1, 3) or None in v:
                raise SceneError(f"{at}: '{k}' needs 1 or 3 finite numbers (spectral and xyz "
                                 "are not read)")
            rgb = (v[0],) * 3 if len(v) == 1 else tuple(v)
            if k == "Kd":
                cur.kd = rgb
            else:
                if min(rgb) < 0:
                    raise SceneError(f"{at}: 'Ks' must be >= 0")
                cur.ks = (rgb[0] + rgb[1] + rgb[2]) / 3
        elif k == "Ns":
            v = _num(tok[1]) if len(tok) == 2 else None
            if v is None or v < 0:
                raise SceneError(f"{at}: 'Ns' needs one finite number >= 0")
            cur.n = max(v, 1.0)
        else:
            v = _num(tok[1]) if len(tok) == 2 else None
            if v is None or not 0 <= v <= 1:
                raise SceneError(f"{at}: '{k}' needs one number in [0,1]")
            cur.opacity = v if k == "d" else 1 - v
    return found


def _read_obj(path: Path, default_mat: int, names: dict[str, int], materials: list,
              tris, norms, mats, where: str = "") -> None:
    """Append the OBJ's triangles, as obj.c reads the file (docs/hsr.md "OBJ") and
    yp_shade.c gives their corners normals (docs/shading.md "Normals")."""
    text = _read_text(path, "OBJ", where)
    verts, vns = [], []
    nvt = 0
    polys = []      # (vertex idx list, normal idx list (None = none), material, group)
    cur, group, mine = default_mat, -1, {}
    for lineno, tok in _lines(text, path):
        at, k = f"{path}:{lineno}", tok[0]
        if k in ("v", "vn", "vt"):
            if k == "v" and len(tok) not in (4, 5, 7):
                raise SceneError(f"{at}: 'v' needs 3 coordinates (then w, or r g b)")
            if k == "vn" and len(tok) != 4:
                raise SceneError(f"{at}: 'vn' needs 3 numbers")
            if k == "vt" and not 2 <= len(tok) <= 4:
                raise SceneError(f"{at}: 'vt' needs 1 to 3 numbers")
            x = []
            for t in tok[1:]:
                v = _num(t)
                if v is None:
                    raise SceneError(f"{at}: bad or non-finite number '{t}'")
                x.append(v)
            if k == "v":
                verts.append(x[:3])
            elif k == "vn":
                if x == [0.0, 0.0, 0.0]:
                    raise SceneError(f"{at}: 'vn' has zero length")
                vns.append(x)
            else:
                nvt += 1
        elif k == "f":
            if len(tok) < 4:
                raise SceneError(f"{at}: face needs at least 3 vertices")
            vi, ni = [], []
            for t in tok[1:]:
                parts = t.split("/")
                bad = len(parts) > 3 or parts[0] == "" or (len(parts) == 2 and parts[1] == "")
                raw = []
                for q in parts:
                    r = None if q == "" else (_int(q) if len(q) < 32 else None)
                    bad |= q != "" and r is None
                    raw.append(r)
                if bad:
                    raise SceneError(f"{at}: bad vertex index '{t}' (v, v/vt, v//vn or "
                                     "v/vt/vn)")
                raw += [None] * (3 - len(raw))
                idx = []
                for which, r, cnt in zip(("vertex", "texture", "normal"), raw,
                                         (len(verts), nvt, len(vns))):
                    q = None if r is None else r - 1 if r > 0 else cnt + r if r < 0 else -1
                    if q is not None and not 0 <= q < cnt:
                        raise SceneError(f"{at}: {which} index {r} out of range (1..{cnt})")
                    idx.append(q)
                vi.append(idx[0])
                ni.append(idx[2])
            polys.append((vi, ni, cur, group))
        elif k == "s":
            g = 0 if len(tok) == 2 and tok[1] == "off" else (_int(tok[1]) if len(tok) == 2
                                                            else None)
            if g is None or not 0 <= g <= 2147483647:
                raise SceneError(f"{at}: 's' needs a group number >= 0 or 'off'")
            group = g
        elif k == "mtllib":
            if len(tok) < 2:
                raise SceneError(f"{at}: 'mtllib' needs a file name")
            for t in tok[1:]:
                mine.update(_read_mtl(Path(t) if t.startswith("/") else path.parent / t, at,
                                      materials))
        elif k == "usemtl":
            # a scene-file material of that name, else this file's .mtl ones read so far,
            # else the obj statement's material
            if len(tok) != 2:
                raise SceneError(f"{at}: 'usemtl' needs one name")
            cur = names.get(tok[1], mine.get(tok[1], default_mat))
    if not polys:
        return
    V = np.array(verts, dtype=np.float64)
    VN = np.array(vns, dtype=np.float64) if vns else np.zeros((0, 3))
    # triangles: corner vertex / normal indices, polygon, whole (convex and planar: one
    # face in the C reader, its fan here), smoothing group, material
    tv, tn, tp, tw, tg, tm = [], [], [], [], [], []
    for k, (vi, ni, m, g) in enumerate(polys):
        tri, whole = _triangulate([verts[v] for v in vi]) if len(vi) > 3 else ([(0, 1, 2)], True)
        for t in tri:
            tv.append([vi[c] for c in t])
            tn.append([-1 if ni[c] is None else ni[c] for c in t])
        tp += [k] * len(tri)
        tw += [whole] * len(tri)
        tg += [g] * len(tri)
        tm += [m] * len(tri)
    tv, tn, tp, tg = (np.array(x, dtype=np.int64) for x in (tv, tn, tp, tg))
    tw = np.array(tw, dtype=bool)
    tpos = V[tv]                                          # (T, 3, 3)
    tnewell = _newell(tpos)                               # (T, 3), |.| = 2 area
    pn = np.zeros((len(polys), 3))                        # the polygon's Newell normal
    np.add.at(pn, tp, tnewell)
    # the face normal: the polygon's if it is one face in the C reader, else the triangle's
    fn = np.where(tw[:, None], pn[tp], tnewell)
    # smooth normals per (vertex, group): each polygon of the group using the vertex once
    cv = np.array([v for vi, _, _, _ in polys for v in vi], dtype=np.int64)
    cg = np.array([g for vi, _, _, g in polys for _ in vi], dtype=np.int64)
    cp = np.array([k for k, (vi, _, _, _) in enumerate(polys) for _ in vi], dtype=np.int64)
    groups, cgi = np.unique(cg, return_inverse=True)
    ng = len(groups)
    vg_key = cv * ng + cgi.reshape(-1)
    uniq = np.unique(np.stack([vg_key, cp], 1), axis=0)   # distinct (vertex+group, polygon)
    keys, inv = np.unique(uniq[:, 0], return_inverse=True)
    acc = np.zeros((len(keys), 3))
    np.add.at(acc, inv.reshape(-1), pn[uniq[:, 1]])
    ln = np.linalg.norm(acc, axis=1, keepdims=True)
    smooth = np.divide(acc, ln, out=np.zeros_like(acc), where=ln > 0)
    corner_key = tv * ng + np.searchsorted(groups, tg)[:, None]
    nrm = smooth[np.searchsorted(keys, corner_key)]       # (T, 3, 3)
    flat = tg == 0                                        # 's off': the face normal
    nrm[flat] = fn[flat][:, None, :]
    authored = tn >= 0                                    # `vn` overrides
    nrm[authored] = VN[tn[authored]]
    tris.extend(tpos)
    norms.extend(nrm)
    mats.extend(zip(tm, fn))


def load_scene(path) -> Scene:
    """Parse a scene file (docs/hsr.md + docs/shading.md extensions) and its OBJ files."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as e:
        raise SceneError(f"{path}: cannot read ({e.strerror})") from None
    sc = Scene()
    sc.materials = [Material("default", (0.8, 0.8, 0.8))]
    names = {"default": 0}
    tris, norms, mats = [], [], []
    bg_image = None
    for lineno, line in enumerate(text.splitlines(), 1):
        tok = _tokens(line)
        if not tok:
            continue
        k, where = tok[0], f"{path}:{lineno}"
        if k == "screen":
            w, h = _nums(tok[1:], 2, where)
            sc.width, sc.height = int(w), int(h)
        elif k == "camera":
            if len(tok) != 15 or (tok[1], tok[5], tok[9], tok[13]) != ("eye", "at", "up", "fov"):
                raise SceneError(f"{where}: expected 'camera eye X Y Z at X Y Z up X Y Z fov DEG'")
            sc.eye = tuple(_nums(tok[2:5], 3, where))
            sc.at = tuple(_nums(tok[6:9], 3, where))
            sc.up = tuple(_nums(tok[10:13], 3, where))
            sc.fov = _nums(tok[14:], 1, where)[0]
        elif k == "near":
            sc.near = _nums(tok[1:], 1, where)[0]
        elif k == "light":
            if len(tok) == 5:
                v = _nums(tok[1:], 4, where)
                rgb = (v[3],) * 3
            elif len(tok) == 7:
                v = _nums(tok[1:], 6, where)
                rgb = tuple(v[3:6])
            else:
                raise SceneError(f"{where}: 'light DX DY DZ I' or 'light DX DY DZ R G B'")
            L = np.array(v[:3])
            if not np.linalg.norm(L) > 0:
                raise SceneError(f"{where}: zero light direction")
            sc.lights.append((L / np.linalg.norm(L), np.array(rgb, dtype=np.float64)))
        elif k == "ambient":
            sc.ambient = _nums(tok[1:], 1, where)[0]
        elif k == "background" and len(tok) == 3 and tok[1] == "image":
            bg_image = (path.parent / tok[2], where)
        elif k == "background":
            sc.background = tuple(_nums(tok[1:], 3, where))
        elif k == "material":
            if len(tok) < 5:
                raise SceneError(f"{where}: expected 'material NAME R G B [opacity O] "
                                 "[specular KS N] [flat]'")
            m = Material(tok[1], tuple(_nums(tok[2:5], 3, where)))
            i = 5
            while i < len(tok):
                if tok[i] == "opacity":
                    m.opacity = _nums(tok[i + 1:i + 2], 1, where)[0]
                    i += 2
                elif tok[i] == "specular":
                    m.ks, m.n = _nums(tok[i + 1:i + 3], 2, where)
                    i += 3
                elif tok[i] in ("flat", "smooth"):
                    m.flat = tok[i] == "flat"
                    i += 1
                elif tok[i] == "shading" and i + 1 < len(tok):
                    m.flat = tok[i + 1] == "flat"
                    i += 2
                else:
                    raise SceneError(f"{where}: unknown material option {tok[i]!r}")
            names[m.name] = len(sc.materials)
            sc.materials.append(m)
        elif k == "obj":
            if len(tok) == 4 and tok[2] == "material":
                if tok[3] not in names:
                    raise SceneError(f"{where}: unknown material {tok[3]!r}")
                mat = names[tok[3]]
            elif len(tok) == 2:
                mat = 0
            else:
                raise SceneError(f"{where}: expected 'obj PATH [material NAME]'")
            p = Path(tok[1])
            _read_obj(p if p.is_absolute() else path.parent / p, mat, names, sc.materials,
                      tris, norms, mats, where=f"{where}: ")
        elif k == "grid":
            pass
        else:
            warnings.warn(f"{where}: statement {k!r} ignored by the reference renderer",
                          stacklevel=2)
    if not sc.lights:   # scene.c's default light
        sc.lights.append((np.ones(3) / math.sqrt(3), np.full(3, 0.8)))
    sc.pos = np.array(tris, dtype=np.float64).reshape(-1, 3, 3)
    nv = np.array(norms, dtype=np.float64).reshape(-1, 3, 3)
    midx = np.array([m for m, _ in mats], dtype=np.int64)
    fnorm = np.array([n for _, n in mats], dtype=np.float64).reshape(-1, 3)
    flat = np.array([sc.materials[m].flat for m in midx], dtype=bool)
    nv[flat] = fnorm[flat][:, None, :]
    sc.nrm, sc.mat = nv, midx
    if bg_image is not None:
        sc.background_image = _read_ppm(*bg_image, sc.width, sc.height)
    return sc


def _read_ppm(path: Path, where: str, W: int, H: int) -> np.ndarray:
    """A binary PPM (P6) as (H, W, 3) in 1.0 units: quantised to 12 bits and scaled to
    the screen by nearest neighbour exactly as yproc's read_ppm (yp_shade.c)."""
    try:
        data = path.read_bytes()
    except OSError as e:
        raise SceneError(f"{where}: cannot read background image {path} ({e.strerror})") from None
    fields, pos = [], 0
    while len(fields) < 4:
        while pos < len(data) and data[pos:pos + 1].isspace():
            pos += 1
        end = pos
        while end < len(data) and not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    try:
        magic, w, h, maxv = fields[0], int(fields[1]), int(fields[2]), int(fields[3])
    except ValueError:
        magic = None
    if magic != b"P6" or not (0 < maxv < 65536) or w < 1 or h < 1:
        raise SceneError(f"{where}: {path}: not a binary PPM (P6)")
    pos += 1
    dt = np.dtype(">u2") if maxv > 255 else np.dtype("u1")
    n = 3 * w * h
    if len(data) - pos < n * dt.itemsize:
        raise SceneError(f"{where}: {path}: truncated")
    src = np.frombuffer(data, dtype=dt, count=n, offset=pos).reshape(h, w, 3).astype(np.float64)
    src = _llround(src * 4095.0 / maxv)
    sy = (np.arange(H) * h) // H
    sx = (np.arange(W) * w) // W
    return src[sy][:, sx] / 4095.0


def _llround(v: np.ndarray) -> np.ndarray:
    return np.sign(v) * np.floor(np.abs(v) + 0.5)


@dataclass
class Projected:
    """Screen-space triangles: xy (T,3,2) in pixels (quantised), iz (T,3) = 1/depth,
    world positions and vertex normals (T,3,3), material index (T,)."""
    xy: np.ndarray
    iz: np.ndarray
    pos: np.ndarray
    nrm: np.ndarray
    mat: np.ndarray


def camera(sc: Scene):
    eye, at, up = (np.array(t, dtype=np.float64) for t in (sc.eye, sc.at, sc.up))
    w = eye - at
    u = np.cross(up, w)
    w /= np.linalg.norm(w)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    f = (sc.height / 2) / math.tan(sc.fov * math.pi / 360.0)
    return eye, u, v, w, f


def project(sc: Scene, quantise: bool = True) -> Projected:
    eye, u, v, w, f = camera(sc)
    d = sc.pos - eye
    E = np.stack([d @ u, d @ v, d @ w], -1)            # eye space (T,3,3)
    inside = E[..., 2] <= -sc.near
    keep_all = inside.all(1)
    out_xyz, out_pos, out_nrm, out_mat = [E[keep_all]], [sc.pos[keep_all]], \
        [sc.nrm[keep_all]], [sc.mat[keep_all]]
    # Triangles crossing the near plane: clip in eye space (project.c's clip()),
    # attributes interpolated along the cut edges, fan back into triangles.
    for t in np.flatnonzero(inside.any(1) & ~keep_all):
        pts = []
        for i in range(3):
            a, b = i, (i + 1) % 3
            da, db = E[t, a, 2] + sc.near, E[t, b, 2] + sc.near
            if da <= 0:
                pts.append((E[t, a], sc.pos[t, a], sc.nrm[t, a]))
            if (da < 0 < db) or (da > 0 > db):
                s = da / (da - db)
                pts.append(tuple(x[t, a] + s * (x[t, b] - x[t, a]) for x in (E, sc.pos, sc.nrm)))
        for j in range(1, len(pts) - 1):
            tri = [pts[0], pts[j], pts[j + 1]]
            out_xyz.append(np.array([[p[0] for p in tri]]))
            out_pos.append(np.array([[p[1] for p in tri]]))
            out_nrm.append(np.array([[p[2] for p in tri]]))
            out_mat.append(np.array([sc.mat[t]]))
    E = np.concatenate(out_xyz)
    iz = 1.0 / -E[..., 2]
    xy = np.stack([sc.width / 2 + f * E[..., 0] * iz, sc.height / 2 - f * E[..., 1] * iz], -1)
    if quantise:
        xy = _llround(xy * SUBPIXEL) / SUBPIXEL
    return Projected(xy, iz, np.concatenate(out_pos), np.concatenate(out_nrm),
                     np.concatenate(out_mat))


class _Raster:
    """Per-triangle edge setup: screen-linear barycentrics and the top-left tie rule."""

    def __init__(self, P: Projected):
        x, y = P.xy[..., 0], P.xy[..., 1]
        area = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
        self.ok = np.abs(area) > 0
        sgn = np.where(area < 0, -1.0, 1.0)
        # edge i is opposite vertex i: e_i(p) = sgn * cross(v_{i+2} - v_{i+1}, p - v_{i+1})
        self.A = np.zeros((len(x), 3))
        self.B = np.zeros((len(x), 3))
        self.C = np.zeros((len(x), 3))
        self.bias = np.zeros((len(x), 3), dtype=bool)   # True: a sample on this edge counts
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            ex, ey = x[:, k] - x[:, j], y[:, k] - y[:, j]
            self.A[:, i] = -sgn * ey
            self.B[:, i] = sgn * ex
            self.C[:, i] = sgn * (ey * x[:, j] - ex * y[:, j])
            # top-left rule in the orientation where inside is e > 0
            self.bias[:, i] = (self.B[:, i] < 0) | ((self.B[:, i] == 0) & (self.A[:, i] > 0))
        self.area = np.abs(area)
        self.ymin = y.min(1)
        self.ymax = y.max(1)
        self.xmin = x.min(1)
        self.xmax = x.max(1)


def render(sc: Scene, samples: int = 16, band: int = 16, quantise: bool = True,
           progress=None, info: dict | None = None) -> np.ndarray:
    """The frame as float (H, W, 3) in pixel units (1.0 = 4095).

    With `info` (a dict), info["edges"] is set to a bool (H, W) mask of the pixels whose
    sub-samples do not all see the same front-most opaque triangle (or all background):
    the pixels an edge crosses."""
    S = samples
    W, H = sc.width, sc.height
    P = project(sc, quantise)
    R = _Raster(P)
    opacity = np.array([m.opacity for m in sc.materials])[P.mat]
    kd = np.array([m.kd for m in sc.materials])[P.mat]
    ks = np.array([m.ks for m in sc.materials])[P.mat]
    kn = np.array([m.n for m in sc.materials])[P.mat]
    opaque = opacity >= 1.0
    eye, u, v, w, f = camera(sc)
    bg = np.array(sc.background, dtype=np.float64)
    out = np.zeros((H, W, 3))
    edges = np.zeros((H, W), dtype=bool)
    alltri = np.flatnonzero(R.ok)
    for y0 in range(0, H, band):
        y1 = min(H, y0 + band)
        ny, nx = (y1 - y0) * S, W * S
        sy = y0 + (np.arange(ny) + 0.5) / S           # sample y coordinates of the band
        sx = (np.arange(nx) + 0.5) / S
        tri = alltri[(R.ymax[alltri] >= y0) & (R.ymin[alltri] <= y1)]

        def raster(sel, zmin=None, zmax=None):
            """Nearest fragment of the triangles `sel` per sample, with iz in
            (zmin, zmax) when given: returns (iz, id, l1, l2) (id -1 = none)."""
            zb = np.full((ny, nx), -np.inf)
            ids = np.full((ny, nx), -1, dtype=np.int64)
            l1 = np.zeros((ny, nx))
            l2 = np.zeros((ny, nx))
            for t in sel:
                i0 = max(0, int(math.floor((R.ymin[t] - y0) * S - 0.5)))
                i1 = min(ny, int(math.ceil((R.ymax[t] - y0) * S + 0.5)))
                j0 = max(0, int(math.floor(R.xmin[t] * S - 0.5)))
                j1 = min(nx, int(math.ceil(R.xmax[t] * S + 0.5)))
                if i1 <= i0 or j1 <= j0:
                    continue
                X = sx[None, j0:j1]
                Y = sy[i0:i1, None]
                e = [R.A[t, k] * X + R.B[t, k] * Y + R.C[t, k] for k in range(3)]
                m = np.ones((i1 - i0, j1 - j0), dtype=bool)
                for k in range(3):
                    m &= (e[k] > 0) | ((e[k] == 0) & R.bias[t, k])
                if not m.any():
                    continue
                a0, a1 = e[0] / R.area[t], e[1] / R.area[t]
                z = a0 * P.iz[t, 0] + a1 * P.iz[t, 1] + (1 - a0 - a1) * P.iz[t, 2]
                zs = zb[i0:i1, j0:j1]
                m &= z > zs
                if zmin is not None:
                    m &= z > zmin[i0:i1, j0:j1]
                if zmax is not None:
                    m &= z < zmax[i0:i1, j0:j1]
                zs[m] = z[m]
                ids[i0:i1, j0:j1][m] = t
                l1[i0:i1, j0:j1][m] = a0[m]
                l2[i0:i1, j0:j1][m] = a1[m]
            return zb, ids, l1, l2

        def shade(zb, ids, l1, l2):
            """Phong colour (ny, nx, 3) at the samples with ids >= 0 (others 0)."""
            col = np.zeros((ny, nx, 3))
            hit = ids >= 0
            if not hit.any():
                return col
            t = ids[hit]
            a0, a1 = l1[hit], l2[hit]
            a = np.stack([a0, a1, 1 - a0 - a1], -1) * P.iz[t]     # perspective-correct
            a /= a.sum(-1, keepdims=True)
            N = np.einsum("si,sij->sj", a, P.nrm[t])
            N /= np.linalg.norm(N, axis=-1, keepdims=True)
            # the surface point from the screen position and its depth (exactly the
            # plane of the projected triangle at this sample)
            yy, xx = np.nonzero(hit)
            depth = 1.0 / zb[hit]
            xe = (sx[xx] - W / 2) * depth / f
            ye = (H / 2 - sy[yy]) * depth / f
            Pw = eye + xe[:, None] * u + ye[:, None] * v - depth[:, None] * w
            Ev = eye - Pw
            Ev /= np.linalg.norm(Ev, axis=-1, keepdims=True)
            flip = (N * Ev).sum(-1) < 0
            N[flip] = -N[flip]
            I = sc.ambient * kd[t]
            for L, Il in sc.lights:
                nl = N @ L
                R_ = 2 * nl[:, None] * N - L
                er = np.maximum(0.0, (Ev * R_).sum(-1))
                spec = ks[t] * np.power(er, kn[t])
                I = I + Il * (kd[t] * np.maximum(0.0, nl)[:, None] + spec[:, None])
            col[hit] = I
            return col

        zo, io, l1o, l2o = raster(tri[opaque[tri]])
        blk = io.reshape(y1 - y0, S, W, S)
        edges[y0:y1] = blk.min(axis=(1, 3)) != blk.max(axis=(1, 3))
        col = shade(zo, io, l1o, l2o)
        if sc.background_image is None:
            col[io < 0] = bg
        else:   # every sample takes the background of its own pixel
            img = np.repeat(np.repeat(sc.background_image[y0:y1], S, axis=0), S, axis=1)
            col[io < 0] = img[io < 0]
        ttri = tri[~opaque[tri]]
        if len(ttri):
            # depth peeling of the transparent layers in front of the opaque surface,
            # front to back: C = sum_k T_k o_k I_k + T C_opaque, T_{k+1} = T_k (1 - o_k)
            acc = np.zeros_like(col)
            T = np.ones((ny, nx))
            front = np.full((ny, nx), np.inf)
            while True:
                zt, it, l1t, l2t = raster(ttri, zmin=zo, zmax=front)
                if not (it >= 0).any():
                    break
                o = np.where(it >= 0, opacity[np.maximum(it, 0)], 0.0)
                acc += (T * o)[..., None] * shade(zt, it, l1t, l2t)
                T *= 1 - o
                front = np.where(it >= 0, zt, -np.inf)
            col = acc + T[..., None] * col
        out[y0:y1] = col.reshape(y1 - y0, S, W, S, 3).mean(axis=(1, 3))
        if progress:
            progress(y1, H)
    if info is not None:
        info["edges"] = edges
    return out * PIXEL_SCALE


def render_file(path, samples: int = 16, progress=None, info: dict | None = None) -> np.ndarray:
    return render(load_scene(path), samples=samples, progress=progress, info=info)


def psnr(frame: np.ndarray, ref: np.ndarray, peak: float = PIXEL_SCALE) -> float:
    """PSNR in dB over all channels (12-bit frame, peak 4095)."""
    mse = float(np.mean((np.asarray(frame, dtype=np.float64) - ref) ** 2))
    return math.inf if mse == 0 else 10 * math.log10(peak * peak / mse)


# An outlier: a pixel that is more than OUTLIER_ERROR of full scale off the reference (in
# its worst channel) where the reference is locally smooth (its 3x3 neighbourhood spans
# less than OUTLIER_SMOOTH of full scale in every channel). Edges, where the box filter and
# the reference's 16x16 samples legitimately differ by more, do not count; an isolated
# wrong pixel or a short streak on a smooth surface does, however good the average is.
OUTLIER_ERROR = 0.15
OUTLIER_SMOOTH = 0.10


def outliers(frame: np.ndarray, ref: np.ndarray, error: float = OUTLIER_ERROR,
             smooth: float = OUTLIER_SMOOTH) -> np.ndarray:
    """Boolean (H, W) mask of the outlier pixels of `frame` (12-bit, H x W x 3) against the
    float reference `ref` (same shape, pixel units)."""
    f = np.asarray(frame, dtype=np.float64)
    r = np.asarray(ref, dtype=np.float64)
    if f.shape != r.shape or f.ndim != 3:
        raise ValueError(f"outliers: frame {f.shape} and reference {r.shape} must be H x W x 3")
    err = np.abs(f - r).max(axis=-1)
    p = np.pad(r, ((1, 1), (1, 1), (0, 0)), mode="edge")
    H, W = r.shape[:2]
    win = np.stack([p[i:i + H, j:j + W] for i in range(3) for j in range(3)])
    span = (win.max(axis=0) - win.min(axis=0)).max(axis=-1)
    return (err > error * PIXEL_SCALE) & (span < smooth * PIXEL_SCALE)


def outlier_map(frame: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """An 8-bit RGB picture of the outliers: the frame dimmed to grey, each outlier a red
    3x3 square (a single pixel is hard to find in a 640x480 picture)."""
    grey = (np.asarray(frame, dtype=np.float64).mean(axis=-1) / PIXEL_SCALE * 110 + 60)
    img = np.repeat(grey[..., None], 3, axis=-1).astype(np.uint8)
    H, W = mask.shape
    for y, x in np.argwhere(mask):
        img[max(y - 1, 0):min(y + 2, H), max(x - 1, 0):min(x + 2, W)] = (255, 0, 0)
    return img


def main(argv=None) -> int:
    import argparse
    import time

    ap = argparse.ArgumentParser(description="numpy reference renderer (16x16 Phong)")
    ap.add_argument("scene")
    ap.add_argument("-o", "--output", required=True, help="16-bit PNG (or .npy float frame)")
    ap.add_argument("--samples", type=int, default=16)
    a = ap.parse_args(argv)
    t0 = time.monotonic()
    img = render_file(a.scene, a.samples,
                      progress=lambda d, n: print(f"\rreference: {d}/{n} rows", end="",
                                                  file=sys.stderr))
    print(f"\nreference: {time.monotonic() - t0:.1f} s", file=sys.stderr)
    if a.output.endswith(".npy"):
        np.save(a.output, img)
    else:
        from .frame import write_png16
        write_png16(a.output, np.clip(np.round(img), 0, 4095).astype(np.uint16))
    return 0


if __name__ == "__main__":
    sys.exit(main())
