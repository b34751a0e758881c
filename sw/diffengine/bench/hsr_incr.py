"""Incremental HSR against a full build (issue 19 item 3), this tree and a baseline
revision measured alternately in the same run:

* teapot + a 12-triangle box moved sideways (`hsr_bench move`, the scene of `diffengine
  bench hsr`'s move table): full build, `hsr_rebuild`, the move as one `hsr_move` per
  face and as one `hsr_change_many`, and back; every move is checked against a full
  build of the moved scene;
* scaling: N = 10 .. 10,000 boxes ("parts", 12 triangles each) scattered in front of
  the camera at a constant depth complexity, one part in the middle moved by its size:
  build and move;
* the CAD drag (`yproc anim sw/scenes/anim/cad_drag.anim`): incremental (HSR + scan of
  the damaged lines) against full (HSR rebuild + scan of every line) per frame, and
  the baseline's frame deltas compared byte for byte with this tree's.

    diffengine bench hsr-incr [--baseline-rev main] [--repeat 3] [--quick] [--write]

The baseline's `hsr_bench` is this tree's tools/hsr_bench.c built with
-DHSR_BENCH_BASELINE against the baseline's libhsr (its move timings are per face only),
its `yproc` is built from the baseline's sources (`git archive`, a temporary directory).
Times are process CPU time (one core).  Records out/bench/hsr-incr.json; --write keeps it
in docs/bench and renders the section "hsr-incr" of docs/performance.md.
"""
from __future__ import annotations

import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .. import REPO as ROOT
from . import baseline, record, render as doc
from .hsr import kv, run, teapot_scene_dir

HSR = ROOT / "sw" / "hsr"
BENCH = HSR / "build" / "hsr_bench"
YPROC = ROOT / "sw" / "yproc" / "build" / "yproc"
ANIM = "sw/scenes/anim/cad_drag.anim"
PARTS = [10, 30, 100, 300, 1000, 3000, 10000]
DRAG_FRAMES = range(1, 21)      # cad_drag.anim: the slider dragged (pane opacity 8-14)
LIGHT_FRAMES = range(21, 36)    # the light turning, no HSR change
QUADS = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]


def log(msg: str) -> None:
    record.log("hsr-incr", msg)


# ------------------------------------------------------------- binaries

def build_baseline(rev: str, tmp: Path) -> tuple[Path, Path]:
    """(hsr_bench, yproc) of revision rev, from `git archive` in tmp."""
    src = baseline.extract(rev, tmp / "base")
    subprocess.run(["make", "-s", "-C", str(src / "sw" / "yproc"), "build/yproc"], check=True)
    bench = src / "hsr_bench_baseline"
    subprocess.run(["cc", "-std=c11", "-O2", "-DHSR_BENCH_BASELINE", f"-I{src / 'sw/hsr/include'}",
                    "-o", str(bench), str(HSR / "tools" / "hsr_bench.c"),
                    str(src / "sw/hsr/build/libhsr.a"), "-lm"], check=True)
    return bench, src / "sw" / "yproc" / "build" / "yproc"


# ------------------------------------------------------------- scenes

def box_lines(lo, hi, first: int) -> list[str]:
    """an axis-aligned box: 8 vertices (v lines) and 12 triangles, vertex numbers from first"""
    vs = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    out = ["v %.6f %.6f %.6f" % v for v in vs]
    for a, b, c, d in QUADS:
        out += [f"f {first + a} {first + b} {first + c}", f"f {first + a} {first + c} {first + d}"]
    return out


def teapot_box_scenes(tmp: Path, n: int) -> tuple[Path, Path]:
    """the teapot (make_teapot -n n) with a box in front, before and after the move
    (the scenes of `diffengine bench hsr`'s move table)"""
    out = []
    for tag, dx in (("a", -0.6), ("b", -0.1)):
        obj = tmp / f"box_{tag}.obj"
        obj.write_text("\n".join(["usemtl box"] + box_lines((-0.25 + dx, 0.9, 2.3), (0.25 + dx, 1.4, 2.8), 1)) + "\n")
        out.append(teapot_scene_dir(tmp / f"{tag}{n}", n, extra_obj=str(obj)))
    return out[0], out[1]


