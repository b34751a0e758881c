"""Viewer latency (issue 19 item 5): a scripted drag of N steps through the viewer's server
path (viewer.server.Session: the requests the page sends, no browser, no socket) on the
teapot-with-box and the CAD scene. Per step: pointer-to-frame latency (the drag request
in, the frame band's bytes out) split into HSR, scan, `yproc serve` I/O, golden model and
encode; then the refinement when the pointer rests. Baseline in the same run: a frame
rendered from scratch (a new `yproc serve`: scene load, HSR build, every line scanned,
every line through the golden model).

With --baseline-yproc PATH (issue 19 item 5's before/after) each scene is dragged with
that `yproc` binary first and then with this tree's, in the same run, and the record is
docs/bench/viewer-lat.json (its own section of docs/performance.md).
"""
from __future__ import annotations

import statistics
import time

from .. import REPO
from ..host import yproc
from . import record
from . import render as doc

SCENES = {
    "teapot": (REPO / "sw/scenes/teapot/teapot_box.scene", 1, "the box (12 faces)"),
    "cad": (REPO / "sw/scenes/cad/cad.scene", 2, "the bracket (12 faces)"),
    # the ball is 624 of the scene's 788 faces: each step is a full HSR build
    "cad-ball": (REPO / "sw/scenes/cad/cad.scene", 3, "the ball (624 faces)"),
}
STAGES = ("hsr_ms", "scan_ms", "serve_io_ms", "model_ms", "encode_ms")


def pct(xs, p):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(p / 100 * (len(xs) - 1))))]


def drag(name: str, steps: int, budget: float, px: float, log, model: str = "auto",
         exe=None) -> dict:
    from ..viewer.engine import Engine
    from ..viewer.server import Session
    scene, obj, what = SCENES[name]
    exe = exe or yproc.build()
    t0 = time.perf_counter()
    eng = Engine(scene, exe, budget_ms=budget, model=model)
    open_s = time.perf_counter() - t0
    full0 = eng.last_ms
    try:
        sess = Session(eng)
        # the part as picked (in the CAD scene the glass panel is in front of the parts: a
        # click there picks the glass, so the part is named here, not clicked)
        sess.picked = {"obj": obj, "material": eng.info["objects"][obj]["material"], "face": -1}
        rows = []
        for k in range(1, steps + 1):
            t = time.perf_counter()
            out, fr = sess.handle({"type": "drag", "dx": px * k, "dy": -0.3 * px * k})
            t_enc = time.perf_counter()
            blob = sess.band(fr[0])
            t1 = time.perf_counter()
            st = dict(fr[1], encode_ms=(t1 - t_enc) * 1e3, latency_ms=(t1 - t) * 1e3,
                      bytes=len(blob or b""))
            rows.append(st)
            if k % 10 == 0:
                log(f"{name}: step {k}/{steps}: {st['latency_ms']:.0f} ms "
                    f"({'coarse' if st['coarse'] else 'full'})")
        t = time.perf_counter()
        out, fr = sess.handle({"type": "drag_end"})
        rest_ms = (time.perf_counter() - t) * 1e3
        rest_rows = len(fr[0]) if fr else 0
        # the baseline, same run: a frame from scratch (a new `yproc serve`: scene load,
        # HSR build, every line scanned, every line through the golden model)
        t = time.perf_counter()
        Engine(scene, exe, budget_ms=budget, model=model).close()
        full_ms = (time.perf_counter() - t) * 1e3
    finally:
        eng.close()
    lat = [r["latency_ms"] for r in rows]
    return {"scene": name, "file": str(scene.relative_to(REPO)), "dragged": what, "model": eng.model,
            "faces": eng.info["faces"], "steps": steps, "budget_ms": budget, "open_s": open_s,
            "first_frame_ms": full0, "median_ms": statistics.median(lat), "p95_ms": pct(lat, 95),
            "max_ms": max(lat),
            "stage_median_ms": {s: statistics.median(r[s] for r in rows) for s in STAGES},
            "coarse_steps": sum(r["coarse"] for r in rows),
            "rebuilt_steps": sum(bool(r["rebuilt"]) for r in rows),
            "changed_lines_median": statistics.median(sum(r["changed"]) / 3 for r in rows),
            "rest_ms": rest_ms, "rest_rows": rest_rows, "scratch_ms": full_ms,
            "latencies": [round(v, 2) for v in lat]}


