"""Generate the project's test images for image reconstruction (sw/images/*.png).

Every image is synthetic and deterministic (fixed seeds, no external data), so the set
is free to redistribute and byte-identical on every run. 256x128, 16-bit PNG. Values
are made on the array's 12-bit pixel scale first and stored as 16-bit by bit
replication (v16 = v12 * 65535 / 4095, exact for the round trip back to 12 bits), so
that "piecewise linear on the 12-bit grid" survives storage.

  ramps.png    grey, every scanline exactly piecewise linear in 12-bit integers
               (ramps, triangles, plateaus, saw teeth): the exactness test image
  zoneplate.png grey, cos(k r^2) zone plate: all spatial frequencies, worst case
  circles.png  grey, anti-aliased discs of several greys on a diagonal gradient
  bars.png     grey, text-like strokes and bars: step edges, the raster codes' case
  natural.png  grey, 1/f^1.8 filtered noise + soft shading: a "natural-like" image
  spheres.png  colour (RGB), Phong-shaded spheres on a graded floor: a rendered frame

640x480 (the display's width, for the real-time capacity figures):

  natural640.png grey, the natural-like image's recipe at 640x480 (its own noise field)
  teapot.png   colour, the project's own rendered Utah teapot frame (`diffengine demo
               --no-rtl`: OBJ -> HSR -> y-processor -> golden model, 12-bit pixels
               stored exactly); the most natural image the project can ship - smooth
               Phong shading, anti-aliased silhouettes, a textured-free background
  tiny_rgb.png colour 72x54: the teapot frame cropped to 576x432 and 8x8 box-averaged,
               small enough to decode whole through a Verilated 8-chip array (tb/recon)

The teapot images need the C y-processor (built by `make -C sw/hsr` on demand by
demo.py, ~25 s); `--synthetic-only` skips them.

Natural photographs (fetched on demand, not shipped, `fetch_photo`): no network but the
package registries is reachable here, so the Kodak set cannot be fetched; the photos
come from the scikit-image wheel on PyPI (`pip download scikit-image==0.26.0
--no-deps`), which ships them in skimage/data/, and are checked by SHA-256 after
extraction (the wheel itself differs per platform). Licences (skimage/data/_fetchers.py):

  camera  512x512 grey, "No copyright restrictions. CC0 by the photographer (Lav Varshney)."
  coffee  600x400 RGB, "No copyright restrictions. CC0 by the photographer (Rachel
          Michetti)." (courtesy of Pikolo Espresso Bar)

Usage: diffengine bench recon-images [--out sw/images] [--synthetic-only] [--photos]
"""
from __future__ import annotations

import sys
from pathlib import Path

import OpenImageIO as oiio  # noqa: I001  (imported before numpy: see write_png)
import numpy as np

from .. import REPO

W, H = 256, 128
MAXV = 4095


