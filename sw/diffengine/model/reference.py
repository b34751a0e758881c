"""Numpy reference renderer: z-buffer + per-sample Phong, 16x16 supersampled.

The shading model is the normative one shared with the C y-processor (docs/shading.md):
directional lights, ambient, per-vertex smooth normals (area-weighted, `vn` overrides,
`flat` materials use the face normal), two-sided, perspective-correct barycentric normal
interpolation, local viewer, I_c = A kd_c + sum_l I_l,c (kd_c max(0, N.L) +
KS max(0, E.R)^N), transparency o I_front + (1 - o) C_behind front to back over the
`background`. 1.0 = 4095 pixel units.

The scene, OBJ and MTL files are read by the C library, the project's one reader
(`yproc read`, load_scene below); from there on everything is this module's own: the
triangles' corner normals, projection, sampling and shading.

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


def _newell(p: np.ndarray) -> np.ndarray:
    """Newell normal of polygon(s) p (..., n, 3): unnormalised, |.| = 2 area."""
    q = np.roll(p, -1, axis=-2)
    return np.stack([((p[..., 1] - q[..., 1]) * (p[..., 2] + q[..., 2])).sum(-1),
                     ((p[..., 2] - q[..., 2]) * (p[..., 0] + q[..., 0])).sum(-1),
                     ((p[..., 0] - q[..., 0]) * (p[..., 1] + q[..., 1])).sum(-1)], -1)


def load_scene(path) -> Scene:
    """The scene file and its OBJ/MTL files, read by the C library (`yproc read`, one
    reader for every format: docs/hsr.md "hsr-scene-1"); the triangles and their corner
    normals are made here (docs/shading.md "Normals"), so the shading stays this module's.
    SceneError carries the reader's "file:line: message"."""
    from ..host import yproc
    try:
        d = yproc.read_scene(path)
    except yproc.YprocError as e:
        raise SceneError(str(e)) from None
    cam = d["camera"]
    sc = Scene(width=d["screen"][0], height=d["screen"][1], eye=tuple(cam["eye"]),
               at=tuple(cam["at"]), up=tuple(cam["up"]), fov=cam["fov"], near=cam["near"],
               ambient=d["ambient"], background=tuple(d["background"]))
    sc.materials = [Material(m["name"], tuple(m["kd"]), m["opacity"], m["ks"], m["n"], m["flat"])
                    for m in d["materials"]]
    for lt in d["lights"]:
        L = np.array(lt["dir"], dtype=np.float64)
        sc.lights.append((L / np.linalg.norm(L), np.array(lt["rgb"], dtype=np.float64)))
    _triangles(sc, d)
    if d["background_image"] is not None:
        sc.background_image = _read_ppm(Path(d["background_image"]),
                                        f"{d['file']}:{d['background_image_line']}",
                                        sc.width, sc.height)
    return sc


def _triangles(sc: Scene, d: dict) -> None:
    """sc.pos / nrm / mat from the reader's faces. A face is a polygon the reader kept
    whole (convex and planar), drawn as its fan, or one triangle of a polygon it split
    (consecutive faces with the same `poly`). Corner normals: an authored `vn`, else `s off`
    the face normal, else the normalised sum over the polygons of the vertex's smoothing
    group of their normals; a `flat` material takes the face normal everywhere."""
    V = np.array(d["vertices"], dtype=np.float64).reshape(-1, 3)
    VN = np.array(d["normals"], dtype=np.float64).reshape(-1, 3)
    F = {k: np.array(v, dtype=np.int64) for k, v in d["faces"].items()}
    cv_all = np.array(d["corners"]["vertex"], dtype=np.int64)
    cn_all = np.array(d["corners"]["normal"], dtype=np.int64)
    if len(F["first"]) == 0:
        sc.pos, sc.nrm, sc.mat = np.zeros((0, 3, 3)), np.zeros((0, 3, 3)), np.zeros(0, np.int64)
        return
    # the fan of each face: (face, 0, k, k + 1) corner offsets
    nt = F["count"] - 2
    tf = np.repeat(np.arange(len(nt)), nt)
    k = np.arange(len(tf)) - np.repeat(np.cumsum(nt) - nt, nt) + 1
    corners = F["first"][tf][:, None] + np.stack([np.zeros_like(k), k, k + 1], 1)
    tv, tn = cv_all[corners], cn_all[corners]
    tp, tg, tm = F["poly"][tf], F["smooth"][tf], F["material"][tf]
    tpos = V[tv]                                          # (T, 3, 3)
    tnewell = _newell(tpos)                               # (T, 3), |.| = 2 area
    npoly = int(tp.max()) + 1
    pn = np.zeros((npoly, 3))                             # the polygon's normal
    np.add.at(pn, tp, tnewell)
    # the face normal: the polygon's if the reader kept it whole, else the triangle's
    faces_of_poly = np.bincount(F["poly"], minlength=npoly)
    whole = faces_of_poly[tp] == 1
    fn = np.where(whole[:, None], pn[tp], tnewell)
    # smooth normals per (vertex, group): each polygon of the group using the vertex once
    cf = np.repeat(np.arange(len(F["first"])), F["count"])    # the face of every corner
    cv, cg, cp = cv_all[:len(cf)], F["smooth"][cf], F["poly"][cf]
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
    flat_mat = np.array([m.flat for m in sc.materials], dtype=bool)[tm]
    nrm[flat_mat] = fn[flat_mat][:, None, :]
    sc.pos, sc.nrm, sc.mat = tpos, nrm, tm


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


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("scene")
    ap.add_argument("-o", "--output", required=True, help="16-bit PNG (or .npy float frame)")
    ap.add_argument("--samples", type=int, default=16)
    ap.set_defaults(func=command)


def command(a) -> int:
    import time
    t0 = time.monotonic()
    try:
        img = render_file(a.scene, a.samples,
                          progress=lambda d, n: print(f"\rreference: {d}/{n} rows", end="",
                                                      file=sys.stderr))
    except SceneError as e:   # file:line: message, no traceback
        print(f"diffengine reference: {e}", file=sys.stderr)
        return 1
    print(f"\nreference: {time.monotonic() - t0:.1f} s", file=sys.stderr)
    if a.output.endswith(".npy"):
        np.save(a.output, img)
    else:
        from ..formats.frame import write_png16
        write_png16(a.output, np.clip(np.round(img), 0, 4095).astype(np.uint16))
    return 0
