"""Span-serial array throughput on real frames (docs/fpga.md, "Span-serial array").

For each scene: `yproc scan` at 640x480 writes the three colour streams; each goes
through the Verilated de_span_array (648 columns, cocotb test `stream_file` in
tb/de_span_array) twice, and every frame must equal the functional model:

  * unpaced: slots as fast as the array takes them -> core clocks each line needs;
  * paced like the display's bus: HTotal = 800 slots per line (Nops pad), one slot per
    RATIO core clocks on average, slot k at floor(k * RATIO) (span_timing.slot_due; RATIO
    a fraction, by default the board's 25/8 from its PLL, board()) -> how long after its
    Refresh was due each line's last pixel left the array, and the largest backlog of
    slots; once more at --compare-ratio (3, the bench's old integer ratio).

The verdict (issue 18 item 5), at RATIO, over all three colours of each scene: (a) the
worst line unpaced within 90 % of the line period (RATIO x 800 core clocks); (b) paced,
no line's last pixel later than the board's SpanLatency (300 pixel clocks = 300 x RATIO
core clocks) after its Refresh was due. The command exits 1 if either fails (after
keeping the record and, with --write, rendering it), and says which.

Baseline from the same streams: the plain array takes one slot per pixel clock and has
every PE see every slot, i.e. 648 column operations per slot.

Levers (issue 18: the worst line within 90 % of the line budget): the red stream of each
scene once more through the RTL built without them (Forward = 0, Prefetch = 0, a
16-entry pass table; also with the driver's old idle clock after every slot) and with
each alone, against the RTL as it is, all in the same run; the levers not built (more
engines per colour, an ideal bypass, a faster core clock) from the timing model
(span_timing), which is checked against every RTL run here, line by line.

    diffengine bench span [--scenes teapot,cad] [--ratio 25/8] [--compare-ratio 3]
                          [--latency 300] [--no-levers] [--write]

Records out/bench/span.json (bench.record); --write keeps it in docs/bench, renders the
section of docs/performance.md and writes docs/img/span_clocks.png.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
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
HTOTAL = sum(isa.VIDEO_MODES[0][1])   # 800 slots per line of the bus (640x480, spec/video.toml)

# The board's clocks and span path, read from the one place each is set: the PLL's
# dividers in the ULX3S shell (pixel clock = VCO / CLKOS_DIV, core clock = VCO /
# CLKOS2_DIV, so the ratio is CLKOS_DIV / CLKOS2_DIV = 25/8), SpanLatency from the
# board Makefile that passes it to de_board_core, the span FIFO's depth from
# de_board_core's SpanFifoAw (the Makefile does not override it).
BOARD_SHELL = "fpga/ulx3s/ulx3s_top.sv"
BOARD_MAKEFILE = "fpga/ulx3s/Makefile"
BOARD_CORE = "rtl/board/de_board_core.sv"


def _grab(rel: str, pattern: str) -> tuple[int, str]:
    """The first number `pattern` captures in the file `rel`, and its file:line."""
    path = ROOT / rel
    text = path.read_text()
    m = re.search(pattern, text, re.M)
    if not m:
        raise SystemExit(f"bench span: {path}: no match for {pattern!r} (the board's "
                         f"clocks are read from there)")
    line = text.count("\n", 0, m.start()) + 1
    return int(m.group(1)), f"{rel}:{line}"


def board() -> dict:
    """The board's clock ratio (core clocks per pixel clock, a Fraction), its clocks in
    MHz, SpanLatency (pixel clocks) and span FIFO depth (slots), each with the file:line
    it comes from."""
    ref = _grab(BOARD_SHELL, r"^\s*\.CLKI_DIV\s*\((\d+)\)")[0]
    fb = _grab(BOARD_SHELL, r"^\s*\.CLKFB_DIV\s*\((\d+)\)")[0]
    op = _grab(BOARD_SHELL, r"^\s*\.CLKOP_DIV\s*\((\d+)\)")[0]
    pix, pix_at = _grab(BOARD_SHELL, r"^\s*\.CLKOS_DIV\s*\((\d+)\)")
    core, core_at = _grab(BOARD_SHELL, r"^\s*\.CLKOS2_DIV\s*\((\d+)\)")
    lat, lat_at = _grab(BOARD_MAKEFILE, r"^SPAN_LATENCY\s*\??=\s*(\d+)")
    aw, aw_at = _grab(BOARD_CORE, r"parameter\s+int\s+unsigned\s+SpanFifoAw\s*=\s*(\d+)")
    vco = Fraction(25) / ref * fb * op        # clk_25mhz, feedback from CLKOP
    return {"ratio": Fraction(pix, core), "pixel_mhz": float(vco / pix),
            "core_mhz": float(vco / core), "latency_px": lat, "fifo_slots": 1 << aw,
            "sources": {"ratio": f"{pix_at}, {core_at}", "latency": lat_at, "fifo": aw_at}}


def ratio_arg(text: str) -> Fraction:
    """argparse type of --ratio: "3", "3.125", "25/8" -> Fraction; a clear error else."""
    try:
        return span_timing.parse_ratio(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def compare_arg(text: str) -> Fraction:
    """argparse type of --compare-ratio: a ratio, or 0 / none for no comparison."""
    return Fraction(0) if text.strip() in ("0", "none") else ratio_arg(text)


def fmt_ratio(r) -> str:
    """25/8 -> "25/8 = 3.125", 3 -> "3"."""
    r = Fraction(r)
    return str(r) if r.denominator == 1 else f"{r} = {float(r):g}"


def run_stream(path: Path, out: Path, rate, lever: tuple = NOW) -> dict:
    _, fwd, pf, aw, gap = lever
    env = dict(os.environ, DE_SPAN_STREAM=str(path), DE_SPAN_OUT=str(out),
               DE_SPAN_RATE=str(Fraction(rate)), DE_SPAN_FWD=str(fwd), DE_SPAN_PF=str(pf),
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
    ap.add_argument("--scenes", default="teapot,cad", help="scenes (%(default)s)")
    ap.add_argument("--ratio", type=ratio_arg, default=None,
                    help="core clocks per pixel clock of the paced runs and the verdict: "
                    "3, 3.125, 25/8 (default: the board's, CLKOS_DIV / CLKOS2_DIV of the "
                    f"PLL in {BOARD_SHELL})")
    ap.add_argument("--compare-ratio", type=compare_arg, default=Fraction(3),
                    help="a second ratio whose paced runs are measured in the same run, "
                    "for comparison (default 3, the bench's old integer ratio; 0 or none: "
                    "skip)")
    ap.add_argument("--latency", type=int, default=None,
                    help="SpanLatency in pixel clocks for the paced criterion (default: "
                    f"the board's SPAN_LATENCY, {BOARD_MAKEFILE})")
    ap.add_argument("--no-levers", action="store_true",
                    help="skip the lever table (5 more RTL builds and runs per scene)")
    record.add_write(ap)
    ap.set_defaults(func=command)


def model_paced(slots, rate, **kw) -> dict:
    """The timing model paced like the bus at `rate` (RTL levers by default)."""
    st: dict = {}
    span_timing.simulate(slots, rate=rate, stats=st,
                         **(kw or dict(prefetch=True, fwd="rtl", table=32)))
    return {"lag": st["lag"], "backlog": st["backlog"]}


def command(a) -> int:
    run = record.Run("span")
    brd = board()
    ratio = a.ratio if a.ratio is not None else brd["ratio"]
    latency = a.latency if a.latency is not None else brd["latency_px"]
    ratios = [ratio] + [r for r in [a.compare_ratio] if r and r != ratio]
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
            c = free["clocks_per_line"]
            log(f"  clocks/line mean {sum(c) / len(c):.0f} max {max(c)}")
            slots = list(binfmt.decode_de48(s.read_bytes(), str(s)))
            paced = {}
            for r in ratios:
                log(f"{name} {ch}: paced, slot k at floor(k x {fmt_ratio(r)}) clocks")
                p = run_stream(s, d / f"{ch}_paced_{float(r):g}.json", r)
                m = model_paced(slots, r)
                # The model against the RTL, paced: lag per line (all lines), backlog.
                p["model_lag_err"] = max(abs(x - y) for x, y in zip(p["lag_clocks"], m["lag"]))
                p["model_backlog"] = m["backlog"]
                paced[str(r)] = p
                late = sum(x > latency * r for x in p["lag_clocks"])
                log(f"  paced lag max {max(p['lag_clocks'])} (model within "
                    f"{p['model_lag_err']}), backlog {p['backlog_slots']} (model "
                    f"{m['backlog']}), {late} lines later than {latency} pixel clocks")
            rows.append({"scene": name, "ch": ch, "slots": slots_per_line(s),
                         "free": free, "paced": paced})
        if not a.no_levers:
            levers.append(measure_levers(name, d / "r.de48", rows[-3]["free"], ratio))
    rec = run.save({"rows": rows, "ratio": str(ratio), "ratios": [str(r) for r in ratios],
                    "latency_px": latency, "board": {k: (str(v) if k == "ratio" else v)
                                                     for k, v in brd.items()},
                    "levers": levers}, a.write)
    log(f"raw results: {tmp}")
    print(render_levers(rec["data"]))
    ok, text = verdict(rec["data"])
    if a.write:
        plot(rec["data"], ROOT / "docs" / "img" / "span_clocks.png")
        status = doc.write(["span"])
    else:
        print(render(rec))
        status = 0
    print(text)
    return status or (0 if ok else 1)


def summary(c: list[int], ratio) -> dict:
    return {"mean": sum(c) / len(c), "max": max(c),
            "pct": float(100 * max(c) / (Fraction(ratio) * HTOTAL)),
            "worst_line": c.index(max(c))}


def measure_levers(scene: str, path: Path, now: dict, ratio) -> dict:
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


def _ratio(data: dict) -> Fraction:
    return Fraction(str(data["ratio"]))


def _paced(row: dict, data: dict) -> dict:
    """A row's paced runs by ratio ("25/8" -> run); a record from before the fractional
    ratio has one run at its integer ratio."""
    p = row["paced"]
    return p if "lag_clocks" not in p else {str(data["ratio"]): p}


def _ratios(data: dict) -> list[Fraction]:
    return [Fraction(r) for r in data.get("ratios", [str(data["ratio"])])]


def verdict(data: dict, ratio=None) -> tuple[bool, str]:
    """Issue 18 item 5 at `ratio` (default the record's own), over every colour of each
    scene: (a) the worst line unpaced <= 90 % of the line period (ratio x 800 core clocks);
    (b) paced at that ratio, no line later than SpanLatency pixel clocks (= SpanLatency x
    ratio core clocks), with the worst lag as a % of it. -> (both hold, the text)."""
    r = Fraction(ratio if ratio is not None else _ratio(data))
    lat_px = data.get("latency_px")
    budget, lat = r * HTOTAL, (lat_px or 0) * r
    scenes = list(dict.fromkeys(row["scene"] for row in data["rows"]))
    a_ok, b_ok, a_txt, b_txt = True, True, [], []
    for sc in scenes:
        rows = [row for row in data["rows"] if row["scene"] == sc]
        w = max(max(row["free"]["clocks_per_line"]) for row in rows)
        a_ok &= w <= BUDGET_90 * budget
        a_txt.append(f"{sc} {w:,} ({float(100 * w / budget):.1f} %)")
        runs = [_paced(row, data).get(str(r)) for row in rows]
        if lat_px is None or None in runs:
            b_ok = False
            b_txt.append(f"{sc}: not measured at ratio {r}")
            continue
        lag = max(max(p["lag_clocks"]) for p in runs)
        late = max(sum(x > lat for x in p["lag_clocks"]) for p in runs)
        b_ok &= late == 0
        b_txt.append(f"{sc} lag {lag:,} ({float(100 * lag / lat):.1f} %), "
                     f"{late} late line{'s' * (late != 1)}")
    failed = [c for c, ok in (("(a)", a_ok), ("(b)", b_ok)) if not ok]
    text = (f"At ratio {fmt_ratio(r)}: (a) worst line unpaced, of the {float(budget):,g}-clock "
            f"line period: {', '.join(a_txt)}: {'within' if a_ok else 'NOT within'} 90 %. "
            f"(b) paced, the worst lag of a line's last pixel behind its Refresh, of "
            f"SpanLatency {lat_px} pixel clocks = {float(lat):,g} core clocks (late lines: "
            f"the most of any colour): {'; '.join(b_txt)}. "
            + ("Verdict: PASS, (a) and (b) hold." if not failed else
               f"Verdict: FAIL, {' and '.join(failed)} failed."))
    return not failed, text


def render_levers(data: dict) -> str:
    """The lever table: the worst line of each scene against the line budget."""
    ratio = _ratio(data)
    levs = data.get("levers") or []
    if not levs:
        return ""
    budget = ratio * HTOTAL
    head = " | ".join(f"{lv['scene']}: mean / max, max / {float(budget):,g}" for lv in levs)
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
    pix = (data.get("board") or {}).get("pixel_mhz", 25.0)
    for r in [x for x in _ratios(data)[1:] + [Fraction(4)] if x != ratio]:
        b = HTOTAL * r
        lines.append(f"| core clock {float(r * pix):g} MHz ({fmt_ratio(r)} x the board's "
                     f"{pix:g} MHz pixel clock: {float(b):,g} clocks per line), the RTL now | "
                     "budget | " + " | ".join(
                         f"{lv['rtl'][-1]['max']:,} of {float(b):,g}, "
                         f"**{float(100 * lv['rtl'][-1]['max'] / b):.0f} %**"
                         for lv in levs) + " |")
    return "\n".join(lines) + "\n"


def plot(data: dict, path: Path) -> None:
    """Top: core clocks per line of the first stream against the line period; bottom:
    each scene's red stream paced, lag per line against SpanLatency, at every ratio."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows, ratio = data["rows"], _ratio(data)
    r0 = rows[0]
    c = r0["free"]["clocks_per_line"]
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(9, 7.4))
    ax.plot(c, lw=0.8, label=f"span array: core clocks per line ({r0['scene']}, {r0['ch']})")
    ax.plot([float(ratio) * s for s in r0["slots"]], lw=0.8,
            label=f"{float(ratio):g} x slots per line (the bus: one slot per "
                  f"{float(ratio):g} clocks)")
    ax.axhline(float(ratio * HTOTAL), color="k", ls="--", lw=0.8,
               label=f"line period: {float(ratio):g} x {HTOTAL} clocks")
    ax.axhline(float(BUDGET_90 * ratio * HTOTAL), color="r", ls=":", lw=0.8, label="90 %")
    ax.set_xlabel("scanline")
    ax.set_ylabel("core clocks")
    ax.set_title("de_span_array, 648 columns: work per line against the line period")
    ax.legend(loc="upper right", fontsize=8)
    lat = data.get("latency_px")
    styles = iter(["-", "--", ":", "-."])
    scenes = list(dict.fromkeys(row["scene"] for row in rows))
    for r in _ratios(data):
        ls = next(styles)
        for row in rows:
            p = _paced(row, data).get(str(r))
            if row["ch"] == "r" and p:
                bx.plot(p["lag_clocks"], lw=0.8, ls=ls, color=f"C{scenes.index(row['scene'])}",
                        label=f"{row['scene']} r, ratio {float(r):g}")
        if lat:
            bx.axhline(float(lat * r), color="k", ls=ls, lw=0.7,
                       label=f"SpanLatency {lat} px = {float(lat * r):g} clocks at {float(r):g}")
    bx.set_xlabel("scanline")
    bx.set_ylabel("core clocks")
    bx.set_title("paced like the bus: Refresh due -> the line's last pixel out (lag)")
    bx.legend(loc="upper right", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def time_s(rec: dict) -> float:
    """Wall time of the RTL runs of a record."""
    data = rec["data"]
    t = sum(r["free"].get("wall_s", 0) + sum(p.get("wall_s", 0) for p in _paced(r, data).values())
            for r in data["rows"])
    return t + sum(x.get("wall_s", 0) for lv in data.get("levers", []) for x in lv["rtl"])


def render(rec: dict) -> str:
    """The "Span-serial array: clocks per line" section of docs/performance.md."""
    data = rec["data"]
    rows, ratio, ratios = data["rows"], _ratio(data), _ratios(data)
    lat = data.get("latency_px")
    brd = data.get("board") or {}
    minutes = (time_s(rec)) / 60
    lines = []
    for r in rows:
        c, sl = r["free"]["clocks_per_line"], r["slots"]
        runs = _paced(r, data)
        paced = []
        for x in ratios:
            p = runs[str(x)]
            lag = p["lag_clocks"]
            late = sum(v > lat * x for v in lag) if lat else "-"
            err = f" (model ±{p['model_lag_err']})" if "model_lag_err" in p else ""
            paced.append(f"{max(lag):,}{err}, {p['backlog_slots']}, {late}")
        plain_ops = 648 * sum(sl) / len(sl)
        lines.append(
            f"| {r['scene']} | {r['ch']} | {sum(sl) / len(sl):.0f} / {max(sl)} | "
            f"{sum(c) / len(c):,.0f} / {max(c):,} | "
            f"{float(100 * max(c) / (ratio * HTOTAL)):.1f} % | " + " | ".join(paced) +
            f" | {plain_ops / (sum(c) / len(c)):.0f}x |")
    paced_head = [f"paced at {fmt_ratio(x)}: lag max (clocks), backlog, late lines"
                  for x in ratios]
    table = record.table_head("scene", "colour", "slots per line mean / max",
                              "span array clocks per line mean / max",
                              f"max / {float(ratio * HTOTAL):,g}", *paced_head,
                              "plain array ops / span clocks")
    verdicts = [verdict(data, x)[1] for x in ratios]
    fifo_txt = (f"\n(the board's span FIFO holds {brd['fifo_slots']:,} slots, "
                f"{brd['sources']['fifo']})" if brd else "")
    src = brd.get("sources", {})
    board_txt = (f"the board's ratio, {fmt_ratio(ratio)}\n({brd['core_mhz']:g} MHz core / "
                 f"{brd['pixel_mhz']:g} MHz pixel clock: the PLL's CLKOS_DIV / CLKOS2_DIV, "
                 f"{src.get('ratio')})" if brd and Fraction(brd["ratio"]) == ratio
                 else f"ratio {fmt_ratio(ratio)}")
    body = f"""{SECTION}

Reproduce: `make bench-span` (`diffengine bench span --write`,
{rec['seconds'] / 60:.0f} min, of which {minutes:.0f} min of RTL runs, on {rec['date']} UTC,
load average {rec['load_before']} before, {rec['load_after']} after: other jobs shared the 2
cores; cycle counts do not depend on the load).
Each 640x480 colour stream of `yproc scan` goes through the Verilated `de_span_array`
(648 columns, 4 slots per pass, Forward, Prefetch, a 32-entry pass table) once unpaced
and once paced at each ratio, and every frame must equal the functional model bit for
bit. *Unpaced*: slots back to back as fast as the array takes them (as a FIFO with a
backlog hands them over), so the clocks a line needs.
*Paced*: the display's bus, {HTOTAL} slots per line (Nops pad), one slot per *ratio* core
clocks on average, slot k due at floor(k × ratio) (exact for a fraction; the same pacer,
`span_timing.slot_due`, in the RTL driver and the timing model), at
{board_txt},
and at {', '.join(fmt_ratio(x) for x in ratios[1:]) or 'no other ratio'} for comparison.
*lag* = clocks from the moment a line's Refresh was due until its last pixel left the
array (the drain puts out one pixel per core clock, so the first leaves ~648 clocks
earlier), with the timing model's largest difference from the RTL over all lines;
*backlog* = slots that had to wait because the array was not ready{fifo_txt};
*late lines* = lines whose lag is over
SpanLatency = {lat} pixel clocks ({src.get('latency', '')}) = {lat} × ratio core clocks,
i.e. not complete in the line buffer when the display reads it out. Baseline, same
streams: the plain array takes one slot per pixel clock and every PE sees every slot,
648 column operations per slot; the last column gives its operations per line over the
span array's clocks per line.

{chr(10).join(table)}
{chr(10).join(lines)}

![core clocks per line; paced lag per line](img/span_clocks.png)

A line's work is its spans (one clock per column a command touches) and the in-flight
waits (a command that starts on a column an earlier one has just visited waits until
that one has left the first 4 stages, at most 4 clocks; its state is then bypassed from
write back), plus the front end's clock per slot and per pass when the pass table runs
empty; the Refresh costs one clock (the old bank drains in parallel).

**Verdict** (issue 18 item 5; `diffengine bench span` exits 1 when it fails at its
`--ratio`, {fmt_ratio(ratio)} here). {verdicts[0]}

{chr(10).join('For comparison. ' + v for v in verdicts[1:])}

### Span-serial array: levers against the line budget (issue 18)

The worst line of each frame against the line period ({fmt_ratio(ratio)} x {HTOTAL} =
{float(ratio * HTOTAL):,g} core clocks; issue 18 asks for at most 90 %), red stream,
unpaced. RTL rows are Verilated builds of `de_span_array` measured in this run (every
frame bit-exact); model rows are `span_timing.simulate`, whose figures for the RTL rows
are within the clocks per line shown (lines 1-479). Forward: a token waits only while
an earlier token of its column is in the first K stages, and gets the column's state
from write back or the two clocks after it (at most K clocks of wait instead of K + 3).
Prefetch: the next pass is decoded a clock ahead and starts right behind the last token
of the running one (no load clock per pass). A 32-entry pass table lets the front end
run further ahead behind a long pass. More engines per colour (disjoint column ranges,
each with its own state banks and pipeline) and an ideal bypass are estimates; the core
clock rows divide the RTL's worst line by another line period.
*Paced* figures in the lever table are the model's, paced like the bus at
{fmt_ratio(ratio)}: the largest lag (clocks from a Refresh's due time to its line's last
pixel; ~661 is the drain alone) and the largest backlog of slots. The worst line
unpaced is not the whole story: a pass table that fills up behind long passes stops the
front end, and the bus's slots then wait in the display FIFO.

{render_levers(data)}
"""
    return body