def to16(v12: np.ndarray) -> np.ndarray:
    v12 = np.clip(np.rint(v12), 0, MAXV).astype(np.int64)
    return ((v12 * 65535 + MAXV // 2) // MAXV).astype(np.uint16)


def ramps() -> np.ndarray:
    rng = np.random.default_rng(1995)
    img = np.zeros((H, W), dtype=np.int64)
    x = np.arange(W)
    for y in range(H):
        # knots at integer columns, integer slopes: exact piecewise linear on the grid
        nk = 2 + (y % 7)
        knots = np.sort(rng.choice(np.arange(8, W - 8), size=nk, replace=False))
        knots = np.concatenate([[0], knots, [W - 1]])
        vals = rng.integers(200, 3900, size=len(knots))
        row = np.zeros(W, dtype=np.int64)
        for a, b, va, vb in zip(knots[:-1], knots[1:], vals[:-1], vals[1:]):
            slope = (vb - va) // max(b - a, 1)
            seg = va + slope * (x[a:b + 1] - a)
            row[a:b + 1] = seg
            vals[list(knots).index(b)] = seg[-1]  # keep continuity with integer slope
        if y % 5 == 0:  # plateaus with jumps (still piecewise linear, two kinks per step)
            row[W // 3: W // 2] = 3000 - y * 4
        img[y] = np.clip(row, 0, MAXV)
    return img


def zoneplate() -> np.ndarray:
    yy, xx = np.mgrid[0:H, 0:W].astype(float)
    r2 = (xx - W / 2) ** 2 + (yy - H / 2) ** 2
    k = np.pi / (2.0 * W)
    return 2047.5 + 1800.0 * np.cos(k * r2)


def _smoothstep_disc(xx, yy, cx, cy, r):
    d = np.sqrt((xx - cx) ** 2 + (yy - cy) ** 2)
    return np.clip(r + 0.5 - d, 0.0, 1.0)  # 1-pixel anti-aliased edge


def circles() -> np.ndarray:
    yy, xx = np.mgrid[0:H, 0:W].astype(float)
    img = 600.0 + 1400.0 * (xx / W) + 600.0 * (yy / H)
    discs = [(50, 40, 30, 3600), (130, 70, 45, 300), (200, 35, 25, 2800),
             (215, 100, 20, 1200), (90, 105, 15, 3900), (160, 20, 10, 100)]
    for cx, cy, r, v in discs:
        a = _smoothstep_disc(xx, yy, cx, cy, r)
        img = img * (1 - a) + v * a
    return img


def bars() -> np.ndarray:
    rng = np.random.default_rng(7)
    img = np.full((H, W), 3700.0)
    # "text lines": rows of glyph-like boxes with vertical and horizontal strokes
    for line_y in range(8, H - 16, 20):
        x = 6
        while x < W - 12:
            gw = int(rng.integers(5, 11))
            kind = int(rng.integers(0, 4))
            ink = 300.0 + 200.0 * rng.random()
            if kind == 0:  # vertical stem
                img[line_y:line_y + 12, x:x + 2] = ink
            elif kind == 1:  # box outline
                img[line_y:line_y + 12, x:x + gw] = ink
                img[line_y + 2:line_y + 10, x + 2:x + gw - 2] = 3700.0
            elif kind == 2:  # bar with a crossbar
                img[line_y:line_y + 12, x:x + 2] = ink
                img[line_y + 5:line_y + 7, x:x + gw] = ink
            else:  # space
                pass
            x += gw + 2
    # a grey-scale step wedge at the bottom
    for i in range(16):
        img[H - 8:, i * 16:(i + 1) * 16] = i * 273.0
    return img


def _filtered_noise(rng, shape, beta=1.8):
    f = np.fft.fft2(rng.standard_normal(shape))
    fy = np.fft.fftfreq(shape[0])[:, None]
    fx = np.fft.fftfreq(shape[1])[None, :]
    r = np.sqrt(fx ** 2 + fy ** 2)
    r[0, 0] = 1.0
    f *= r ** (-beta / 1.0) * 0.5
    f[0, 0] = 0
    n = np.real(np.fft.ifft2(f))
    return (n - n.mean()) / n.std()


def natural(h: int = H, w: int = W, seed: int = 42) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = _filtered_noise(rng, (h, w))
    yy, xx = np.mgrid[0:h, 0:w].astype(float)
    sx, sy = w / W, h / H
    shade = 0.6 * np.exp(-((xx - 170 * sx) ** 2 / sx ** 2 + (yy - 50 * sy) ** 2 / sy ** 2)
                         / (2 * 60.0 ** 2))
    img = 2048 + 650 * n + 900 * shade - 300 * (yy / h)
    return img


def natural640() -> np.ndarray:
    return natural(480, 640, seed=640)


def render_teapot() -> np.ndarray:
    """The teapot frame of `diffengine demo --no-rtl` as 12-bit RGB (480, 640, 3)."""
    import os
    import subprocess
    import sys
    import tempfile

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(REPO / "sw"), *filter(None, [os.environ.get("PYTHONPATH")])]))
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, "-m", "diffengine", "demo", "--no-rtl", "--out", tmp],
                       check=True, stdout=subprocess.DEVNULL, env=env)
        buf = oiio.ImageBuf(str(Path(tmp) / "demo.png"))
        px = buf.get_pixels(oiio.UINT16)
    v = (px.astype(np.int64) * MAXV + 32767) // 65535
    return v[:, :, :3].astype(float)


def tiny_rgb(teapot: np.ndarray) -> np.ndarray:
    c = teapot[24:24 + 432, 32:32 + 576]
    return c.reshape(54, 8, 72, 8, 3).mean(axis=(1, 3))


def spheres() -> np.ndarray:
    yy, xx = np.mgrid[0:H, 0:W].astype(float)
    # floor/sky background: vertical colour gradient
    t = yy / H
    rgb = np.stack([800 + 1800 * t, 1200 + 1200 * t, 2600 - 600 * t], axis=-1)
    light = np.array([-0.5, -0.6, 0.62])
    light /= np.linalg.norm(light)
    view = np.array([0.0, 0.0, 1.0])
    half = light + view
    half /= np.linalg.norm(half)
    scene = [(70, 70, 45, (0.9, 0.25, 0.2)), (165, 60, 38, (0.2, 0.7, 0.3)),
             (225, 95, 25, (0.25, 0.35, 0.95))]
    zbuf = np.full((H, W), -np.inf)
    for cx, cy, r, col in scene:
        dx, dy = (xx - cx) / r, (yy - cy) / r
        d2 = dx ** 2 + dy ** 2
        inside = d2 < 1.0
        nz = np.sqrt(np.clip(1.0 - d2, 0.0, 1.0))
        z = nz * r
        vis = inside & (z > zbuf)
        ndotl = np.clip(dx * light[0] + dy * light[1] + nz * light[2], 0, 1)
        ndoth = np.clip(dx * half[0] + dy * half[1] + nz * half[2], 0, 1)
        spec = ndoth ** 40
        for c in range(3):
            v = 4095 * (0.08 * col[c] + 0.75 * col[c] * ndotl) + 3000 * spec
            rgb[..., c] = np.where(vis, v, rgb[..., c])
        zbuf = np.where(vis, z, zbuf)
    return rgb


