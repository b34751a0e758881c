"""Span-serial array throughput on real frames (docs/fpga.md, "Span-serial array").

For each scene: `yproc scan` at 640x480 writes the three colour streams; each goes
through the Verilated de_span_array (648 columns, cocotb test `stream_file` in
tb/de_span_array) twice, and every frame must equal the functional model:

  * unpaced: slots as fast as the array takes them -> core clocks each line needs;
  * paced like the display's bus: HTotal = 800 slots per line (Nops pad), one slot every
    RATIO core clocks -> how long after its Refresh was due each line's last pixel left
    the array (the latency a display path must allow), and the largest backlog of slots.

Baseline from the same streams: the plain array takes one slot per pixel clock and has
every PE see every slot, i.e. 648 column operations per slot.

Levers (issue 18: the worst line within 90 % of the line budget): the red stream of each
scene once more through the RTL built without them (Forward = 0, Prefetch = 0, a
16-entry pass table; also with the driver's old idle clock after every slot) and with
each alone, against the RTL as it is, all in the same run; the levers not built (more
engines per colour, an ideal bypass, a faster core clock) from the timing model
(span_timing), which is checked against every RTL run here, line by line.

    diffengine bench span [--scenes teapot,cad] [--ratio 3] [--no-levers] [--write]

Records out/bench/span.json (bench.record); --write keeps it in docs/bench, renders the
section of docs/performance.md and writes docs/img/span_clocks.png.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .. import REPO as ROOT
from .. import isa
from ..formats import binfmt
from . import record, render as doc, span_timing

SECTION = "## Span-serial array: clocks per line on real frames"
SCENES = {"teapot": "sw/scenes/teapot/teapot.scene", "cad": "sw/scenes/cad/cad.scene"}


def log(msg: str) -> None:
    record.log("span", msg)


# RTL builds for the levers: (name, Forward, Prefetch, PassAw, driver gap).
NOW = ("the RTL now: Forward + Prefetch + 32-entry pass table", 1, 1, 5, 0)
RTL_LEVERS = [
    ("none (the RTL before), the driver's old idle clock after every slot", 0, 0, 4, 1),
    ("none (the RTL before), slots back to back", 0, 0, 4, 0),
    ("Prefetch alone", 0, 1, 4, 0),
    ("Forward alone", 1, 0, 4, 0),
    ("Forward + Prefetch", 1, 1, 4, 0),
    ("Forward + Prefetch + 128-entry pass table (PassAw = 7)", 1, 1, 7, 0),
]
BUDGET_90 = 0.9


def run_stream(path: Path, out: Path, rate: int, lever: tuple = NOW) -> dict:
    _, fwd, pf, aw, gap = lever
    env = dict(os.environ, DE_SPAN_STREAM=str(path), DE_SPAN_OUT=str(out),
               DE_SPAN_RATE=str(rate), DE_SPAN_FWD=str(fwd), DE_SPAN_PF=str(pf),
               DE_SPAN_PASSAW=str(aw), DE_SPAN_GAP=str(gap))
    t = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "pytest", "-q", "-x", "de_span_array"],
                         cwd=ROOT / "tb", env=env, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"bench_span: {path} (rate {rate}) failed:\n{res.stdout[-3000:]}")
    r = json.loads(out.read_text())
    r["wall_s"] = time.perf_counter() - t
    return r


def slots_per_line(path: Path) -> list[int]:
    n, out = 0, []
    for ident, _ in binfmt.decode_de48(path.read_bytes(), str(path)):
        n += 1
        if ident == isa.REFRESH:
            out.append(n)
            n = 0
    return out


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("--scenes", default="teapot,cad")
    ap.add_argument("--ratio", type=int, default=3)
    ap.add_argument("--no-levers", action="store_true",
                    help="skip the lever table (5 more RTL builds and runs per scene)")
    record.add_write(ap)
    ap.set_defaults(func=command)


def command(a) -> int:
    run = record.Run("span")
    subprocess.run(["make", "-s", "-C", "sw/yproc", "build/yproc"], cwd=ROOT, check=True)
    tmp = Path(tempfile.mkdtemp(prefix="bench_span_"))
    rows, levers = [], []
    for name in a.scenes.split(","):
        d = tmp / name
        d.mkdir()
        log(f"{name}: yproc scan")
        subprocess.run([str(ROOT / "sw/yproc/build/yproc"), "scan", SCENES[name], "-o", str(d)],
                       cwd=ROOT, check=True, capture_output=True)
        for ch in "rgb":
            s = d / f"{ch}.de48"
            log(f"{name} {ch}: unpaced")
            free = run_stream(s, d / f"{ch}_free.json", 0)
            log(f"{name} {ch}: paced at 1 slot / {a.ratio} clocks")
            paced = run_stream(s, d / f"{ch}_paced.json", a.ratio)
            rows.append({"scene": name, "ch": ch, "slots": slots_per_line(s),
                         "free": free, "paced": paced})
            c = free["clocks_per_line"]
            log(f"  clocks/line mean {sum(c) / len(c):.0f} max {max(c)}; paced lag max "
                f"{max(paced['lag_clocks'])}, backlog {paced['backlog_slots']}")
        if not a.no_levers:
            levers.append(measure_levers(name, d / "r.de48", rows[-3]["free"], a.ratio))
    rec = run.save({"rows": rows, "ratio": a.ratio, "levers": levers}, a.write)
    log(f"raw results: {tmp}")
    print(render_levers(rec["data"]))
    if a.write:
        plot(rows, a.ratio, ROOT / "docs" / "img" / "span_clocks.png")
        return doc.write(["span"])
    print(render(rec))
    return 0


def summary(c: list[int], ratio: int) -> dict:
    return {"mean": sum(c) / len(c), "max": max(c), "pct": 100 * max(c) / (ratio * 800),
            "worst_line": c.index(max(c))}


def measure_levers(scene: str, path: Path, now: dict, ratio: int) -> dict:
    """The red stream through the RTL without the levers and with each, and the timing
    model for the same builds and for the levers not built."""
    slots = list(binfmt.decode_de48(path.read_bytes(), str(path)))
    out = {"scene": scene, "rtl": [], "model": []}

    def model(**kw):
        return span_timing.simulate(slots, **kw)

    def paced(**kw):
        """The model paced like the bus: the largest lag and backlog."""
        st: dict = {}
        span_timing.simulate(slots, rate=ratio, stats=st, **kw)
        return {"model_lag": max(st["lag"]), "model_backlog": st["backlog"]}

    for lever in RTL_LEVERS + [NOW]:
        name, fwd, pf, aw, gap = lever
        log(f"{scene} r, levers: {name}")
        r = now if lever is NOW else run_stream(path, path.with_suffix(f".{fwd}{pf}{aw}{gap}.json"),
                                                0, lever)
        c = r["clocks_per_line"]
        kw = dict(prefetch=bool(pf), fwd="rtl" if fwd else "none", table=1 << aw)
        m = model(gap=gap, **kw)
        # Line 0 also holds the reset sweep and the first slots' way in: left out.
        err = max(abs(x - y) for x, y in zip(c[1:], m[1:]))
        out["rtl"].append({"name": name, **summary(c, ratio), "model_max": max(m),
                           "model_err": err, **paced(**kw),
                           "wall_s": 0 if lever is NOW else r["wall_s"]})
        log(f"  RTL mean {sum(c) / len(c):.0f} max {max(c)}; model max {max(m)}, "
            f"|model - RTL| <= {err} clocks per line")
    best = dict(prefetch=True, fwd="rtl", table=32)
    for name, kw in [
            ("32-entry pass table alone", dict(table=32)),
            ("ideal bypass (no wait ever; the most better packing of spans by the "
             "y-processor could save) + Prefetch + 32 entries", dict(best, fwd="ideal")),
            ("2 engines per colour (+ Forward, Prefetch, 32 entries)", dict(best, engines=2)),
            ("3 engines per colour (+ Forward, Prefetch, 32 entries)", dict(best, engines=3))]:
        m = model(**kw)
        out["model"].append({"name": name, **summary(m, ratio), **paced(**kw)})
    return out


def render_levers(data: dict) -> str:
    """The lever table: the worst line of each scene against the line budget."""
    ratio = data["ratio"]
    levs = data.get("levers") or []
    if not levs:
        return ""
    budget = ratio * 800
    head = " | ".join(f"{lv['scene']}: mean / max, max / {budget:,}" for lv in levs)
    lines = [f"| lever | from | {head} |", "|---|---|" + "---|" * len(levs)]

    def cells(rs):
        return " | ".join(f"{r['mean']:,.0f} / {r['max']:,}, **{r['pct']:.1f} %**"
                          + (f"; paced: lag {r['model_lag']:,}, backlog {r['model_backlog']}"
                             if "model_lag" in r else "") for r in rs)

    for i, r0 in enumerate(levs[0]["rtl"]):
        rs = [lv["rtl"][i] for lv in levs]
        errs = ", ".join(f"{r['model_err']}" for r in rs)
        lines.append(f"| {r0['name']} | RTL (model within {errs} clocks per line) | "
                     f"{cells(rs)} |")
    for i, r0 in enumerate(levs[0]["model"]):
        lines.append(f"| {r0['name']} | model | {cells([lv['model'][i] for lv in levs])} |")
    for mhz, r in [(78.125, 78.125 / 25.0), (100.7, 4.0)]:
        b = 800 * r
        lines.append(f"| core clock {mhz} MHz ({r:g} x the pixel clock: {b:,.0f} clocks per "
                     f"line), the RTL now | budget | " + " | ".join(
                         f"{lv['rtl'][-1]['max']:,} of {b:,.0f}, **{100 * lv['rtl'][-1]['max'] / b:.0f} %**"
                         for lv in levs) + " |")
    # The verdict over every colour of the main table (the lever rows are the red stream).
    worst = {}
    for r in data["rows"]:
        worst[r["scene"]] = max(worst.get(r["scene"], 0), max(r["free"]["clocks_per_line"]))
    ok = all(w <= BUDGET_90 * budget for w in worst.values())
    each = ", ".join(f"{sc} {w:,} ({100 * w / budget:.1f} %)" for sc, w in worst.items())
    verdict = (f"Worst line over all three colours, the RTL now: {each}. "
               + ("Every frame here stays within 90 % of the line budget." if ok else
                  "NOT every frame here stays within 90 % of the line budget."))
    return "\n".join(lines) + "\n\n" + verdict + "\n"


def plot(rows: list, ratio: int, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    r = rows[0]
    c = r["free"]["clocks_per_line"]
    fig, ax = plt.subplots(figsize=(9, 4.2))
    ax.plot(c, lw=0.8, label=f"span array: core clocks per line ({r['scene']}, {r['ch']})")
    ax.plot([ratio * s for s in r["slots"]], lw=0.8,
            label=f"{ratio} x slots per line (the bus delivers one slot per {ratio} clocks)")
    ax.axhline(ratio * 800, color="k", ls="--", lw=0.8, label=f"line period: {ratio} x 800 clocks")
    ax.set_xlabel("scanline")
    ax.set_ylabel("core clocks")
    ax.set_title("de_span_array, 648 columns: work per line against the line period")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def time_s(rec: dict) -> float:
    """Wall time of the RTL runs of a record."""
    t = sum(r["free"].get("wall_s", 0) + r["paced"].get("wall_s", 0) for r in rec["data"]["rows"])
    return t + sum(x.get("wall_s", 0) for lv in rec["data"].get("levers", []) for x in lv["rtl"])


def render(rec: dict) -> str:
    """The "Span-serial array: clocks per line" section of docs/performance.md."""
    rows, ratio = rec["data"]["rows"], rec["data"]["ratio"]
    minutes = (time_s(rec)) / 60
    lines = []
    for r in rows:
        c, sl = r["free"]["clocks_per_line"], r["slots"]
        lag, p = r["paced"]["lag_clocks"], r["paced"]
        plain_ops = 648 * sum(sl) / len(sl)
        lines.append(
            f"| {r['scene']} | {r['ch']} | {sum(sl) / len(sl):.0f} / {max(sl)} | "
            f"{sum(c) / len(c):,.0f} / {max(c):,} | {100 * max(c) / (ratio * 800):.0f} % | "
            f"{max(lag)} ({max(lag) / ratio:.0f} px) | {p['backlog_slots']} | "
            f"{plain_ops / (sum(c) / len(c)):.0f}x |")
    ok = [r["scene"] for r in rows if r["paced"]["backlog_slots"] == 0]
    bad = [r for r in rows if r["paced"]["backlog_slots"] > 0]
    verdict = ""
    if ok:
        verdict += (f"Paced at the bus rate the array keeps up with every line of "
                    f"{', '.join(sorted(set(ok)))}: no slot waits, and each line's last pixel "
                    f"is out within the lag above of its Refresh. ")
    for sc in sorted({r["scene"] for r in bad}):
        rs = [r for r in bad if r["scene"] == sc]
        verdict += (f"On {sc}, paced, the array falls up to "
                    f"{max(r['paced']['backlog_slots'] for r in rs)} slots behind the bus "
                    f"(the pass table full behind long passes) and a line's last pixel comes "
                    f"up to {max(max(r['paced']['lag_clocks']) for r in rs)} clocks after "
                    f"its Refresh was due; a display path (de_span_video) needs a FIFO that "
                    f"deep and a Latency that long. ")
    body = f"""{SECTION}

