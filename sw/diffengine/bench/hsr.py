"""Benchmarks of the host C hidden-surface removal (sw/hsr), chapter 5 of Kuijk (1995).

    make bench-hsr                      # = diffengine bench hsr --write
    diffengine bench hsr [--quick] [--queries 300] [--write]

1. Table 5.2: the six test scenes of section 5.3.3 regenerated from their
   descriptions (100K extents in a 10000 x 10000 window; Teapot: the ~40K
   projected triangles of the Utah teapot), NQ x NQ query positions over the
   window, Grid-List 10..1000 cells a side; ratio of domains addressed
   (list entries visited + empty cells addressed, footnote 10) per overlapping
   extent, printed beside the source's figures.
2. Fig. 5.30: HSR time against triangle count for tri-steps, tri-spets (both
   insertion orders) and the teapot; power-law exponents fitted.
3. Teapot speed: microseconds per input triangle and per visible domain.
4. Incremental move of one small object (a 12-triangle box in front of the
   teapot) against a full rebuild, same run, with an equality check.

Records out/bench/hsr.json (bench.record); --write keeps it in docs/bench, renders the
section "Hidden-surface removal (host C)" of docs/performance.md and writes
docs/img/hsr_table52.png, docs/img/hsr_fig530.png.
Scene generation is seeded (--seed, default 1995).
"""
from __future__ import annotations

import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .. import REPO as ROOT
from ..host import yproc as yproc_tool
from . import record, render as doc

HSR = ROOT / "sw" / "hsr"
BENCH = HSR / "build" / "hsr_bench"
YPROC = yproc_tool.YPROC
sys.path.insert(0, str(ROOT / "sw" / "scenes" / "teapot"))
import make_teapot  # noqa: E402

SECTION = "## Hidden-surface removal (host C)"
WIN = 10000                  # window side (units) of the Table 5.2 scenes
N_DOM = 100_000
SUBDIV = [10, 15, 30, 60, 100, 150, 300, 600, 1000]
SCENES = ["Random", "Landscape", "Cluster", "Two-size", "Vlsi", "Teapot"]
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


def run(cmd, **kw):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, cmd))} failed:\n{r.stdout}{r.stderr}")
    return r.stdout


def kv(line: str) -> dict:
    t = line.split()
    return {t[i]: t[i + 1] for i in range(0, len(t) - 1, 2)}


# ------------------------------------------------------------- scenes (5.3.3)

def _clip(l, b, r, t):
    l, b = np.clip(l, 0, WIN), np.clip(b, 0, WIN)
    r, t = np.clip(r, 0, WIN), np.clip(t, 0, WIN)
    return np.stack([l, b, np.maximum(r, l), np.maximum(t, b)], 1).astype(np.int64)


def _boxes(cx, cy, w, h):
    return _clip(np.rint(cx - w / 2), np.rint(cy - h / 2), np.rint(cx + w / 2), np.rint(cy + h / 2))


def scene_random(rng, n=N_DOM):
    """Homogeneous; extent sides 0.0075-0.0125 x window (75-125), mean area ~1e4,
    coverage 10."""
    w, h = rng.uniform(75, 125, n), rng.uniform(75, 125, n)
    return _boxes(rng.uniform(0, WIN, n), rng.uniform(0, WIN, n), w, h)


def scene_landscape(rng, n=N_DOM, smax=750.0):
    """Ground plane in perspective below a horizon at 2/3 of the height: at
    distance u below the horizon the extent side is k*u (x 0.75-1.25) and the
    density ~1/u^2, so coverage is constant below the horizon (15 there = 10 over
    the whole image).  The description gives no size range: the largest side is
    set to smax = 750 (0.075 x window), which is what the source's ratio at
    1000 x 1000 cells (dominated by w_max, h_max) implies; u_min follows from n."""
    yh = 2 * WIN / 3
    k = smax / 1.25 / yh
    umin = 1 / (n * k * k / (15 * WIN) + 1 / yh)
    r = rng.uniform(0, 1, n)
    u = 1 / (1 / umin - r * (1 / umin - 1 / yh))           # pdf ~ 1/u^2 on [umin, yh]
    s = k * u * rng.uniform(0.75, 1.25, n)
    s2 = k * u * rng.uniform(0.75, 1.25, n)
    return _boxes(rng.uniform(0, WIN, n), yh - u, s, s2)


