"""Y-processor figures for docs/performance.md, measured in one run:

* commands (slots) per line against the line capacity, per shipped scene and shading,
  with the lines degraded / merged / overflowing (docs/yproc.md section 5);
* instructions per visible pattern row beside Table 7.3's assumptions;
* host time per frame, full and incremental, for the animation (`yproc anim`), both
  measured in the same run, frame by frame (the full re-render is the baseline);
* a plot of slots per line against capacity: docs/img/yproc_slots_per_line.png.

    diffengine bench yproc [--write] [--quick]                   # record "yproc"
    diffengine bench yproc --scaling [--baseline-rev REV] [--repeat 5] [--write]
                                                                 # record "yproc-scaling"

--quick skips the no-aa / gouraud / flat variants. Progress goes to stderr.

--scaling (issue 21, large meshes): `yproc scan` time against the triangle count, from
about 1K to 100K triangles at 640x480: teapots made by sw/scenes/teapot/make_teapot.py
(-n 4, 7, 13, 22, 40: 992 .. 102,080 triangles, same camera) and the Stanford bunny
(sw/scenes/meshes/bunny.scene, 69,451).  With --baseline-rev, the yproc of that revision
(sources taken with `git archive`, bench.baseline, built in a temporary directory) runs alternately with
this tree's in the same session; every figure is the min and median of --repeat runs,
wall clock and the child's CPU time (user + sys), with the load average before and after.
Both record out/bench/NAME.json (bench.record); --write keeps it in docs/bench and renders
the section NAME of docs/performance.md (bench.render).
"""
from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .. import REPO as ROOT
from . import baseline, record, render as doc

YPROC = ROOT / "sw" / "yproc" / "build" / "yproc"
SECTION = "## Y-processor: commands per line and host time"
# Table 7.3 (640x485 at 21.5 MHz, 683 slots per 640-pixel line): slots per pattern row
TABLE_7_3 = {"phong": 6.5, "gouraud": 4.3, "flat": 3.2}

RUNS = [  # scene, label, extra args
    ("sw/scenes/teapot/teapot.scene", "teapot", []),
    ("sw/scenes/teapot/teapot.scene", "teapot", ["--no-aa"]),
    ("sw/scenes/teapot/teapot.scene", "teapot", ["--shading", "gouraud"]),
    ("sw/scenes/teapot/teapot.scene", "teapot", ["--shading", "flat"]),
    ("sw/scenes/teapot/teapot_phong.scene", "teapot_phong", []),
    ("sw/scenes/teapot/teapot_phong.scene", "teapot_phong", ["--no-aa"]),
    ("sw/scenes/cad/cad.scene", "cad", []),
    ("sw/scenes/cad/cad.scene", "cad", ["--no-aa"]),
    ("sw/scenes/cad/cad.scene", "cad", ["--shading", "gouraud"]),
    ("sw/scenes/cad/cad.scene", "cad", ["--shading", "flat"]),
    ("sw/scenes/cad/cad_sky.scene", "cad_sky", []),
]
ANIM = "sw/scenes/anim/cad_drag.anim"
SCALING_TEAPOTS = [4, 7, 13, 22, 40]          # make_teapot.py -n: 992 .. 102,080 triangles
SCALING_MESH = "sw/scenes/meshes/bunny.scene"  # 69,451 triangles


def log(msg: str) -> None:
    record.log("yproc", msg)


def scan(scene: str, args: list, out: Path) -> dict:
    res = subprocess.run([str(YPROC), "scan", str(ROOT / scene), "-o", str(out), *args],
                         capture_output=True, text=True)
    if res.returncode:
        sys.exit(f"bench_yproc: yproc scan {scene} {' '.join(args)} failed:\n{res.stderr}")
    return json.loads((out / "stats.json").read_text())


def row(label: str, args: list, st: dict) -> dict:
    t = st["totals"]
    lines = st["lines"]
    rows = sum(ln["patterns"] for ln in lines)
    slots_r = t["slots"][0]
    mode = ("no-aa" if not st["aa"] else "aa")
    return {"scene": label, "shading": st["shading"], "aa": st["aa"], "label": f"{st['shading']}, {mode}",
            "faces": st["faces"], "llr": st["llr_domains"], "capacity": st["capacity"],
            "mean": t["mean_slots"][0], "max": t["max_slots"][0],
            "degraded": t["lines_degraded"], "merged": t["lines_merged"], "overflow": t["lines_overflow"],
            "pattern_rows": rows,
            # the line's background term (Eval1 over the line, 3 slots) is not a pattern's
            "per_row": (slots_r - 3 * st["height"]) / rows if rows else 0.0,
            "knots": t["knots"], "dis": t["dis"], "spec": t["specular_evals"],
            "hsr_ms": st["times_ms"]["hsr"], "scan_ms": st["times_ms"]["scan"],
            "slots_per_line": [ln["slots"][0] for ln in lines]}


