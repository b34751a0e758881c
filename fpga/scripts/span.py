#!/usr/bin/env python3
"""FPGA flow for the span-serial virtual array (rtl/varray/de_span_array.sv, docs/fpga.md).

    span.py [--cols 648] [--slots 4] [--ratio 3] [--freq 100] [--seed 1]

Synthesises fpga/span_top.sv with one and with three colours of --cols columns on the
LFE5U-85F (synth_ecp5), places and routes the three-colour design with nextpnr-ecp5 and
exits 1 when its fmax is below the core clock it needs: --ratio x the 640x480@60 pixel
clock (the array takes one column per core clock; docs/fpga.md says how the ratio is
chosen). Reports: fpga/reports/span_ecp5.{json,txt}; build products: fpga/build/span/.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from flow import (BUILD, ECP5, PIXEL_CLOCK_640, REPORTS, core_srcs, count,  # noqa: E402
                  fmax_of, nextpnr, path_summary, synth_seconds, timing_check, tool_versions, yosys)

SRCS = core_srcs("fpga", "span")   # fpga/de_fpga.core: de_pkg, de_span_array, span_top
KEYS = ["LUT4", "TRELLIS_FF", "CCU2C", "PFUMX", "L6MUX21", "TRELLIS_DPR16X4", "DP16KD",
        "MULT18X18D"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cols", type=int, default=648)
    ap.add_argument("--slots", type=int, default=4)
    ap.add_argument("--ratio", type=int, default=3,
                    help="core clock / pixel clock (default 3: 75.5 MHz)")
    ap.add_argument("--freq", type=float, default=100.0, help="nextpnr clock constraint")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    runs = {}
    for colours in (1, 3):
        tag = f"c{colours}_cols{args.cols}_slots{args.slots}"
        out = BUILD / "span" / tag
        print(f"[span {tag}] synthesis", flush=True)
        cells = yosys("span_ecp5.ys", out, "span_top", SRCS,
                      {"NumCols": args.cols, "MaxSlots": args.slots, "NumColours": colours})
        runs[tag] = {"colours": colours, "cells": {k: count(cells, k) for k in KEYS},
                     "seconds": synth_seconds(out)}
    need = args.ratio * PIXEL_CLOCK_640
    print(f"[span {tag}] place and route on {ECP5['name']} (needs {need:.2f} MHz)", flush=True)
    rep = nextpnr("ecp5", ECP5["args"], BUILD / "span" / tag, args.freq, args.seed)
    util = {k: v for k, v in (rep or {}).get("utilization", {}).items() if v["used"]}
    runs[tag]["pnr"] = {"fmax_mhz": fmax_of(rep), "needs_mhz": round(need, 3),
                        "utilization": util,
                        "critical_path": path_summary(rep) if rep else {}}
    report = {"command": "make -C fpga span", "device": ECP5["name"], "tools": tool_versions(),
              "columns_per_colour": args.cols, "max_slots": args.slots, "ratio": args.ratio,
              "nextpnr": {"freq_constraint_mhz": args.freq, "seed": args.seed}, "runs": runs}
    REPORTS.mkdir(exist_ok=True)
    (REPORTS / "span_ecp5.json").write_text(json.dumps(report, indent=1) + "\n")
    txt = text(report)
    (REPORTS / "span_ecp5.txt").write_text(txt)
    print(txt)
    return timing_check(runs[tag]["pnr"]["fmax_mhz"], need,
                        f"span array, 3 x {args.cols} columns, core clock {args.ratio} x pixel")


def text(rep: dict) -> str:
    L = [f"Span-serial array de_span_array on {rep['device']} - `{rep['command']}`",
         f"tools: {rep['tools']}",
         f"{rep['columns_per_colour']} columns per colour, {rep['max_slots']} slots per pass", "",
         f"{'run':28}" + "".join(f"{k:>16}" for k in KEYS) + f"{'s':>6}"]
    for tag, r in rep["runs"].items():
        L.append(f"{tag:28}" + "".join(f"{r['cells'][k]:>16}" for k in KEYS)
                 + f"{str(r['seconds']):>6}")
    dev = {"LUT4": ECP5["lut4"], "TRELLIS_FF": ECP5["ff"], "DP16KD": ECP5["dp16kd"]}
    for tag, r in rep["runs"].items():
        if "pnr" not in r:
            continue
        p = r["pnr"]
        L += ["", f"Place and route {tag} (nextpnr --freq {rep['nextpnr']['freq_constraint_mhz']}"
              f" --seed {rep['nextpnr']['seed']}): fmax {p['fmax_mhz']} MHz, needs "
              f"{p['needs_mhz']} MHz ({rep['ratio']} x {PIXEL_CLOCK_640} MHz)"]
        for k, v in p["utilization"].items():
            L.append(f"  {k:16} {v['used']:>7} / {v['available']:<7} "
                     f"({100 * v['used'] / max(v['available'], 1):.1f} %)")
        cp = p["critical_path"]
        if cp:
            L.append(f"  critical path {cp['total_ns']} ns = {cp['logic_ns']} logic + "
                     f"{cp['routing_ns']} routing, {cp['lut_levels']} LUT levels, "
                     f"{cp['carry_steps']} carry steps; from {cp['from']} to {cp['to']}")
            if cp["rtl_lines"]:
                L.append(f"  through {', '.join(cp['rtl_lines'][:8])}")
    one = next(iter(rep["runs"].values()))["cells"]
    L += ["", "One colour against the device: " + ", ".join(
        f"{k} {one[k]} ({100 * one[k] / n:.1f} %)" for k, n in dev.items())]
    return "\n".join(L) + "\n"


if __name__ == "__main__":
    sys.exit(main())