def parts_scenes(tmp: Path, n: int, seed: int = 1995) -> tuple[Path, Path]:
    """n boxes in a 12 x 9 x 6 volume seen from z = 20 (side s so that about three
    cover each pixel); the last, at the centre, moved by s in x between the two scenes"""
    rng = np.random.default_rng(seed + n)
    s = (3 * 12 * 9 / n) ** 0.5
    size = s * rng.uniform(0.5, 1.5, (n, 3))
    ctr = np.column_stack([rng.uniform(-6, 6, n), rng.uniform(-4.5, 4.5, n), rng.uniform(-3, 3, n)])
    ctr[-1] = (-s / 2, 0, 0)
    size[-1] = (s, s, s)
    out = []
    for tag, dx in (("a", 0.0), ("b", s)):
        d = tmp / f"parts{n}{tag}"
        d.mkdir(parents=True, exist_ok=True)
        lines = []
        for i in range(n):
            c = ctr[i] + (dx if i == n - 1 else 0, 0, 0)
            lines += box_lines(c - size[i] / 2, c + size[i] / 2, 8 * i + 1)
        (d / "parts.obj").write_text("\n".join(lines) + "\n")
        (d / "parts.scene").write_text(
            "# diffengine bench hsr-incr: boxes scattered in front of the camera\n"
            "screen 640 480\ncamera eye 0 0 20 at 0 0 0 up 0 1 0 fov 30\n"
            "light 0.4 0.8 0.6 0.8\nambient 0.2\nbackground 1 1 1\ngrid 32\n"
            "material part 0.8 0.75 0.6\nobj parts.obj material part\n")
        out.append(d / "parts.scene")
    return out[0], out[1]


# ------------------------------------------------------------- runs

def move_runs(bins, sa: Path, sb: Path, repeat: int, rounds: int) -> dict:
    """binary name -> the best of every figure of `hsr_bench move` over repeat runs (alternated)"""
    res: dict = {}
    for _ in range(repeat):
        for name, bench in bins:
            d = kv(run([bench, "move", sa, sb, 12, rounds]))
            if d["check"] != "ok":
                raise SystemExit(f"hsr_bench move {sa} {sb}: check {d['check']}")
            r = res.setdefault(name, {})
            for k in ("build", "rebuild", "move", "move_back", "move_many", "move_many_back"):
                r[k] = min(r.get(k, float("inf")), float(d[k]))
            for k in ("faces", "visible_a", "visible_b", "visible_moved", "visible_cycled"):
                r[k] = int(d[k])
    return res


def anim_runs(bins, tmp: Path, repeat: int) -> dict:
    """binary name -> per frame the min over repeat runs of yproc anim's times; the
    frames differing from a full re-render; whether the outputs equal the first binary's"""
    res: dict = {}
    outs = {}
    for k in range(repeat):
        for name, yproc in bins:
            out = tmp / f"anim_{name.split()[0]}_{k}"
            r = subprocess.run([str(yproc), "anim", str(ROOT / ANIM), "-o", str(out)],
                               capture_output=True, text=True)
            if r.returncode:
                raise SystemExit(f"{yproc} anim {ANIM} failed:\n{r.stderr}")
            st = json.loads((out / "anim_stats.json").read_text())
            outs.setdefault(name, out)
            e = res.setdefault(name, {"frames": {}, "differing": 0})
            e["differing"] = max(e["differing"], st["frames_differing_from_full"])
            for fr in st["frame"][1:]:
                f = e["frames"].setdefault(fr["frame"], {})
                for key in ("incremental_hsr_ms", "incremental_scan_ms", "full_hsr_ms", "full_scan_ms"):
                    f[key] = min(f.get(key, float("inf")), fr[key])
                f["changed"] = fr["changed_lines"][0]
    first = outs[bins[0][0]]
    files = sorted(p.relative_to(first) for p in first.rglob("*") if p.is_file() and p.name != "anim_stats.json")
    for name, out in outs.items():
        res[name]["files"] = len(files)
        res[name]["identical_to_first"] = all((out / p).exists() and (out / p).read_bytes() == (first / p).read_bytes()
                                              for p in files)
    return res


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("--baseline-rev", default=None,
                    help="also measure this git revision (e.g. main), alternately with this tree")
    ap.add_argument("--repeat", type=int, default=3, help="runs per figure and binary (min taken)")
    ap.add_argument("--quick", action="store_true", help="parts up to 1,000, the small teapot, one anim run")
    record.add_write(ap)
    ap.set_defaults(func=command)


