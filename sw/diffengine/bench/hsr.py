"""Benchmarks of the host C hidden-surface removal (sw/hsr), chapter 5 of Kuijk (1995).

    make bench-hsr                      # = diffengine bench hsr --write
    diffengine bench hsr [--quick] [--write]

(Table 5.2 and Figs. 5.13-5.18, the Grid-List on the six test scenes of section
5.3.3: `diffengine bench table52`, bench/table52.py.)

1. Fig. 5.30: HSR time against triangle count for tri-steps, tri-spets (both
   insertion orders) and the teapot; power-law exponents fitted.
2. Teapot speed: microseconds per input triangle and per visible domain.
3. Incremental move of one small object (a 12-triangle box in front of the
   teapot) against a full rebuild, same run, with an equality check.

Records out/bench/hsr.json (bench.record); --write keeps it in docs/bench, renders the
section "Hidden-surface removal (host C)" of docs/performance.md and writes
docs/img/hsr_fig530.png.
"""
from __future__ import annotations

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


def run(cmd, **kw):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, cmd))} failed:\n{r.stdout}{r.stderr}")
    return r.stdout


def kv(line: str) -> dict:
    t = line.split()
    return {t[i]: t[i + 1] for i in range(0, len(t) - 1, 2)}


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

def plots(f530):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    img = ROOT / "docs" / "img"
    img.mkdir(parents=True, exist_ok=True)
    if f530:
        fig530_plot(plt, f530, img)


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
    record.add_write(ap, "docs/performance.md, docs/img/hsr_*.png")
    ap.add_argument("--quick", action="store_true", help="smaller sizes (a smoke run)")
    ap.add_argument("--teapot-n", type=int, default=25, help="teapot tessellation (25: 39800 triangles)")
    ap.add_argument("--seed", type=int, default=1995)
    ap.add_argument("--skip", nargs="*", default=[], choices=["fig", "move"])
    ap.set_defaults(func=command)


def command(args) -> int:
    run = record.Run("hsr")
    r = subprocess.run(["make", "-C", str(HSR), "build/hsr_bench"], capture_output=True, text=True)
    if r.returncode:
        raise SystemExit(r.stdout + r.stderr)
    yproc_tool.build()
    load0 = os.getloadavg()[0]
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_hsr_") as td:
        tmp = Path(td)
        f530 = mv = orders = None
        if "fig" not in args.skip:
            print("Fig. 5.30: HSR time against triangles")
            f530 = fig530(args, tmp)
            print("Fig. 5.30: both insertion orders alternately (reversed / forward)")
            orders = fig530_orders(3 if args.quick else 5)
        if "move" not in args.skip:
            print("Incremental move vs full rebuild")
            mv = move_bench(args, tmp)
    secs = time.perf_counter() - t_start

    data = {"quick": args.quick, "seed": args.seed,
            "teapot_n": args.teapot_n, "seconds": secs, "cpu": cpu_name(),
            "system": platform.system(), "machine": platform.machine(), "load_start": load0,
            "load_end": os.getloadavg()[0],
            "fig530": f530, "fig530_orders": orders, "move": mv}
    rec = run.save(data, args.write and not args.skip)
    text = render(rec)
    print()
    print(text)
    if args.write:
        plots(rec["data"]["fig530"])
        if args.skip:   # a partial run must not drop the other subsections
            print("--skip: plots written; merge the text above into docs/performance.md by hand")
        else:
            return doc.write(["hsr"])
    return 0


def render(rec: dict) -> str:
    """The "Hidden-surface removal (host C)" section of docs/performance.md."""
    d = rec["data"]
    f530, mv = d["fig530"], d["move"]
    parts = [SECTION, ""]
    parts.append(f"`make bench-hsr` (= `diffengine bench hsr --write`{' --quick' if d['quick'] else ''}, "
                 f"seed {d['seed']}; took {d['seconds']:.0f} s). One core of {d['cpu']}, `cc -O2`, "
                 f"{d['system']} {d['machine']}; 1-min load average {d['load_start']:.1f} at the start, "
                 f"{d['load_end']:.1f} at the end (other jobs share the machine: times are indicative). "
                 "The C tool is `sw/hsr/build/hsr_bench` "
                 "(`sw/hsr/tools/hsr_bench.c`). Plot: `docs/img/hsr_fig530.png`. "
                 "(Table 5.2: section \"Grid-List efficiency\", `diffengine bench table52`.)")
    parts.append("")
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
