#!/usr/bin/env python3
"""Timing gate and report of the ULX3S board top (fpga/ulx3s/Makefile, docs/board.md §8).

Reads nextpnr's --report JSON, the yosys stat JSON and the nextpnr log; prints and writes
fpga/reports/board_ulx3s.{txt,json}: cells after synthesis (LUT4, FF, DP16KD, MULT18),
the placed utilisation, and per clock domain nextpnr's fmax against its constraint and
against the nominal rates (pixel 25.175 MHz VESA, bit clock 5 x 25.175 = 125.875 MHz).
Exit 1 when any clock's fmax is below its constraint: the Makefile then makes no .bit.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

NOMINAL = {"pixel": 25.175, "shift": 5 * 25.175, "core": 78.125}
DEVICE = {"LUT4": 83640, "TRELLIS_FF": 83640, "DP16KD": 208, "MULT18X18D": 156}


def domain(name: str) -> str:
    if "shift" in name:
        return "shift"
    if "core" in name:
        return "core"
    if "pix" in name:
        return "pixel"
    return name


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--report", required=True)
    ap.add_argument("--stat", required=True)
    ap.add_argument("--log", required=True)
    ap.add_argument("--num-chips", type=int, required=True)
    ap.add_argument("--pf-depth", type=int, required=True,
                    help="prefetch FIFO words per colour (the frames are in the SDRAM)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--span", type=int, default=0)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()

    rep = json.loads(Path(a.report).read_text())
    stat = json.loads(Path(a.stat).read_text())
    cells = stat["design"]["num_cells_by_type"]
    log = Path(a.log).read_text() if Path(a.log).exists() else ""
    tool = re.findall(r"nextpnr-\S+", log[:400])

    lines = [f"Difference Engine board top on ULX3S (LFE5U-85F-6 CABGA381) - make -C fpga/ulx3s",
             (f"configuration: span-serial arrays, {9 * a.num_chips} columns x 3 colours on the "
              "78.125 MHz core clock, " if a.span else
              f"configuration: NumChips {a.num_chips} per colour ({9 * a.num_chips} PEs x 3 colours), ") +
             f"SDRAM frame store, prefetch FIFOs {a.pf_depth} words x 3 colours, NumBuf 1, "
             "BufDepth 16, mode 0 "
             f"(640x480 timing, 25.0 MHz pixel clock)",
             f"nextpnr seed {a.seed}", "",
             "Synthesis (yosys synth_ecp5), cells of the whole board top:"]
    syn = {}
    for k in ("LUT4", "TRELLIS_FF", "CCU2C", "PFUMX", "L6MUX21", "TRELLIS_DPR16X4", "DP16KD",
              "MULT18X18D", "ALU54B", "EHXPLLL", "ODDRX1F"):
        syn[k] = int(cells.get(k, 0))
        pct = f"  ({100 * syn[k] / DEVICE[k]:.1f} % of {DEVICE[k]})" if k in DEVICE else ""
        lines.append(f"  {k:16s} {syn[k]:7d}{pct}")
    util = {k: v["used"] for k, v in rep.get("utilization", {}).items() if v["used"]}
    lines += ["", "Placed (nextpnr utilisation): " + ", ".join(f"{k} {v}" for k, v in util.items()),
              "", "Timing (nextpnr, worst register-to-register path per clock):"]
    ok = True
    clocks = {}
    for name, v in sorted(rep.get("fmax", {}).items()):
        ach, con = v["achieved"], v["constraint"]
        dom = domain(name)
        nom = NOMINAL.get(dom)
        margin = ach - con
        status = "PASS" if ach >= con else "FAIL"
        ok &= ach >= con
        s = (f"  {dom:6s} ({name}): fmax {ach:7.2f} MHz vs constraint {con:7.2f} MHz: "
             f"margin {margin:+.2f} MHz ({100 * margin / con:+.0f} %) {status}")
        if nom:
            s += f"; vs nominal {nom:.3f} MHz: {100 * (ach - nom) / nom:+.0f} %"
        lines.append(s)
        clocks[name] = {"domain": dom, "fmax_mhz": round(ach, 2), "constraint_mhz": con,
                        "margin_mhz": round(margin, 2), "pass": ach >= con}
    if not clocks:
        lines.append("  no clock in the report")
        ok = False
    lines += ["", f"Timing check: {'PASS' if ok else 'FAIL'}"]
    text = "\n".join(lines) + "\n"
    print(text, end="")
    out = Path(a.out)
    out.with_suffix(".txt").write_text(text)
    out.with_suffix(".json").write_text(json.dumps(
        {"num_chips": a.num_chips, "pf_depth": a.pf_depth, "seed": a.seed, "tool": tool,
         "span": a.span,
         "synth_cells": syn, "placed": util, "clocks": clocks, "pass": ok}, indent=1) + "\n")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
