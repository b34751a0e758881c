"""Table 5.2 (Grid-List efficiency) and Figs. 5.13-5.18 (slice and cell distributions),
section 5.3.3 of Kuijk (1995), on the six test scenes regenerated from their descriptions.

    diffengine bench table52 [--queries 1000] [--sweep-queries 300] [--quick] [--write]

1. Table 5.2: for every scene, query size 10 and 100 and grid m = 10..1000, the query
   scan of sw/hsr (hsr_gridlist_query) at NQ x NQ positions (default 1000 x 1000 =
   1M, as the source: "we scanned the entire image using 1M different positions"),
   in both readings of the source's ratio: total addressed / total overlapping, and
   the mean over positions of addressed / overlapping.
2. The scan checked: every query's count is recounted from sorted copies of the cell
   lists (hsr_bench exits 1 on a difference), the entries the list order forces any
   scan of those cells to visit, and the larger cell range of the source's loops
   started ceil((w_Q + w_max) m / X) cells back.
3. Sweeps (at --sweep-queries positions): the query size on Random (which size
   reproduces which cell of the source), and the generator parameters the source does
   not give: Landscape's largest extent side, Cluster's sigma.
4. Figs. 5.13-5.18: domains per slice (10, 100, 1000 slices), per cell (40 x 40), max
   and mean per cell per row (100 x 100, 1000 x 1000) -> docs/img/hsr_fig51[3-8].png.

Records out/bench/table52.json; --write keeps it in docs/bench, renders the section
"Grid-List efficiency (Table 5.2)" of docs/performance.md and writes the plots
(docs/img/hsr_table52.png, docs/img/hsr_fig513.png .. hsr_fig518.png).
"""
from __future__ import annotations

import json
import math
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from .. import REPO as ROOT
from ..host import yproc as yproc_tool
from . import record, render as doc
from .hsr import kv, run, teapot_scene_dir

HSR = ROOT / "sw" / "hsr"
BENCH = HSR / "build" / "hsr_bench"
IMG = ROOT / "docs" / "img"

SECTION = "## Grid-List efficiency (Table 5.2, Figs. 5.13-5.18)"
WIN = 10000                  # window side (units): 100K extents of mean area 1e4, coverage 10
N_DOM = 100_000
SUBDIV = [10, 15, 30, 60, 100, 150, 300, 600, 1000]
SCENES = ["Random", "Landscape", "Cluster", "Two-size", "Vlsi", "Teapot"]
QSIZES = (10, 100)
# Table 5.2 of the source: {query size: {scene: [ratio per SUBDIV]}}
SOURCE = {
    10: {"Random": [16.6, 10.2, 4.3, 2.4, 1.9, 1.9, 2.3, 5.8, 13.7],
         "Landscape": [25.4, 13.6, 5.4, 3.2, 2.4, 3.1, 4.7, 13.3, 33.2],
         "Cluster": [18.7, 11.5, 4.9, 3.0, 3.1, 4.1, 8.8, 31.7, 83.2],
         "Two-size": [22.7, 12.0, 5.0, 2.8, 2.5, 3.5, 6.3, 18.5, 46.9],
         "Vlsi": [15.2, 8.1, 4.1, 2.5, 3.1, 4.1, 9.4, 30.1, 78.5],
         "Teapot": [43.3, 16.6, 7.0, 3.9, 2.9, 3.7, 4.2, 8.5, 18.2]},
    100: {"Random": [2.7, 2.3, 1.9, 1.8, 1.8, 1.9, 2.8, 6.6, 15.7],
          "Landscape": [11.3, 10.1, 8.7, 8.5, 9.4, 11.4, 22.4, 66.7, 169.1],
          "Cluster": [3.5, 2.6, 2.1, 2.1, 2.4, 3.3, 8.2, 27.4, 72.9],
          "Two-size": [3.2, 2.8, 2.4, 2.4, 2.6, 3.1, 6.2, 18.4, 47.3],
          "Vlsi": [6.1, 5.0, 5.1, 3.3, 4.0, 5.2, 11.9, 38.4, 100.8],
          "Teapot": [7.3, 7.0, 2.7, 2.2, 2.0, 2.2, 4.2, 12.5, 32.1]},
}
TOL = 0.25                   # "within 25 % of the source"
Q_SWEEP = [10, 20, 50, 100, 150, 200, 300, 500, 1000]
LANDSCAPE_SMAX = [150, 200, 300, 400, 750]
CLUSTER_SIGMA = [12, 8, 6, 4, 3]            # sigma = WIN / value
SWEEP_M = [10, 30, 100, 300, 1000]
# the figures' subdivisions
SLICES = (10, 100, 1000)