def plot(rows: list, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 4.2), dpi=110)
    for r in rows:
        if r["aa"] and r["shading"] == "phong":
            ax.plot(r["slots_per_line"], lw=0.9, label=f"{r['scene']} (mean {r['mean']:.0f})")
    cap = rows[0]["capacity"]
    ax.axhline(cap, color="k", ls="--", lw=1)
    ax.text(5, cap + 8, f"capacity {cap} slots/line (640x480, HTotal - 2)", fontsize=8)
    ax.set_xlabel("scanline")
    ax.set_ylabel("command slots (red stream)")
    ax.set_ylim(0, cap * 1.12)
    ax.set_title("Commands per line against capacity, area-sampled Phong")
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def build_rev(rev: str, tmp: Path) -> Path:
    """yproc of git revision rev, built from `git archive` in tmp (the repository is not touched)."""
    src = baseline.extract(rev, tmp / "base")
    # before issue 17 the y-processor was built inside sw/hsr
    home = src / "sw" / ("yproc" if (src / "sw" / "yproc" / "Makefile").exists() else "hsr")
    subprocess.run(["make", "-s", "-C", str(home), "build/yproc"], check=True)
    return home / "build" / "yproc"


def timed_scan(yproc: Path, scene: Path, out: Path) -> tuple:
    """(wall s, CPU s of the child, stats.json) of one `yproc scan`"""
    r0, t0 = os.times(), time.perf_counter()
    res = subprocess.run([str(yproc), "scan", str(scene), "-o", str(out)], capture_output=True, text=True)
    wall, r1 = time.perf_counter() - t0, os.times()
    if res.returncode:
        sys.exit(f"bench_yproc: {yproc} scan {scene} failed:\n{res.stderr}")
    cpu = (r1.children_user - r0.children_user) + (r1.children_system - r0.children_system)
    return wall, cpu, json.loads((out / "stats.json").read_text())


def scaling(a) -> int:
    run = record.Run("yproc-scaling")
    rev = record.revision(a.baseline_rev) if a.baseline_rev else None
    head = record.revision()
    with tempfile.TemporaryDirectory() as tmpd:
        tmp = Path(tmpd)
        bins = [("this tree", YPROC)]
        if rev:
            log(f"building the baseline yproc of {rev}")
            bins.append((f"baseline {rev}", build_rev(rev, tmp)))
        scenes = []
        for n in SCALING_TEAPOTS:
            d = tmp / f"teapot{n}"
            subprocess.run([sys.executable, str(ROOT / "sw/scenes/teapot/make_teapot.py"), "-n", str(n),
                            "-o", str(d)], check=True, capture_output=True)
            scenes.append((f"teapot -n {n}", d / "teapot.scene"))
        scenes.append(("bunny", ROOT / SCALING_MESH))
        load0 = record.loadavg()
        res = {}   # (scene, binary) -> list of (wall, cpu, stats)
        t_start = time.time()
        for name, scene in scenes:
            for k in range(a.repeat):
                for bname, b in bins:   # alternate: baseline and this tree in turn
                    res.setdefault((name, bname), []).append(timed_scan(b, scene, tmp / "out"))
            r = res[(name, bins[0][0])]
            log(f"[scaling] {name}: {r[0][2]['faces']} triangles, " + ", ".join(
                f"{bn} {min(x[0] for x in res[(name, bn)]):.2f} s" for bn, _ in bins))
        load1 = record.loadavg()
    def brief(st):   # what the table shows of yproc's stats.json
        return {"faces": st["faces"], "llr_domains": st["llr_domains"],
                "times_ms": {k: st["times_ms"][k] for k in ("hsr", "scan")}}

    data = {"baseline_rev": a.baseline_rev, "repeat": a.repeat, "rev": rev, "head": head,
            "started": time.strftime("%Y-%m-%d %H:%M", time.localtime(t_start)),
            "seconds": round(time.time() - t_start), "load_before": load0,
            "load_after": load1, "scenes": [name for name, _ in scenes],
            "binaries": [bname for bname, _ in bins],
            "runs": {f"{name}|{bname}": [[w, c, brief(st)] for w, c, st in res[(name, bname)]]
                     for name, _ in scenes for bname, _ in bins}}
    rec = run.save(data, a.write)
    print(render_scaling(rec))
    return doc.write(["yproc-scaling"]) if a.write else 0


