#!/usr/bin/env python3
"""Rate-distortion and capacity report for image reconstruction (docs/reconstruction.md).

For every test image in sw/images: spline codes (spline1 = Eval2 + SetdI knots,
spline2 = Eval3 + SetddI knots) over a sweep of lam, the Eval0 raster, the lossy
run-length Eval0 raster over a sweep of tolerances, and JPEG over a sweep of qualities;
PSNR (12-bit peak, pixels from the golden model) against instructions per frame and
against bytes (48-bit stream, 6 bytes per instruction; JPEG file bytes). Capacity:
per-line instruction budget of 640x480@60 (capacity.slots_per_line) and the quality
each code reaches within it.

Usage: scripts/recon_report.py [--quick] [--images a,b,...]
Writes docs/reconstruction.md and docs/img/recon_*.png.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "sw"))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from diffengine import encode as EN  # noqa: E402
from diffengine import encode_raster as ER  # noqa: E402
from diffengine import encode_spline as ES  # noqa: E402

try:
    from diffengine.capacity import slots_per_line
    PER_LINE = slots_per_line("640x480@60")
    PER_LINE_SRC = "capacity.slots_per_line('640x480@60')"
except ImportError:  # pragma: no cover
    PER_LINE, PER_LINE_SRC = 800, "800 (capacity.py absent)"

IMG = ROOT / "docs" / "img"
DOC = ROOT / "docs" / "reconstruction.md"
NAMES = ["ramps", "zoneplate", "circles", "bars", "natural", "spheres"]
CAP = 99.0  # plot infinite PSNR (exact) at this height


def fin(p):
    return min(p, CAP)


def run_image(name, lams, tols, quals):
    x = EN.load_image(ROOT / "sw" / "images" / f"{name}.png")
    encs = [EN.ChannelEncoder(c) for c in EN.channels(x)]
    rows = {"spline1": [], "spline2": [], "rle": [], "raster": [], "jpeg": []}

    def combine(results):
        return (sum(r.slots for r in results), sum(r.bytes for r in results),
                EN.image_psnr(results, x), max(r.max_slots_per_line for r in results))

    for d in (1, 2):
        for lam in lams:
            res = [e.spline_lam(d, lam) if lam > 0 else e.spline_lossless(d) for e in encs]
            rows[f"spline{d}"].append((lam,) + combine(res))
    for t in tols:
        rows["rle"].append((t,) + combine([e.rle_tol(t) for e in encs]))
    rows["raster"].append((0,) + combine([e.raster() for e in encs]))
    for q in quals:
        size, dec = ER.jpeg_roundtrip(x, q)
        rows["jpeg"].append((q, None, size, ES.psnr(dec, x), None))
    # capacity: best quality within the per-line budget of 640x480@60, and within the
    # image's proportional share of a 640-column line
    share = PER_LINE * x.shape[1] // 640
    cap = {}
    for budget, tag in ((PER_LINE, "full"), (share, "share")):
        for codec in ("spline1", "spline2", "rle"):
            res = [e.encode(codec, slots_per_line=budget) for e in encs]
            fits = all(r.max_slots_per_line <= budget for r in res)
            cap[codec, tag] = (EN.image_psnr(res, x), max(r.max_slots_per_line for r in res), fits)
        rast = [e.raster() for e in encs]
        cap["raster", tag] = (EN.image_psnr(rast, x), max(r.max_slots_per_line for r in rast),
                              all(r.max_slots_per_line <= budget for r in rast))
    # JPEG at the bytes of spline2 at 40 dB
    m = [e.encode("spline2", psnr=40.0) for e in encs]
    sb = sum(r.bytes for r in m)
    q, jb, dec = ER.jpeg_matched(x, sb)
    matched = dict(spline_bytes=sb, spline_psnr=EN.image_psnr(m, x), q=q, jpeg_bytes=jb,
                   jpeg_psnr=ES.psnr(dec, x),
                   decoded=np.stack([r.pixels for r in m], -1) if x.ndim == 3 else m[0].pixels)
    return x, rows, cap, share, matched


STYLE = {"spline1": ("C0", "o-", "spline1 (Eval2+SetdI)"),
         "spline2": ("C1", "s-", "spline2 (Eval3+SetddI)"),
         "rle": ("C2", "^-", "RLE Eval0 raster (lossy tol.)"),
         "raster": ("C3", "D", "Eval0 per pixel"),
         "jpeg": ("C4", "x--", "JPEG (8-bit, file bytes)")}


def plot(name, x, rows, path):
    fig, axs = plt.subplots(1, 2, figsize=(11, 4))
    lines = x.shape[0]
    for codec, pts in rows.items():
        col, mk, lab = STYLE[codec]
        pts = sorted(pts, key=lambda r: r[2])
        by = [p[2] for p in pts]
        ps = [fin(p[3]) for p in pts]
        axs[1].plot(by, ps, mk, color=col, label=lab, ms=4)
        if codec != "jpeg":
            axs[0].plot([p[1] / lines for p in pts], ps, mk, color=col, label=lab, ms=4)
    axs[0].axvline(PER_LINE, color="k", lw=0.8, ls=":")
    axs[0].text(PER_LINE, 30, f" {PER_LINE}/line\n 640x480@60", fontsize=7)
    axs[0].set_xlabel("instructions per line (frame / lines)")
    axs[1].set_xlabel("bytes (48-bit stream: 6 per instruction; JPEG: file)")
    for ax in axs:
        ax.set_xscale("log")
        ax.set_ylabel(f"PSNR dB, 12-bit peak ({CAP:g} = exact)")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_ylim(20, CAP + 2)
    axs[1].legend(fontsize=7, loc="lower right")
    fig.suptitle(f"{name}: {x.shape[1]}x{x.shape[0]}" + (" RGB" if x.ndim == 3 else " grey"))
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def montage(results, path):
    fig, axs = plt.subplots(len(results), 2, figsize=(8, 1.9 * len(results)))
    for i, (name, x, dec, p) in enumerate(results):
        for j, (img, title) in enumerate(((x, f"{name} original"),
                                          (dec, f"spline2 decoded (golden model), {p:.1f} dB"))):
            a = axs[i, j]
            v = np.asarray(img, float) / 4095.0
            a.imshow(np.clip(v, 0, 1), cmap=None if v.ndim == 3 else "gray", vmin=0, vmax=1)
            a.set_title(title, fontsize=8)
            a.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def fmt_p(p):
    return "exact" if p == float("inf") else f"{p:.1f}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer sweep points")
    ap.add_argument("--images", default=",".join(NAMES))
    args = ap.parse_args(argv)
    names = args.images.split(",")
    step = 1.0 if args.quick else 0.5
    lams = [0.0] + list(10 ** np.arange(0.0, 7.01, step))
    tols = [0, 1, 2, 4, 8, 16, 32, 64, 128, 256, 512]
    quals = [2, 5, 10, 20, 30, 50, 70, 85, 95, 100]
    IMG.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    out = {}
    for name in names:
        t = time.time()
        out[name] = run_image(name, lams, tols, quals)
        plot(name, out[name][0], out[name][1], IMG / f"recon_{name}.png")
        print(f"{name}: {time.time() - t:.1f} s", flush=True)
    montage([(n, out[n][0], out[n][4]["decoded"], out[n][4]["spline_psnr"]) for n in names],
            IMG / "recon_decoded.png")
    write_doc(out, names, time.time() - t0)
    print(f"wrote {DOC} and {IMG}/recon_*.png")
    return 0


def write_doc(out, names, secs):
    L = []
    a = L.append
    a("# Image reconstruction: spline- and wavelet-coded images decoded by the array")
    a("")
    a("Generated by `scripts/recon_report.py` (do not edit by hand; "
      f"{secs:.0f} s). Source: Kuijk 1995 §7.7.2 - the array interpolates any spline, its")
    a("signed accumulator sums the scales of a multiresolution code, and decoding time")
    a("depends on the number of knots, not on the span lengths. Code: `sw/diffengine/encode.py`")
    a("(`encode_main`, the `diffengine encode` engine), `encode_spline.py`, `encode_raster.py`;")
    a("test images: `scripts/make_test_images.py` -> `sw/images/` (synthetic, deterministic,")
    a("free to redistribute); tests: `sw/tests/test_encode.py`.")
    a("")
    a("## How an image becomes commands")
    a("")
    a("* **Pixels.** 8/16-bit images map to the array's 12-bit pixel (D[35:24]), v12 =")
    a("  round(v * 4095 / max). PSNR uses peak 4095 and the *golden model's* output")
    a("  (`functional.render`) of the emitted commands; the encoder's own integer simulation")
    a("  must agree bit for bit (checked on every encode).")
    a("* **Per scanline, a multiresolution spline.** spline1: one `Eval2 (0, W, I, dI)` and a")
    a("  `SetdI (k, g)` per knot (piecewise linear; the Set overrides the slope that forward")
    a("  differencing brings into PE k). spline2: `Eval3 (0, W, I, dI, ddI)` and `SetddI (k, g)`")
    a("  knots (discrete C1 quadratic spline). A knot costs 2 instructions wherever it is.")
    a("* **Analysis:** a B-spline pyramid per line - least squares of the residual onto")
    a("  discrete B-splines box_h^(d+1) at h = 32, 16, ..., 2, then unit impulses (h = 1).")
    a("  Coefficient c of an atom with knot cost k instructions is kept iff c^2 >= lam*k")
    a("  (greedy by energy per instruction). The kept atoms' knots form the knot set; the")
    a("  line is refitted by least squares over all splines with those knots (a local")
    a("  divided-difference B-spline basis, condition number ~2-10), quantised to 12.24 with")
    a("  exact integer error feedback, offset by +0.5 so that the array's truncation rounds.")
    a("  Pixels whose squared error still exceeds lam - and any that would wrap (no")
    a("  saturation, §1) - get an `Eval0` patch after the Eval (1 instruction per run).")
    a("  lam = 0 is lossless: knots exactly where the (d+1)-th difference is nonzero.")
    a("* **Accumulating the scales.** `--emission layered` sends one Eval per scale, each with")
    a("  the Sets of the knots that scale introduced, and lets D sum them (the signed")
    a("  accumulation of §7.7.2); `merged` folds all knots into one Eval; `auto` (default) takes")
    a("  the cheaper per line. Pixels are identical (tested); merged is always cheaper here")
    a("  (each extra scale costs an Eval), so the figures below are the merged form.")
    a("  Per-coefficient emission (each B-spline its own accumulated Eval3 + 2 SetddI = 9")
    a("  instructions) was not implemented: a knot in the merged form costs 2.")
    a("* **Vertical handling: per-row coding.** Exact, stateless, and the array needs every")
    a("  line's commands every frame anyway (it keeps nothing across Refresh), so")
    a("  interpolating coded rows in a y-processor would shrink stored bytes, not the")
    a("  per-line instruction load that decides real time. Vertical redundancy is therefore")
    a("  unused - the main reason JPEG wins on bytes.")
    a("* **Colour:** three independent streams (R, G, B), one command file each.")
    a("* **Baselines:** `raster` = one Eval0 per pixel (W+1 per line); `rle` = one Eval0 per")
    a("  run, lossy with tolerance t (max error t); JPEG via OpenImageIO, 8 bits, file bytes.")
    a("")
    a(f"Capacity: 640x480@60 gives **{PER_LINE} instruction slots per line** ({PER_LINE_SRC},")
    a("Refresh included). The test images are 256 columns wide, so the tables give both the")
    a(f"whole line ({PER_LINE}) and the image's proportional share of a 640-column line")
    a(f"({PER_LINE} x 256/640 = {PER_LINE * 256 // 640}), i.e. the budget if the image were")
    a("tiled across the screen.")
    a("")
    a("## Rate-distortion")
    a("")
    for n in names:
        a(f"### {n}")
        a("")
        a(f"![{n}](img/recon_{n}.png)")
        a("")
        rows = out[n][1]
        lines = out[n][0].shape[0]
        a("| code | setting | instr./line (mean) | max/line | bytes | PSNR dB |")
        a("|---|---|---|---|---|---|")
        for codec in ("spline1", "spline2"):
            pts = rows[codec]
            pick = [pts[0]] + pts[1::3]
            for p in pick:
                a(f"| {codec} | lam={p[0]:g} | {p[1] / lines:.1f} | {p[4]} | {p[2]} | {fmt_p(p[3])} |")
        for p in rows["rle"][:1] + rows["rle"][3::3]:
            a(f"| rle | tol={p[0]} | {p[1] / lines:.1f} | {p[4]} | {p[2]} | {fmt_p(p[3])} |")
        p = rows["raster"][0]
        a(f"| raster | - | {p[1] / lines:.1f} | {p[4]} | {p[2]} | {fmt_p(p[3])} |")
        for p in rows["jpeg"][::3]:
            a(f"| jpeg | q={p[0]} | - | - | {p[2]} | {fmt_p(p[3])} |")
        a("")
    a("## JPEG at matched bytes")
    a("")
    a("spline2 coded for PSNR >= 40 dB, then the highest JPEG quality whose file is no larger.")
    a("")
    a("| image | spline2 bytes | spline2 PSNR | JPEG q | JPEG bytes | JPEG PSNR |")
    a("|---|---|---|---|---|---|")
    for n in names:
        m = out[n][4]
        a(f"| {n} | {m['spline_bytes']} | {fmt_p(m['spline_psnr'])} | {m['q']} | "
          f"{m['jpeg_bytes']} | {fmt_p(m['jpeg_psnr'])} |")
    a("")
    a("![decoded](img/recon_decoded.png)")
    a("")
    a("## Capacity: real-time decoding at 640x480@60")
    a("")
    a("Best PSNR with every line within the budget (per-line search of lam / tolerance);")
    a("'max' is the largest line actually emitted; a code that cannot fit even at its")
    a("coarsest setting is marked 'no'.")
    a("")
    a(f"| image | budget | spline1 | spline2 | rle | raster (W+1) |")
    a("|---|---|---|---|---|---|")
    for n in names:
        cap, share = out[n][2], out[n][3]
        for tag, b in (("full", PER_LINE), ("share", share)):
            cells = []
            for codec in ("spline1", "spline2", "rle", "raster"):
                p, mx, fits = cap[codec, tag]
                pv = fmt_p(p) + ("" if p == float("inf") else " dB")
                cells.append(f"{pv}, max {mx}" + ("" if fits else " **no**"))
            a(f"| {n} | {b}/line | " + " | ".join(cells) + " |")
    a("")
    a("Lossless instruction counts per line (max over lines) against the budget:")
    a("")
    a("| image | spline1 | spline2 | rle | raster | fits 640x480@60 losslessly |")
    a("|---|---|---|---|---|---|")
    for n in names:
        rows = out[n][1]
        mx = {c: rows[c][0][4] for c in ("spline1", "spline2", "rle", "raster")}
        best = min(mx, key=mx.get)
        a(f"| {n} | {mx['spline1']} | {mx['spline2']} | {mx['rle']} | {mx['raster']} | "
          f"{'yes' if mx[best] <= PER_LINE else 'no'} (cheapest: {best}) |")
    a("")
    a("## Findings")
    a("")
    a("Fewest instructions per line (frame total / lines) among the swept points that reach")
    a("the PSNR (lossless point included); bold = best code for that image and target:")
    a("")
    a("| image | target | spline1 | spline2 | rle | raster |")
    a("|---|---|---|---|---|---|")
    for n in names:
        rows, lines = out[n][1], out[n][0].shape[0]
        for tgt in (40.0, 50.0):
            best = {}
            for c in ("spline1", "spline2", "rle", "raster"):
                ok = [p[1] / lines for p in rows[c] if p[3] >= tgt]
                best[c] = min(ok) if ok else None
            win = min((v, c) for c, v in best.items() if v is not None)[1]
            cells = [("**%.1f**" if c == win else "%.1f") % best[c] if best[c] is not None
                     else "-" for c in ("spline1", "spline2", "rle", "raster")]
            a(f"| {n} | {tgt:g} dB | " + " | ".join(cells) + " |")
    a("")
    a("* A knot costs 2 instructions, an Eval0 run 1. In these measurements the spline")
    a("  codes need the fewest instructions only on `ramps` (exactly piecewise linear:")
    a("  lossless at 16 per line, spline1). On every other image the lossy Eval0")
    a("  run-length raster needs fewer: ~1.3x fewer on `natural` at 40 dB, ~4x on")
    a("  `circles` and `bars`, and on the zone plate splines cost more than a raster.")
    a("  Near-lossless splines on busy lines cost ~2 instructions per pixel, twice the")
    a("  Eval0 raster. The encoder's knot placement is the weak point (next bullet).")
    a("* On bytes, JPEG wins by a wide margin: a 48-bit instruction per knot, no entropy")
    a("  coding and no vertical prediction cannot match an entropy-coded 2-D transform. The")
    a("  array's case is decoding at video rate with no frame buffer (§7.7.2), not storage.")
    a("* 640x480@60 gives 800 instructions per line, so every 256-wide test image fits even")
    a("  as an Eval0 raster (257/line); within the proportional share of a 640-column line")
    a("  the table above shows which code keeps which quality.")
    a("* The spline selection is a simple greedy on pyramid coefficients followed by a")
    a("  least-squares refit; a true rate-distortion knot optimisation (e.g. knot removal,")
    a("  dynamic programming per line, SetI value-jump knots for edges) should move the")
    a("  spline curves left and is the obvious next step.")
    a("")
    a("## Not done / pending")
    a("")
    a("* RTL decoding is checked on 72-column crops of four images (spline2, spline1, RLE,")
    a("  raster; `tb/recon/test_recon_rtl.py`, bit-identical), not on whole frames.")
    a("* No y-processor (vertical) interpolation, no entropy coding of the stream, no")
    a("  per-coefficient emission, no rendered teapot image (the shaded-spheres frame")
    a("  stands in), no SetI (value-jump) knots for step edges.")
    DOC.write_text("\n".join(L) + "\n", encoding="utf-8")


if __name__ == "__main__":
    raise SystemExit(main())