def command(a) -> int:
    for d, target in ((HSR, "build/hsr_bench"), (ROOT / "sw" / "yproc", "build/yproc")):
        if subprocess.run(["make", "-s", "-C", str(d), target]).returncode:
            return 1
    runrec = record.Run("hsr-incr")
    rev = record.revision(a.baseline_rev) if a.baseline_rev else None
    t0 = time.time()
    with tempfile.TemporaryDirectory(prefix="bench_hsr_incr_") as td:
        tmp = Path(td)
        bins, ybins = [("this tree", BENCH)], [("this tree", YPROC)]
        if rev:
            log(f"building the baseline of {rev}")
            b, y = build_baseline(a.baseline_rev, tmp)
            bins.append((f"baseline {rev}", b))
            ybins.append((f"baseline {rev}", y))
        teapots = {}
        for n in ([8] if a.quick else [8, 25]):
            sa, sb = teapot_box_scenes(tmp, n)
            teapots[n] = move_runs(bins, sa, sb, a.repeat, 5 if n <= 8 else 2)
            r = teapots[n]["this tree"]
            log(f"teapot -n {n} + box: {r['faces']} faces, build {r['build'] * 1e3:.1f} ms, move "
                f"{r['move'] * 1e3:.2f} ms per face / {r['move_many'] * 1e3:.2f} ms batched"
                + "".join(f"; {k}: move {v['move'] * 1e3:.2f} ms, build {v['build'] * 1e3:.1f} ms"
                          for k, v in teapots[n].items() if k != "this tree"))
        parts = {}
        for n in [p for p in PARTS if not a.quick or p <= 1000]:
            sa, sb = parts_scenes(tmp, n)
            parts[n] = move_runs(bins, sa, sb, a.repeat, 3 if n <= 1000 else 2)
            r = parts[n]["this tree"]
            log(f"parts {n}: build {r['build'] * 1e3:.1f} ms, move {r['move_many'] * 1e3:.2f} ms batched"
                + "".join(f"; {k}: move {v['move'] * 1e3:.2f} ms" for k, v in parts[n].items() if k != "this tree"))
        log("cad_drag.anim")
        anim = anim_runs(ybins, tmp, 1 if a.quick else a.repeat)
    data = {"baseline_rev": a.baseline_rev, "rev": rev, "head": record.revision(), "repeat": a.repeat,
            "quick": a.quick, "seconds": round(time.time() - t0),
            "teapot": {str(k): v for k, v in teapots.items()},
            "parts": {str(k): v for k, v in parts.items()}, "anim": anim}
    rec = runrec.save(data, a.write)
    print(render(rec))
    return doc.write(["hsr-incr"]) if a.write else 0


# ------------------------------------------------------------- output

def _anim_summary(frames: dict, sel) -> dict:
    fr = [frames[str(i)] if str(i) in frames else frames[i] for i in sel]
    inc = [f["incremental_hsr_ms"] + f["incremental_scan_ms"] for f in fr]
    full = [f["full_hsr_ms"] + f["full_scan_ms"] for f in fr]
    return {"n": len(fr), "changed": statistics.mean(f["changed"] for f in fr),
            "inc_hsr": statistics.mean(f["incremental_hsr_ms"] for f in fr),
            "inc_scan": statistics.mean(f["incremental_scan_ms"] for f in fr),
            "full_hsr": statistics.mean(f["full_hsr_ms"] for f in fr),
            "full_scan": statistics.mean(f["full_scan_ms"] for f in fr),
            "ratio": statistics.mean(inc) / statistics.mean(full),
            "worst": max(i / f for i, f in zip(inc, full))}


def _pct(x: float) -> str:
    return f"{100 * x:.1f} %" if x >= 0.01 else f"{100 * x:.2f} %" if x >= 1e-4 else f"{100 * x:.3f} %"