def render_scaling(rec: dict) -> str:
    """The scaling table (yproc scan time against triangle count) of docs/performance.md."""
    d = rec["data"]
    rev, head, load0, load1 = d["rev"], d["head"], d["load_before"], d["load_after"]
    res = {tuple(k.split("|")): v for k, v in d["runs"].items()}
    scenes = [(name, None) for name in d["scenes"]]
    bins = [(bname, None) for bname in d["binaries"]]
    L = [f"Reproduce: `diffengine bench yproc --scaling"
         f"{' --baseline-rev ' + d['baseline_rev'] if d['baseline_rev'] else ''} --repeat {d['repeat']}` "
         f"(started {d['started']}, revision {head}"
         f"{', baseline ' + rev if rev else ''}; {d['seconds']:.0f} s; 1-min load average "
         f"{load0} before, {load1} after, on the shared 2-core machine). Each `yproc scan` "
         f"(load, HSR, scan conversion, write) ran {d['repeat']} times, "
         f"{'the two binaries alternately, ' if rev else ''}640x480, Phong, AA; "
         "wall = min / median wall clock, CPU = min user + sys of the process, "
         "HSR and scan = min of yproc's own CPU-time stages; us/tri = min wall / triangles.", "",
         "| scene | triangles | visible domains | binary | wall s (min / median) | CPU s | HSR s | scan s | us / tri |",
         "|---|---|---|---|---|---|---|---|---|"]
    for name, _ in scenes:
        for bname, _ in bins:
            r = res[(name, bname)]
            st = r[0][2]
            w = [x[0] for x in r]
            L.append(f"| {name} | {st['faces']:,} | {st['llr_domains']:,} | {bname} | {min(w):.2f} / "
                     f"{statistics.median(w):.2f} | {min(x[1] for x in r):.2f} | "
                     f"{min(x[2]['times_ms']['hsr'] for x in r) / 1e3:.2f} | "
                     f"{min(x[2]['times_ms']['scan'] for x in r) / 1e3:.2f} | {1e6 * min(w) / st['faces']:.1f} |")
    if rev:
        L += ["", "| scene | triangles | speed-up, min wall | speed-up, min CPU |", "|---|---|---|---|"]
        for name, _ in scenes:
            b, c = res[(name, bins[1][0])], res[(name, bins[0][0])]
            L.append(f"| {name} | {c[0][2]['faces']:,} | {min(x[0] for x in b) / min(x[0] for x in c):.1f}x | "
                     f"{min(x[1] for x in b) / min(x[1] for x in c):.1f}x |")
    return "\n".join(L)



def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    record.add_write(ap, "docs/performance.md and the plot")
    ap.add_argument("--quick", action="store_true", help="default shading with AA only")
    ap.add_argument("--scaling", action="store_true", help="yproc scan time against triangle count (1K..100K)")
    ap.add_argument("--baseline-rev", help="with --scaling: also time the yproc of this git revision")
    ap.add_argument("--repeat", type=int, default=5, help="with --scaling: runs per scene and binary")
    ap.set_defaults(func=command)


def command(a) -> int:
    if subprocess.run(["make", "-s", "-C", str(ROOT / "sw" / "yproc"), "build/yproc"]).returncode:
        return 1
    if a.scaling:
        return scaling(a)
    run = record.Run("yproc")
    runs = [r for r in RUNS if not (a.quick and r[2])]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, (scene, label, args) in enumerate(runs, 1):
            t0 = time.time()
            rows.append(row(label, args, scan(scene, args, Path(tmp) / f"s{i}")))
            log(f"[{i}/{len(runs)}] {label} {' '.join(args) or '(default)'}: mean "
                f"{rows[-1]['mean']:.0f} slots/line, {time.time() - t0:.1f} s")
        log(f"[anim] yproc anim {ANIM} (36 frames, each also re-rendered in full)")
        res = subprocess.run([str(YPROC), "anim", str(ROOT / ANIM), "-o", str(Path(tmp) / "anim")],
                             capture_output=True, text=True)
        if res.returncode:
            sys.exit(f"bench_yproc: yproc anim failed:\n{res.stderr}")
        anim = json.loads((Path(tmp) / "anim" / "anim_stats.json").read_text())
    anim["frame"] = [{k: v for k, v in f.items() if k in ANIM_KEYS} for f in anim["frame"]]
    rec = run.save({"rows": rows, "anim": anim, "date": time.strftime("%Y-%m-%d")}, a.write)
    print(render(rec))
    if a.write:
        plot(rec["data"]["rows"], ROOT / "docs" / "img" / "yproc_slots_per_line.png")
        return doc.write(["yproc"])
    return 0