# ------------------------------------------------------------- scenes (5.3.3)

def _inside(rng, n, draw):
    """n boxes (left, bot, right, top) from `draw(rng, k)` -> (cx, cy, w, h) arrays,
    redrawing those that leave the window: clipping them instead would pile their
    left / bot up on the border (a spike in the first slice of Figs. 5.13-5.15)."""
    out = np.empty((0, 4), np.int64)
    while len(out) < n:
        cx, cy, w, h = draw(rng, 2 * (n - len(out)) + 64)
        e = np.stack([np.rint(cx - w / 2), np.rint(cy - h / 2), np.rint(cx + w / 2), np.rint(cy + h / 2)], 1)
        e = e[(e[:, 0] >= 0) & (e[:, 1] >= 0) & (e[:, 2] <= WIN) & (e[:, 3] <= WIN)].astype(np.int64)
        out = np.concatenate([out, e])
    return out[:n]


def scene_random(rng, n=N_DOM):
    """Homogeneous; extent sides 0.0075-0.0125 x window (75-125), mean area ~1e4,
    coverage 10."""
    return _inside(rng, n, lambda r, k: (r.uniform(0, WIN, k), r.uniform(0, WIN, k),
                                         r.uniform(75, 125, k), r.uniform(75, 125, k)))


def scene_landscape(rng, n=N_DOM, smax=200.0):
    """Ground plane in perspective below a horizon at 2/3 of the height: at
    distance u below the horizon the extent side is k*u (x 0.75-1.25) and the
    density ~1/u^2, so coverage is constant below the horizon (15 there = 10 over
    the whole image).  The description gives no size range: smax is the largest
    side (swept by the benchmark); u_min follows from n and the coverage: with pdf
    ~1/u^2 on [u_min, yh], E[u^2] = u_min yh, so coverage 15 below the horizon needs
    n k^2 u_min / WIN = 15 (smax must exceed ~125 for u_min < yh)."""
    yh = 2 * WIN / 3
    kk = smax / 1.25 / yh
    umin = 15 * WIN / (n * kk * kk)
    if umin >= yh:
        raise ValueError(f"Landscape: smax {smax} too small for coverage 10 with {n} domains")

    def draw(r, k):
        u = 1 / (1 / umin - r.uniform(0, 1, k) * (1 / umin - 1 / yh))   # pdf ~ 1/u^2 on [umin, yh]
        return (r.uniform(0, WIN, k), yh - u, kk * u * r.uniform(0.75, 1.25, k),
                kk * u * r.uniform(0.75, 1.25, k))
    return _inside(rng, n, draw)


def scene_cluster(rng, n=N_DOM, sigma=WIN / 6):
    """Gaussian around the centre (sigma = window/6 by default, not given by the
    source; swept by the benchmark), Random sizes."""
    return _inside(rng, n, lambda r, k: (r.normal(WIN / 2, sigma, k), r.normal(WIN / 2, sigma, k),
                                         r.uniform(75, 125, k), r.uniform(75, 125, k)))


def scene_twosize(rng, n=N_DOM):
    """Homogeneous; sizes 0.5x and 2.5x Random; 1/8 large keeps coverage 10
    (0.875*0.25 + 0.125*6.25 = 1)."""
    def draw(r, k):
        f = np.where(r.uniform(0, 1, k) < 0.125, 2.5, 0.5)
        return r.uniform(0, WIN, k), r.uniform(0, WIN, k), r.uniform(75, 125, k) * f, r.uniform(75, 125, k) * f
    return _inside(rng, n, draw)


def scene_vlsi(rng, n=N_DOM):
    """Centred on the nodes of a 100 x 100 grid: squares of 0.005 x window (50),
    or horizontal / vertical strips 25 wide and 400-600 long; 3/4 strips keeps
    coverage 10 (0.25*2500 + 0.75*12500 = 1e4)."""
    cell = WIN / 100

    def draw(r, k):
        cx = (r.integers(0, 100, k) + 0.5) * cell
        cy = (r.integers(0, 100, k) + 0.5) * cell
        kind = r.uniform(0, 1, k)
        L = r.uniform(400, 600, k)
        w = np.where(kind < 0.25, 50, np.where(kind < 0.625, L, 25))
        h = np.where(kind < 0.25, 50, np.where(kind < 0.625, 25, L))
        return cx, cy, w, h
    return _inside(rng, n, draw)