def render(rec: dict) -> str:
    """The "Incremental HSR against a full build" section of docs/performance.md."""
    d = rec["data"]
    names = ["this tree"] + ([f"baseline {d['rev']}"] if d["rev"] else [])
    L = [f"`{rec['command']}` ({rec['date']}, revision {d['head']}"
         f"{', baseline ' + d['baseline_rev'] + ' = ' + d['rev'] if d['rev'] else ''}; {d['seconds']} s; "
         f"1-min load average {rec['load_before']} before, {rec['load_after']} after, on the shared "
         f"2-core machine). Process CPU time (one core); each figure is the best of {d['repeat']} runs, "
         "the binaries alternately (and inside a run the best of its rounds). Every move is checked "
         "against a full build of the moved scene (visible area per MLR id, `hsr_check`).", "",
         "**Teapot + 12-triangle box moved sideways** (`hsr_bench move`; move = the 12 faces moved, "
         "per face = one `hsr_move` each, batched = one `hsr_change_many`):", "",
         "| faces | binary | full build ms | hsr_rebuild ms | move per face ms | back ms | move batched ms "
         "| back ms | move / build | visible domains built / after moves |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    for n, rs in d["teapot"].items():
        for name in names:
            r = rs[name]
            best = min(r["move"], r["move_many"])
            many = "-" if r["move_many"] == float("inf") else f"{r['move_many'] * 1e3:.2f}"
            manyb = "-" if r["move_many_back"] == float("inf") else f"{r['move_many_back'] * 1e3:.2f}"
            L.append(f"| {r['faces']:,} | {name} | {r['build'] * 1e3:.1f} | {r['rebuild'] * 1e3:.1f} | "
                     f"{r['move'] * 1e3:.2f} | {r['move_back'] * 1e3:.2f} | {many} | {manyb} | "
                     f"{_pct(best / r['build'])} | {r['visible_a']:,} / {r['visible_cycled']:,} |")
    L += ["", "**Scaling: N parts** (boxes of 12 triangles scattered in a 12 x 9 x 6 volume, side "
          "chosen so that about three cover each pixel; the part at the centre moved by its side; "
          "`diffengine bench hsr-incr` writes the scenes):", "",
          "| parts | triangles | visible domains | full build ms | move ms (batched) | move / build "
          + "".join(f"| {nm.split()[0]} move ms (per face) " for nm in names[1:]) + "|",
          "|---|---|---|---|---|---|" + "---|" * (len(names) - 1)]
    for n, rs in d["parts"].items():
        r = rs["this tree"]
        L.append(f"| {int(n):,} | {r['faces']:,} | {r['visible_a']:,} | {r['build'] * 1e3:.1f} | "
                 f"{r['move_many'] * 1e3:.2f} | {_pct(r['move_many'] / r['build'])} "
                 + "".join(f"| {rs[nm]['move'] * 1e3:.2f} " for nm in names[1:]) + "|")
    L += ["", f"**CAD drag** (`yproc anim {ANIM}`, 640x480; per frame the min of the runs; "
          "incremental = HSR update + scan of the damaged lines, full = HSR rebuild + scan of every "
          "line, both in the same process):", "",
          "| frames | binary | changed lines | incremental ms (HSR + scan) | full ms (HSR + scan) "
          "| incremental / full, mean | worst frame |", "|---|---|---|---|---|---|---|"]
    for label, sel in (("1-20 drag (+ opacity 8-14)", DRAG_FRAMES), ("21-35 light", LIGHT_FRAMES),
                       ("all 35", range(1, 36))):
        for name in names:
            s = _anim_summary(d["anim"][name]["frames"], sel)
            L.append(f"| {label} | {name} | {s['changed']:.0f} | {s['inc_hsr'] + s['inc_scan']:.1f} "
                     f"({s['inc_hsr']:.1f} + {s['inc_scan']:.1f}) | {s['full_hsr'] + s['full_scan']:.1f} "
                     f"({s['full_hsr']:.1f} + {s['full_scan']:.1f}) | {100 * s['ratio']:.0f} % | "
                     f"{100 * s['worst']:.0f} % |")
    for name in names:
        a = d["anim"][name]
        L.append("")
        L.append(f"{name}: frames differing from their full re-render: {a['differing']}"
                 + (f"; the {a['files']} output files (frame 0, deltas) byte-identical to this tree's: "
                    f"{'yes' if a['identical_to_first'] else 'NO'}" if name != "this tree" else "") + ".")
    return "\n".join(L)