IMAGES = {"ramps": ramps, "zoneplate": zoneplate, "circles": circles, "bars": bars,
          "natural": natural, "spheres": spheres, "natural640": natural640}


def write_png(path: Path, v12: np.ndarray) -> None:
    data = to16(v12)
    nch = 1 if data.ndim == 2 else data.shape[2]
    spec = oiio.ImageSpec(int(data.shape[1]), int(data.shape[0]), int(nch), oiio.UINT16)
    buf = oiio.ImageBuf(spec)
    buf.set_pixels(oiio.ROI(), np.ascontiguousarray(data.reshape(data.shape[0], data.shape[1], nch)))
    if not buf.write(str(path)):
        raise SystemExit(f"cannot write {path}: {buf.geterror()}")


SKIMAGE = "scikit-image==0.26.0"
PHOTOS = {
    "camera": ("skimage/data/camera.png",
               "b0793d2adda0fa6ae899c03989482bff9a42d3d5690fc7e3648f2795d730c23a",
               "CC0, photographer Lav Varshney (scikit-image 0.26.0 skimage/data)"),
    "coffee": ("skimage/data/coffee.png",
               "cc02f8ca188b167c775a7101b5d767d1e71792cf762c33d6fa15a4599b5a8de7",
               "CC0, photographer Rachel Michetti (scikit-image 0.26.0 skimage/data)"),
}
PHOTO_CACHE = REPO / "build" / "photos"


class FetchError(RuntimeError):
    """A photograph could not be fetched or failed its checksum."""


def _sha256(path: Path) -> str:
    import hashlib

    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def fetch_photo(name: str, cache: Path = PHOTO_CACHE) -> Path:
    """Path of a checked natural photograph, downloading the wheel that holds it if the
    cache lacks it (pip, PyPI). Raises FetchError (with pip's message) without network."""
    import subprocess
    import sys
    import zipfile

    if name not in PHOTOS:
        raise FetchError(f"unknown photograph {name!r} (one of {', '.join(PHOTOS)})")
    member, digest, _ = PHOTOS[name]
    out = Path(cache) / f"{name}.png"
    if out.is_file() and _sha256(out) == digest:
        return out
    Path(cache).mkdir(parents=True, exist_ok=True)
    wheels = sorted(Path(cache).glob("scikit_image-0.26.0-*.whl"))
    if not wheels:
        print(f"fetching {SKIMAGE} (wheel, ~14 MB) for {name}.png ...", file=sys.stderr)
        res = subprocess.run([sys.executable, "-m", "pip", "download", SKIMAGE, "--no-deps",
                              "--only-binary", ":all:", "-d", str(cache)],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        wheels = sorted(Path(cache).glob("scikit_image-0.26.0-*.whl"))
        if res.returncode or not wheels:
            raise FetchError(f"{cache}: pip download {SKIMAGE} failed (no network?):\n"
                             + res.stdout[-1500:])
    with zipfile.ZipFile(wheels[0]) as z:
        out.write_bytes(z.read(member))
    got = _sha256(out)
    if got != digest:
        out.unlink()
        raise FetchError(f"{wheels[0]}:{member}: SHA-256 {got}, expected {digest}")
    return out


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("--out", default=str(REPO / "sw" / "images"))
    ap.add_argument("--synthetic-only", action="store_true", help="skip the teapot frames")
    ap.add_argument("--photos", action="store_true", help="only fetch and check the natural "
                    f"photographs into {PHOTO_CACHE} (not shipped: CC0, from {SKIMAGE})")
    ap.set_defaults(func=command)


def command(args) -> int:
    if args.photos:
        try:
            for name in PHOTOS:
                print(f"{fetch_photo(name)}: SHA-256 ok, licence {PHOTOS[name][2]}")
        except FetchError as e:
            print(f"diffengine bench recon-images: error: {e}", file=sys.stderr)
            return 2
        return 0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, fn in IMAGES.items():
        write_png(out / f"{name}.png", fn())
        print(f"wrote {out / (name + '.png')}")
    if not args.synthetic_only:
        tea = render_teapot()
        for name, img in (("teapot", tea), ("tiny_rgb", tiny_rgb(tea))):
            write_png(out / f"{name}.png", img)
            print(f"wrote {out / (name + '.png')}")
    return 0