Reproduce: `make bench-span` (`diffengine bench span --write`, {minutes:.0f} min on
{rec['date']}, load average {rec['load_before']} before, {rec['load_after']} after).
Each 640x480 colour stream of `yproc scan` goes through the Verilated `de_span_array`
(648 columns, 4 slots per pass, Forward, Prefetch, a 32-entry pass table) twice, and
both frames must equal the functional model bit for bit. *Unpaced*: slots back to back
as fast as the array takes them (as a FIFO with a backlog hands them over), so the
clocks a line needs.
*Paced*: the display's bus, 800 slots per line (Nops pad), one slot every {ratio} core
clocks ({ratio} x 25.175 = {ratio * 25.175:.2f} MHz): *lag* = clocks from the moment a line's
Refresh was due until its last pixel left the array (the drain puts out one pixel per
core clock, so the first leaves ~648 clocks earlier); *backlog* = slots that had to
wait because the array was not ready. Baseline, same streams: the plain array takes one
slot per pixel clock and every PE sees every slot, 648 column operations per slot; the
last column gives its operations per line over the span array's clocks per line.

| scene | colour | slots per line mean / max | span array clocks per line mean / max | max / line period | paced: lag max, clocks | paced: backlog | plain array ops / span clocks |
|---|---|---|---|---|---|---|---|
{chr(10).join(lines)}