def configure(ap) -> None:
    """The arguments of `diffengine bench viewer`."""
    ap.add_argument("--scenes", default="teapot,cad", help="teapot,cad (also cad-ball)")
    ap.add_argument("--steps", type=int, default=100, help="drag steps per scene (default 100)")
    ap.add_argument("--px", type=float, default=2.0, help="pointer move per step, pixels")
    ap.add_argument("--budget-ms", type=float, default=50.0,
                    help="the viewer's frame budget (coarse frames above it)")
    ap.add_argument("--model", choices=("auto", "fast", "numpy"), default="auto",
                    help="golden model: C (diffengine.model.fast) when there (auto), or numpy")
    ap.add_argument("--baseline-yproc", metavar="PATH",
                    help="also drag with this yproc binary first, same run (record viewer-lat)")
    ap.add_argument("--baseline-label", default="baseline",
                    help="what the baseline binary is (e.g. 'main 4a92cc4'), for the table")
    record.add_write(ap)
    ap.set_defaults(func=command)


def command(a) -> int:
    import os
    from pathlib import Path
    base = Path(a.baseline_yproc).resolve() if a.baseline_yproc else None
    if base is not None and not os.access(base, os.X_OK):
        print(f"diffengine bench viewer: error: --baseline-yproc {base}: not an executable file")
        return 2
    run = record.Run("viewer-lat" if base else "viewer")
    res, before = [], []
    for name in a.scenes.split(","):
        if name not in SCENES:
            run.log(f"error: unknown scene {name!r} ({', '.join(SCENES)})")
            return 2
        if base:
            run.log(f"{name}: {a.steps}-step drag with the baseline {base}")
            before.append(dict(drag(name, a.steps, a.budget_ms, a.px, run.log, a.model, base),
                               yproc=a.baseline_label))
            r = before[-1]
            run.log(f"{name}: baseline median {r['median_ms']:.0f} ms, p95 {r['p95_ms']:.0f} ms")
        run.log(f"{name}: {a.steps}-step drag through the viewer's server path")
        res.append(drag(name, a.steps, a.budget_ms, a.px, run.log, a.model))
        r = res[-1]
        run.log(f"{name}: median {r['median_ms']:.0f} ms, p95 {r['p95_ms']:.0f} ms; "
                f"from scratch {r['scratch_ms']:.0f} ms")
    data = {"scenes": res, "cpus": os.cpu_count()}
    if base:
        data["baseline"] = before
    rec = run.save(data, a.write)
    if a.write:
        return doc.write(["viewer-lat" if base else "viewer"])
    print(render_lat(rec) if base else render(rec))
    return 0


def _row(r: dict, label: str) -> str:
    s = r["stage_median_ms"]
    return (f"| {r['scene']} ({r['faces']} faces) | {r['dragged']} | {label}"
            f"{r.get('model', 'numpy')} | {r['steps']} | "
            f"{r['median_ms']:.0f} | {r['p95_ms']:.0f} | {r['max_ms']:.0f} | "
            f"{s['hsr_ms']:.0f} | {s['scan_ms']:.0f} | {s['serve_io_ms']:.0f} | "
            f"{s['model_ms']:.0f} | {s['encode_ms']:.1f} | {r['coarse_steps']} | "
            f"{r['rebuilt_steps']} | {r['changed_lines_median']:.0f} | {r['rest_ms']:.0f} | "
            f"{r['scratch_ms']:.0f} |")


def _head(rec: dict, what: str) -> list[str]:
    d = rec["data"]
    return [f"`{rec['command']}` ({rec['date']}, revision {rec['revision']}, load average "
            f"{rec['load_before']} before / {rec['load_after']} after on {d['cpus']} cores; "
            "wall-clock times, one process plus `yproc serve`, so each stage runs on one core):",
            "",
            f"| scene | dragged | {what}model | steps | median ms | p95 ms | max ms | HSR | scan | "
            "serve I/O | model | encode | coarse steps | HSR rebuilds | changed lines | "
            "rest (refine) ms | from scratch ms |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
            + ("---|" if what else "")]


def _goal(scenes, whose: str = "") -> str:
    goal = all(r["median_ms"] <= 50 and r["p95_ms"] <= 100 for r in scenes)
    return ("Stage columns are per-step medians (ms). Goals (issue 19): median <= 50 ms, "
            f"p95 <= 100 ms: **{'met' if goal else 'not met'}** in this run{whose}.")


def render(rec: dict) -> str:
    """The "Viewer: pointer-to-frame latency" section of docs/performance.md."""
    d = rec["data"]
    out = _head(rec, "") + [_row(r, "") for r in d["scenes"]]
    out += ["", _goal(d["scenes"])]
    return "\n".join(out)


def render_lat(rec: dict) -> str:
    """The "Viewer latency: before and after" section (record viewer-lat): per scene the
    baseline binary's drag, then this tree's, from the same run."""
    d = rec["data"]
    out = _head(rec, "yproc | ")
    for b, r in zip(d["baseline"], d["scenes"]):
        out.append(_row(b, f"{b['yproc']} | "))
        out.append(_row(r, f"this tree ({rec['revision']}) | "))
    out += ["", _goal(d["scenes"], " by this tree's rows")]
    return "\n".join(out)