def scene_cluster(rng, n=N_DOM):
    """Gaussian around the centre (sigma = window/6, redrawn outside), Random sizes."""
    c = rng.normal(WIN / 2, WIN / 6, (3 * n, 2))
    c = c[((c >= 0) & (c < WIN)).all(1)][:n]
    w, h = rng.uniform(75, 125, n), rng.uniform(75, 125, n)
    return _boxes(c[:, 0], c[:, 1], w, h)


def scene_twosize(rng, n=N_DOM):
    """Homogeneous; sizes 0.5x and 2.5x Random; 1/8 large keeps coverage 10
    (0.875*0.25 + 0.125*6.25 = 1)."""
    big = rng.uniform(0, 1, n) < 0.125
    f = np.where(big, 2.5, 0.5)
    w, h = rng.uniform(75, 125, n) * f, rng.uniform(75, 125, n) * f
    return _boxes(rng.uniform(0, WIN, n), rng.uniform(0, WIN, n), w, h)


def scene_vlsi(rng, n=N_DOM):
    """Centred on the nodes of a 100 x 100 grid: squares of 0.005 x window (50),
    or horizontal / vertical strips 25 wide and 400-600 long; 3/4 strips keeps
    coverage 10 (0.25*2500 + 0.75*12500 = 1e4)."""
    cell = WIN / 100
    cx = (rng.integers(0, 100, n) + 0.5) * cell
    cy = (rng.integers(0, 100, n) + 0.5) * cell
    kind = rng.uniform(0, 1, n)
    L = rng.uniform(400, 600, n)
    w = np.where(kind < 0.25, 50, np.where(kind < 0.625, L, 25))
    h = np.where(kind < 0.25, 50, np.where(kind < 0.625, 25, L))
    return _boxes(cx, cy, w, h)


def teapot_scene_dir(tmp: Path, n: int, width=640, height=480, extra_obj=None, fov=30.0):
    d = tmp / f"teapot{n}_{width}x{height}"
    d.mkdir(parents=True, exist_ok=True)
    if not (d / "teapot.obj").exists():
        make_teapot.write_obj(d / "teapot.obj", n)
    extra = ""
    if extra_obj:
        src = Path(extra_obj)
        (d / src.name).write_text(src.read_text())
        extra = f"obj {src.name} material box\n"
    mat = "material box 0.2 0.4 0.9\n" if extra_obj else ""
    (d / "teapot.scene").write_text(make_teapot.scene_text("teapot.obj", width, height, fov, 32, mat + extra))
    return d / "teapot.scene"


def scene_teapot(tmp: Path, n=25):
    """Projected triangles of the teapot (n = 25: 39800) on a 10000 x 10000 screen."""
    sc = teapot_scene_dir(tmp, n, WIN, WIN, fov=40.0)   # square screen: wider fov
    out = tmp / "teapot_input.json"
    run([YPROC, "hsr", sc, "--dump-input", out])
    boxes = []
    for p in json.loads(out.read_text())["polygons"]:
        pts = np.concatenate([np.asarray(r, float) for r in p["rings"] if r]) if p["rings"] else None
        if pts is None or len(pts) == 0:
            continue
        lo, hi = pts.min(0), pts.max(0)
        boxes.append((math.floor(lo[0]), math.floor(WIN - hi[1]), math.ceil(hi[0]), math.ceil(WIN - lo[1])))
    return np.asarray(boxes, np.int64)


# ------------------------------------------------------------- Table 5.2

def table52(args, tmp: Path):
    rng = np.random.default_rng(args.seed)
    gens = {"Random": scene_random, "Landscape": scene_landscape, "Cluster": scene_cluster,
            "Two-size": scene_twosize, "Vlsi": scene_vlsi}
    res = {10: {}, 100: {}}
    info = {}
    for name in SCENES:
        t0 = time.perf_counter()
        e = scene_teapot(tmp, args.teapot_n) if name == "Teapot" else gens[name](rng)
        f = tmp / f"ext_{name}.txt"
        np.savetxt(f, e, fmt="%d")
        area = ((e[:, 2] - e[:, 0]) * (e[:, 3] - e[:, 1])).astype(float)
        occupied = WIN * WIN
        if name == "Teapot":     # coverage over the teapot's part of the image
            occupied = (e[:, 2].max() - e[:, 0].min()) * (e[:, 3].max() - e[:, 1].min())
        info[name] = dict(n=len(e), mean_area=area.mean(), coverage=area.sum() / occupied,
                          wmax=int((e[:, 2] - e[:, 0]).max()), hmax=int((e[:, 3] - e[:, 1]).max()))
        for q in (10, 100):
            out = run([BENCH, "grid", f, WIN, q, args.queries] + SUBDIV)
            res[q][name] = []
            for line in out.splitlines():
                d = kv(line)
                addressed = int(d["entries"]) + int(d["empty_cells"])
                res[q][name].append(dict(m=int(d["grid"]), ratio=addressed / max(1, int(d["overlaps"])),
                                         entries_ratio=int(d["entries"]) / max(1, int(d["overlaps"])),
                                         mean_ratio=float(d["mean_ratio"]),
                                         overlaps=int(d["overlaps"]) / int(d["queries"])))
        print(f"  {name:9s} {len(e):6d} extents, coverage {info[name]['coverage']:.1f}, "
              f"w_max {info[name]['wmax']} h_max {info[name]['hmax']} ({time.perf_counter() - t0:.1f} s)",
              flush=True)
    return res, info