![core clocks per line](img/span_clocks.png)

A line's work is its spans (one clock per column a command touches) and the in-flight
waits (a command that starts on a column an earlier one has just visited waits until
that one has left the first 4 stages, at most 4 clocks; its state is then bypassed from
write back), plus the front end's clock per slot and per pass when the pass table runs
empty; the Refresh costs one clock (the old bank drains in parallel).

{verdict}

### Span-serial array: levers against the line budget (issue 18)

The worst line of each frame against the line period ({ratio} x 800 = {ratio * 800:,} core
clocks; issue 18 asks for at most 90 %), red stream, unpaced. RTL rows are Verilated
builds of `de_span_array` measured in this run (every frame bit-exact); model rows are
`span_timing.simulate`, whose figures for the RTL rows are within the clocks per line
shown (lines 1-479). Forward: a token waits only while an earlier token of its column
is in the first K stages, and gets the column's state from write back or the two clocks
after it (at most K clocks of wait instead of K + 3). Prefetch: the next pass is decoded
a clock ahead and starts right behind the last token of the running one (no load clock
per pass). A 32-entry pass table lets the front end run further ahead behind a long
pass. More engines per colour (disjoint column ranges, each with its own state banks and
pipeline) and an ideal bypass are estimates; the core clock rows divide the RTL's worst
line by a longer line period: 78.125 MHz is the board's PLL output (pixel clock 25.0 MHz).
*Paced* figures in the lever table (where given) are the model's, paced like the bus: the
largest lag (clocks from a Refresh's due time to its line's last pixel; ~661 is the
drain alone) and the largest backlog of slots (de_span_video's FIFO holds 256). The
worst line unpaced is not the whole story: a pass table that fills up behind long passes
stops the front end, and the bus's slots then wait in the display FIFO.

{render_levers(rec['data'])}
"""
    return body
