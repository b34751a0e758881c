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

    diffengine bench span [--scenes teapot,cad] [--ratio 3] [--write]

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
from . import record, render as doc

SECTION = "## Span-serial array: clocks per line on real frames"
SCENES = {"teapot": "sw/scenes/teapot/teapot.scene", "cad": "sw/scenes/cad/cad.scene"}


def log(msg: str) -> None:
    record.log("span", msg)


def run_stream(path: Path, out: Path, rate: int) -> dict:
    env = dict(os.environ, DE_SPAN_STREAM=str(path), DE_SPAN_OUT=str(out),
               DE_SPAN_RATE=str(rate))
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
    ap.add_argument("--write", action="store_true")
    ap.set_defaults(func=command)


def command(a) -> int:
    run = record.Run("span")
    subprocess.run(["make", "-s", "-C", "sw/hsr", "build/yproc"], cwd=ROOT, check=True)
    tmp = Path(tempfile.mkdtemp(prefix="bench_span_"))
    rows = []
    for name in a.scenes.split(","):
        d = tmp / name
        d.mkdir()
        log(f"{name}: yproc scan")
        subprocess.run([str(ROOT / "sw/hsr/build/yproc"), "scan", SCENES[name], "-o", str(d)],
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
    rec = run.save({"rows": rows, "ratio": a.ratio}, a.write)
    log(f"raw results: {tmp}")
    if a.write:
        plot(rows, a.ratio, ROOT / "docs" / "img" / "span_clocks.png")
        return doc.write(["span"])
    print(render(rec))
    return 0


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


def render(rec: dict) -> str:
    """The "Span-serial array: clocks per line" section of docs/performance.md."""
    rows, ratio = rec["data"]["rows"], rec["data"]["ratio"]
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
        verdict += (f"On {sc} a band of lines needs more than the line period: the array "
                    f"falls up to {max(r['paced']['backlog_slots'] for r in rs)} slots behind "
                    f"the bus and a line's last pixel comes up to "
                    f"{max(max(r['paced']['lag_clocks']) for r in rs)} clocks after its "
                    f"Refresh; a display path (de_span_video) then needs a FIFO that deep "
                    f"and a Latency that long, or a faster core clock. ")
    body = f"""{SECTION}

Reproduce: `make bench-span` (`diffengine bench span --write`, ~{len(rows) * 1} min). Each
640x480 colour stream of `yproc scan` goes through the Verilated `de_span_array` (648
columns, 4 slots per pass) twice, and both frames must equal the functional model bit
for bit. *Unpaced*: slots as fast as the array takes them, so the clocks a line needs.
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

A line's work is its spans (one clock per column a command touches), one clock per
pass and the in-flight stalls (a command that starts on a column the previous one has
just visited waits up to 7 clocks for its write back); the Refresh costs one clock (the
old bank drains in parallel).

{verdict}
"""
    return body