def table52_text(res, info, queries):
    lines = []
    hdr = "| subdivision | " + " | ".join(SCENES) + " |"
    sep = "|---|" + "---|" * len(SCENES)
    for q in (10, 100):
        lines += [f"Query extent size {q} ({queries}x{queries} positions); each cell: measured (source).", "",
                  hdr, sep]
        for i, m in enumerate(SUBDIV):
            cells = [f"{res[q][s][i]['ratio']:.1f} ({SOURCE[q][s][i]})" for s in SCENES]
            lines.append(f"| {m} | " + " | ".join(cells) + " |")
        best = [min(res[q][s], key=lambda r: r["ratio"]) for s in SCENES]
        lines.append("| best (at m) | " + " | ".join(f"{b['ratio']:.1f} ({b['m']})" for b in best) + " |")
        lines.append("")
    lines += ["Alternative reading of the source's ratio: mean over query positions (with at least one "
              "overlap) of addressed / overlapping, query size 10 / 100; each cell: measured (source).", "",
              hdr, sep]
    for i, m in enumerate(SUBDIV):
        cells = [f"{res[10][s][i]['mean_ratio']:.1f} / {res[100][s][i]['mean_ratio']:.1f} "
                 f"({SOURCE[10][s][i]} / {SOURCE[100][s][i]})" for s in SCENES]
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    lines.append("")
    lines.append("Scenes as generated: " + "; ".join(
        f"{s} {info[s]['n']} extents, coverage {info[s]['coverage']:.1f}, largest {info[s]['wmax']}x{info[s]['hmax']}"
        for s in SCENES) + ".")
    return "\n".join(lines)


# ------------------------------------------------------------- Fig 5.30

def fit_exponent(xs, ys):
    xs, ys = np.log(np.asarray(xs, float)), np.log(np.asarray(ys, float))
    return float(np.polyfit(xs, ys, 1)[0])


def fig530(args, tmp: Path):
    out = {}
    steps = [25, 50, 100, 200, 400] + ([] if args.quick else [800])
    # tri-spets is linear both ways (in-place hidden parents, stamp marks, a wholly
    # covered LLR domain's slot taken over by the new front domain), so it can go further.
    spets = [100, 200, 400, 800, 1600] + ([] if args.quick else [3200, 6400, 12800])
    for name, sizes, order in (("tri-steps", steps, ""), ("tri-steps reversed", steps[:-1], "reverse"),
                               ("tri-spets", spets, ""), ("tri-spets reversed", spets, "reverse")):
        kind = "steps" if "steps" in name else "spets"
        pts = []
        for n in sizes:
            rep = 5 if kind == "spets" else (3 if n <= 200 else 1)   # spets: 12800 take ~0.05 s
            d = kv(run([BENCH, "stack", kind, n, rep] + ([order] if order else [])))
            pts.append((n, int(d["visible"]), float(d["seconds"])))
        out[name] = pts
        print(f"  {name:19s} " + "  ".join(f"{n}:{s:.3g}s" for n, _, s in pts), flush=True)
    tp = []
    for n in ([2, 3, 4, 6, 8, 12] + ([] if args.quick else [16, args.teapot_n])):
        sc = teapot_scene_dir(tmp, n)
        d = kv(run([BENCH, "hsr", sc, 3 if n <= 8 else 1]))
        tp.append((int(d["faces"]), int(d["visible"]), float(d["seconds"])))
    out["teapot"] = tp
    print("  teapot              " + "  ".join(f"{n}:{s:.3g}s" for n, _, s in tp), flush=True)
    return out