def scene_teapot(tmp: Path, n=25):
    """Bounding boxes of the projected triangles of the teapot (n = 25: 39800) on a
    10000 x 10000 screen (side view, y up)."""
    sc = teapot_scene_dir(tmp, n, WIN, WIN, fov=40.0)   # square screen: wider fov
    out = tmp / "teapot_input.json"
    run([yproc_tool.build(), "hsr", sc, "--dump-input", out])
    boxes = []
    for p in json.loads(out.read_text())["polygons"]:
        pts = np.concatenate([np.asarray(r, float) for r in p["rings"] if r]) if p["rings"] else None
        if pts is None or len(pts) == 0:
            continue
        lo, hi = pts.min(0), pts.max(0)
        boxes.append((math.floor(lo[0]), math.floor(WIN - hi[1]), math.ceil(hi[0]), math.ceil(WIN - lo[1])))
    return np.asarray(boxes, np.int64)


GENERATORS = {"Random": scene_random, "Landscape": scene_landscape, "Cluster": scene_cluster,
              "Two-size": scene_twosize, "Vlsi": scene_vlsi}


def scenes(seed: int, tmp: Path | None = None, teapot_n: int = 25) -> dict:
    """The six scenes (Teapot only with tmp), generated in the order of SCENES from
    one generator seeded with `seed` (so each scene is the same in every run)."""
    rng = np.random.default_rng(seed)
    out = {}
    for name in SCENES:
        if name == "Teapot":
            if tmp is not None:
                out[name] = scene_teapot(tmp, teapot_n)
        else:
            out[name] = GENERATORS[name](rng)
    return out


def scene_info(name: str, e: np.ndarray) -> dict:
    area = ((e[:, 2] - e[:, 0]) * (e[:, 3] - e[:, 1])).astype(float)
    occupied = WIN * WIN
    if name == "Teapot":     # coverage over the teapot's part of the image
        occupied = (e[:, 2].max() - e[:, 0].min()) * (e[:, 3].max() - e[:, 1].min())
    return dict(n=len(e), mean_area=float(area.mean()), coverage=float(area.sum() / occupied),
                wmax=int((e[:, 2] - e[:, 0]).max()), hmax=int((e[:, 3] - e[:, 1]).max()))


# ------------------------------------------------------------- distributions (Figs 5.13-5.18)