# what the section shows of each frame of anim_stats.json
ANIM_KEYS = ("changed_lines", "incremental_ms", "incremental_hsr_ms", "incremental_scan_ms",
             "full_ms", "full_hsr_ms", "full_scan_ms")


def render(rec: dict) -> str:
    """The "Y-processor: commands per line and host time" section of docs/performance.md."""
    rows, anim = rec["data"]["rows"], rec["data"]["anim"]
    cap = rows[0]["capacity"]
    L = [SECTION, "",
         f"Reproduce: `make bench` (`diffengine bench yproc --write`) "
         f"({rec['data']['date']}; CPU times of one process on the shared 2-core machine).",
         "", f"**Commands per line against capacity** (640×480, {cap} slots per line and colour; "
         "red stream). A *pattern row* is one visible pattern on one scanline; slots per "
         "pattern row = (slots − the 3-slot background term per line) / pattern rows. "
         "Table 7.3's assumption (640×485, 683 slots per 640 pixels) is 6.5 slots for a "
         "quadratic pattern, 4.3 linear, 3.2 constant.", "",
         "| scene (faces, LLR domains) | shading | mean slots/line | max | lines degraded (merged) | overflow | pattern rows | slots / pattern row | Table 7.3 | knots | Dis | specular Evals | scan ms |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        L.append(f"| {r['scene']} ({r['faces']}, {r['llr']}) | {r['label']} | {r['mean']:.0f} | {r['max']} | "
                 f"{r['degraded']} ({r['merged']}) | {r['overflow']} | {r['pattern_rows']} | {r['per_row']:.2f} | "
                 f"{TABLE_7_3[r['shading']]} | {r['knots']} | {r['dis']} | {r['spec']} | {r['scan_ms']:.0f} |")
    L += ["", "![slots per line](img/yproc_slots_per_line.png)", "",
          "Point-sampled patterns (`no-aa`) need about what Table 7.3 assumes; exact area "
          "sampling adds the partly covered edge pixels (one Eval1 each, plus knots where a "
          "colour ramp meets them), so a line costs roughly twice as much, and the busiest "
          "teapot lines are degraded (docs/yproc.md section 7).", ""]
    fr = [f for f in anim["frame"] if "incremental_ms" in f]
    moved = [f for f in fr if f["incremental_hsr_ms"] > 1.0]
    light = [f for f in fr if f["incremental_hsr_ms"] <= 1.0]

    def mean(fs, k):
        return sum(f[k] for f in fs) / len(fs) if fs else float("nan")

    L += [f"**Host time per frame, full against incremental** (`{ANIM}`, {anim['frames']} frames "
          f"{anim['width']}×{anim['height']}; every frame is rendered both ways in the same run, and "
          f"{anim['frames_differing_from_full']} frames differ from the full re-render).", "",
          "| frames | changed lines per colour (of 480) | incremental ms (HSR + scan) | full ms (HSR + scan) |",
          "|---|---|---|---|"]
    for name, fs in (("object dragged / opacity change", moved), ("light moving (no HSR change)", light), ("all", fr)):
        if not fs:
            continue
        L.append(f"| {name}: {len(fs)} | {mean([{'c': f['changed_lines'][0]} for f in fs], 'c'):.0f} | "
                 f"{mean(fs, 'incremental_ms'):.0f} ({mean(fs, 'incremental_hsr_ms'):.0f} + "
                 f"{mean(fs, 'incremental_scan_ms'):.0f}) | {mean(fs, 'full_ms'):.0f} "
                 f"({mean(fs, 'full_hsr_ms'):.0f} + {mean(fs, 'full_scan_ms'):.0f}) |")
    L += ["", "The y-processor's incremental part re-scans only the damaged lines; the HSR's "
          "incremental move costs more than a rebuild on this small scene (docs/yproc.md "
          "section 7, docs/hsr.md).", ""]
    return "\n".join(L)