def fig530_orders(rounds=5, sizes=(100, 200, 400)):
    """Both insertion orders of each stack, alternately in the same run (the machine is
    shared: only ratios within a run are comparable); best of 5 per call, then the best
    of `rounds` calls per order and the median of the per-round ratios reversed / forward."""
    rows = []
    for kind in ("steps", "spets"):
        for n in sizes:
            fw, rv = [], []
            for _ in range(rounds):
                fw.append(float(kv(run([BENCH, "stack", kind, n, 5]))["seconds"]))
                rv.append(float(kv(run([BENCH, "stack", kind, n, 5, "reverse"]))["seconds"]))
            ratios = sorted(b / a for a, b in zip(fw, rv))
            rows.append(dict(scene=f"tri-{kind}", n=n, forward=min(fw), reversed=min(rv),
                             ratio=ratios[len(ratios) // 2]))
            r = rows[-1]
            print(f"  tri-{kind} {n}: forward {r['forward'] * 1e3:.3f} ms, reversed "
                  f"{r['reversed'] * 1e3:.3f} ms, reversed / forward {r['ratio']:.2f}", flush=True)
    return rows


def move_bench(args, tmp: Path):
    """A 12-triangle box in front of the teapot, moved sideways by ~ its size."""
    rows = []
    for n in ([8] if args.quick else [8, args.teapot_n]):
        verts = lambda dx: [(x + dx, y, z) for x in (-0.25, 0.25) for y in (0.9, 1.4) for z in (2.3, 2.8)]
        quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        for tag, dx in (("a", -0.6), ("b", -0.1)):
            lines = ["usemtl box"] + ["v %g %g %g" % v for v in verts(dx)]
            for a, b, c, d in quads:
                lines += [f"f {a + 1} {b + 1} {c + 1}", f"f {a + 1} {c + 1} {d + 1}"]
            (tmp / f"box_{tag}.obj").write_text("\n".join(lines) + "\n")
        sa = teapot_scene_dir(tmp / "a", n, extra_obj=str(tmp / "box_a.obj"))
        sb = teapot_scene_dir(tmp / "b", n, extra_obj=str(tmp / "box_b.obj"))
        d = kv(run([BENCH, "move", sa, sb, 12, 3 if n <= 8 else 2]))
        rows.append(dict(faces=int(d["faces"]), vis_a=int(d["visible_a"]), vis_b=int(d["visible_b"]),
                         build=float(d["build"]), rebuild=float(d["rebuild"]), move=float(d["move"]),
                         back=float(d["move_back"]), check=d["check"]))
        r = rows[-1]
        print(f"  move: {r['faces']} faces, build {r['build']:.3f} s, rebuild {r['rebuild']:.3f} s, "
              f"move 12 faces {r['move'] * 1e3:.1f} ms (back {r['back'] * 1e3:.1f} ms), check {r['check']}",
              flush=True)
    return rows


# ------------------------------------------------------------- output

def plots(res, f530):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    img = ROOT / "docs" / "img"
    img.mkdir(parents=True, exist_ok=True)
    if res:
        table52_plot(plt, res, img)
    if f530:
        fig530_plot(plt, f530, img)


def table52_plot(plt, res, img):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for ax, q in zip(axes, (10, 100)):
        for i, s in enumerate(SCENES):
            c = f"C{i}"
            ax.plot(SUBDIV, [r["ratio"] for r in res[q][s]], "-o", color=c, ms=3, label=f"{s}")
            ax.plot(SUBDIV, SOURCE[q][s], "--", color=c, lw=0.8)
        ax.set_xscale("log"); ax.set_yscale("log")
        ax.set_xlabel("grid subdivision m (m x m cells)")
        ax.set_title(f"query extent size {q}")
        ax.grid(True, which="both", lw=0.3)
    axes[0].set_ylabel("domains addressed / overlapping extent")
    axes[0].legend(fontsize=8, title="solid: measured, dashed: Table 5.2", title_fontsize=8)
    fig.tight_layout()
    fig.savefig(img / "hsr_table52.png", dpi=110)
    plt.close(fig)


def fig530_plot(plt, f530, img):
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for i, (name, pts) in enumerate(f530.items()):
        n = [p[0] for p in pts]
        t = [p[2] for p in pts]
        k = fit_exponent(n[len(n) // 2:], t[len(t) // 2:])   # the upper half, as in the table
        ax.plot(n, t, "-o" if "reversed" not in name else "--x", ms=3, color=f"C{i}",
                label=f"{name} (~n^{k:.2f})")
    ax.set_xscale("log"); ax.set_yscale("log")
    ax.set_xlabel("triangles"); ax.set_ylabel("seconds (HSR of the whole scene)")
    ax.set_title("Fig. 5.30 regenerated (sw/hsr, one core)")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(img / "hsr_fig530.png", dpi=110)
    plt.close(fig)


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("--write", action="store_true", help="keep the record in docs/bench, render docs/performance.md, docs/img/hsr_*.png")
    ap.add_argument("--quick", action="store_true", help="smaller sizes (a smoke run)")
    ap.add_argument("--queries", type=int, default=300, help="query positions per axis (default 300)")
    ap.add_argument("--teapot-n", type=int, default=25, help="teapot tessellation (25: 39800 triangles)")
    ap.add_argument("--seed", type=int, default=1995)
    ap.add_argument("--skip", nargs="*", default=[], choices=["table", "fig", "move"])
    ap.set_defaults(func=command)


def command(args) -> int:
    run = record.Run("hsr")
    if args.quick:
        args.queries = min(args.queries, 100)
    r = subprocess.run(["make", "-C", str(HSR), "build/hsr_bench"], capture_output=True, text=True)
    if r.returncode:
        raise SystemExit(r.stdout + r.stderr)
    yproc_tool.build()
    load0 = os.getloadavg()[0]
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_hsr_") as td:
        tmp = Path(td)
        res = info = f530 = mv = orders = None
        if "table" not in args.skip:
            print("Table 5.2: Grid-List efficiency")
            res, info = table52(args, tmp)
            print(table52_text(res, info, args.queries))
        if "fig" not in args.skip:
            print("Fig. 5.30: HSR time against triangles")
            f530 = fig530(args, tmp)
            print("Fig. 5.30: both insertion orders alternately (reversed / forward)")
            orders = fig530_orders(3 if args.quick else 5)
        if "move" not in args.skip:
            print("Incremental move vs full rebuild")
            mv = move_bench(args, tmp)
    secs = time.perf_counter() - t_start

    data = {"quick": args.quick, "seed": args.seed, "queries": args.queries,
            "teapot_n": args.teapot_n, "seconds": secs, "cpu": cpu_name(),
            "system": platform.system(), "machine": platform.machine(), "load_start": load0,
            "load_end": os.getloadavg()[0], "table52": res, "table52_info": info,
            "fig530": f530, "fig530_orders": orders, "move": mv}
    rec = run.save(data, args.write and not args.skip)
    text = render(rec)
    print()
    print(text)
    if args.write:
        plots(*_plot_data(rec["data"]))
        if args.skip:   # a partial run must not drop the other subsections
            print("--skip: plots written; merge the text above into docs/performance.md by hand")
        else:
            return doc.write(["hsr"])
    return 0


def _plot_data(d: dict):
    """Table 5.2 and Fig. 5.30 results from a record (JSON keys are strings)."""
    res = {int(q): v for q, v in d["table52"].items()} if d["table52"] else None
    return res, d["fig530"]


def render(rec: dict) -> str:
    """The "Hidden-surface removal (host C)" section of docs/performance.md."""
    d = rec["data"]
    res, f530 = _plot_data(d)
    info, mv = d["table52_info"], d["move"]
    parts = [SECTION, ""]
    parts.append(f"`make bench-hsr` (= `diffengine bench hsr --write`{' --quick' if d['quick'] else ''}, "
                 f"seed {d['seed']}; took {d['seconds']:.0f} s). One core of {d['cpu']}, `cc -O2`, "
                 f"{d['system']} {d['machine']}; 1-min load average {d['load_start']:.1f} at the start, "
                 f"{d['load_end']:.1f} at the end (other jobs share the machine: times are indicative). "
                 "The C tool is `sw/hsr/build/hsr_bench` "
                 "(`sw/hsr/tools/hsr_bench.c`). Plots: `docs/img/hsr_table52.png`, `docs/img/hsr_fig530.png`.")
    parts.append("")
    if res:
        parts += ["### Grid-List efficiency (Table 5.2)", "",
                  "Scenes regenerated from the descriptions of section 5.3.3 (the exact data sets are not "
                  "published): 100K extents in a 10000 x 10000 window (Random: sides 75-125; Landscape: "
                  "ground plane in perspective, horizon at 2/3 height, size proportional to the distance "
                  "below it, density to its inverse square; Cluster: Gaussian, sigma = window/6; Two-size: "
                  "1/8 at 2.5x and 7/8 at 0.5x the Random size; Vlsi: on the nodes of a 100 x 100 grid, "
                  "50 x 50 squares and 25-wide strips 400-600 long; Teapot: bounding boxes of the projected "
                  f"triangles of the Utah teapot, n = {d['teapot_n']}, side view, on a 10000 x 10000 screen). "
                  "Queries: square extents on a regular grid of positions over the whole window. "
                  "*Addressed* = Grid-List entries visited (including the entry that ends a list) + empty "
                  "cells addressed (footnote 10: memory accesses); the ratio is addressed / overlapping "
                  "extents, summed over all queries.", "",
                  table52_text(res, info, d['queries']), ""]
    if f530:
        parts += ["### HSR time against triangle count (Fig. 5.30)", "",
                  "tri-steps: n nested right triangles sharing a corner, smaller ones nearer (all n "
                  "visible); tri-spets: larger ones nearer (1 visible); added largest first, or reversed. "
                  "Teapot: the side view of `sw/scenes/teapot`, all faces (no back-face culling), "
                  "tessellation n = 2..25 (64n^2 - 8n triangles), `hsr_scene_build` (projection + HSR). "
                  "Best of 5 for tri-spets, of 3 for small other runs. Exponent k of a power-law fit t ~ n^k over the upper half "
                  "of each series.", "",
                  "| scene | triangles | visible domains | seconds | us / triangle |", "|---|---|---|---|---|"]
        for name, pts in f530.items():
            for n, v, s in pts:
                parts.append(f"| {name} | {n} | {v} | {s:.4f} | {1e6 * s / n:.1f} |")
        parts += ["", "| scene | fitted exponent k | source (Fig. 5.30) |", "|---|---|---|"]
        src = {"tri-steps": "2 (\"exactly quadratic\")", "tri-spets": "1 (\"exactly linear\")",
               "tri-steps reversed": "same as tri-steps", "tri-spets reversed": "same as tri-spets",
               "teapot": "between the two"}
        for name, pts in f530.items():
            h = len(pts) // 2   # the upper half, as the text says
            k = fit_exponent([p[0] for p in pts][h:], [p[2] for p in pts][h:])
            parts.append(f"| {name} | {k:.2f} | {src[name]} |")
        if d.get("fig530_orders"):
            parts += ["", "Both orders alternately in the same run (`hsr_bench stack KIND N 5 [reverse]`, "
                      "forward then reversed, 5 rounds; best of the rounds per order, median of the "
                      "per-round ratios; docs/hsr.md, \"Fig. 5.30: the two insertion orders\", says why "
                      "tri-steps reversed costs more):", "",
                      "| scene | triangles | forward ms | reversed ms | reversed / forward |", "|---|---|---|---|---|"]
            for r in d["fig530_orders"]:
                parts.append(f"| {r['scene']} | {r['n']} | {r['forward'] * 1e3:.3f} | {r['reversed'] * 1e3:.3f} "
                             f"| {r['ratio']:.2f} |")
        n, v, s = f530["teapot"][-1]
        parts += ["", f"Teapot speed ({n} triangles, {v} visible domains): **{1e6 * s / n:.0f} us per input "
                  f"triangle, {1e6 * s / v:.0f} us per visible domain** ({s:.2f} s for the whole scene). "
                  "The source estimates ~10K instructions per triangle on a 50 MHz R4000 (~200 us; "
                  "section 5.4.6).", ""]
    if mv:
        parts += ["### Incremental move vs full rebuild", "",
                  "A 12-triangle box in front of the teapot is moved sideways (`hsr_move` of its 12 faces, "
                  "i.e. remove with damage repair + add), and back; the full alternatives are the build "
                  "from the scene and `hsr_rebuild` (re-add every MLR domain). After the move every MLR "
                  "id's visible area equals a full build of the moved scene (1e-9) and `hsr_check` "
                  "passes (column *check*).", "",
                  "| faces | visible before / after | full build s | hsr_rebuild s | move ms | move back ms "
                  "| rebuild / move | check |", "|---|---|---|---|---|---|---|---|"]
        for r in mv:
            parts.append(f"| {r['faces']} | {r['vis_a']} / {r['vis_b']} | {r['build']:.3f} | {r['rebuild']:.3f} "
                         f"| {r['move'] * 1e3:.1f} | {r['back'] * 1e3:.1f} | {r['rebuild'] / r['move']:.0f}x "
                         f"| {r['check']} |")
        parts.append("")
    return "\n".join(parts)