def slice_counts(e: np.ndarray, m: int) -> np.ndarray:
    """Domains per horizontal slice (the slice holding domain.bot, section 5.3.1),
    slices ceil(WIN/m) high as in gridlist.c, bottom slice first."""
    h = -(-WIN // m)
    return np.bincount(np.clip(e[:, 1] // h, 0, m - 1), minlength=m)


def cell_counts(e: np.ndarray, m: int) -> np.ndarray:
    """Domains per cell (the cell holding (left, bot), section 5.3.2), [row, column]."""
    c = -(-WIN // m)
    r, k = np.clip(e[:, 1] // c, 0, m - 1), np.clip(e[:, 0] // c, 0, m - 1)
    return np.bincount(r * m + k, minlength=m * m).reshape(m, m)


def distributions(e: np.ndarray) -> dict:
    """What Figs. 5.13-5.18 plot, for one scene."""
    d = {f"slices{m}": slice_counts(e, m).tolist() for m in SLICES}
    d["cells40"] = cell_counts(e, 40).tolist()
    c100 = cell_counts(e, 100)
    d["rowmax100"], d["rowmean100"] = c100.max(1).tolist(), c100.mean(1).tolist()
    d["rowmax1000"] = cell_counts(e, 1000).max(1).tolist()
    return d


def homogeneity(counts, n: int) -> float:
    """max count x number of bins / number of domains: 1 for a perfectly even
    distribution; "the maximum is inversely proportional to the number of bins"
    keeps it the same from one subdivision to the next."""
    c = np.asarray(counts)
    return float(c.max() * c.size / n)


# ------------------------------------------------------------- the query scan

def grid_run(ext_file: Path, q: int, nq: int, subdiv) -> list[dict]:
    """hsr_bench grid: one row per subdivision with the counts and both ratio readings."""
    rows = []
    for line in run([BENCH, "grid", ext_file, WIN, q, nq] + list(subdiv)).splitlines():
        d = kv(line)
        o = max(1, int(d["overlaps"]))
        ent, emp = int(d["entries"]), int(d["empty_cells"])
        rows.append(dict(m=int(d["grid"]), ratio=(ent + emp) / o, mean_ratio=float(d["mean_ratio"]),
                         entries_ratio=ent / o, passed_ratio=int(d["passed"]) / o,
                         cells_ratio=(ent + int(d["cells"])) / o,
                         seed_ratio=(int(d["seed_entries"]) + int(d["seed_empty"])) / o,
                         seed_mean_ratio=float(d["seed_mean_ratio"]),
                         overlaps=int(d["overlaps"]) / int(d["queries"]), seconds=float(d["seconds"])))
    return rows


def table52(args, tmp: Path, sc: dict) -> dict:
    res = {q: {} for q in QSIZES}
    for name in SCENES:
        t0 = time.perf_counter()
        f = tmp / f"ext_{name}.txt"
        np.savetxt(f, sc[name], fmt="%d")
        for q in QSIZES:
            res[q][name] = grid_run(f, q, args.queries, SUBDIV)
        print(f"  {name:9s} {len(sc[name]):6d} extents ({time.perf_counter() - t0:.0f} s)", flush=True)
    return res


def sweeps(args, tmp: Path, sc: dict) -> dict:
    """Query size on Random; Landscape's largest side; Cluster's sigma."""
    out = {"qsize": {}, "landscape": {}, "cluster": {}}
    f = tmp / "ext_Random.txt"
    np.savetxt(f, sc["Random"], fmt="%d")
    for q in Q_SWEEP:
        out["qsize"][q] = grid_run(f, q, args.sweep_queries, SUBDIV)
    print("  query size on Random: " + " ".join(map(str, Q_SWEEP)), flush=True)
    for key, values, make in (
            ("landscape", LANDSCAPE_SMAX, lambda v, rng: scene_landscape(rng, smax=float(v))),
            ("cluster", CLUSTER_SIGMA, lambda v, rng: scene_cluster(rng, sigma=WIN / v))):
        for v in values:
            f = tmp / f"ext_{key}_{v}.txt"
            e = make(v, np.random.default_rng(args.seed + 1))
            np.savetxt(f, e, fmt="%d")
            out[key][v] = {"info": scene_info(key, e),
                           **{q: grid_run(f, q, args.sweep_queries, SWEEP_M) for q in QSIZES}}
        print(f"  {key}: " + " ".join(map(str, values)), flush=True)
    return out


# ------------------------------------------------------------- text

def within(x: float, src: float) -> bool:
    return abs(x / src - 1) <= TOL


def _cell(x, src):
    return f"{x:.1f} ({src})" + ("" if within(x, src) else " *")


def table_text(res, key: str, title: str) -> list[str]:
    hdr = "| m | " + " | ".join(SCENES) + " |"
    sep = "|---|" + "---|" * len(SCENES)
    lines = []
    for q in QSIZES:
        lines += [f"{title}, query size {q}; each cell: measured (source), * = more than 25 % off.", "",
                  hdr, sep]
        for i, m in enumerate(SUBDIV):
            lines.append(f"| {m} | " + " | ".join(_cell(res[q][s][i][key], SOURCE[q][s][i]) for s in SCENES) + " |")
        n_in = [sum(within(res[q][s][i][key], SOURCE[q][s][i]) for i in range(len(SUBDIV))) for s in SCENES]
        lines.append("| within 25 % | " + " | ".join(f"{k} / {len(SUBDIV)}" for k in n_in) + " |")
        lines.append("")
    return lines


def scan_text(res) -> list[str]:
    lines = ["| m | query | ours: addressed | of which entries | entries the order forces (lower bound) "
             "| source's loop range (ceil((w_Q+w_max) m/X) + 1 cells a side) | Table 5.2 |",
             "|---|---|---|---|---|---|---|"]
    for q in QSIZES:
        for i, m in enumerate(SUBDIV):
            r = res[q]["Random"][i]
            lines.append(f"| {m} | {q} | {r['ratio']:.1f} | {r['entries_ratio']:.1f} | {r['passed_ratio']:.1f} "
                         f"| {r['seed_ratio']:.1f} | {SOURCE[q]['Random'][i]} |")
    return lines


def best_q(rows_by_q: dict, i: int, src: float) -> str:
    """The swept query size whose ratio is nearest the source's (log distance)."""
    qs = sorted(rows_by_q, key=int)
    q = min(qs, key=lambda k: abs(math.log(rows_by_q[k][i]["ratio"] / src)))
    return f"{q} ({rows_by_q[q][i]['ratio']:.1f})"


def qsweep_text(sw, nq) -> list[str]:
    qs = sorted(sw["qsize"], key=int)
    lines = [f"Random, query sizes swept ({nq} x {nq} positions), ratio of totals:", "",
             "| m | " + " | ".join(f"q {q}" for q in qs) + " | source 10 | nearest q | source 100 | nearest q |",
             "|---|" + "---|" * (len(qs) + 4)]
    for i, m in enumerate(SUBDIV):
        lines.append(f"| {m} | " + " | ".join(f"{sw['qsize'][q][i]['ratio']:.1f}" for q in qs)
                     + f" | {SOURCE[10]['Random'][i]} | {best_q(sw['qsize'], i, SOURCE[10]['Random'][i])}"
                     + f" | {SOURCE[100]['Random'][i]} | {best_q(sw['qsize'], i, SOURCE[100]['Random'][i])} |")
    return lines


def param_sweep_text(sw, key: str, scene: str, label) -> list[str]:
    vals = sorted(sw[key], key=float)
    idx = [SUBDIV.index(m) for m in SWEEP_M]
    lines = ["| " + label("") + " | largest extent | " + " | ".join(f"m {m}: q 10 / q 100" for m in SWEEP_M) + " |",
             "|---|---|" + "---|" * len(SWEEP_M)]
    for v in vals:
        d = sw[key][v]
        cells = []
        for j, m in enumerate(SWEEP_M):
            a, b = d["10"][j] if "10" in d else d[10][j], d["100"][j] if "100" in d else d[100][j]
            cells.append(f"{a['ratio']:.1f} / {b['ratio']:.1f} (mean {a['mean_ratio']:.1f} / {b['mean_ratio']:.1f})")
        lines.append(f"| {label(v)} | {d['info']['wmax']}x{d['info']['hmax']} | " + " | ".join(cells) + " |")
    lines.append("| source | | " + " | ".join(f"{SOURCE[10][scene][i]} / {SOURCE[100][scene][i]}" for i in idx) + " |")
    return lines


def dist_text(dist: dict) -> list[str]:
    """The seed's observations as numbers: max x bins / N per subdivision."""
    lines = ["| scene | 10 slices | 100 slices | 1000 slices | 40x40 cells | 100x100 cells | 1000x1000 cells |",
             "|---|---|---|---|---|---|---|"]
    for s in SCENES:
        if s not in dist:
            continue
        d = dist[s]
        n = sum(d["slices10"])
        h = [homogeneity(d[f"slices{m}"], n) for m in SLICES]
        c40 = homogeneity(d["cells40"], n)
        c100 = max(d["rowmax100"]) * 100 * 100 / n
        c1000 = max(d["rowmax1000"]) * 1000 * 1000 / n
        lines.append(f"| {s} | " + " | ".join(f"{x:.2f}" for x in h + [c40, c100, c1000]) + " |")
    return lines


# ------------------------------------------------------------- plots

def plots(res, dist):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    IMG.mkdir(parents=True, exist_ok=True)
    if res:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
        for ax, q in zip(axes, QSIZES):
            for i, s in enumerate(SCENES):
                c = f"C{i}"
                ax.plot(SUBDIV, [r["ratio"] for r in res[q][s]], "-o", color=c, ms=3, label=s)
                ax.plot(SUBDIV, SOURCE[q][s], "--", color=c, lw=0.8)
            ax.set_xscale("log"); ax.set_yscale("log")
            ax.set_xlabel("grid subdivision m (m x m cells)")
            ax.set_title(f"query extent size {q}")
            ax.grid(True, which="both", lw=0.3)
        axes[0].set_ylabel("domains addressed / overlapping extent")
        axes[0].legend(fontsize=8, title="solid: measured, dashed: Table 5.2", title_fontsize=8)
        fig.tight_layout()
        fig.savefig(IMG / "hsr_table52.png", dpi=110)
        plt.close(fig)
    if dist:
        dist_plots(plt, dist)


def _six(plt, title):
    fig, axes = plt.subplots(2, 3, figsize=(11, 6))
    fig.suptitle(title, fontsize=10)
    return fig, [a for row in axes for a in row]


def dist_plots(plt, dist):
    names = [s for s in SCENES if s in dist]
    for fig_no, m in zip((13, 14, 15), SLICES):
        fig, axes = _six(plt, f"Fig. 5.{fig_no} regenerated: domains per slice, {m} horizontal slices "
                              "(slice of domain.bot; y up, bottom slice left)")
        for ax, s in zip(axes, names):
            c = dist[s][f"slices{m}"]
            ax.bar(np.arange(m), c, width=1.0, color="C0", lw=0)
            ax.set_title(f"{s} ({sum(c)} domains)", fontsize=9)
            ax.set_xlabel("slice", fontsize=8); ax.tick_params(labelsize=7)
        fig.tight_layout()
        fig.savefig(IMG / f"hsr_fig5{fig_no}.png", dpi=100)
        plt.close(fig)
    fig, axes = _six(plt, "Fig. 5.16 regenerated: domains per cell, 40 x 40 cells (cell of (left, bot))")
    for ax, s in zip(axes, names):
        c = np.asarray(dist[s]["cells40"])
        im = ax.imshow(c, origin="lower", cmap="viridis")
        ax.set_title(f"{s} (max {c.max()})", fontsize=9); ax.tick_params(labelsize=7)
        fig.colorbar(im, ax=ax, fraction=0.046)
    fig.tight_layout()
    fig.savefig(IMG / "hsr_fig516.png", dpi=100)
    plt.close(fig)
    for fig_no, key, m in ((17, "100", 100), (18, "1000", 1000)):
        fig, axes = _six(plt, f"Fig. 5.{fig_no} regenerated: per row of cells, the maximum"
                              f"{' (and mean)' if m == 100 else ''} domains per cell, {m} x {m} cells")
        for ax, s in zip(axes, names):
            ax.plot(np.arange(m), dist[s][f"rowmax{key}"], color="C0", lw=0.8, label="max")
            if m == 100:
                ax.plot(np.arange(m), dist[s]["rowmean100"], color="C1", lw=0.8, label="mean")
                ax.legend(fontsize=7)
            ax.set_title(s, fontsize=9); ax.set_xlabel("row of cells", fontsize=8); ax.tick_params(labelsize=7)
        fig.tight_layout()
        fig.savefig(IMG / f"hsr_fig5{fig_no}.png", dpi=100)
        plt.close(fig)


# ------------------------------------------------------------- command

def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    record.add_write(ap, "docs/performance.md, docs/img/hsr_*.png")
    ap.add_argument("--quick", action="store_true", help="100 x 100 positions, no sweeps (a smoke run)")
    ap.add_argument("--queries", type=int, default=1000,
                    help="query positions per axis for Table 5.2 (default 1000: 1M, as the source)")
    ap.add_argument("--sweep-queries", type=int, default=300, help="query positions per axis in the sweeps")
    ap.add_argument("--teapot-n", type=int, default=25, help="teapot tessellation (25: 39800 triangles)")
    ap.add_argument("--seed", type=int, default=1995)
    ap.add_argument("--skip", nargs="*", default=[], choices=["table", "sweep", "dist"])
    ap.set_defaults(func=command)


def command(args) -> int:
    rn = record.Run("table52")
    if args.quick:
        args.queries = min(args.queries, 100)
        args.skip = sorted(set(args.skip) | {"sweep"})
    r = subprocess.run(["make", "-C", str(HSR), "build/hsr_bench"], capture_output=True, text=True)
    if r.returncode:
        raise SystemExit(r.stdout + r.stderr)
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_t52_") as td:
        tmp = Path(td)
        sc = scenes(args.seed, tmp, args.teapot_n)
        info = {s: scene_info(s, e) for s, e in sc.items()}
        res = sw = dist = None
        if "dist" not in args.skip:
            dist = {s: distributions(e) for s, e in sc.items()}
        if "table" not in args.skip:
            print(f"Table 5.2: Grid-List efficiency, {args.queries} x {args.queries} query positions")
            res = table52(args, tmp, sc)
        if "sweep" not in args.skip:
            print("Sweeps")
            sw = sweeps(args, tmp, sc)
    data = {"quick": args.quick, "seed": args.seed, "queries": args.queries,
            "sweep_queries": args.sweep_queries, "teapot_n": args.teapot_n,
            "seconds": time.perf_counter() - t_start, "table52": res, "info": info,
            "sweeps": sw, "dist": dist}
    rec = rn.save(data, args.write and not args.skip and not args.quick)
    text = render(rec)
    print()
    print(text)
    if args.write:
        plots(_res(rec["data"]), rec["data"]["dist"])
        if args.skip or args.quick:
            print("--skip / --quick: plots written, the record not kept; docs/performance.md unchanged")
        else:
            return doc.write(["table52"])
    return 0


def _res(d: dict):
    return {int(q): v for q, v in d["table52"].items()} if d.get("table52") else None


def render(rec: dict) -> str:
    """The "Grid-List efficiency" section of docs/performance.md."""
    d = rec["data"]
    res, sw, info, dist = _res(d), d.get("sweeps"), d["info"], d.get("dist")
    nq = d["queries"]
    parts = [SECTION, "",
             f"`{rec['command']}` ({rec['date']} UTC, revision {rec['revision']}, took {d['seconds']:.0f} s, "
             f"1-min load {rec['load_before']} before, {rec['load_after']} after; counts, not times, so the "
             f"load does not matter). The C tool is `sw/hsr/build/hsr_bench grid` "
             f"(`sw/hsr/tools/hsr_bench.c`) around the real query `hsr_gridlist_query` of "
             f"`sw/hsr/src/gridlist.c`. Plots: `docs/img/hsr_table52.png`, `docs/img/hsr_fig513.png` .. "
             f"`hsr_fig518.png` (shown beside the source's descriptions in docs/hsr.md).", "",
             "Scenes regenerated from the descriptions of section 5.3.3 (the data sets are not published), "
             f"seed {d['seed']}: 100K extents in a 10000 x 10000 window (the source: 100K domains of mean area "
             "1e4, coverage 10; Random: sides 75-125; Landscape: ground plane in perspective, horizon at 2/3 "
             "height, size proportional to the distance below it, density to its inverse square, largest side "
             "200 (chosen so that Figs. 5.13-5.15 hold: see the sweep below); Cluster: Gaussian, sigma = window/6; Two-size: 1/8 at 2.5x and 7/8 at 0.5x the Random size; "
             "Vlsi: on the nodes of a 100 x 100 grid, 50 x 50 squares and 25-wide strips 400-600 long; Teapot: "
             f"bounding boxes of the projected triangles of the Utah teapot, n = {d['teapot_n']}, side view). "
             + "; ".join(f"{s}: {info[s]['n']} extents, coverage {info[s]['coverage']:.1f}, largest "
                         f"{info[s]['wmax']}x{info[s]['hmax']}" for s in SCENES if s in info) + ".", ""]
    if res:
        parts += [f"Queries: square extents of side 10 and 100 centred on a regular {nq} x {nq} grid of "
                  f"positions over the whole window ({nq * nq:,} positions; the source: \"we scanned the "
                  "entire image using 1M different positions\"). *Addressed* = Grid-List entries visited "
                  "(including the entry that ends a list) + empty cells addressed (footnote 10: memory "
                  "accesses). Two readings of the source's ratio: total addressed / total overlapping "
                  "extents, and the mean over positions (with at least one overlap) of addressed / "
                  "overlapping.", ""]
        parts += table_text(res, "ratio", "Reading 1, total addressed / total overlapping")
        parts += table_text(res, "mean_ratio", "Reading 2, mean over positions of addressed / overlapping")
        parts += ["**Does our scan go further than the source's?** No. Every query's count was recounted "
                  "from independent sorted copies of the cell lists (`hsr_bench grid` exits 1 on any "
                  "difference: none). Random, reading 1: *entries the order forces* are the entries with "
                  "right+top >= Q.left+Q.bot in the cells visited, which any scan of those cell lists must "
                  "pass (ours adds at most the one entry per cell that stops the list); the cells visited are "
                  "columns col(Q.left - w_max) .. col(Q.right), the fewest that find every overlap. The "
                  "source's loops, started ceil((w_Q + w_max) m / X) cells before the cell of Q.right "
                  "(section 5.3.1, 5.3.2), visit a superset, and count more:", ""]
        parts += scan_text(res)
        r10, r100 = res[10]["Random"][0], res[100]["Random"][0]
        parts += ["", f"At m = 10 a cell holds ~1000 extents; sorted on decreasing right+top, the list of the "
                  "query's own cell puts every extent above or right of the query (in that cell) before the "
                  "ones that can overlap. Per query, Random, m = 10: the lists force "
                  f"{r10['passed_ratio'] * r10['overlaps']:.0f} entries (query 10) and "
                  f"{r100['passed_ratio'] * r100['overlaps']:.0f} (query 100) for {r10['overlaps']:.1f} and "
                  f"{r100['overlaps']:.1f} overlaps; the source's ratios, {SOURCE[10]['Random'][0]} and "
                  f"{SOURCE[100]['Random'][0]}, mean {SOURCE[10]['Random'][0] * r10['overlaps']:.0f} and "
                  f"{SOURCE[100]['Random'][0] * r100['overlaps']:.0f} addressed for the same overlaps: fewer "
                  "than the lists force any correct scan of those cells to pass, and fewer for the larger "
                  "query, which no walk of sorted lists does. So no change of the scan reproduces the "
                  "source's coarse grids: the difference is in the query (its size or units), the scene or "
                  "what was counted, not in how far the lists are walked, and the real `hsr_gridlist_query` "
                  "is left as it is. (A note on expression 5.3, which the source says its results are "
                  "\"conform\": its second term (round-off), i/m - Q.right/X a fraction of the window times N/m^2 "
                  "extents per cell, is m times smaller than the round-off it describes, a strip i/m - "
                  "Q.right/X of the window wide and one cell high, which holds N (i/m - Q.right/X) / m extents.)",
                  ""]
    if sw:
        parts += qsweep_text(sw, d["sweep_queries"])
        parts += ["", "No single query size reproduces a whole column of the source: the query-10 column is "
                  "met by sides ~100-200 at coarse grids and ~10-100 at fine ones, the query-100 column by "
                  "~1000 at coarse grids but by nothing at fine grids (at m = 1000 our ratio falls from "
                  "~17 towards ~10.5 as the query grows, ((w_max+q)/10)^2 cells against (w+q)^2/1000 "
                  "overlaps; the source's 15.7 for query 100 is above its 13.7 for query 10). A query of "
                  "0.01 x the window (100, the size the source gives for Figs. 5.19-5.25) matches its "
                  "query-10 column from m = 150 up. At m = 1000 the 1M centred positions put every "
                  "query-10 extent exactly on the 10-unit cells (Q.right on a cell border: one more column "
                  "and row than at a random position): Random reads 18.2 there against 16.6 at 300 x 300 "
                  "positions.", "",
                  f"Landscape, largest extent side swept (same generator, {d['sweep_queries']} x "
                  f"{d['sweep_queries']} positions; reading 1 (reading 2 in brackets), query 10 / query 100):",
                  ""]
        parts += param_sweep_text(sw, "landscape", "Landscape", lambda v: "largest side" if v == "" else str(v))
        parts += ["", f"Cluster, sigma swept (window / value):", ""]
        parts += param_sweep_text(sw, "cluster", "Cluster", lambda v: "sigma = W /" if v == "" else str(v))
        parts += [""]
    if res and sw:
        parts += ["**Per scene** (1M positions). Random (fully described): query 100 within 25 % from "
                  "m = 150 up (reading 2: all four cells; reading 1: three, m = 300 at -25.x %); query 10 "
                  "1.1-1.7x above there; at m <= 100 both sizes 1.3-8x above, which the lower bound above "
                  "shows no scan of these lists can close. Two-size and Vlsi (fully described up to the "
                  "shares that coverage 10 fixes): the same at coarse grids; from m = 150 up query 100 is "
                  "within 25 %, query 10 is 1.5-2x (Two-size) and ~3x (Vlsi) above: Vlsi's 600-long strips "
                  "make every query visit ~62 x 62 cells at m = 1000, whatever the data near it. Cluster: "
                  "reading 1 cannot tell it from Random (the totals weight every position equally and the "
                  "mean density is the same), reading 2 (the mean over positions) comes within ~30 % of the "
                  "source at m = 300-1000 (the source: 3-10x Random there), so the source's ratio is most "
                  "likely the mean over positions. Landscape: reading 1, query 10, within 25 % from m = 300 "
                  "up with the largest side 200 (the side that also makes Figs. 5.13-5.15 hold); the "
                  "source's query-100 column (above its query 10 at every m >= 30, 169 at m = 1000) is met "
                  "by no largest side in the sweep: larger sides raise both sizes together. Teapot: reading "
                  "2, query 100, within 25 % from m = 300 up; its coverage over its own part of the image is "
                  "3.3, not the source's ~10 (bounding boxes of 39,800 triangles over the teapot's region: "
                  "independent of its size on the screen), so it is not the source's teapot model.", ""]
    if dist:
        parts += ["Figs. 5.13-5.18 in numbers: the largest count per slice or cell times the number of slices "
                  "or cells, over the number of domains (1 = perfectly even; the same value at every "
                  "subdivision = \"the maximum is inversely proportional to the number of slices\"); "
                  "`sw/tests/test_table52_scenes.py` checks the source's observations on these scenes.", ""]
        parts += dist_text(dist)
        parts += [""]
    return "\n".join(parts)
